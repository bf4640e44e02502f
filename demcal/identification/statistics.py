"""Statistics of the valid parameter sets (paper Table 5) and the identified parameters.

The valid sets are a DataFrame with one column per contact parameter (LIGGGHTS names, SI
units) and one row per valid set, e.g. from
:meth:`demcal.identification.screening.ScreeningResult.to_frame`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from demcal.core.parameters import PARAMETER_LABELS

STATISTICS = ("mean", "sd", "max", "range", "sd/range")
"""Per-parameter rows of Table 5, in order."""

VALID_GROUP = "valid sets"
"""First index level of the two count rows of Table 5 (``number`` and ``percent``)."""


def _check_columns(valid: pd.DataFrame, parameters: Sequence[str], what: str) -> None:
    missing = [p for p in parameters if p not in valid.columns]
    if missing:
        raise KeyError(f"{what}: valid-set table has no column(s) {missing}")


def valid_set_statistics(
    valid: pd.DataFrame,
    axes_ranges: Mapping[str, tuple[float, float]],
    n_total: int,
    label: str = "valid",
) -> pd.DataFrame:
    """Table 5 for one group of valid sets.

    Parameters
    ----------
    valid : pandas.DataFrame, shape (n_valid, >= n_parameters)
        Valid sets; must hold a column for every parameter in ``axes_ranges``.
    axes_ranges : Mapping[str, tuple[float, float]]
        Per parameter, the (low, high) of its screening axis; the range is high - low
        (e.g. 0.9 for mu_s in [0.1, 1.0]). Its order sets the row order.
    n_total : int
        Number of screened candidate sets (the denominator of the percentage).
    label : str
        Column name of the returned table (e.g. ``"SSC"``, ``"AoR"``, ``"SSC & AoR"``).

    Returns
    -------
    pandas.DataFrame, one column ``label``
        Rows indexed by (parameter, statistic) with statistic in mean, sd (sample standard
        deviation, ddof=1), max, range, sd/range, followed by (``"valid sets"``, ``"number"``)
        and (``"valid sets"``, ``"percent"``). Statistics are NaN when there are too few
        valid sets (none; sd with one).
    """
    if n_total < 1:
        raise ValueError(f"valid_set_statistics: n_total must be >= 1, got {n_total}")
    if len(valid) > n_total:
        raise ValueError(
            f"valid_set_statistics: {len(valid)} valid sets exceed n_total = {n_total}"
        )
    parameters = list(axes_ranges)
    _check_columns(valid, parameters, "valid_set_statistics")
    keys: list[tuple[str, str]] = []
    values: list[float] = []
    for name in parameters:
        low, high = axes_ranges[name]
        span = float(high) - float(low)
        if not span > 0.0:
            raise ValueError(
                f"valid_set_statistics: range of {name!r} must have high > low, got ({low}, {high})"
            )
        column = valid[name].to_numpy(dtype=np.float64)
        n = column.size
        mean = float(column.mean()) if n else math.nan
        sd = float(column.std(ddof=1)) if n > 1 else math.nan
        top = float(column.max()) if n else math.nan
        for stat, value in zip(STATISTICS, (mean, sd, top, span, sd / span), strict=True):
            keys.append((name, stat))
            values.append(value)
    keys += [(VALID_GROUP, "number"), (VALID_GROUP, "percent")]
    values += [float(len(valid)), 100.0 * len(valid) / n_total]
    index = pd.MultiIndex.from_tuples(keys, names=["parameter", "statistic"])
    return pd.DataFrame({label: values}, index=index)


def combine_statistics(tables: Sequence[pd.DataFrame]) -> pd.DataFrame:
    """Side-by-side Table 5 of several groups (e.g. SSC, AoR, SSC & AoR).

    All tables must come from :func:`valid_set_statistics` with the same parameters.
    """
    if not tables:
        raise ValueError("combine_statistics: no tables given")
    first = tables[0].index
    for table in tables[1:]:
        if not table.index.equals(first):
            raise ValueError("combine_statistics: tables have different rows")
    return pd.concat(list(tables), axis=1)


def identified_parameters(
    valid: pd.DataFrame, parameters: Sequence[str] | None = None
) -> dict[str, dict[str, float]]:
    """Identified value of each parameter: statistics over the valid sets.

    Parameters
    ----------
    valid : pandas.DataFrame, shape (n_valid, ...)
        Valid sets, one column per parameter.
    parameters : Sequence[str], optional
        Columns to summarise; defaults to the known contact parameters present in ``valid``.

    Returns
    -------
    dict[str, dict[str, float]]
        Per parameter: ``mean``, ``sd`` (ddof=1; 0 for a single set), ``min``, ``max`` in the
        parameter's SI unit. The means form the parameter set used downstream.
    """
    if parameters is None:
        parameters = [p for p in PARAMETER_LABELS if p in valid.columns]
        if not parameters:
            raise KeyError(
                f"identified_parameters: valid-set table has none of the columns "
                f"{list(PARAMETER_LABELS)}"
            )
    _check_columns(valid, parameters, "identified_parameters")
    if len(valid) == 0:
        raise ValueError("identified_parameters: there are no valid sets to identify from")
    out: dict[str, dict[str, float]] = {}
    for name in parameters:
        column = valid[name].to_numpy(dtype=np.float64)
        out[name] = {
            "mean": float(column.mean()),
            "sd": float(column.std(ddof=1)) if column.size > 1 else 0.0,
            "min": float(column.min()),
            "max": float(column.max()),
        }
    return out


@dataclass(frozen=True)
class DominantBinMap:
    """Which colour-parameter bin holds most valid sets in each cell of a 2-D parameter grid.

    Attributes
    ----------
    x_edges : numpy.ndarray, shape (n_x + 1,)
        Cell edges along the x parameter.
    y_edges : numpy.ndarray, shape (n_y + 1,)
        Cell edges along the y parameter.
    bin_edges : numpy.ndarray, shape (n_bins + 1,)
        Edges of the equal bins of the colour parameter.
    counts : numpy.ndarray of int, shape (n_y, n_x, n_bins)
        Valid sets per cell and bin.
    dominant : numpy.ndarray of int, shape (n_y, n_x)
        Index of the bin with most valid sets (lowest bin on ties); -1 in empty cells.
    """

    x_edges: np.ndarray
    y_edges: np.ndarray
    bin_edges: np.ndarray
    counts: np.ndarray
    dominant: np.ndarray


def _bin_index(values: np.ndarray, edges: np.ndarray, name: str) -> np.ndarray:
    lo, hi = edges[0], edges[-1]
    if values.size and (values.min() < lo or values.max() > hi):
        raise ValueError(f"values of {name!r} lie outside the axis range [{lo}, {hi}]")
    # The upper edge belongs to the last bin.
    return np.clip(np.searchsorted(edges, values, side="right") - 1, 0, edges.size - 2)


def _value_range(values: np.ndarray | Sequence[float], name: str) -> tuple[float, float]:
    arr = np.asarray(values, dtype=np.float64)
    if arr.size < 2 or not arr.max() > arr.min():
        raise ValueError(f"axis {name!r}: need at least two distinct values to span a range")
    return float(arr.min()), float(arr.max())


def dominant_bin_map(
    valid: pd.DataFrame,
    axes: Mapping[str, np.ndarray | Sequence[float]],
    n_cells: int | tuple[int, int] = 20,
    n_bins: int = 4,
    x: str = "coefficientFriction",
    y: str = "coefficientRollingFriction",
    colour: str = "coefficientRestitution",
) -> DominantBinMap:
    """Per (x, y) cell, the colour-parameter bin that holds most valid sets (paper Fig. 7).

    Parameters
    ----------
    valid : pandas.DataFrame
        Valid sets with columns ``x``, ``y`` and ``colour``.
    axes : Mapping[str, array_like]
        Per parameter, either the screening axis values or its (low, high); the cell and
        bin edges span the min..max of what is given.
    n_cells : int or (int, int)
        Number of cells along x and y.
    n_bins : int
        Number of equal bins over the colour axis range (4 COR ranges in the paper).
    x, y, colour : str
        Column names (defaults: mu_s, mu_r, COR).

    Returns
    -------
    DominantBinMap
    """
    _check_columns(valid, [x, y, colour], "dominant_bin_map")
    for name in (x, y, colour):
        if name not in axes:
            raise KeyError(f"dominant_bin_map: no axis range for {name!r}")
    nx, ny = (n_cells, n_cells) if isinstance(n_cells, int) else n_cells
    if nx < 1 or ny < 1 or n_bins < 1:
        raise ValueError(
            f"dominant_bin_map: n_cells and n_bins must be >= 1, got {n_cells}, {n_bins}"
        )
    x_edges = np.linspace(*_value_range(axes[x], x), nx + 1)
    y_edges = np.linspace(*_value_range(axes[y], y), ny + 1)
    bin_edges = np.linspace(*_value_range(axes[colour], colour), n_bins + 1)
    ix = _bin_index(valid[x].to_numpy(dtype=np.float64), x_edges, x)
    iy = _bin_index(valid[y].to_numpy(dtype=np.float64), y_edges, y)
    ib = _bin_index(valid[colour].to_numpy(dtype=np.float64), bin_edges, colour)
    counts = np.zeros((ny, nx, n_bins), dtype=np.int64)
    np.add.at(counts, (iy, ix, ib), 1)
    dominant = np.where(counts.sum(axis=2) > 0, counts.argmax(axis=2), -1)
    return DominantBinMap(x_edges, y_edges, bin_edges, counts, dominant)


def _format_cell(statistic: str, value: float) -> str:
    if math.isnan(value):
        return "-"
    if statistic == "number":
        return f"{round(value):d}"
    if statistic == "percent":
        return f"{value:.2f}"
    return f"{value:.4g}"


def table5_markdown(table: pd.DataFrame) -> str:
    """Table 5 as a GitHub-flavoured markdown table.

    Parameters
    ----------
    table : pandas.DataFrame
        Output of :func:`valid_set_statistics` or :func:`combine_statistics`.

    Returns
    -------
    str
        Markdown with columns parameter, statistic and one per group; counts as integers,
        percentages with two decimals, other values with four significant digits.
    """
    header = ["parameter", "statistic", *map(str, table.columns)]
    lines = [
        "| " + " | ".join(header) + " |",
        "|" + "|".join(["---", "---"] + ["---:"] * len(table.columns)) + "|",
    ]
    previous = None
    for (parameter, statistic), row in table.iterrows():
        shown = PARAMETER_LABELS.get(parameter, parameter) if parameter != previous else ""
        previous = parameter
        cells = [_format_cell(statistic, float(v)) for v in row.to_numpy()]
        lines.append("| " + " | ".join([shown, statistic, *cells]) + " |")
    return "\n".join(lines) + "\n"


def write_table5_markdown(table: pd.DataFrame, path: str | Path) -> Path:
    """Write :func:`table5_markdown` to ``path``; returns the path."""
    out = Path(path)
    out.write_text(table5_markdown(table), encoding="utf-8")
    return out


def write_table5_csv(table: pd.DataFrame, path: str | Path) -> Path:
    """Write Table 5 as CSV (columns parameter, statistic, one per group); returns the path."""
    out = Path(path)
    table.to_csv(out, index=True, float_format="%.10g")
    return out


def read_table5_csv(path: str | Path) -> pd.DataFrame:
    """Read a Table 5 CSV written by :func:`write_table5_csv`."""
    source = Path(path)
    frame = pd.read_csv(source)
    for column in ("parameter", "statistic"):
        if column not in frame.columns:
            raise KeyError(f"{source}: Table 5 CSV has no column {column!r}")
    return frame.set_index(["parameter", "statistic"])
