"""Tests of demcal.decks.case_validation: limits, messages, all-at-once reports, missing columns."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import pandas as pd
import pytest

from demcal.core.config import load_config
from demcal.decks.case_validation import (
    CaseValidationError,
    MissingColumnError,
    ValidationRules,
    validate_case,
    validate_design,
)
from demcal.design.build import factorial_design
from demcal.design.table import expand_load_conditions

ROOT = Path(__file__).resolve().parents[2]
# The levels of the paper's Table 2, as the paper profile gives them to the workflow.
PAPER_TABLE2_LEVELS = load_config(ROOT / "config" / "paper.yaml")["design"]["levels"]

GOOD = {
    "case_id": "c0007",
    "coefficientFriction": 0.6,
    "coefficientRollingFriction": 0.4,
    "coefficientRestitution": 0.7,
    "density": 3000.0,
    "cohesionEnergyDensity": 0.0,
    "youngsModulus": 1.0e7,
    "poissonsRatio": 0.4,
    "dCylDp": 20.0,
}


def _with(**changes: object) -> dict[str, object]:
    return {**GOOD, **changes}


def test_good_case_passes() -> None:
    validate_case(GOOD)
    validate_case(GOOD, ValidationRules(min_dCylDp=20.0))
    validate_case(pd.Series(GOOD))


def test_message_names_case_field_and_value() -> None:
    with pytest.raises(CaseValidationError) as info:
        validate_case(_with(coefficientRestitution=1.3))
    assert str(info.value) == "case c0007: coefficientRestitution = 1.3 is outside (0.05, 1]"
    assert info.value.case_ids == ("c0007",)


@pytest.mark.parametrize(
    ("field", "bad", "edge_ok"),
    [
        ("coefficientFriction", -0.01, 0.0),
        ("coefficientRollingFriction", -1e-9, 0.0),
        ("coefficientRestitution", 0.05, 1.0),
        ("coefficientRestitution", 1.0000001, 0.0500001),
        ("density", 0.0, 1e-3),
        ("youngsModulus", 4.99e6, 5.0e6),
        ("poissonsRatio", 0.5, 0.4999),
        ("poissonsRatio", 0.0, 1e-6),
        ("cohesionEnergyDensity", -1.0, 0.0),
        ("dCylDp", 0.0, 0.5),
    ],
)
def test_each_limit_is_enforced_at_its_edge(field: str, bad: float, edge_ok: float) -> None:
    validate_case(_with(**{field: edge_ok}))
    with pytest.raises(CaseValidationError, match=f"case c0007: {field} = "):
        validate_case(_with(**{field: bad}))


def test_soft_particles_allow_low_youngs_modulus() -> None:
    soft = _with(youngsModulus=1.0e6)
    with pytest.raises(
        CaseValidationError, match=r"youngsModulus = 1000000 is outside \[5000000, 1000000000\]"
    ):
        validate_case(soft)
    validate_case(soft, ValidationRules(allow_soft_particles=True))
    with pytest.raises(
        CaseValidationError, match=r"youngsModulus = 0 is outside \(0, 1000000000\]"
    ):
        validate_case(_with(youngsModulus=0.0), ValidationRules(allow_soft_particles=True))


def test_stiff_particles_need_hard_particles_which_decks_never_set() -> None:
    # LIGGGHTS 3.8 refuses a Young's modulus above 1 GPa unless the deck says hard_particles yes.
    validate_case(_with(youngsModulus=1.0e9))
    with pytest.raises(
        CaseValidationError, match=r"youngsModulus = 2000000000 is outside \[5000000, 1000000000\]"
    ):
        validate_case(_with(youngsModulus=2.0e9))


def test_minimum_dcyldp_from_caller() -> None:
    rules = ValidationRules(min_dCylDp=20.0)
    with pytest.raises(CaseValidationError, match=r"dCylDp = 19.5 is outside \[20, inf\)"):
        validate_case(_with(dCylDp=19.5), rules)
    # with a minimum, the column becomes required
    no_cyl = {k: v for k, v in GOOD.items() if k != "dCylDp"}
    validate_case(no_cyl)
    with pytest.raises(MissingColumnError, match="'dCylDp'"):
        validate_case(no_cyl, rules)


def test_non_numbers_are_reported() -> None:
    with pytest.raises(CaseValidationError) as info:
        validate_case(_with(density="heavy", coefficientFriction=float("nan")))
    assert info.value.problems == (
        "case c0007: coefficientFriction = nan is not a number",
        "case c0007: density = 'heavy' is not a number",
    )


def test_all_problems_of_one_case_are_listed() -> None:
    with pytest.raises(CaseValidationError) as info:
        validate_case(_with(coefficientFriction=-0.2, poissonsRatio=0.6))
    assert info.value.problems == (
        "case c0007: coefficientFriction = -0.2 is outside [0, inf)",
        "case c0007: poissonsRatio = 0.6 is outside (0, 0.5)",
    )


def test_extra_checks() -> None:
    def dense_enough(row: Mapping[str, object]) -> str | None:
        rho = float(row["density"])  # type: ignore[arg-type]
        return None if rho >= 2500.0 else f"density = {rho:g} is below the 2500 kg/m^3 of Table 2"

    rules = ValidationRules(extra_checks=(dense_enough,))
    validate_case(GOOD, rules)
    with pytest.raises(CaseValidationError) as info:
        validate_case(_with(density=2000.0), rules)
    assert str(info.value) == "case c0007: density = 2000 is below the 2500 kg/m^3 of Table 2"


def test_missing_required_column_is_named() -> None:
    row = {k: v for k, v in GOOD.items() if k != "coefficientRestitution"}
    with pytest.raises(MissingColumnError) as info:
        validate_case(row)
    assert "'coefficientRestitution'" in str(info.value) and "c0007" in str(info.value)
    assert isinstance(info.value, KeyError)
    with pytest.raises(MissingColumnError, match="'case_id'"):
        validate_case({k: v for k, v in GOOD.items() if k != "case_id"})


def test_validate_design_reports_all_bad_cases_at_once() -> None:
    design = factorial_design(PAPER_TABLE2_LEVELS)
    validate_design(design, ValidationRules(min_dCylDp=20.0))
    design.loc[6, "coefficientRestitution"] = 1.3
    design.loc[40, "density"] = -1.0
    design.loc[41, "coefficientFriction"] = -0.5
    design.loc[41, "dCylDp"] = 10.0
    with pytest.raises(CaseValidationError) as info:
        validate_design(design, ValidationRules(min_dCylDp=20.0))
    assert info.value.case_ids == ("c0007", "c0041", "c0042")
    assert info.value.problems == (
        "case c0007: coefficientRestitution = 1.3 is outside (0.05, 1]",
        "case c0041: density = -1 is outside (0, inf)",
        "case c0042: coefficientFriction = -0.5 is outside [0, inf)",
        "case c0042: dCylDp = 10 is outside [20, inf)",
    )


def test_validate_design_expanded_table_reports_each_case_once() -> None:
    design = factorial_design({"coefficientFriction": [0.4, 0.6], "density": [3000.0]})
    design["coefficientRollingFriction"] = 0.4
    design["coefficientRestitution"] = [0.7, 0.01]
    expanded = expand_load_conditions(design, [1068.0, 10070.0], [0.4, 1.0])
    with pytest.raises(CaseValidationError) as info:
        validate_design(expanded)
    assert info.value.problems == (
        "case c0002: coefficientRestitution = 0.01 is outside (0.05, 1]",
    )


def test_validate_design_missing_columns() -> None:
    design = factorial_design({"coefficientFriction": [0.4], "density": [3000.0]})
    with pytest.raises(MissingColumnError) as info:
        validate_design(design)
    message = str(info.value)
    assert "'coefficientRollingFriction'" in message and "'coefficientRestitution'" in message
    assert "'density'" not in message
