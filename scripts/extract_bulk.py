"""Bulk values of one DEM case (a failed run gives rows flagged as failed)."""

from pathlib import Path

from demcal.bulk_values import extract
from demcal.dataset import case_rows
from demcal.rule_log import rule_log


def main(test: str, info: str, p_values: list[float], output: str, log: str) -> None:
    with rule_log(log) as logger:
        rows = case_rows(test, Path(info).parent, extract, p_values)
        rows.to_csv(output, index=False, float_format="%.10g")
        logger.info("%d rows, status %s", len(rows), rows["status"].iloc[0])


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    main(sm.wildcards.test, sm.input.info, list(sm.params.p_values), sm.output.bulk, sm.log[0])
