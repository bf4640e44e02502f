"""Physical validity of DEM cases before any engine run.

Each design row is checked against the limits LIGGGHTS 3.8 itself enforces or that the physics
requires (SI units):

=============================  ==============================================
coefficientFriction            >= 0
coefficientRollingFriction     >= 0
coefficientRestitution         in (0.05, 1]  (LIGGGHTS rejects values outside)
density                        > 0
youngsModulus                  >= 5e6 Pa (LIGGGHTS rejects softer particles unless
                               ``soft_particles yes``; then > 0)
poissonsRatio                  in (0, 0.5)
cohesionEnergyDensity          >= 0
dCylDp                         >= the caller's minimum (> 0 when none is given)
=============================  ==============================================

Fields listed in ``ValidationRules.required`` must be present; the others are checked when
present. Extra checks are callables ``check(row) -> str | None`` returning a description of
the problem (or None when the row is fine).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import pandas as pd

__all__ = [
    "MIN_YOUNGS_MODULUS",
    "CaseValidationError",
    "MissingColumnError",
    "ValidationRules",
    "validate_case",
    "validate_design",
]

#: Smallest Young's modulus LIGGGHTS accepts without ``soft_particles yes``, Pa.
MIN_YOUNGS_MODULUS = 5.0e6

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
    required: tuple[str, ...] = (
        "coefficientFriction",
        "coefficientRollingFriction",
        "coefficientRestitution",
        "density",
    )
    extra_checks: tuple[ExtraCheck, ...] = ()

    def required_fields(self) -> tuple[str, ...]:
        """All fields a case must contain, ``case_id`` first."""
        fields = [CASE_ID, *self.required]
        if self.min_dCylDp is not None:
            fields.append("dCylDp")
        return tuple(dict.fromkeys(fields))


def _fmt(x: float) -> str:
    return "inf" if math.isinf(x) else f"{x:.12g}"


@dataclass(frozen=True)
class _Interval:
    low: float
    high: float
    low_closed: bool
    high_closed: bool

    def contains(self, x: float) -> bool:
        above = x >= self.low if self.low_closed else x > self.low
        below = x <= self.high if self.high_closed else x < self.high
        return above and below

    def __str__(self) -> str:
        left = "[" if self.low_closed else "("
        right = "]" if self.high_closed and not math.isinf(self.high) else ")"
        return f"{left}{_fmt(self.low)}, {_fmt(self.high)}{right}"


def _limits(rules: ValidationRules) -> dict[str, _Interval]:
    inf = math.inf
    min_y = MIN_YOUNGS_MODULUS if not rules.allow_soft_particles else 0.0
    min_d = rules.min_dCylDp
    return {
        "coefficientFriction": _Interval(0.0, inf, True, False),
        "coefficientRollingFriction": _Interval(0.0, inf, True, False),
        "coefficientRestitution": _Interval(0.05, 1.0, False, True),
        "density": _Interval(0.0, inf, False, False),
        "youngsModulus": _Interval(min_y, inf, not rules.allow_soft_particles, False),
        "poissonsRatio": _Interval(0.0, 0.5, False, False),
        "cohesionEnergyDensity": _Interval(0.0, inf, True, False),
        "dCylDp": (
            _Interval(0.0, inf, False, False)
            if min_d is None
            else _Interval(float(min_d), inf, True, False)
        ),
    }


def _case_problems(row: Mapping[str, object], rules: ValidationRules) -> list[str]:
    """Problems of one row (without the ``case <id>:`` prefix)."""
    problems: list[str] = []
    for name, interval in _limits(rules).items():
        if name not in row:
            continue
        value = row[name]
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            problems.append(f"{name} = {value!r} is not a number")
            continue
        x = float(value)
        if math.isnan(x):
            problems.append(f"{name} = nan is not a number")
        elif not interval.contains(x):
            problems.append(f"{name} = {_fmt(x)} is outside {interval}")
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
