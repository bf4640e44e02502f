"""Designs of DEM cases: one row per case, identified by a stable id ("c0001", "c0002", ...).

A design assigns values to contact and set-up parameters (LIGGGHTS keyword names, SI units).
Four kinds are supported:

- ``factorial``: the full Cartesian product of given levels (the paper's Table 2);
- ``random``: independent uniform draws;
- ``lhs``: a Latin hypercube (one point per stratum and column);
- ``sobol``: a scrambled, seeded Sobol' sequence (balanced only for n a power of two).

The sampled kinds map a unit hypercube onto three kinds of columns: continuous ranges
``(low, high)``, integer ranges (``integer`` names a range column whose values are whole numbers
in ``[low, high]``), and ``choices`` (a list of allowed values, e.g. dCylDp in {20, 36, 38, 40};
the unit coordinate picks an index). ``fixed`` columns hold one constant value.

Columns are ordered canonically (known parameters in the order of ``PARAMETER_ORDER``, then any
other names in the order given), and the unit-cube dimensions follow that order, so the same
specification gives the same table whatever the key order of its mappings. Sampled values are
rounded to ``SIGNIFICANT_DIGITS`` significant digits so that a table written with
:func:`write_design_table` reads back bit-identical.
"""

from __future__ import annotations

import itertools
import math
import re
import warnings
from collections.abc import Collection, Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import qmc

__all__ = [
    "CASE_ID_COLUMN",
    "PAPER_TABLE2_LEVELS",
    "PARAMETER_ORDER",
    "SIGNIFICANT_DIGITS",
    "DesignSpecError",
    "DesignTableError",
    "build_design",
    "case_ids",
    "expand_load_conditions",
    "factorial_design",
    "latin_hypercube_design",
    "random_design",
    "read_design_table",
    "sobol_design",
    "write_design_table",
]

CASE_ID_COLUMN = "case_id"

#: Canonical column order of the known parameters (LIGGGHTS keywords, then set-up values).
PARAMETER_ORDER: tuple[str, ...] = (
    "coefficientFriction",
    "coefficientRollingFriction",
    "coefficientRestitution",
    "density",
    "cohesionEnergyDensity",
    "youngsModulus",
    "poissonsRatio",
    "dCylDp",
)

#: Levels of the paper's Table 2 (DEM variable input values for training the ANNs).
PAPER_TABLE2_LEVELS: dict[str, tuple[float, ...]] = {
    "coefficientFriction": (0.4, 0.6, 0.8),
    "coefficientRollingFriction": (0.4, 0.6, 0.8),
    "coefficientRestitution": (0.5, 0.7, 0.9),
    "density": (2500.0, 3000.0, 3500.0),
    "dCylDp": (20.0, 36.0, 38.0, 40.0),
}

#: Significant digits kept in sampled values and written to design tables.
SIGNIFICANT_DIGITS = 12
_FLOAT_FORMAT = f"%.{SIGNIFICANT_DIGITS}g"
_CASE_ID_PATTERN = re.compile(r"^c\d{4,}$")
_KINDS = ("factorial", "random", "lhs", "sobol")
_CONDITION_COLUMNS = ("normal_stress", "P")


class DesignSpecError(ValueError):
    """A design specification is incomplete or inconsistent; the message names the key."""


class DesignTableError(ValueError):
    """A design table file is malformed; the message names the file and the column."""


# ----------------------------------------------------------------------------------------------
# helpers


def case_ids(n: int) -> list[str]:
    """Stable case identifiers ``c0001 ... c{n}``.

    Parameters
    ----------
    n : int
        Number of cases (>= 0).

    Returns
    -------
    list of str
        ``n`` ids, zero-padded to at least four digits (wider when n > 9999 so that the ids
        still sort in case order).
    """
    if n < 0:
        raise DesignSpecError(f"number of cases must be >= 0, got {n}")
    width = max(4, len(str(n)))
    return [f"c{i:0{width}d}" for i in range(1, n + 1)]


def _round_sig(values: np.ndarray) -> np.ndarray:
    """Round to SIGNIFICANT_DIGITS so values survive the text format unchanged."""
    return np.array([float(_FLOAT_FORMAT % v) for v in np.asarray(values, dtype=float)])


def _ordered_names(names: Sequence[str]) -> list[str]:
    known = [p for p in PARAMETER_ORDER if p in names]
    others = [n for n in names if n not in PARAMETER_ORDER]
    return known + others


def _finite_float(value: object, where: str) -> float:
    try:
        out = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise DesignSpecError(f"{where}: expected a number, got {value!r}") from None
    if not math.isfinite(out):
        raise DesignSpecError(f"{where}: expected a finite number, got {value!r}")
    return out


def _number_list(value: object, where: str) -> list[float]:
    """A list or 1-D array of finite numbers (YAML lists, tuples and numpy arrays alike)."""
    if isinstance(value, np.ndarray) and value.ndim == 1:
        items: list[object] = value.tolist()
    elif isinstance(value, Sequence) and not isinstance(value, str | bytes):
        items = list(value)
    else:
        raise DesignSpecError(f"{where}: expected a list of numbers, got {value!r}")
    return [_finite_float(v, where) for v in items]


def _frame(ids: list[str], columns: Mapping[str, np.ndarray]) -> pd.DataFrame:
    data: dict[str, object] = {CASE_ID_COLUMN: ids}
    for name in _ordered_names(list(columns)):
        data[name] = np.asarray(columns[name], dtype=float)
    return pd.DataFrame(data)


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
    names = _ordered_names(list(levels))
    per_name: list[list[float]] = []
    for name in names:
        floats = _number_list(levels[name], f"levels.{name}")
        if not floats:
            raise DesignSpecError(f"levels.{name}: expected a non-empty list of numbers")
        if len(set(floats)) != len(floats):
            raise DesignSpecError(f"levels.{name}: repeated level in {floats!r}")
        per_name.append(floats)
    rows = np.array(list(itertools.product(*per_name)), dtype=float).reshape(-1, len(names))
    return _frame(case_ids(len(rows)), {n: rows[:, j] for j, n in enumerate(names)})


# ----------------------------------------------------------------------------------------------
# sampled designs


def _parse_range(name: str, bounds: object) -> tuple[float, float]:
    where = f"ranges.{name}"
    values = _number_list(bounds, where)
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
    sampled = _ordered_names([*ranges, *choices])
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
                columns[name] = _round_sig(low + u * (high - low))
        else:
            allowed = np.array(_number_list(choices[name], f"choices.{name}"))
            if allowed.size == 0:
                raise DesignSpecError(f"choices.{name}: expected a non-empty list of numbers")
            idx = np.minimum(np.floor(u * len(allowed)), len(allowed) - 1).astype(int)
            columns[name] = allowed[idx]
    for name, value in fixed.items():
        columns[name] = np.full(n, _finite_float(value, f"fixed.{name}"))
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
    return _frame(case_ids(n), columns)


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

_ALLOWED_KEYS = {
    "factorial": {"kind", "levels", "fixed"},
    "random": {"kind", "ranges", "n", "seed", "fixed", "integer", "choices"},
    "lhs": {"kind", "ranges", "n", "seed", "fixed", "integer", "choices"},
    "sobol": {"kind", "ranges", "n", "seed", "fixed", "integer", "choices"},
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
            table[name] = _finite_float(value, f"fixed.{name}")
        order = [CASE_ID_COLUMN, *_ordered_names([c for c in table if c != CASE_ID_COLUMN])]
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


# ----------------------------------------------------------------------------------------------
# load conditions


def expand_load_conditions(
    design: pd.DataFrame,
    normal_stresses: Sequence[float],
    P_values: Sequence[float],
) -> pd.DataFrame:
    """One row per case and shear-cell load condition.

    Parameters
    ----------
    design : pandas.DataFrame
        A design table with a ``case_id`` column (n rows).
    normal_stresses : sequence of float
        Pre-shear normal stresses, Pa (> 0).
    P_values : sequence of float
        Shear load as a fraction of the pre-shear load, in (0, 1].

    Returns
    -------
    pandas.DataFrame
        ``n * len(normal_stresses) * len(P_values)`` rows: the design columns followed by
        ``normal_stress`` and ``P``; ordered by case, then normal stress, then P (as given).
    """
    if CASE_ID_COLUMN not in design.columns:
        raise DesignSpecError(f"design: missing column '{CASE_ID_COLUMN}'")
    stresses = [_finite_float(s, "normal_stresses") for s in normal_stresses]
    loads = [_finite_float(p, "P_values") for p in P_values]
    if not stresses or not loads:
        raise DesignSpecError("normal_stresses and P_values must both be non-empty")
    if any(s <= 0 for s in stresses):
        raise DesignSpecError(f"normal_stresses: must be > 0 Pa, got {stresses}")
    if any(not 0 < p <= 1 for p in loads):
        raise DesignSpecError(f"P_values: must lie in (0, 1], got {loads}")
    for col in _CONDITION_COLUMNS:
        if col in design.columns:
            raise DesignSpecError(f"design: already has a '{col}' column")
    conditions = pd.DataFrame(
        list(itertools.product(stresses, loads)), columns=["normal_stress", "P"], dtype=float
    )
    out = design.merge(conditions, how="cross")
    return out.reset_index(drop=True)


# ----------------------------------------------------------------------------------------------
# files


def write_design_table(df: pd.DataFrame, path: str | Path) -> None:
    """Write a design table as CSV with a fixed float format (byte-stable).

    Parameters
    ----------
    df : pandas.DataFrame
        Table with a ``case_id`` column and numeric parameter columns.
    path : str or Path
        Output file; parent directories are created.

    Notes
    -----
    Floats are written with ``%.12g`` and ``\\n`` line endings, so equal tables give
    byte-identical files.
    """
    if CASE_ID_COLUMN not in df.columns:
        raise DesignSpecError(f"{path}: table has no '{CASE_ID_COLUMN}' column")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(path, index=False, float_format=_FLOAT_FORMAT, lineterminator="\n")


def read_design_table(path: str | Path) -> pd.DataFrame:
    """Read a design table written by :func:`write_design_table`.

    Parameters
    ----------
    path : str or Path
        CSV file.

    Returns
    -------
    pandas.DataFrame
        ``case_id`` as str, every other column as float64.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    DesignTableError
        If the ``case_id`` column is missing, ids are malformed or repeated (per load
        condition when ``normal_stress``/``P`` columns are present), or a parameter
        column holds a non-numeric or empty value (the message names file, column and row).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"design table not found: {path}")
    try:
        raw = pd.read_csv(path, dtype=str, keep_default_na=False)
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise DesignTableError(f"{path}: not a readable CSV table ({exc})") from None
    if CASE_ID_COLUMN not in raw.columns:
        raise DesignTableError(f"{path}: missing column '{CASE_ID_COLUMN}'")
    ids = raw[CASE_ID_COLUMN]
    bad = [i for i in ids if not _CASE_ID_PATTERN.match(i)]
    if bad:
        raise DesignTableError(
            f"{path}: column '{CASE_ID_COLUMN}' has malformed id {bad[0]!r} (expected 'c0001')"
        )
    # a table expanded over load conditions repeats each id once per condition
    key = [CASE_ID_COLUMN, *(c for c in _CONDITION_COLUMNS if c in raw.columns)]
    repeated = raw[raw.duplicated(subset=key)]
    if len(repeated):
        what = " and ".join(f"{c}={repeated[c].iloc[0]}" for c in key[1:])
        raise DesignTableError(
            f"{path}: column '{CASE_ID_COLUMN}' repeats id {repeated[CASE_ID_COLUMN].iloc[0]!r}"
            + (f" with {what}" if what else "")
        )
    data: dict[str, object] = {CASE_ID_COLUMN: ids.tolist()}
    for col in raw.columns:
        if col == CASE_ID_COLUMN:
            continue
        values = pd.to_numeric(raw[col].str.strip(), errors="coerce")
        invalid = values.isna()
        if invalid.any():
            row = int(np.flatnonzero(invalid.to_numpy())[0])
            raise DesignTableError(
                f"{path}: column '{col}' has non-numeric value {raw[col].iloc[row]!r} "
                f"(case {ids.iloc[row]})"
            )
        data[col] = values.to_numpy(dtype=float)
    return pd.DataFrame(data)
