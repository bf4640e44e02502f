"""The four kinds of design of DEM cases and their construction from a configuration mapping.

- ``factorial``: the full Cartesian product of given levels (the paper's Table 2, in
  ``config/paper.yaml``);
- ``random``: independent uniform draws;
- ``lhs``: a Latin hypercube (one point per stratum and column);
- ``sobol``: a scrambled, seeded Sobol' sequence (balanced only for n a power of two).

The sampled kinds map a unit hypercube onto three kinds of columns: continuous ranges
``(low, high)``, integer ranges (``integer`` names a range column whose values are whole numbers
in ``[low, high]``), and ``choices`` (a list of allowed values, e.g. dCylDp in {20, 36, 38, 40};
the unit coordinate picks an index). ``fixed`` columns hold one constant value. The unit-cube
dimensions follow the canonical column order of :mod:`demcal.design.table`, so the same
specification gives the same table whatever the key order of its mappings.
"""

from __future__ import annotations

import itertools
import warnings
from collections.abc import Collection, Mapping, Sequence

import numpy as np
import pandas as pd
from scipy.stats import qmc

from demcal.core.config import DESIGN_KEYS_BY_KIND
from demcal.design.table import (
    CASE_ID_COLUMN,
    DesignSpecError,
    case_ids,
    design_frame,
    finite_float,
    number_list,
    ordered_names,
    round_significant,
)

__all__ = [
    "build_design",
    "factorial_design",
    "latin_hypercube_design",
    "random_design",
    "sobol_design",
]

_KINDS = tuple(DESIGN_KEYS_BY_KIND)


# ----------------------------------------------------------------------------------------------
# factorial


def factorial_design(levels: Mapping[str, Sequence[float]]) -> pd.DataFrame:
    """Full factorial design: every combination of the given levels, one row per case.

    Parameters
    ----------
    levels : mapping of str to sequence of float
        Parameter name -> its levels (SI units). The first column in canonical order varies
        slowest, the last fastest.

    Returns
    -------
    pandas.DataFrame
        ``prod(len(levels[k]))`` rows; columns ``case_id`` then the parameters in canonical
        order (float64).

    Raises
    ------
    DesignSpecError
        If ``levels`` is empty, a parameter has no levels, a level is not a finite number or
        a level is repeated.
    """
    if not levels:
        raise DesignSpecError("levels: at least one parameter is required")
    names = ordered_names(list(levels))
    per_name: list[list[float]] = []
    for name in names:
        floats = number_list(levels[name], f"levels.{name}")
        if not floats:
            raise DesignSpecError(f"levels.{name}: expected a non-empty list of numbers")
        if len(set(floats)) != len(floats):
            raise DesignSpecError(f"levels.{name}: repeated level in {floats!r}")
        per_name.append(floats)
    rows = np.array(list(itertools.product(*per_name)), dtype=float).reshape(-1, len(names))
    return design_frame(case_ids(len(rows)), {n: rows[:, j] for j, n in enumerate(names)})


# ----------------------------------------------------------------------------------------------
# sampled designs


def _parse_range(name: str, bounds: object) -> tuple[float, float]:
    where = f"ranges.{name}"
    values = number_list(bounds, where)
    if len(values) != 2:
        raise DesignSpecError(f"{where}: expected [low, high], got {bounds!r}")
    low, high = values
    if not low < high:
        raise DesignSpecError(f"{where}: low must be < high, got [{low}, {high}]")
    return low, high


def _check_layout(
    ranges: Mapping[str, Sequence[float]],
    choices: Mapping[str, Sequence[float]],
    fixed: Mapping[str, float],
    integer: Collection[str],
) -> None:
    seen: dict[str, str] = {}
    for group, names in (("ranges", ranges), ("choices", choices), ("fixed", fixed)):
        for name in names:
            if name == CASE_ID_COLUMN:
                raise DesignSpecError(f"{group}.{name}: '{CASE_ID_COLUMN}' is reserved")
            if name in seen:
                raise DesignSpecError(f"{group}.{name}: also given in {seen[name]}")
            seen[name] = group
    for name in integer:
        if name not in ranges:
            raise DesignSpecError(f"integer: '{name}' is not a key of ranges")
    if not seen:
        raise DesignSpecError("ranges/choices/fixed: at least one parameter is required")


def _map_unit_cube(
    unit: np.ndarray,
    ranges: Mapping[str, Sequence[float]],
    choices: Mapping[str, Sequence[float]],
    fixed: Mapping[str, float],
    integer: Collection[str],
) -> dict[str, np.ndarray]:
    """Map unit-cube samples (n, d) onto the sampled columns in canonical order."""
    n = unit.shape[0]
    sampled = ordered_names([*ranges, *choices])
    columns: dict[str, np.ndarray] = {}
    for j, name in enumerate(sampled):
        u = unit[:, j]
        if name in ranges:
            low, high = _parse_range(name, ranges[name])
            if name in integer:
                if low != round(low) or high != round(high):
                    raise DesignSpecError(
                        f"ranges.{name}: integer column needs whole bounds, got [{low}, {high}]"
                    )
                span = int(high - low) + 1
                idx = np.minimum(np.floor(u * span), span - 1)
                columns[name] = low + idx
            else:
                columns[name] = round_significant(low + u * (high - low))
        else:
            allowed = np.array(number_list(choices[name], f"choices.{name}"))
            if allowed.size == 0:
                raise DesignSpecError(f"choices.{name}: expected a non-empty list of numbers")
            idx = np.minimum(np.floor(u * len(allowed)), len(allowed) - 1).astype(int)
            columns[name] = allowed[idx]
    for name, value in fixed.items():
        columns[name] = np.full(n, finite_float(value, f"fixed.{name}"))
    return columns


def _sampled_design(
    kind: str,
    ranges: Mapping[str, Sequence[float]],
    n: int,
    seed: int,
    fixed: Mapping[str, float] | None,
    integer: Collection[str] | None,
    choices: Mapping[str, Sequence[float]] | None,
) -> pd.DataFrame:
    fixed = dict(fixed or {})
    choices = dict(choices or {})
    integer = set(integer or ())
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
        raise DesignSpecError(f"n: expected a positive integer, got {n!r}")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise DesignSpecError(f"seed: expected a non-negative integer, got {seed!r}")
    _check_layout(ranges, choices, fixed, integer)
    d = len(ranges) + len(choices)
    n = int(n)
    if d == 0:
        unit = np.empty((n, 0))
    elif kind == "random":
        unit = np.random.default_rng(int(seed)).random((n, d))
    elif kind == "lhs":
        unit = qmc.LatinHypercube(d, rng=int(seed)).random(n)
    else:  # sobol
        sampler = qmc.Sobol(d, scramble=True, rng=int(seed))
        if n & (n - 1) == 0:
            unit = sampler.random_base2(int(n).bit_length() - 1)
        else:
            warnings.warn(
                f"sobol design with n = {n}: Sobol' points are balanced only when n is a "
                "power of two",
                UserWarning,
                stacklevel=3,
            )
            with warnings.catch_warnings():
                # the condition is reported once above, in terms of this function's input
                warnings.simplefilter("ignore", UserWarning)
                unit = sampler.random(n)
    columns = _map_unit_cube(unit, ranges, choices, fixed, integer)
    return design_frame(case_ids(n), columns)


def random_design(
    ranges: Mapping[str, Sequence[float]],
    n: int,
    seed: int,
    *,
    fixed: Mapping[str, float] | None = None,
    integer: Collection[str] | None = None,
    choices: Mapping[str, Sequence[float]] | None = None,
) -> pd.DataFrame:
    """Independent uniform draws within each range.

    Parameters
    ----------
    ranges : mapping of str to (low, high)
        Continuous (or, via ``integer``, whole-number) parameter ranges, SI units.
    n : int
        Number of cases.
    seed : int
        Seed of the random generator; the same seed gives the same table.
    fixed : mapping of str to float, optional
        Parameters held at one value in every case.
    integer : collection of str, optional
        Names of ``ranges`` entries that take whole values in ``[low, high]`` (inclusive).
    choices : mapping of str to sequence of float, optional
        Parameters restricted to a list of allowed values (an index is sampled).

    Returns
    -------
    pandas.DataFrame
        ``n`` rows: ``case_id`` then parameters in canonical order (float64).
    """
    return _sampled_design("random", ranges, n, seed, fixed, integer, choices)


def latin_hypercube_design(
    ranges: Mapping[str, Sequence[float]],
    n: int,
    seed: int,
    *,
    fixed: Mapping[str, float] | None = None,
    integer: Collection[str] | None = None,
    choices: Mapping[str, Sequence[float]] | None = None,
) -> pd.DataFrame:
    """Latin hypercube design: each column has exactly one case in each of n equal strata.

    Parameters and return value as in :func:`random_design`.
    """
    return _sampled_design("lhs", ranges, n, seed, fixed, integer, choices)


def sobol_design(
    ranges: Mapping[str, Sequence[float]],
    n: int,
    seed: int,
    *,
    fixed: Mapping[str, float] | None = None,
    integer: Collection[str] | None = None,
    choices: Mapping[str, Sequence[float]] | None = None,
) -> pd.DataFrame:
    """Scrambled Sobol' design (seeded Owen scrambling).

    Parameters and return value as in :func:`random_design`. A ``UserWarning`` is issued when
    ``n`` is not a power of two, because only then are the points balanced.
    """
    return _sampled_design("sobol", ranges, n, seed, fixed, integer, choices)


# ----------------------------------------------------------------------------------------------
# dispatch from a configuration mapping

#: Keys a spec may have: those of the configuration's ``design`` section, and for a sampled
#: design ``integer`` (the parameters drawn as whole numbers, which only the discrepancy
#: workflow's extended designs use).
_ALLOWED_KEYS = {
    kind: {*keys, *(() if kind == "factorial" else ("integer",))}
    for kind, keys in DESIGN_KEYS_BY_KIND.items()
}


def _mapping(spec: Mapping, key: str, required: bool) -> Mapping:
    if key not in spec:
        if required:
            raise DesignSpecError(f"design spec: missing key '{key}'")
        return {}
    value = spec[key]
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise DesignSpecError(f"design spec: '{key}' must be a mapping, got {value!r}")
    return value


def build_design(spec: Mapping) -> pd.DataFrame:
    """Build a design from a configuration mapping.

    Parameters
    ----------
    spec : mapping
        ``kind`` in {"factorial", "random", "lhs", "sobol"}. For ``factorial``: ``levels``
        (name -> list of levels) and optional ``fixed``. For the sampled kinds: ``ranges``
        (name -> [low, high]), ``n``, ``seed`` and optional ``fixed``, ``integer`` (list of
        range names) and ``choices`` (name -> list of allowed values). Example::

            {"kind": "lhs", "n": 64, "seed": 7,
             "ranges": {"coefficientFriction": [0.1, 1.0], "density": [2500, 3500]},
             "choices": {"dCylDp": [20, 36, 38, 40]},
             "fixed": {"youngsModulus": 1.0e7}}

    Returns
    -------
    pandas.DataFrame
        One row per case (see :func:`random_design`).

    Raises
    ------
    DesignSpecError
        Naming the offending key: missing or unknown ``kind``, missing ``n``/``seed``/
        ``ranges``/``levels``, unexpected keys, bad values.
    """
    if not isinstance(spec, Mapping):
        raise DesignSpecError(f"design spec: expected a mapping, got {type(spec).__name__}")
    if "kind" not in spec:
        raise DesignSpecError("design spec: missing key 'kind'")
    kind = spec["kind"]
    if kind not in _KINDS:
        raise DesignSpecError(f"design spec: 'kind' must be one of {list(_KINDS)}, got {kind!r}")
    unknown = sorted(set(spec) - _ALLOWED_KEYS[kind])
    if unknown:
        raise DesignSpecError(f"design spec: unexpected key(s) {unknown} for kind '{kind}'")
    fixed = _mapping(spec, "fixed", required=False)
    if kind == "factorial":
        levels = _mapping(spec, "levels", required=True)
        clash = sorted(set(levels) & set(fixed))
        if clash:
            raise DesignSpecError(f"design spec: 'fixed' and 'levels' both give {clash}")
        table = factorial_design(levels)
        for name, value in fixed.items():
            table[name] = finite_float(value, f"fixed.{name}")
        order = [CASE_ID_COLUMN, *ordered_names([c for c in table if c != CASE_ID_COLUMN])]
        return table[order]
    for key in ("n", "seed"):
        if key not in spec:
            raise DesignSpecError(f"design spec: missing key '{key}' for kind '{kind}'")
    ranges = _mapping(spec, "ranges", required=False)
    choices = _mapping(spec, "choices", required=False)
    if not ranges and not choices:
        raise DesignSpecError(f"design spec: missing key 'ranges' for kind '{kind}'")
    integer = spec.get("integer") or []
    if isinstance(integer, str) or not isinstance(integer, Sequence):
        raise DesignSpecError(f"design spec: 'integer' must be a list of names, got {integer!r}")
    return _sampled_design(kind, ranges, spec["n"], spec["seed"], fixed, integer, choices)
