"""Discrepancy step 3 (Add): recalibrate the extended model (its magnitude as one more axis)."""

from demcal.core.rule_log import rule_log
from demcal.discrepancy.recalibration import write_recalibration


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        result, record = write_recalibration(
            dict(zip(snakemake.params.outputs, snakemake.input.models, strict=True)),
            snakemake.input.experiment,
            dict(snakemake.config),
            snakemake.input.ranking,
            snakemake.output.table,
            snakemake.output.record,
            snakemake.output.markdown,
        )
        logger.info("extended model: %s; best point %s", result.verdict, record["point"])


main(snakemake)  # noqa: F821
