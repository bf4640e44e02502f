"""Discrepancy step 3 (Add): the training data of the extended model."""

from demcal.core.rule_log import rule_log
from demcal.discrepancy.extension import write_extended_dataset


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        data = write_extended_dataset(
            dict(snakemake.config),
            snakemake.input.ranking,
            snakemake.input.dataset,
            snakemake.input.probes,
            snakemake.input.extended,
            list(snakemake.params.tests),
            snakemake.output.dataset,
        )
        logger.info("extended training data: %s", data["source"].value_counts().to_dict())


main(snakemake)  # noqa: F821
