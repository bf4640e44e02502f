"""Hidden truths are drawn away from the probe levels, inside ranges that extend past them."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from demcal.core.config import load_config
from demcal.discrepancy.truths import (
    MAX_EFFECT_FRACTION,
    draw_truth,
    load_truth_spec,
    truth_config,
)
from demcal.particles.size_distribution import size_distribution

ROOT = Path(__file__).resolve().parents[2]
TRUTHS = ROOT / "config" / "experiments" / "truth"

CONFIG = {
    "profile": "tiny",
    "particles": {"classes": 1, "distribution": "monodisperse"},
    "material": {"rolling_friction": False},
    "design": {"ranges": {"coefficientFriction": [0.1, 0.9]}},
    "discrepancy": {
        "candidates": [
            {
                "name": "cohesion",
                "description": "c",
                "parameter": "cohesionEnergyDensity",
                "off_value": 0.0,
                "range": [0.0, 100000.0],
                "probe_levels": [20000.0, 50000.0, 80000.0],
            },
            {
                "name": "rolling",
                "description": "r",
                "switch": {"material": {"rolling_friction": True}},
                "parameter": "coefficientRollingFriction",
                "off_value": 0.0,
                "range": [0.0, 0.4],
                "probe_levels": [0.1, 0.2, 0.3],
            },
            {
                "name": "polydispersity",
                "description": "p",
                "switch": {"particles": {"distribution": "sinter_fines"}},
                "parameter": "sizeClasses",
                "config_key": "particles.classes",
                "off_value": 1,
                "range": [1, 6],
                "probe_levels": [2, 4, 6],
                "integer": True,
            },
        ]
    },
}


def spec(effect: str | None, **extra) -> dict:
    return {
        "material": "m",
        "effect": effect,
        "parameters": {"coefficientRestitution": 0.7},
        "draw": {"coefficientFriction": [0.25, 0.75]},
        **extra,
    }


def test_drawn_magnitudes_keep_clear_of_probe_levels_and_inside_the_span() -> None:
    magnitudes = [draw_truth(spec("cohesion"), CONFIG, seed).magnitude for seed in range(200)]
    assert all(m is not None for m in magnitudes)
    # Default span: 15-70 % of the range; clearance 5 % of the range from 20 000 and 50 000.
    assert min(magnitudes) >= 15000.0 and max(magnitudes) <= 70000.0
    assert all(abs(m - level) > 5000.0 for m in magnitudes for level in (20000.0, 50000.0))
    # Drawn, not chosen: what is left of the span, [25 000, 45 000] and [55 000, 70 000], is
    # covered to its ends.
    assert min(magnitudes) < 27000.0 and max(magnitudes) > 68000.0
    assert any(43000.0 < m for m in magnitudes if m < 50000.0)
    assert any(m < 57000.0 for m in magnitudes if m > 50000.0)


def test_the_same_seed_gives_the_same_truth_and_another_seed_another() -> None:
    a, b = draw_truth(spec("rolling"), CONFIG, 7), draw_truth(spec("rolling"), CONFIG, 7)
    c = draw_truth(spec("rolling"), CONFIG, 8)
    assert a == b and a.magnitude != c.magnitude
    assert a.parameters["coefficientRollingFriction"] == a.magnitude
    assert 0.25 <= a.parameters["coefficientFriction"] <= 0.75
    assert a.parameters["coefficientRestitution"] == 0.7
    assert a.drawn == {
        "coefficientFriction": a.parameters["coefficientFriction"],
        "coefficientRollingFriction": a.magnitude,
    }


def test_the_effect_is_switched_on_as_the_workflow_would_add_it() -> None:
    rolling = draw_truth(spec("rolling"), CONFIG, 1)
    assert truth_config(rolling, CONFIG)["material"]["rolling_friction"] is True
    poly = draw_truth(spec("polydispersity"), CONFIG, 3)
    # A whole number of classes away from the probe levels 2, 4, 6 within 15-70 % of [1, 6].
    assert poly.magnitude == 3.0 and "sizeClasses" not in poly.parameters
    config = truth_config(poly, CONFIG)
    assert config["particles"] == {"classes": 3, "distribution": "sinter_fines"}
    nothing = draw_truth(spec(None), CONFIG, 1)
    assert nothing.magnitude is None and truth_config(nothing, CONFIG) == CONFIG


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ({"effect_span": [0.2, 1.0]}, "must extend past the truth"),
        ({"effect_span": [0.5, 0.3]}, "must satisfy"),
        ({"draw": {"coefficientFriction": [0.05, 0.5]}}, "leaves the design range"),
        ({"probe_clearance": 0.3}, "leave no room"),
    ],
)
def test_truths_that_would_make_the_check_trivial_are_refused(extra: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        draw_truth(spec("cohesion", **extra), CONFIG, 1, "truth.yaml")


def test_an_effect_outside_the_catalogue_is_refused_by_name() -> None:
    with pytest.raises(ValueError, match=r"truth\.yaml: effect 'moisture' is not a candidate"):
        draw_truth(spec("moisture"), CONFIG, 1, "truth.yaml")


def test_shipped_truth_specifications_draw_on_both_profiles() -> None:
    for name in ("tiny", "config"):
        config = yaml.safe_load((ROOT / "config" / f"{name}.yaml").read_text())
        if name == "config":
            config["profile"] = "quick"
        names = {c["name"] for c in config["discrepancy"]["candidates"]}
        for path in sorted(TRUTHS.glob("hidden_*.yaml")):
            effect = yaml.safe_load(path.read_text())["effect"]
            if effect is not None and effect not in names:
                # Wall friction is a candidate of the quick catalogue only.
                assert name == "tiny", (name, effect)
                with pytest.raises(ValueError, match=f"{path}: effect '{effect}' is not a"):
                    draw_truth(load_truth_spec(path), config, 1, str(path))
                continue
            truth = draw_truth(load_truth_spec(path), config, 1, str(path))
            assert truth.effect == effect, path
            if truth.magnitude is not None:
                levels = next(
                    c["probe_levels"]
                    for c in config["discrepancy"]["candidates"]
                    if c["name"] == truth.effect
                )
                assert len(levels) >= 3, (name, truth.effect)
                assert truth.magnitude not in levels
    assert MAX_EFFECT_FRACTION <= 0.8


def test_an_outside_effect_switches_the_configuration_per_profile() -> None:
    spec = load_truth_spec(TRUTHS / "hidden_softer.yaml")
    tiny = yaml.safe_load((ROOT / "config" / "tiny.yaml").read_text())
    quick = {**yaml.safe_load((ROOT / "config" / "config.yaml").read_text()), "profile": "quick"}
    for config in (tiny, quick):
        truth = draw_truth(spec, config, 3)
        assert truth.effect is None and truth.magnitude is None
        runs = truth_config(truth, config)
        # One fixed modulus, as a real material has, instead of the model's modulus per unit
        # stress: four times below the model's at the middle stress (2 029 Pa) and below it at
        # every stress the studies fit (1 068 Pa and up).
        per_stress = config["shear_cell"]["youngs_modulus_per_stress"]
        modulus = runs["material"]["youngsModulus"]
        assert runs["shear_cell"]["youngs_modulus_per_stress"] == 0.0
        assert 4.0 * modulus == pytest.approx(per_stress * 2029.0, rel=0.05)
        assert modulus < per_stress * 1068.0
        # Only the stiffness changes.
        for section, key in (
            ("shear_cell", "youngs_modulus_per_stress"),
            ("material", "youngsModulus"),
        ):
            assert {k: v for k, v in runs[section].items() if k != key} == {
                k: v for k, v in config[section].items() if k != key
            }


def test_shipped_polydispersity_truths_spread_over_the_draw_span() -> None:
    # As a whole number the draw could only give 3 classes; the shipped catalogues draw a
    # continuous number of sieve classes, clear of the probes 2, 4 and 6.
    spec = load_truth_spec(TRUTHS / "hidden_polydispersity.yaml")
    for name in ("tiny", "config"):
        config = yaml.safe_load((ROOT / "config" / f"{name}.yaml").read_text())
        if name == "config":
            config["profile"] = "quick"
        drawn = np.array([draw_truth(spec, config, seed).magnitude for seed in range(101, 121)])
        assert np.all((drawn >= 1.75) & (drawn <= 4.5)), (name, drawn)
        assert np.min(np.abs(drawn[:, None] - np.array([2.0, 4.0, 6.0])), axis=1).min() > 0.25
        assert np.unique(np.round(drawn, 6)).size == drawn.size
        assert drawn.max() - drawn.min() > 1.5, (name, drawn)
        # The truth runs keep the fraction: part of the next finer sieve class.
        validated = load_config(ROOT / "config" / f"{name}.yaml")
        validated["profile"] = config["profile"]
        truth = draw_truth(spec, validated, 101)
        particles = truth_config(truth, validated)["particles"]
        assert particles["classes"] == truth.magnitude
        dist = size_distribution(particles)
        assert dist.n_classes == math.ceil(truth.magnitude) > truth.magnitude


def test_a_hidden_wall_friction_keeps_clear_of_the_sliding_friction() -> None:
    # The absent value of wall friction is the truth's own sliding friction: a wall friction
    # drawn next to it hides nothing. Seed 101 drew 0.62 against 0.72 before the clearance.
    spec = load_truth_spec(TRUTHS / "hidden_wallfriction.yaml")
    config = {**yaml.safe_load((ROOT / "config" / "config.yaml").read_text()), "profile": "quick"}
    (low, high) = next(
        c["range"] for c in config["discrepancy"]["candidates"] if c["name"] == "wallfriction"
    )
    gaps, magnitudes = [], []
    for seed in range(101, 161):
        truth = draw_truth(spec, config, seed)
        gaps.append(abs(truth.magnitude - truth.parameters["coefficientFriction"]))
        magnitudes.append(truth.magnitude)
    assert min(gaps) > 0.15 * (high - low)
    # Still drawn over the span, on both sides of the sliding friction.
    assert min(magnitudes) < 0.3 and max(magnitudes) > 0.65
    first = draw_truth(spec, config, 101)
    assert first.parameters["coefficientFriction"] == pytest.approx(0.7218, abs=1e-4)
    assert abs(first.magnitude - 0.7218) > 0.135
    # Where the absent value lies at the range's end (cohesion: 0) the same seeds draw the same
    # truths as without the clearance: the span already starts 15 % of the range above it.
    cohesion = load_truth_spec(TRUTHS / "hidden_cohesion.yaml")
    for seed in range(101, 121):
        assert draw_truth(cohesion, config, seed) == draw_truth(
            {**cohesion, "off_clearance": 0.0}, config, seed
        )
