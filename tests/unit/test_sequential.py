"""Sequential calibration: the choice of the next round's sets, the rounds' case ids, the round
dataset and the stopping rule."""

import math

import numpy as np
import pandas as pd
import pytest

from demcal.core.config import load_config
from demcal.core.experiments import Experiment, MeasuredCondition
from demcal.sequential.proposal import (
    BulkProcesses,
    draw_candidates,
    greedy_maximin,
    greedy_uncertain,
    misfit_and_uncertainty,
    observables,
    propose,
    straddle,
    unit_cube,
)
from demcal.sequential.rounds import (
    box_volume,
    check_sequential,
    round_bases,
    round_case_ids,
    round_dataset,
    round_of_case,
    round_record,
    rounds_table,
    runs_per_set,
    valid_box,
    verification_runs,
)

RANGES = {"coefficientFriction": [0.1, 1.0], "coefficientRollingFriction": [0.1, 1.0]}


@pytest.fixture
def config(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text(
        "profile: tiny\n"
        "design: {kind: lhs, n: 6, seed: 3, ranges: {coefficientFriction: [0.1, 1.0],"
        " coefficientRollingFriction: [0.1, 1.0]}}\n"
        "shear_cell: {normal_stresses: [2029.0], P: [0.5, 1.0], separate_runs: true}\n"
        "sequential: {enabled: true, batch: 3, max_rounds: 4, budget: 60}\n"
        "verification: {seeds: 2}\n"
    )
    return load_config(path)


def test_round_ids_continue_the_numbering(config):
    assert round_bases(config, 0) == [f"c{i:04d}" for i in range(1, 7)]
    assert round_bases(config, 1) == ["c0007", "c0008", "c0009"]
    assert round_bases(config, 3) == ["c0013", "c0014", "c0015"]
    assert [round_of_case(config, b) for b in ("c0006", "c0007", "c0009", "c0010", "c0015")] == [
        0,
        1,
        1,
        2,
        3,
    ]
    assert round_case_ids(config, 1, "shear_cell")[:2] == ["c0007_s1_p1", "c0007_s1_p2"]
    assert round_case_ids(config, 1, "angle_of_repose") == ["c0007", "c0008", "c0009"]
    # two shear decks and one heap per set; two replicate seeds per verification
    assert runs_per_set(config) == 3 and verification_runs(config) == 6
    heaps = {**config, "design": {**config["design"], "repose_replicates": 3}}
    assert round_case_ids(heaps, 1, "angle_of_repose")[:4] == [
        "c0007",
        "c0007_r2",
        "c0007_r3",
        "c0008",
    ]
    assert runs_per_set(heaps) == 2 + 3
    nine = {**config, "verification": {**config["verification"], "repose_seeds": 9}}
    assert verification_runs(nine) == 2 * 2 + 9


def test_factorial_and_choices_are_refused(config):
    with pytest.raises(ValueError, match=r"design\.kind"):
        check_sequential({**config, "design": {**config["design"], "kind": "factorial"}})
    with pytest.raises(ValueError, match=r"design\.choices"):
        check_sequential({**config, "design": {**config["design"], "choices": {"dCylDp": [8]}}})


def _bulk(tmp_path, name, rows):
    path = tmp_path / f"{name}.csv"
    pd.DataFrame(rows).to_csv(path, index=False)
    return path


def test_round_dataset_names_the_verification_runs(tmp_path):
    row = {"test": "angle_of_repose", "status": "ok", "aor": 30.0, "coefficientFriction": 0.5}
    previous = _bulk(tmp_path, "prev", [{**row, "case_id": "c0001", "design_id": "c0001"}])
    verify = [
        _bulk(tmp_path, f"v{k}", [{**row, "case_id": f"identified{k}", "design_id": "x"}])
        for k in ("", "2")
    ]
    new = [_bulk(tmp_path, "new", [{**row, "case_id": "c0007", "design_id": "c0007"}])]
    data = round_dataset(new, previous, verify, previous_round=0)
    assert list(data["case_id"]) == ["c0001", "c0007", "identified@round0", "identified2@round0"]
    # both replicates are one parameter set: they never straddle a train/test split
    assert list(data["design_id"])[2:] == ["identified@round0"] * 2


def test_greedy_maximin_spreads_and_avoids_earlier_runs():
    pool = np.array([[0.0, 0.0], [0.05, 0.0], [1.0, 1.0], [0.5, 0.5]])
    existing = np.array([[0.0, 0.05]])
    # far corner first, then the centre; the two points next to the earlier run last
    assert greedy_maximin(pool, existing, 2) == [2, 3]
    assert greedy_maximin(pool, np.empty((0, 2)), 4)[0] == 0
    # asking for more than the pool holds gives the whole pool, farthest first
    assert greedy_maximin(pool, existing, 10) == [2, 3, 1, 0]


def test_propose_follows_the_stated_rule():
    """Half of the batch inside the valid sets, the rest the most uncertain near ones; a far,
    very uncertain candidate is never chosen."""
    candidates = pd.DataFrame(
        {"coefficientFriction": [0.2, 0.3, 0.9, 0.95, 0.5], "coefficientRollingFriction": 0.5}
    )
    misfit = np.array([1.5, 1.8, 9.0, 9.0, 2.9])
    # straddle scores 0.48, 3.12, 89, 89, 0.06
    uncertainty = np.array([0.5, 2.0, 50.0, 50.0, 1.0])
    valid = pd.DataFrame(
        {"coefficientFriction": [0.41, 0.42, 0.6], "coefficientRollingFriction": [0.5, 0.5, 0.5]}
    )
    existing = pd.DataFrame({"coefficientFriction": [0.4], "coefficientRollingFriction": [0.5]})
    chosen = propose(candidates, misfit, uncertainty, valid, existing, RANGES, 4, 0.5, 3.0)
    assert list(chosen["reason"]) == ["valid", "valid", "uncertain", "uncertain"]
    # the valid set farthest from the earlier run first
    assert chosen["coefficientFriction"].iloc[0] == pytest.approx(0.6)
    # the near candidate whose band straddles the edge most first; the far ones (misfit 9) never
    assert chosen["coefficientFriction"].iloc[2] == pytest.approx(0.3)
    assert not set(chosen["coefficientFriction"]) & {0.9, 0.95}
    # nothing valid and nothing near: the sets with the smallest misfit, spread out
    far = propose(candidates, misfit + 10, uncertainty, valid.iloc[:0], existing, RANGES, 2, 0.5, 3)
    assert set(far["reason"]) == {"nearest"} and len(far) == 2


def test_processes_find_the_region_of_a_known_response():
    """A response known in closed form: the misfit is smallest where it meets the measurement
    and the uncertainty is largest far from the runs."""
    rng = np.random.default_rng(0)
    mu = rng.uniform(0.1, 1.0, 40)
    data = pd.DataFrame(
        {
            "test": "angle_of_repose",
            "status": "ok",
            "design_id": [f"c{i:04d}" for i in range(40)],
            "coefficientFriction": mu,
            "coefficientRollingFriction": rng.uniform(0.1, 1.0, 40),
            "aor": 20.0 + 20.0 * mu,
        }
    )
    experiment = Experiment("m", "", [], angle_of_repose=30.0)
    measured = observables(experiment)
    processes = BulkProcesses(data, ["aor"], {}, seed=1)
    candidates = draw_candidates(RANGES, 2000, seed=2)
    misfit, uncertainty = misfit_and_uncertainty(candidates, processes, measured, 0.05)
    best = candidates["coefficientFriction"].to_numpy()[misfit <= 1.0]
    # aor = 30 +- 5 % at mu = 0.5 +- 0.075
    assert best.min() > 0.40 and best.max() < 0.60 and len(best) > 100
    assert np.all(uncertainty < 1.0)  # inside the data the process is sure to a tolerance


def test_straddle_prefers_the_uncertain_edge():
    misfit = np.array([1.0, 1.0, 3.0, 0.0])
    uncertainty = np.array([0.1, 1.0, 1.0, 0.1])
    np.testing.assert_allclose(straddle(misfit, uncertainty), [0.196, 1.96, -0.04, -0.804])
    # damping: a candidate at an earlier run scores nothing, one far away keeps its score
    pool = np.array([[0.0, 0.0], [0.02, 0.0], [0.9, 0.9], [0.5, 0.5]])
    score = np.array([5.0, 4.9, 4.5, 1.0])
    assert greedy_uncertain(pool, score, np.array([[0.0, 0.0]]), 2) == [2, 1]


def test_observables_cover_every_measured_value():
    experiment = Experiment(
        "m",
        "",
        [MeasuredCondition(values={"mu_psh": 0.6, "rho_b": 1700.0}, normal_stress=2029.0, P=1.0)],
        angle_of_repose=38.0,
    )
    found = observables(experiment)
    assert [(o.output, o.measured) for o in found] == [
        ("mu_psh", 0.6),
        ("rho_b", 1700.0),
        ("aor", 38.0),
    ]
    assert found[0].load == {"normal_stress": 2029.0, "P": 1.0} and found[2].load == {}


def test_valid_box_and_volume():
    valid = pd.DataFrame(
        {"coefficientFriction": np.linspace(0.1, 1.0, 101), "coefficientRollingFriction": 0.55}
    )
    box = valid_box(valid, RANGES)
    assert box["coefficientFriction"] == pytest.approx([0.05, 0.95])
    assert box["coefficientRollingFriction"] == pytest.approx([0.5, 0.5])
    assert box_volume(box) == 0.0 and box_volume({}) == 0.0
    assert box_volume({"a": [0.2, 0.6], "b": [0.0, 0.5]}) == pytest.approx(0.2)


def _verification(within: bool, dem: float | None = None, sd: float = 0.2) -> pd.DataFrame:
    """An angle of 30 deg verified by 3 heaps, by default 30.5 (within 5 %) or 36.0 (not)."""
    value = dem if dem is not None else (30.5 if within else 36.0)
    return pd.DataFrame(
        {
            "observable": ["aor"],
            "normal_stress": [math.nan],
            "P": [math.nan],
            "measured": [30.0],
            "dem_configured": [value],
            "dem_sd_configured": [sd],
            "runs_configured": [3],
            "deviation_configured": [abs(value / 30.0 - 1.0)],
            "within_tolerance_configured": [within],
        }
    )


def test_stopping_rule(config):
    identified = {"group": "AoR", "n_valid": {"AoR": 120}}
    valid = pd.DataFrame(
        {"coefficientFriction": [0.3, 0.5, 0.7], "coefficientRollingFriction": [0.2, 0.4, 0.6]}
    )
    first = round_record(0, config, identified, valid, _verification(True), {}, None)
    # 6 sets x 3 runs + a verification of 2 seeds x 3 runs
    assert first["runs"] == 24 and first["runs_total"] == 24
    # round 0 has no earlier box: it cannot be settled, whatever the verification says
    assert not first["settled"] and not first["stop"]
    second = round_record(1, config, identified, valid, _verification(True), {}, first)
    assert second["runs_total"] == 24 + 9 + 6
    assert second["settled"] and second["stop"] and second["reason"].startswith("verified")
    # 30.5 +- 0.2 over 3 heaps: 95 % interval 30.0-31.0, inside the band 28.5-31.5
    assert second["undecided"] == [] and "undecided" not in second["reason"]
    # 31.2 +- 1.0: within 5 % (4 %), but the interval 28.7-33.7 crosses 31.5; the stop stands
    # (another round verifies another set) and says so
    lucky = round_record(1, config, identified, valid, _verification(True, 31.2, 1.0), {}, first)
    assert lucky["stop"] and lucky["undecided"] == ["aor"]
    assert "undecided at 95% confidence: aor" in lucky["reason"]
    assert rounds_table([first, lucky])["undecided"].tolist() == ["", "aor"]
    missed = round_record(1, config, identified, valid, _verification(False), {}, first)
    # a failed verification goes on until the budget: 39 + 15 > 60 would stop
    assert not missed["verified"] and not missed["stop"]
    third = round_record(2, config, identified, valid, _verification(False), {}, missed)
    assert third["stop"] and third["reason"].startswith("budget")
    last = round_record(
        3,
        {**config, "sequential": {**config["sequential"], "budget": 999}},
        identified,
        valid,
        _verification(False),
        {},
        missed,
    )
    assert last["stop"] and last["reason"].startswith("max_rounds")


def test_unit_cube_scales_by_the_design_box():
    frame = pd.DataFrame({"coefficientFriction": [0.1, 1.0], "coefficientRollingFriction": 0.55})
    np.testing.assert_allclose(unit_cube(frame, RANGES), [[0.0, 0.5], [1.0, 0.5]])
