"""Discrepancy step 2, first round: the leading candidates on the probes at theta* and their
own best fits, where they are probed again before the naming."""

from demcal.core.rule_log import rule_log
from demcal.discrepancy.probe_ranking import write_lead


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        points = write_lead(
            dict(zip(snakemake.params.outputs, snakemake.input.models, strict=True)),
            snakemake.input.experiment,
            dict(snakemake.config),
            snakemake.input.find,
            snakemake.input.probes,
            snakemake.output.record,
        )
        for name, point in points.items():
            logger.info("%s probed again at %s", name, point)
        if not points:
            logger.info("no candidate to probe again")


main(snakemake)  # noqa: F821
