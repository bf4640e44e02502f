"""Physical validity of DEM cases before any engine run.

Each design row is checked against the bounds of :data:`demcal.core.parameters.PARAMETERS`
(the limits LIGGGHTS 3.8 itself enforces or that the physics requires, e.g.
coefficientRestitution in (0.05, 1]), with two bounds that depend on the rules:

=============================  ==============================================
youngsModulus                  >= 5e6 Pa (LIGGGHTS rejects softer particles unless
                               ``soft_particles yes``; then > 0) and <= 1e9 Pa
                               (LIGGGHTS rejects stiffer ones unless
                               ``hard_particles yes``, which the decks never set)
dCylDp                         >= the caller's minimum (> 0 when none is given)
=============================  ==============================================

Fields listed in ``ValidationRules.required`` must be present; the others are checked when
present. Extra checks are callables ``check(row) -> str | None`` returning a description of
the problem (or None when the row is fine).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import pandas as pd

from demcal.core.parameters import (
    CONTACT_PARAMETERS,
    MAX_YOUNGS_MODULUS,
    MIN_YOUNGS_MODULUS,
    PARAMETERS,
    Interval,
    out_of_bounds,
)

__all__ = [
    "CaseValidationError",
    "MissingColumnError",
    "ValidationRules",
    "validate_case",
    "validate_design",
]

CASE_ID = "case_id"
ExtraCheck = Callable[[Mapping[str, object]], str | None]


class CaseValidationError(ValueError):
    """One or more cases are physically invalid.

    Attributes
    ----------
    problems : tuple of str
        One line per problem, each starting with ``case <id>:``.
    case_ids : tuple of str
        Ids of the invalid cases, in table order, without repeats.
    """

    def __init__(self, problems: Sequence[str], case_ids: Sequence[str]) -> None:
        self.problems = tuple(problems)
        self.case_ids = tuple(dict.fromkeys(case_ids))
        super().__init__("\n".join(self.problems))


class MissingColumnError(KeyError):
    """A required field is missing from a case or a design table."""

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message

    def __str__(self) -> str:
        return self.message


@dataclass(frozen=True)
class ValidationRules:
    """What counts as a valid case.

    Parameters
    ----------
    min_dCylDp : float, optional
        Smallest allowed ratio cylinder diameter / particle diameter. When given, ``dCylDp``
        becomes a required field; when None, dCylDp (if present) must only be > 0.
    allow_soft_particles : bool
        Accept youngsModulus below 5e6 Pa (LIGGGHTS ``soft_particles yes``).
    required : tuple of str
        Fields every case must have (``case_id`` is always required).
    extra_checks : tuple of callables
        ``check(row) -> str | None``; a returned string describes a problem of that row.
    """

    min_dCylDp: float | None = None
    allow_soft_particles: bool = False
    required: tuple[str, ...] = CONTACT_PARAMETERS
    extra_checks: tuple[ExtraCheck, ...] = ()

    def required_fields(self) -> tuple[str, ...]:
        """All fields a case must contain, ``case_id`` first."""
        fields = [CASE_ID, *self.required]
        if self.min_dCylDp is not None:
            fields.append("dCylDp")
        return tuple(dict.fromkeys(fields))


def _limits(rules: ValidationRules) -> dict[str, Interval]:
    limits = {name: p.bounds for name, p in PARAMETERS.items()}
    lowest = 0.0 if rules.allow_soft_particles else MIN_YOUNGS_MODULUS
    limits["youngsModulus"] = Interval(
        lowest, MAX_YOUNGS_MODULUS, not rules.allow_soft_particles, True
    )
    if rules.min_dCylDp is not None:
        limits["dCylDp"] = Interval(float(rules.min_dCylDp), math.inf, True, False)
    return limits


def _case_problems(row: Mapping[str, object], rules: ValidationRules) -> list[str]:
    """Problems of one row (without the ``case <id>:`` prefix)."""
    problems: list[str] = []
    for name, interval in _limits(rules).items():
        if name not in row:
            continue
        problem = out_of_bounds(name, row[name], interval)
        if problem:
            problems.append(problem)
    for check in rules.extra_checks:
        message = check(row)
        if message:
            problems.append(str(message))
    return problems


def _missing(fields: Sequence[str], present: object, where: str) -> None:
    missing = [f for f in fields if f not in present]  # type: ignore[operator]
    if missing:
        names = ", ".join(f"'{m}'" for m in missing)
        raise MissingColumnError(f"{where}: missing required column(s) {names}")


def validate_case(row: Mapping[str, object], rules: ValidationRules | None = None) -> None:
    """Check one design row.

    Parameters
    ----------
    row : mapping
        Field name -> value (a dict or a pandas Series), with ``case_id``.
    rules : ValidationRules, optional
        Limits to apply; defaults to ``ValidationRules()``.

    Raises
    ------
    MissingColumnError
        If a required field is missing (the message names it).
    CaseValidationError
        Listing every problem of the case, e.g.
        ``case c0007: coefficientRestitution = 1.3 is outside (0.05, 1]``.
    """
    rules = rules or ValidationRules()
    case = row.get(CASE_ID, "<no case_id>")
    _missing(rules.required_fields(), row, f"case {case}")
    problems = _case_problems(row, rules)
    if problems:
        raise CaseValidationError([f"case {case}: {p}" for p in problems], [str(case)])


def validate_design(df: pd.DataFrame, rules: ValidationRules | None = None) -> None:
    """Check every row of a design table and report all invalid cases at once.

    Parameters
    ----------
    df : pandas.DataFrame
        Design table, one row per case (or per case and load condition).
    rules : ValidationRules, optional
        Limits to apply; defaults to ``ValidationRules()``.

    Raises
    ------
    MissingColumnError
        If a required column is missing (the message names all missing columns).
    CaseValidationError
        With one line per problem of every invalid case (repeated rows of the same case are
        reported once).
    """
    rules = rules or ValidationRules()
    _missing(rules.required_fields(), df.columns, "design table")
    problems: list[str] = []
    bad: list[str] = []
    seen: set[str] = set()
    for row in df.to_dict(orient="records"):
        case = str(row[CASE_ID])
        lines = [f"case {case}: {p}" for p in _case_problems(row, rules)]
        new = [line for line in lines if line not in seen]
        seen.update(new)
        if lines:
            bad.append(case)
        problems.extend(new)
    if problems:
        raise CaseValidationError(problems, bad)
