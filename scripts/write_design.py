"""Write the design table of DEM cases (Snakemake script)."""

from demcal.core.rule_log import rule_log
from demcal.design.cases import write_design


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        table = write_design(dict(snakemake.config), snakemake.output.table)
        logger.info("wrote %d cases to %s", len(table), snakemake.output.table)


main(snakemake)  # noqa: F821
