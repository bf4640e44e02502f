"""Options shared by the study scripts: configuration overrides and parameter sets."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from demcal.bulk.engine_comparison import parameter_sets
from demcal.bulk.study_options import (
    add_parameter_sets,
    add_study_options,
    parse_parameter_set,
    study_sets,
    study_settings,
)

ROOT = Path(__file__).resolve().parents[2]
MIDDLE = parameter_sets("quick")["middle"]


def _parse(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add_study_options(parser, config=str(ROOT / "config" / "config.yaml"), sets=["low", "high"])
    return parser.parse_args(list(argv))


def _text(name: str, params: dict[str, float]) -> str:
    return name + "=" + ",".join(f"{k}:{v}" for k, v in params.items())


def test_parse_parameter_set_reads_every_contact_parameter() -> None:
    name, params = parse_parameter_set(
        "sinter=coefficientFriction:0.557, coefficientRollingFriction:0.919,"
        "coefficientRestitution:0.703,density:3116,cohesionEnergyDensity:2e4"
    )
    assert name == "sinter"
    assert params == {
        "coefficientFriction": 0.557,
        "coefficientRollingFriction": 0.919,
        "coefficientRestitution": 0.703,
        "density": 3116.0,
        "cohesionEnergyDensity": 20000.0,
    }


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("coefficientFriction:0.5", "expected NAME=key:value"),
        ("a/b=coefficientFriction:0.5", "NAME without '/'"),
        ("s=coefficientFriction 0.5", "is not key:value"),
        ("s=coefficientFricton:0.5", "did you mean coefficientFriction"),
        ("s=youngsModulus:1e7", "not a contact parameter"),
        ("s=coefficientFriction:0.5,coefficientFriction:0.6", "given twice"),
        ("s=coefficientFriction:high", "'high' is not a number"),
        ("s=coefficientRestitution:1.5", "coefficientRestitution = 1.5 is outside"),
        ("s=coefficientFriction:0.5,density:3000", "missing coefficientRollingFriction"),
    ],
)
def test_parse_parameter_set_names_what_is_wrong(text: str, message: str) -> None:
    with pytest.raises(ValueError, match=re.escape(message)):
        parse_parameter_set(text)


def test_added_sets_come_after_the_named_ones_and_leave_them_alone() -> None:
    named = {"low": {**MIDDLE, "coefficientFriction": 0.3}}
    text = _text("wet", MIDDLE) + ",cohesionEnergyDensity:5e4"
    sets = add_parameter_sets(named, [text])
    assert list(sets) == ["low", "wet"]
    assert sets["wet"] == {**MIDDLE, "cohesionEnergyDensity": 50000.0}
    assert list(named) == ["low"]
    with pytest.raises(ValueError, match="a set named low is already in the study"):
        add_parameter_sets(named, ["low=" + text.partition("=")[2]])


def test_study_sets_follow_the_profile_and_add_the_extra_ones_in_order() -> None:
    wet = {**MIDDLE, "cohesionEnergyDensity": 4e4}
    args = _parse("--sets", "high", "low", "--extra-set", _text("wet", wet))
    sets = study_sets(args, study_settings(args), "quick")
    assert list(sets) == ["high", "low", "wet"]
    assert sets["high"]["coefficientFriction"] == 0.9 and sets["wet"] == wet
    # Without --sets the script's defaults.
    args = _parse()
    assert list(study_sets(args, study_settings(args), "quick")) == ["low", "high"]


def test_overrides_reach_the_settings_and_bad_ones_stop_naming_the_key() -> None:
    args = _parse("--set", "shear_cell.contact_snapshots=25", "--set", "shear_cell.P=[0.5, 1.0]")
    settings = study_settings(args)
    assert settings["shear_cell"]["contact_snapshots"] == 25
    assert settings["shear_cell"]["P"] == [0.5, 1.0]
    with pytest.raises(SystemExit, match="contact_snapshot"):
        study_settings(_parse("--set", "shear_cell.contact_snapshot=25"))
    with pytest.raises(SystemExit, match=re.escape("expected SECTION.KEY=VALUE")):
        study_settings(_parse("--set", "contact_snapshots=25"))
    with pytest.raises(SystemExit, match=re.escape("nowhere.yaml")):
        study_settings(_parse("--config", "nowhere.yaml"))


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--sets"], "no parameter sets"),
        (["--sets", "medium"], "--sets: unknown parameter sets ['medium']"),
        (["--extra-set", "s=coefficientFriction:0.5"], "--extra-set: parameter set s: missing"),
        (["--extra-set", _text("low", MIDDLE)], "a set named low is already in the study"),
    ],
)
def test_study_sets_name_the_option_that_is_wrong(argv: list[str], message: str) -> None:
    args = _parse(*argv)
    with pytest.raises(SystemExit, match=re.escape(message)):
        study_sets(args, study_settings(args), "quick")
