"""Write the design table of DEM cases (Snakemake script)."""

from pathlib import Path

from demcal.core.provenance import write_sidecar
from demcal.core.rule_log import rule_log
from demcal.design.cases import design_from_config
from demcal.design.table import write_design_table


def main(config: dict, output: str, log: str) -> None:
    """Build the design from its config section and write it as CSV."""
    with rule_log(log) as logger:
        table = design_from_config(config)
        Path(output).parent.mkdir(parents=True, exist_ok=True)
        write_design_table(table, output)
        write_sidecar(output, config, seed=int(config["design"]["seed"]))
        logger.info("wrote %d cases to %s", len(table), output)


if __name__ == "__main__":
    main(dict(snakemake.config), snakemake.output.table, snakemake.log[0])  # noqa: F821
