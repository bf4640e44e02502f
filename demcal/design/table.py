"""Design tables of DEM cases: one row per case, identified by a stable id ("c0001", ...).

A design assigns values to contact and set-up parameters (LIGGGHTS keyword names, SI units);
:mod:`demcal.design.build` makes one from a specification. Columns are ordered canonically
(known parameters in the order of ``PARAMETER_ORDER``, then any other names in the order
given). Sampled values are rounded to ``SIGNIFICANT_DIGITS`` significant digits so that a table
written with :func:`write_design_table` reads back bit-identical.
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from demcal.core.parameters import CASE_PARAMETERS

__all__ = [
    "CASE_ID_COLUMN",
    "PARAMETER_ORDER",
    "SIGNIFICANT_DIGITS",
    "DesignSpecError",
    "DesignTableError",
    "case_ids",
    "design_frame",
    "expand_load_conditions",
    "finite_float",
    "number_list",
    "ordered_names",
    "read_design_table",
    "round_significant",
    "write_design_table",
]

CASE_ID_COLUMN = "case_id"

#: Canonical column order of the known parameters (LIGGGHTS keywords, then set-up values).
#: wallFriction is left out: it sorts with the other names, in the order given, and that order
#: fixes the unit-cube dimensions of the designs that vary it.
PARAMETER_ORDER: tuple[str, ...] = tuple(p for p in CASE_PARAMETERS if p != "wallFriction")

#: Significant digits kept in sampled values and written to design tables.
SIGNIFICANT_DIGITS = 12
_FLOAT_FORMAT = f"%.{SIGNIFICANT_DIGITS}g"
_CASE_ID_PATTERN = re.compile(r"^c\d{4,}$")
_CONDITION_COLUMNS = ("normal_stress", "P")


class DesignSpecError(ValueError):
    """A design specification is incomplete or inconsistent; the message names the key."""


class DesignTableError(ValueError):
    """A design table file is malformed; the message names the file and the column."""


# ----------------------------------------------------------------------------------------------
# ids, column order and values


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


def round_significant(values: np.ndarray) -> np.ndarray:
    """Round to SIGNIFICANT_DIGITS so values survive the text format unchanged."""
    return np.array([float(_FLOAT_FORMAT % v) for v in np.asarray(values, dtype=float)])


def ordered_names(names: Sequence[str]) -> list[str]:
    """``names`` in canonical order: known parameters as in ``PARAMETER_ORDER``, then the rest
    in the order given."""
    known = [p for p in PARAMETER_ORDER if p in names]
    others = [n for n in names if n not in PARAMETER_ORDER]
    return known + others


def finite_float(value: object, where: str) -> float:
    """``value`` as a finite float; a :class:`DesignSpecError` names ``where`` otherwise."""
    try:
        out = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise DesignSpecError(f"{where}: expected a number, got {value!r}") from None
    if not math.isfinite(out):
        raise DesignSpecError(f"{where}: expected a finite number, got {value!r}")
    return out


def number_list(value: object, where: str) -> list[float]:
    """A list or 1-D array of finite numbers (YAML lists, tuples and numpy arrays alike)."""
    if isinstance(value, np.ndarray) and value.ndim == 1:
        items: list[object] = value.tolist()
    elif isinstance(value, Sequence) and not isinstance(value, str | bytes):
        items = list(value)
    else:
        raise DesignSpecError(f"{where}: expected a list of numbers, got {value!r}")
    return [finite_float(v, where) for v in items]


def design_frame(ids: list[str], columns: Mapping[str, np.ndarray]) -> pd.DataFrame:
    """A design table: ``case_id`` then the columns (each of shape (n,)) in canonical order."""
    data: dict[str, object] = {CASE_ID_COLUMN: ids}
    for name in ordered_names(list(columns)):
        data[name] = np.asarray(columns[name], dtype=float)
    return pd.DataFrame(data)


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
    stresses = [finite_float(s, "normal_stresses") for s in normal_stresses]
    loads = [finite_float(p, "P_values") for p in P_values]
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
