"""A tiny sequential calibration with real Snakemake and the real engine: two rounds, the stop
decision, the report, the reuse of the last round in the usual stages, and a resumed study that
runs no DEM case twice."""

import json
import shutil
from pathlib import Path

import pandas as pd
import pytest
import yaml

from demcal.core.config import load_config
from demcal.sequential.rounds import round_case_ids, runs_per_set, verification_runs
from tests.engine.conftest import TEST_RAYLEIGH_FRACTION
from tests.figures import read_png
from tests.workflow.test_tiny_workflow import scratch_study, snakemake

ROOT = Path(__file__).resolve().parents[2]

pytestmark = [pytest.mark.workflow, pytest.mark.slow]

TARGETS = (
    "results/sequential/rounds.md",
    "results/verification/verification.md",
    "results/identification/table5.md",
    "results/surrogates/table4.md",
    "results/bulk/run_times.csv",
)


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """Round 0 alone first (an interrupted study), then the whole loop."""
    config = yaml.safe_load((ROOT / "config" / "tiny.yaml").read_text())
    config["design"]["n"] = 7
    # smaller cells than the tiny profile: the loop is under test here, not the bulk values
    config["shear_cell"]["dCylDp"] = 8
    config["angle_of_repose"]["dCylDp"] = 8
    config["material"]["rayleigh_fraction"] = TEST_RAYLEIGH_FRACTION
    # One shear deck per set (2 runs per set) with the measured P = 1 and one shear point.
    config["shear_cell"]["separate_runs"] = False
    config["shear_cell"]["P"] = [0.6, 1.0]
    config["sequential"] = {"enabled": True, "batch": 2, "max_rounds": 2, "candidates": 3000}
    config["surrogate"] = {"hidden_sizes": [3, 4], "cv_folds": 0, "max_epochs": 200}
    config["screening"] = {
        "axes": {
            "coefficientFriction": [0.1, 1.0, 24],
            "coefficientRollingFriction": [0.1, 1.0, 24],
            "coefficientRestitution": [0.5, 0.9, 6],
            "density": [2500.0, 3500.0, 6],
        }
    }
    work = scratch_study(tmp_path_factory.mktemp("sequential_study"), config)
    first = snakemake(work, "--", "results/sequential/round_0/state.json")
    assert first.returncode == 0, first.stderr[-6000:]
    stamps = {p: p.stat().st_mtime_ns for p in (work / "results/cases").rglob("status.json")}
    res = snakemake(work, "--", *TARGETS)
    assert res.returncode == 0, res.stderr[-6000:]
    return work, load_config(work / "config.yaml"), stamps


def _record(work: Path, round_no: int) -> dict:
    return json.loads((work / f"results/sequential/round_{round_no}/state.json").read_text())


def test_rounds_count_every_dem_run(study):
    work, config, _ = study
    table = pd.read_csv(work / "results/sequential/rounds.csv")
    assert list(table["round"]) == [0, 1]
    assert list(table["sets"]) == [7, 2]
    # every engine run of the study: the cases of each round and the verification runs
    cases = sum(1 for _ in (work / "results/cases").rglob("status.json"))
    verified = sum(1 for _ in (work / "results/sequential").rglob("status.json"))
    assert table["runs_total"].iloc[-1] == cases + verified
    assert cases == 9 * runs_per_set(config)
    assert verified in (0, verification_runs(config), 2 * verification_runs(config))
    # two rounds at most: round 1 stops, for a reason the rule gives
    last = _record(work, 1)
    assert last["stop"] and last["reason"].split(":")[0] in ("verified", "max_rounds", "budget")
    assert not _record(work, 0)["stop"]
    text = (work / "results/sequential/rounds.md").read_text()
    assert text.startswith(f"# Sequential calibration: 2 round(s), {last['runs_total']} DEM runs")
    image = read_png(work / "results/sequential/rounds.png")
    assert image.shape[0] > 300 and image.std() > 0.05


def test_next_round_follows_the_rule(study):
    """Round 1's sets: the valid ones are sets the round-0 screening accepted, the others lie
    near the valid region by the processes' own misfit; all inside the design box."""
    work, config, _ = study
    choices = pd.read_csv(work / "results/sequential/round_1/choices.csv")
    design = pd.read_csv(work / "results/sequential/round_1/design.csv")
    assert list(design["case_id"]) == ["c0008", "c0009"]
    assert set(choices["reason"]) <= {"valid", "uncertain", "nearest"}
    for name, (lo, hi) in config["design"]["ranges"].items():
        assert design[name].between(lo, hi).all(), name
    group = _record(work, 0)["group"]
    if group:
        valid = pd.read_csv(
            work
            / "results/sequential/round_0/identification"
            / f"valid_{group.lower().replace(' & ', '_').replace(' ', '_')}.csv.gz"
        )
        for _, row in choices[choices["reason"] == "valid"].iterrows():
            close = (valid["coefficientFriction"] - row["coefficientFriction"]).abs() < 1e-5
            close &= (
                valid["coefficientRollingFriction"] - row["coefficientRollingFriction"]
            ).abs() < 1e-5
            assert close.any()
        near = choices[choices["reason"] == "uncertain"]
        assert (near["misfit"] <= config["sequential"]["near_factor"] + 1e-9).all()
    # the round's cases were rendered from its design
    case = json.loads((work / "results/cases/angle_of_repose/c0008/case.json").read_text())
    assert case["case"]["coefficientFriction"] == pytest.approx(
        float(design["coefficientFriction"].iloc[0])
    )


def test_final_stages_reuse_the_last_round(study):
    """The study's dataset is the last round's; the final identification repeats that round's
    and the verification table holds its runs, not new ones."""
    work, config, _ = study
    final = pd.read_csv(work / "results/bulk/dataset.csv")
    last = pd.read_csv(work / "results/sequential/round_1/dataset.csv")
    pd.testing.assert_frame_equal(final, last)
    # round 1's data: its own cases, round 0's cases and round 0's verification runs
    bases = set(final["design_id"])
    assert {"c0001", "c0008", "c0009"} <= bases
    round0 = _record(work, 0)
    if round0["verification"]:
        assert "identified@round0" in bases
    # the networks and the screening of the last round are taken over, not redone
    for output in ("mu_psh", "aor"):
        final = work / f"results/surrogates/{output}/model.pt"
        looped = work / f"results/sequential/round_1/surrogates/{output}/model.pt"
        assert final.read_bytes() == looped.read_bytes()
        assert (work / f"results/surrogates/{output}/sweep.csv").exists()
    identified = json.loads(
        (work / "results/identification/identified_parameters.json").read_text()
    )
    looped = json.loads(
        (work / "results/sequential/round_1/identification/identified_parameters.json").read_text()
    )
    assert identified["parameters"] == looped["parameters"]
    assert not (work / "results/verification/configured").exists()
    if looped["parameters"]:
        table = pd.read_csv(work / "results/verification/verification.csv")
        aor = table.set_index("observable").loc["aor"]
        heap = pd.read_csv(
            work / "results/sequential/round_1/verification/angle_of_repose/identified/bulk.csv"
        )
        assert aor["dem_configured"] == pytest.approx(float(heap["aor"].iloc[0]))
    times = pd.read_csv(work / "results/bulk/run_times.csv")
    expected = {
        c
        for r in (0, 1)
        for t in ("shear_cell", "angle_of_repose")
        for c in round_case_ids(config, r, t)
    }
    assert set(times["case_id"]) == expected


def test_resumed_study_reruns_nothing(study):
    """Round 0 ran alone first; the whole loop afterwards did not rerun its DEM cases, and a
    finished study has nothing left to do."""
    work, _, stamps = study
    assert stamps, "round 0 ran no case"
    for path, stamp in stamps.items():
        assert path.stat().st_mtime_ns == stamp, path
    again = snakemake(work, "-n", "--", *TARGETS)
    assert again.returncode == 0
    assert "Nothing to be done" in again.stdout + again.stderr


def test_study_interrupted_after_a_later_identification_resumes(study, tmp_path):
    """Stopped after round 1's identification and verification runs, before its record: the
    resumed study writes the same record and table from the finished runs and runs no DEM case
    again (Snakemake registers a finished checkpoint only for jobs of its first pass over the
    DAG, and round 1's identification is not among them here)."""
    work, _, _ = study
    copy = tmp_path / "resumed"
    shutil.copytree(work, copy, symlinks=True)
    seq = copy / "results" / "sequential"
    record, table = seq / "round_1" / "state.json", seq / "rounds.csv"
    before = record.read_text(), table.read_text()
    runs = {p: p.stat().st_mtime_ns for p in (copy / "results").rglob("status.json")}
    assert len(runs) > 0
    for path in (record, seq / "round_1" / "verification.md", *seq.glob("rounds.*")):
        path.unlink()
    res = snakemake(copy, "--", "results/sequential/rounds.md")
    assert res.returncode == 0, res.stderr[-6000:]
    assert (record.read_text(), table.read_text()) == before
    for path, stamp in runs.items():
        assert path.stat().st_mtime_ns == stamp, path
