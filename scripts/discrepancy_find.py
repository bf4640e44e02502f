"""Discrepancy step 1 (Find): best achievable misfit of the current model, gap and verdict."""

from demcal.core.rule_log import rule_log
from demcal.discrepancy.model_from_files import write_find


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        result = write_find(
            dict(zip(snakemake.params.outputs, snakemake.input.models, strict=True)),
            snakemake.input.experiment,
            dict(snakemake.config),
            snakemake.output.table,
            snakemake.output.record,
            snakemake.output.markdown,
        )
        logger.info("%s; theta* = %s", result.verdict, result.best.theta)


main(snakemake)  # noqa: F821
