"""Synthetic measurements as a laboratory states them: the mean of replicate runs from fresh
packings, with their standard error as the sd (one quick run scatters by as much as the
acceptance tolerance), made with the real engine on the tiny decks."""

import math
from pathlib import Path

import pytest
import yaml

from demcal.bulk.synthetic import simulate_reference, write_synthetic_experiment
from demcal.core.config import load_config
from demcal.core.experiments import load_experiment
from demcal.design.cases import shear_suffixes
from tests.engine.conftest import TEST_RAYLEIGH_FRACTION, engine_path

pytestmark = pytest.mark.engine

ROOT = Path(__file__).resolve().parents[2]
TRUTH = ROOT / "config" / "experiments" / "truth" / "synthetic_reference.yaml"


def test_reference_is_the_mean_of_replicates_and_resumes(tmp_path: Path):
    cfg = load_config(ROOT / "config" / "tiny.yaml")
    cfg["material"]["rayleigh_fraction"] = TEST_RAYLEIGH_FRACTION
    cfg["engine"]["command"] = f"{engine_path()} -in {{deck}} -noprogress"
    config_path = tmp_path / "tiny.yaml"
    config_path.write_text(yaml.safe_dump(cfg, sort_keys=False))
    runs = tmp_path / "runs"

    out = write_synthetic_experiment(
        config_path, TRUTH, tmp_path / "reference.yaml", replicates=2, work_dir=runs, workers=2
    )
    statuses = sorted(runs.glob("*/*/status.json"))
    # A heap and the shear decks of one design row (one per P at the tiny scale) per replicate.
    suffixes = shear_suffixes(cfg)
    assert len(suffixes) == 4
    assert [p.relative_to(runs).parent.as_posix() for p in statuses] == [
        "angle_of_repose/reference0",
        "angle_of_repose/reference1",
        *(f"shear_cell/reference{r}{s}" for r in (0, 1) for s in suffixes),
    ]
    stamps = [p.stat().st_mtime_ns for p in statuses]

    # The same runs asked for again are read back from the work directory, not run again.
    truth = yaml.safe_load(TRUTH.read_text())["parameters"]
    bulk = simulate_reference(truth, load_config(config_path), runs, replicates=2)
    assert [p.stat().st_mtime_ns for p in statuses] == stamps
    assert sorted(bulk["replicate"].unique()) == [0, 1]

    made = load_experiment(out)
    assert "mean of 2 runs, noise 0.0%" in yaml.safe_load(out.read_text())["source"]
    # Fresh packings: the two heaps differ, and the stated angle is their mean with the
    # standard error of two runs, |a - b| / 2, as its sd.
    heaps = bulk[bulk["test"] == "angle_of_repose"].sort_values("replicate")["aor"].to_list()
    assert heaps[0] != heaps[1]
    assert made.angle_of_repose == pytest.approx(sum(heaps) / 2, abs=1e-4)
    assert made.angle_of_repose_sd == pytest.approx(abs(heaps[0] - heaps[1]) / 2, abs=1e-4)
    shear = bulk[bulk["test"] == "shear_cell"]
    assert len(made.shear_conditions) == 4
    for cond in made.shear_conditions:
        rows = shear[shear["P"].round(6) == round(cond.P, 6)]
        assert len(rows) == 2, cond.label
        for name in ("mu_psh", "mu_sh", "rho_b"):
            values = rows[name].to_numpy(float)
            assert cond.values[name] == pytest.approx(values.mean(), rel=1e-5), cond.label
            se = abs(values[0] - values[1]) / 2
            assert cond.uncertainties[name] == pytest.approx(se, rel=1e-4, abs=1e-9), cond.label
            assert math.isfinite(cond.values[name]) and cond.values[name] > 0
