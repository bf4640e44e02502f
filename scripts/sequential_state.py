"""Verify a round's identified set, decide whether the sequential study stops, write the round's
record."""

from demcal.core.rule_log import rule_log
from demcal.sequential.round_steps import write_round_record


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        record = write_round_record(
            dict(snakemake.config),
            int(snakemake.wildcards.round),
            snakemake.input.identified,
            list(snakemake.input.verification),
            snakemake.input.experiment,
            dict(zip(snakemake.params.outputs, snakemake.input.table4, strict=True)),
            snakemake.input.previous[0] if snakemake.input.previous else None,
            snakemake.output.record,
            snakemake.output.verification,
        )
        logger.info("round %s: %s", snakemake.wildcards.round, record["reason"])


main(snakemake)  # noqa: F821
