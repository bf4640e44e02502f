"""The rounds of a sequential study: table and figure."""

from demcal.core.rule_log import rule_log
from demcal.sequential.round_steps import write_rounds_report


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        table = write_rounds_report(
            dict(snakemake.config),
            list(snakemake.input.records),
            list(snakemake.input.identified),
            snakemake.output.table,
            snakemake.output.markdown,
            snakemake.output.figure,
        )
        logger.info("%d rounds, %d DEM runs", len(table), int(table["runs_total"].iloc[-1]))


main(snakemake)  # noqa: F821
