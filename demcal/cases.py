"""The DEM cases of a study: design rows expanded to one case per virtual test run.

A shear-cell case is a design row at one pre-shear normal stress (all P values run as cycles
in one deck); an angle-of-repose case is a design row. Cases are named by ids such as
``c0003_s2`` so that wildcards carry ids, never floats.
"""

from collections.abc import Mapping
from typing import Any

import pandas as pd

from demcal.design import build_design

TESTS = ("shear_cell", "angle_of_repose")

# Keys of the design config section that each kind of design reads.
_KEYS_BY_KIND = {
    "factorial": ("kind", "levels", "fixed"),
    "random": ("kind", "n", "seed", "ranges", "choices", "fixed"),
    "lhs": ("kind", "n", "seed", "ranges", "choices", "fixed"),
    "sobol": ("kind", "n", "seed", "ranges", "choices", "fixed"),
}


def design_spec(section: Mapping[str, Any]) -> dict[str, Any]:
    """Reduce the validated ``design`` config section to the keys its kind uses."""
    keys = _KEYS_BY_KIND[section["kind"]]
    return {k: section[k] for k in keys if k in section and section[k] != {}}


def design_from_config(config: Mapping[str, Any]) -> pd.DataFrame:
    """The design table (one row per parameter set) of a validated configuration."""
    return build_design(design_spec(config["design"]))


def case_ids(config: Mapping[str, Any], design: pd.DataFrame, test: str) -> list[str]:
    """Ids of the DEM cases of one test."""
    if test == "angle_of_repose":
        return list(design["case_id"])
    stresses = config["shear_cell"]["normal_stresses"]
    return [f"{cid}_s{k + 1}" for cid in design["case_id"] for k in range(len(stresses))]


def case_row(config: Mapping[str, Any], design: pd.DataFrame, test: str, key: str) -> dict:
    """The parameters of one case: its design row, plus the normal stress for the shear cell.

    Raises
    ------
    KeyError
        When ``key`` is not a case of the design.
    """
    base, _, stress = key.partition("_s")
    rows = design[design["case_id"] == base]
    if rows.empty:
        raise KeyError(f"case {key!r} is not in the design")
    row = {k: (v.item() if hasattr(v, "item") else v) for k, v in rows.iloc[0].items()}
    row["case_id"] = key
    if test == "shear_cell":
        stresses = config["shear_cell"]["normal_stresses"]
        index = int(stress) - 1
        if not 0 <= index < len(stresses):
            raise KeyError(f"case {key!r}: no normal stress number {stress}")
        row["normal_stress"] = float(stresses[index])
    return row


def verification_case(
    config: Mapping[str, Any], identified: Mapping[str, Any], test: str, key: str
) -> dict:
    """A case at the identified mean parameters (``identified`` or ``identified_s<k>``).

    Raises
    ------
    ValueError
        When no parameter set was identified.
    """
    params = identified.get("parameters") or {}
    if not params:
        raise ValueError("no parameter set was identified; nothing to verify")
    row: dict[str, Any] = {"case_id": key, **{k: float(v["mean"]) for k, v in params.items()}}
    if test == "shear_cell":
        stresses = config["shear_cell"]["normal_stresses"]
        row["normal_stress"] = float(stresses[int(key.rpartition("_s")[2]) - 1])
    return row
