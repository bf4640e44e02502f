"""Cycle-to-cycle readings of multi-cycle shear-cell decks: the table, the decks, the script."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from demcal.bulk.cycle_drift import cycle_table
from demcal.bulk.engine_comparison import plan_runs
from demcal.core.config import load_config

ROOT = Path(__file__).resolve().parents[2]
SET = {
    "coefficientFriction": 0.5,
    "coefficientRollingFriction": 0.2,
    "coefficientRestitution": 0.6,
    "density": 2500.0,
}
# A first pre-shear 6 % above the steady state, then a bed that loosens by 1 % a cycle.
FRICTION = np.array([1.06, 1.0, 0.97, 0.97])
DENSITY = np.array([1.02, 1.01, 1.0, 0.99])


def _decks(levels: list[float]) -> pd.DataFrame:
    rows = []
    for d, level in enumerate(levels):
        for cycle, P in enumerate((0.4, 0.6, 0.8, 1.0)):
            rows.append(
                {
                    "case_id": f"c{d}",
                    "cycle": cycle,
                    "P": P,
                    "mu_psh_cycle": level * FRICTION[cycle],
                    "rho_b_cycle": 1500.0 * level * DENSITY[cycle],
                    "mu_sh": 1.02 * level * FRICTION[cycle],
                    "steady_psh": cycle > 0 or d == 0,
                }
            )
    return pd.DataFrame(rows)


def test_cycle_table_reads_each_cycle_against_its_deck() -> None:
    table = cycle_table(_decks([0.45, 0.6, 0.75]))
    assert table["P"].tolist() == [0.4, 0.6, 0.8, 1.0]
    assert table["decks"].tolist() == [3, 3, 3, 3]
    # Whatever the decks' levels, the ratios are the pattern over its mean.
    assert table["psh"].to_numpy() == pytest.approx(FRICTION / FRICTION.mean())
    assert table["rho"].to_numpy() == pytest.approx(DENSITY / DENSITY.mean())
    assert table["sh"].to_numpy() == pytest.approx(np.full(4, 1.02))
    assert table["psh_se"].to_numpy() == pytest.approx(np.zeros(4), abs=1e-12)
    assert table["steady"].tolist() == pytest.approx([1 / 3, 1.0, 1.0, 1.0])


def test_cycle_table_needs_decks_with_cycles() -> None:
    separate = _decks([0.5, 0.6]).query("cycle == 0")
    with pytest.raises(ValueError, match="two or more cycles"):
        cycle_table(separate)
    with pytest.raises(ValueError, match="rho_b_cycle"):
        cycle_table(_decks([0.5]).drop(columns="rho_b_cycle"))


def test_decks_without_P_run_every_value_of_P_as_a_cycle(tmp_path: Path) -> None:
    settings = load_config(ROOT / "config" / "config.yaml")
    settings["shear_cell"]["run_in_travel"] = 0.75
    engines = {"engine": "x -in {deck}", "liggghts": "liggghts -in {deck}"}
    jobs = plan_runs(
        settings, {"mid": SET}, [1], tmp_path, engines, ("shear_cell",), 1068.0, P=None
    )
    assert [job.engine for job in jobs] == ["engine", "liggghts"]
    record = json.loads((jobs[0].case_dir / "case.json").read_text())
    assert "P" not in record["case"] and record["case"]["normal_stress"] == 1068.0
    cycles = record["setup"]["cycles"]
    assert [c["P"] for c in cycles] == settings["shear_cell"]["P"]
    preshears = [c["preshear_end_step"] - c["preshear_start_step"] for c in cycles]
    # The run-in doubles the first pre-shear (0.75 R more on 0.75 R) and no other.
    assert preshears[0] == pytest.approx(2 * preshears[1], abs=2)
    assert len(set(preshears[1:])) == 1
    # The same deck for both codes.
    decks = [(job.case_dir / "in.shear_cell").read_text() for job in jobs]
    assert decks[0] == decks[1]


def _script(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "cycle_study.py"), *args],
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_script_stops_on_a_misspelt_key_before_any_run(tmp_path: Path) -> None:
    out = tmp_path / "study"
    res = _script("--set", "shear_cell.run_in_trave=1", "--out", str(out))
    assert res.returncode != 0 and "run_in_trave" in res.stderr, res.stderr
    assert not out.exists()


def test_script_needs_two_values_of_P_before_any_run(tmp_path: Path) -> None:
    out = tmp_path / "study"
    res = _script("--set", "shear_cell.P=[0.6]", "--out", str(out))
    assert res.returncode != 0 and "at least two values of P" in res.stderr, res.stderr
    assert not out.exists()


def test_script_tabulates_a_studys_dataset(tmp_path: Path) -> None:
    dataset = tmp_path / "dataset.csv"
    _decks([0.45, 0.6]).assign(test="shear_cell").to_csv(dataset, index=False)
    res = _script("--dataset", str(dataset))
    assert res.returncode == 0, res.stderr
    first = next(line for line in res.stdout.splitlines() if line.startswith("| 0 |"))
    assert f"{FRICTION[0] / FRICTION.mean():.3f} +- 0.000" in first
