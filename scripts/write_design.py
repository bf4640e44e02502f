"""Write the design table of DEM cases (Snakemake script)."""

from pathlib import Path

from demcal.design import build_design, write_design_table
from demcal.rule_log import rule_log

# Keys of the design config section that each kind of design reads.
KEYS_BY_KIND = {
    "factorial": ("kind", "levels", "fixed"),
    "random": ("kind", "n", "seed", "ranges", "choices", "fixed"),
    "lhs": ("kind", "n", "seed", "ranges", "choices", "fixed"),
    "sobol": ("kind", "n", "seed", "ranges", "choices", "fixed"),
}


def design_spec(section: dict) -> dict:
    """Reduce the validated ``design`` config section to the keys its kind uses."""
    keys = KEYS_BY_KIND[section["kind"]]
    return {k: section[k] for k in keys if k in section and section[k] != {}}


def main(section: dict, output: str, log: str) -> None:
    """Build the design from its config section and write it as CSV."""
    with rule_log(log) as logger:
        table = build_design(design_spec(section))
        Path(output).parent.mkdir(parents=True, exist_ok=True)
        write_design_table(table, output)
        logger.info("wrote %d cases to %s", len(table), output)


if __name__ == "__main__":
    main(dict(snakemake.params.spec), snakemake.output.table, snakemake.log[0])  # noqa: F821
