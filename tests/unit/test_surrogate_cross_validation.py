"""The cross-validation script on a finished dataset (scripts/surrogate_cross_validation.py)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "surrogate_cross_validation.py"


def _heaps(n: int, seed: int) -> pd.DataFrame:
    """Heaps whose angle rises steeply with mu_s below 0.3 and flattens above (ln mu_s)."""
    rng = np.random.default_rng(seed)
    mu_s, mu_r = rng.uniform(0.1, 1.0, n), rng.uniform(0.1, 1.0, n)
    return pd.DataFrame(
        {
            "test": "angle_of_repose",
            "case_id": [f"c{k:04d}" for k in range(1, n + 1)],
            "design_id": [f"c{k:04d}" for k in range(1, n + 1)],
            "coefficientFriction": mu_s,
            "coefficientRollingFriction": mu_r,
            "coefficientRestitution": rng.uniform(0.5, 0.9, n),
            "density": rng.uniform(2500.0, 3500.0, n),
            "aor": 38.0 + 8.0 * np.log(mu_s) + 6.0 * mu_r + rng.normal(0.0, 0.3, n),
            "status": "ok",
        }
    )


def _run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(SCRIPT), *args], capture_output=True, text=True, timeout=600
    )


def test_script_cross_validates_every_method_on_the_files_given(tmp_path: Path) -> None:
    # Two files (as per-case bulk.csv files would be) are read as one dataset of 30 sets.
    heaps = _heaps(30, seed=4)
    heaps.iloc[:15].to_csv(tmp_path / "a.csv", index=False)
    heaps.iloc[15:].to_csv(tmp_path / "b.csv", index=False)
    config = yaml.safe_load((ROOT / "config" / "tiny.yaml").read_text())
    config["surrogate"] = {"hidden_sizes": [4, 6], "max_epochs": 200}
    (tmp_path / "cfg.yaml").write_text(yaml.safe_dump(config))
    out = tmp_path / "cv"
    res = _run(
        "--dataset", str(tmp_path / "a.csv"), str(tmp_path / "b.csv"),
        "--config", str(tmp_path / "cfg.yaml"), "--out", str(out),
    )  # fmt: skip
    assert res.returncode == 0, res.stderr
    lines = (out / "cross_validation.md").read_text().splitlines()[2:]
    table = {line.split("|")[2].strip(): line.split("|") for line in lines}
    assert set(table) == {"Bayesian", "Gaussian", "ANN"}
    assert all(row[1].strip() == "aor" and row[3].strip() == "30" for row in table.values())
    # The process, on ln(mu_s), recovers the response within its noise of 0.3 deg.
    assert float(table["Gaussian"][5]) > 0.97
    assert float(table["Gaussian"][6]) < 1.0
    assert (out / "aor" / "table4.csv").is_file()


def test_script_names_a_missing_dataset_file(tmp_path: Path) -> None:
    res = _run("--dataset", str(tmp_path / "nope.csv"), "--out", str(tmp_path / "cv"))
    assert res.returncode != 0 and "nope.csv" in res.stderr
    assert not (tmp_path / "cv").exists()


def test_script_scores_the_design_of_its_config_on_a_larger_dataset(tmp_path: Path) -> None:
    # 30 heap sets on file; a design of the first 12 is scored on their runs alone.
    _heaps(30, seed=4).to_csv(tmp_path / "heaps.csv", index=False)
    config = yaml.safe_load((ROOT / "config" / "tiny.yaml").read_text())
    config["surrogate"] = {"hidden_sizes": [4, 5], "max_epochs": 100}
    config["design"] = {**config["design"], "n": 12}
    (tmp_path / "cfg.yaml").write_text(yaml.safe_dump(config))
    out = tmp_path / "cv"
    args = ("--dataset", str(tmp_path / "heaps.csv"), "--config", str(tmp_path / "cfg.yaml"))
    res = _run(*args, "--design-cases", "--out", str(out))
    assert res.returncode == 0, res.stderr
    rows = (out / "cross_validation.md").read_text().splitlines()[2:]
    assert {row.split("|")[4].strip() for row in rows} == {"12"}
    # A design with cases the dataset lacks is refused before any training.
    config["design"]["n"] = 40
    (tmp_path / "cfg.yaml").write_text(yaml.safe_dump(config))
    res = _run(*args, "--design-cases", "--out", str(tmp_path / "cv40"))
    assert res.returncode != 0
    assert "10 cases of the design" in res.stderr and "c0031" in res.stderr
    assert not (tmp_path / "cv40").exists()
