"""Discrepancy step 2 (Name): score the candidate effects with their probe runs, rank them and
write the extended design of the winner."""

from demcal.core.rule_log import rule_log
from demcal.discrepancy.probe_ranking import write_ranking


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        out = snakemake.output
        result = write_ranking(
            dict(zip(snakemake.params.outputs, snakemake.input.models, strict=True)),
            snakemake.input.experiment,
            dict(snakemake.config),
            snakemake.input.find,
            snakemake.input.probes,
            out.table,
            out.markdown,
            out.record,
            out.probes,
            out.design,
            snakemake.input.lead,
            snakemake.input.reprobes,
            out.reprobes,
        )
        if result is None:
            logger.info("nothing missing; ranking not run")
        else:
            logger.info("ranking:\n%s", result.table.to_string())


main(snakemake)  # noqa: F821
