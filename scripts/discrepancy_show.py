"""Discrepancy step 4 (Show): gap before and after, figure, verification and summary."""

import json
from pathlib import Path

import pandas as pd

from demcal.core.provenance import write_sidecar
from demcal.core.rule_log import rule_log
from demcal.discrepancy.extension import read_runs
from demcal.discrepancy.report import gap_figure, verification_markdown
from demcal.discrepancy.workflow import show


def main(sm) -> None:
    with rule_log(sm.log[0]) as logger:
        inp = sm.input
        find_rec = json.loads(Path(inp.find).read_text())
        ranking_rec = json.loads(Path(inp.ranking).read_text())
        extended = "recalibration" in inp.keys()
        table, summary = show(
            pd.read_csv(inp.find_table),
            find_rec,
            ranking_rec,
            pd.read_csv(inp.after_table) if extended else None,
            json.loads(Path(inp.recalibration).read_text()) if extended else None,
            read_runs(inp.reference),
            read_runs(inp.verification) if extended else pd.DataFrame(),
        )
        table.to_csv(sm.output.table, index=False, float_format="%.6g")
        title = (
            f"gap {summary['gap_before_common']:.2f} -> {summary['gap_after']:.2f} after adding "
            f"{summary['winner']} (common sigma)"
            if extended
            else f"gap {summary['gap_before']:.2f}: {summary['reason']}"
        )
        gap_figure(table, title, sm.output.figure)
        Path(sm.output.verification).write_text(verification_markdown(table, summary))
        Path(sm.output.summary).write_text(json.dumps(summary, indent=2, default=float) + "\n")
        write_sidecar(sm.output.summary, dict(sm.config))
        logger.info("summary: %s", summary)


if __name__ == "__main__":
    main(snakemake)  # noqa: F821
