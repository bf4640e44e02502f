"""Segregation in the analysed box of the chute-cooler run: table, index, time series."""

import json
from pathlib import Path

from demcal.application.chute_cooler.analysis import (
    analyse_run,
    index_summary,
    read_system_table,
    write_json,
)
from demcal.application.chute_cooler.figures import plot_steady_state
from demcal.core.provenance import write_sidecar
from demcal.core.rule_log import rule_log


def main(status: str, outputs: dict, config: dict, log: str) -> None:
    with rule_log(log) as logger:
        case_dir = Path(status).parent
        result, record, setup = analyse_run(case_dir)
        run_status = json.loads(Path(status).read_text())
        summary = index_summary(result, record, run_status)
        Path(outputs["table"]).parent.mkdir(parents=True, exist_ok=True)
        result.table.to_csv(outputs["table"], index=False)
        result.series.to_csv(outputs["series"], index=False)
        write_json(summary, outputs["index"])
        plot_steady_state(
            result.series,
            result.window,
            outputs["steady"],
            read_system_table(case_dir),
            box_label=f"box {setup.analysed_box}",
        )
        write_sidecar(outputs["table"], config, seed=int(config["seed"]), extra={"index": summary})
        if not result.window.steady:
            logger.warning("box %d NOT steady: %s", setup.analysed_box, result.window.reason)
        logger.info(
            "S = %.4f (normalised %.3f) over %.3g-%.3g s",
            result.index.index,
            result.index.normalised,
            result.window.start_time,
            result.window.end_time,
        )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    main(sm.input.status, dict(sm.output.items()), dict(sm.config), sm.log[0])
