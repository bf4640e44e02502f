"""Collect every case's bulk values into the tidy dataset; list and count failed cases."""

from demcal.bulk.dataset import write_dataset
from demcal.core.rule_log import rule_log


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        bulk = list(snakemake.input.bulk)
        data, bad = write_dataset(
            bulk, snakemake.output.dataset, snakemake.output.failed, dict(snakemake.config)
        )
        if len(bad):
            logger.warning(
                "%d of %d DEM cases failed and are excluded from training: %s",
                len(bad),
                data["case_id"].nunique(),
                ", ".join(bad["case_id"]),
            )
        logger.info("dataset: %d rows from %d files", len(data), len(bulk))


main(snakemake)  # noqa: F821
