"""The DEM check of the discrepancy workflow: run ids, replicate seeds, held-out loads."""

import pytest

from demcal.core.config import ConfigError
from demcal.core.experiments import Experiment, MeasuredCondition
from demcal.discrepancy.candidates import case_setup
from demcal.discrepancy.dem_check import (
    fitted_experiment,
    held_out_experiment,
    held_out_suffixes,
    parse_run_id,
    replicate_bases,
    run_load,
    run_seed,
)

CONFIG = {
    "seed": 7,
    "experiment": "measured.yaml",
    "shear_cell": {"normal_stresses": [1068.0, 2029.0], "P": [0.5], "separate_runs": True},
    "discrepancy": {"held_out": [{"normal_stress": 1500.0, "P": 0.5}]},
}


def condition(stress: float, p: float = 0.5) -> MeasuredCondition:
    return MeasuredCondition(values={"mu_psh": 0.6}, normal_stress=stress, P=p)


def test_run_ids_name_run_replicate_and_load():
    assert parse_run_id("ref_s2_p1").base == "ref"
    parsed = parse_run_id("ref_r3_s2_p1")
    assert (parsed.run, parsed.replicate, parsed.load, parsed.held_out) == (
        "ref",
        3,
        "_s2_p1",
        None,
    )
    assert parsed.base == "ref_r3"
    held = parse_run_id("verify_h1")
    assert (held.run, held.replicate, held.held_out, held.base) == ("verify", 1, 1, "verify")
    assert parse_run_id("cohesion2").load == ""
    for bad in ("ref_x1", "Ref_s1", "ref_r0_s1", "ref_s1_h1"):
        with pytest.raises(KeyError):
            parse_run_id(bad)
    assert replicate_bases("ref", 3) == ["ref", "ref_r2", "ref_r3"]
    assert replicate_bases("verify", 1) == ["verify"]


def test_replicates_get_their_own_seeds_and_held_out_loads_their_stress():
    assert [run_seed(CONFIG, c) for c in ("ref_s1_p1", "ref_r2_s1_p1", "verify_r3_h1")] == [
        7,
        1007,
        2007,
    ]
    assert held_out_suffixes(CONFIG) == ["_h1"]
    assert run_load(CONFIG, "ref_r2_h1") == {"normal_stress": 1500.0, "P": 0.5}
    assert run_load(CONFIG, "ref_s2_p1") == {"normal_stress": 2029.0, "P": 0.5}
    with pytest.raises(KeyError, match="held_out has 1 entries"):
        run_load(CONFIG, "ref_h2")
    point = {"coefficientFriction": 0.4}
    row, _ = case_setup("shear_cell", "ref_r2_h1", point, CONFIG)
    assert (row["seed"], row["normal_stress"], row["P"]) == (1007, 1500.0, 0.5)


def test_held_out_loads_are_left_out_of_the_fit():
    experiment = Experiment(
        "m", "s", [condition(1068.0), condition(1500.0), condition(2029.0)], 35.0, 1.0
    )
    fitted = fitted_experiment(experiment, CONFIG)
    assert [c.normal_stress for c in fitted.shear_conditions] == [1068.0, 2029.0]
    assert fitted.angle_of_repose == 35.0
    held = held_out_experiment(experiment, CONFIG)
    assert [c.normal_stress for c in held.shear_conditions] == [1500.0]
    assert held.angle_of_repose is None
    # Without held-out loads everything is fitted.
    plain = {**CONFIG, "discrepancy": {"held_out": []}}
    assert fitted_experiment(experiment, plain) == experiment


def test_a_held_out_load_that_was_not_measured_is_named():
    experiment = Experiment("m", "s", [condition(1068.0), condition(1500.0, 0.6)])
    with pytest.raises(ConfigError, match=r"measured.yaml: discrepancy.held_out\[0\]"):
        fitted_experiment(experiment, CONFIG)
    only = Experiment("m", "s", [condition(1500.0)])
    with pytest.raises(ConfigError, match="leaves no measured value to fit"):
        fitted_experiment(only, CONFIG)
