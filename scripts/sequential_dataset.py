"""The DEM data after one round of a sequential study: earlier data, the earlier round's
verification runs and the round's own cases."""

from demcal.core.rule_log import rule_log
from demcal.sequential.round_steps import write_round_dataset


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        data = write_round_dataset(
            dict(snakemake.config),
            int(snakemake.wildcards.round),
            list(snakemake.input.bulk),
            snakemake.input.previous[0] if snakemake.input.previous else None,
            list(snakemake.input.verification),
            snakemake.output.dataset,
            snakemake.output.failed,
        )
        logger.info("round %s: %d rows", snakemake.wildcards.round, len(data))


main(snakemake)  # noqa: F821
