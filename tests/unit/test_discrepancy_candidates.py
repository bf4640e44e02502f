"""The candidate catalogue, its applicability and the cases of the discrepancy workflow."""

import copy
import dataclasses
import json
from pathlib import Path

import pytest

from demcal.core.config import load_config
from demcal.core.experiments import Experiment, MeasuredCondition
from demcal.discrepancy.candidates import (
    applicability,
    base_point,
    candidate_config,
    case_setup,
    deep_merge,
    extended_design,
    parse_candidates,
    probe_runs,
    reprobe_runs,
    run_suffixes,
)
from demcal.discrepancy.plan import DiscrepancyPlan
from demcal.discrepancy.runs import discrepancy_case
from demcal.discrepancy.synthetic import study_config

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def quick():
    """The default configuration: rolling friction on, sinter-fines sizes."""
    return load_config(ROOT / "config" / "config.yaml")


@pytest.fixture(scope="module")
def study(quick):
    """A model without rolling friction and cohesion, one size, mu_s and density varied."""
    raw = {k: copy.deepcopy(v) for k, v in quick.items()}
    config = study_config(raw, "quick")
    return config


def by_name(config):
    return {c.name: c for c in parse_candidates(config["discrepancy"]["candidates"])}


def test_default_catalogue_has_the_three_required_effects(quick):
    names = set(by_name(quick))
    assert {"cohesion", "rolling", "polydispersity"} <= names


def test_applicability_follows_the_current_model(quick, study):
    cands = by_name(quick)
    # Default model: rolling friction on and varied, sinter-fines sizes with 4 classes.
    assert applicability(cands["rolling"], quick)[0] is False
    assert applicability(cands["polydispersity"], quick)[0] is False
    assert applicability(cands["cohesion"], quick)[0] is True
    assert applicability(cands["wallfriction"], quick)[0] is True
    # The study model lacks rolling resistance and size spread.
    assert applicability(cands["rolling"], study)[0] is True
    assert applicability(cands["polydispersity"], study)[0] is True
    with_cohesion = deep_merge(study, {"design": {"fixed": {"cohesionEnergyDensity": 100.0}}})
    ok, reason = applicability(cands["cohesion"], with_cohesion)
    assert not ok and "cohesionEnergyDensity = 100" in reason


def test_parse_candidates_rejects_bad_entries():
    good = {
        "name": "cohesion",
        "description": "d",
        "parameter": "cohesionEnergyDensity",
        "off_value": 0.0,
        "range": [0.0, 1.0],
        "probe_levels": [0.5],
    }
    with pytest.raises(ValueError, match="outside the range"):
        parse_candidates([{**good, "probe_levels": [2.0]}])
    with pytest.raises(ValueError, match="duplicate"):
        parse_candidates([good, good])
    with pytest.raises(ValueError, match="lower-case"):
        parse_candidates([{**good, "name": "Wall_Friction"}])
    with pytest.raises(KeyError, match=r"candidates\[0\]: missing key 'range'"):
        parse_candidates([{k: v for k, v in good.items() if k != "range"}])
    with pytest.raises(ValueError, match="whole"):
        parse_candidates([{**good, "integer": True}])


def test_candidate_config_switches_and_sets_config_keys(study):
    cands = by_name(study)
    rolling = candidate_config(study, cands["rolling"], 0.3)
    assert rolling["material"]["rolling_friction"] is True
    assert study["material"]["rolling_friction"] is False
    poly = candidate_config(study, cands["polydispersity"], 3.0)
    assert poly["particles"]["distribution"] == "sinter_fines"
    assert poly["particles"]["classes"] == 3


def test_case_setup_rows_and_loads(study):
    cands = by_name(study)
    point = base_point({"coefficientFriction": 0.4, "density": 2800.0}, study)
    assert point["coefficientRestitution"] == 0.7 and point["coefficientRollingFriction"] == 0.0
    row, cfg = case_setup("shear_cell", "cohesion2_s2_p1", point, study, cands["cohesion"], 4e4)
    assert row["normal_stress"] == study["shear_cell"]["normal_stresses"][1]
    assert row["P"] == study["shear_cell"]["P"][0]
    assert row["cohesionEnergyDensity"] == 4e4 and row["discrepancy_candidate"] == "cohesion"
    assert cfg == study
    row, _ = case_setup("angle_of_repose", "ref", point, study)
    assert "normal_stress" not in row and row["discrepancy_candidate"] == "none"
    with pytest.raises(KeyError, match="no normal stress number 9"):
        case_setup("shear_cell", "ref_s9_p1", point, study)


def test_run_suffixes_keep_the_measured_conditions(study):
    conds = [
        MeasuredCondition({"rho_b": 1700.0}, {}, 2029.0, 0.5),
        MeasuredCondition({"rho_b": 1700.0}, {}, 99.0, 0.5),
    ]
    # Study model: stresses 1068, 2029, 10070 Pa, P = 0.5, one run per condition.
    separate = deep_merge(study, {"shear_cell": {"separate_runs": True}})
    assert run_suffixes(separate, Experiment("m", "", conds)) == ["_s2_p1"]
    cycles = deep_merge(study, {"shear_cell": {"separate_runs": False}})
    assert run_suffixes(cycles, Experiment("m", "", conds)) == ["_s2"]


def test_base_point_needs_every_contact_parameter(study):
    broken = deep_merge(study, {})
    broken["design"]["fixed"] = {}
    with pytest.raises(KeyError, match="coefficientRollingFriction"):
        base_point({}, broken)


def test_extended_design_adds_the_effect_axis(study):
    cands = by_name(study)
    table = extended_design(study, cands["polydispersity"], 9, 5)
    assert list(table["case_id"]) == [f"e{k:04d}" for k in range(1, 10)]
    # A continuous axis: nine distinct numbers of classes over [1, 6], fractional ones too.
    assert table["sizeClasses"].between(1, 6).all() and table["sizeClasses"].nunique() == 9
    assert (table["sizeClasses"] % 1 != 0).any()
    assert table["coefficientFriction"].between(0.1, 0.9).all()
    assert (table["coefficientRestitution"] == 0.7).all()
    cohesion = extended_design(study, cands["cohesion"], 4, 5)
    # A Latin hypercube: one case per quarter of the cohesion range.
    lo, hi = cands["cohesion"].range
    quarters = sorted(((cohesion["cohesionEnergyDensity"] - lo) // ((hi - lo) / 4)).astype(int))
    assert quarters == [0, 1, 2, 3]


def test_probe_runs_and_plan_file_lists(study, tmp_path):
    cands = [c for c in parse_candidates(study["discrepancy"]["candidates"])]
    runs = probe_runs(cands[:2])
    assert [r.case for r in runs][:3] == ["ref", "cohesion1", "cohesion2"]
    plan = DiscrepancyPlan(
        "results/discrepancy", ["shear_cell"], ["_s1", "_s2"], [], cands[:1], ["_h1"], 2
    )
    assert plan.case_ids(["ref"]) == [("shear_cell", "ref_s1"), ("shear_cell", "ref_s2")]
    find = tmp_path / "find.json"
    find.write_text('{"missing": false}')
    assert plan.probe_bulk(find) == []
    find.write_text('{"missing": true}')
    # Probe runs only at the fitted loads: they feed the naming. The reference runs as often as
    # the DEM check needs it (2 here), each candidate level once by default.
    assert plan.probe_bulk(find) == [
        f"results/discrepancy/probes/shear_cell/{c}_s{k}/bulk.csv"
        for c in ("ref", "ref_r2", "cohesion1", "cohesion2", "cohesion3")
        for k in (1, 2)
    ]
    triple = dataclasses.replace(plan, probe_replicates=3)
    assert triple.probe_cases == [
        "ref", "ref_r2",
        "cohesion1", "cohesion1_r2", "cohesion1_r3",
        "cohesion2", "cohesion2_r2", "cohesion2_r3",
        "cohesion3", "cohesion3_r2", "cohesion3_r3",
    ]  # fmt: skip
    ranking = tmp_path / "ranking.json"
    ranking.write_text('{"winner": null}')
    # The DEM check: every replicate of the reference, at the fitted and the held-out loads.
    reference = [
        f"results/discrepancy/probes/shear_cell/{r}{k}/bulk.csv"
        for r in ("ref", "ref_r2")
        for k in ("_s1", "_s2", "_h1")
    ]
    assert plan.show_inputs(find, ranking) == {"reference": reference}
    ranking.write_text('{"winner": "cohesion"}')
    inputs = plan.show_inputs(find, ranking)
    assert inputs["verification"] == [
        f.replace("probes", "verification").replace("ref", "verify") for f in reference
    ]


def test_leading_candidates_are_probed_again_at_their_own_best_fit(study, tmp_path):
    cands = parse_candidates(study["discrepancy"]["candidates"])
    # Each candidate probed again has its own reference (effect absent) beside its levels.
    assert [r.case for r in reprobe_runs(cands[:1])] == [
        "cohesion0", "cohesion1", "cohesion2", "cohesion3"
    ]  # fmt: skip
    assert [r.candidate for r in reprobe_runs(cands[:1])] == [None, *["cohesion"] * 3]
    plan = DiscrepancyPlan(
        "results/discrepancy", ["shear_cell"], ["_s1"], [], cands, [], 2, probe_replicates=1
    )
    lead = tmp_path / "lead.json"
    lead.write_text(json.dumps({"points": {}}))
    assert plan.reprobe_bulk(lead) == []
    theta_star = base_point({"coefficientFriction": 0.87, "density": 2800.0}, study)
    own = {**theta_star, "coefficientFriction": 0.42}
    rolling = next(c for c in cands if c.name == "rolling")
    lead.write_text(json.dumps({"points": {"rolling": own}}))
    # The reference as often as at theta* (2), every level probe_replicates times (1).
    assert plan.reprobe_cases(lead) == ["rolling0", "rolling0_r2"] + [
        rolling.case_id(j) for j in range(len(rolling.probe_levels))
    ]
    assert plan.reprobe_bulk(lead)[0] == (
        "results/discrepancy/reprobes/shear_cell/rolling0_s1/bulk.csv"
    )
    # The decks: the candidate's own best fit, the effect off in its reference and on at a level.
    record = json.loads(lead.read_text())
    row, _ = discrepancy_case("reprobe", "shear_cell", "rolling0_r2_s1_p1", study, record)
    assert row["coefficientFriction"] == 0.42 and row["discrepancy_candidate"] == "none"
    row, cfg = discrepancy_case("reprobe", "shear_cell", "rolling2_s1_p1", study, record)
    assert row["coefficientFriction"] == 0.42 and row["discrepancy_candidate"] == "rolling"
    assert row["coefficientRollingFriction"] == rolling.probe_levels[1]
    assert cfg["material"]["rolling_friction"] is True
    # A candidate that leads nowhere has no run there.
    with pytest.raises(KeyError, match="no run of a candidate probed again"):
        discrepancy_case("reprobe", "shear_cell", "cohesion1_s1_p1", study, record)
