"""Runs at known parameters (truths, references) resume after an interruption: a case that
finished in its directory with the same command and deck is read back, anything else runs."""

import json
from pathlib import Path

import pandas as pd
import pytest

from demcal.bulk.synthetic import run_case_bulk
from demcal.core.config import load_config
from tests.engine.conftest import TEST_RAYLEIGH_FRACTION, engine_path

pytestmark = pytest.mark.engine

ROOT = Path(__file__).resolve().parents[2]
CASE = {
    "case_id": "truth0",
    "coefficientFriction": 0.4,
    "coefficientRollingFriction": 0.2,
    "coefficientRestitution": 0.6,
    "density": 2500.0,
}


def test_finished_run_is_read_back_and_a_changed_one_runs(tmp_path: Path):
    cfg = load_config(ROOT / "config" / "tiny.yaml")
    cfg["material"]["rayleigh_fraction"] = TEST_RAYLEIGH_FRACTION
    cfg["engine"]["command"] = f"{engine_path()} -in {{deck}} -noprogress"
    case_dir = tmp_path / "angle_of_repose" / "truth0"

    first = run_case_bulk("angle_of_repose", CASE, cfg, case_dir, "truth run")
    assert 5.0 < float(first["aor"].iloc[0]) < 45.0
    status = (case_dir / "status.json").read_text()
    assert json.loads(status)["status"] == "ok"
    stamp = (case_dir / "engine.out").stat().st_mtime_ns

    again = run_case_bulk("angle_of_repose", CASE, cfg, case_dir, "truth run")
    pd.testing.assert_frame_equal(first, again)
    assert (case_dir / "status.json").read_text() == status
    assert (case_dir / "engine.out").stat().st_mtime_ns == stamp

    # The same deck with another command runs (here one that fails at once).
    failing = {**cfg, "engine": {**cfg["engine"], "command": "false -in {deck}"}}
    with pytest.raises(RuntimeError, match=r"truth run .*truth0 failed"):
        run_case_bulk("angle_of_repose", CASE, failing, case_dir, "truth run")
    # A failed run is never read back: the engine runs the case again, to the same result.
    rerun = run_case_bulk("angle_of_repose", CASE, cfg, case_dir, "truth run")
    pd.testing.assert_frame_equal(first, rerun)
    assert (case_dir / "engine.out").stat().st_mtime_ns != stamp
    stamp = (case_dir / "engine.out").stat().st_mtime_ns

    # Another parameter value renders another deck, which runs.
    changed = run_case_bulk(
        "angle_of_repose", {**CASE, "coefficientFriction": 0.6}, cfg, case_dir, "truth run"
    )
    assert (case_dir / "engine.out").stat().st_mtime_ns != stamp
    assert (
        "coefficientFriction peratomtypepair 2 0.6 "
        in (case_dir / "in.angle_of_repose").read_text()
    )
    assert json.loads((case_dir / "status.json").read_text())["status"] == "ok"
    assert float(changed["aor"].iloc[0]) != float(first["aor"].iloc[0])
