"""Segregation of a moving box over time: the time series, its steady window and the
time-averaged layer table and index.

The analysis runs over a time series of snapshots, with the box moved to where it is at each
snapshot. The record counts from the first snapshot at which all three layers hold particles.
Steady state is the tail of that record in which neither S nor the solid fraction of the box
(particle volume over box volume) shows a significant trend
(:func:`demcal.core.steady_state.detect_plateau`); the layer table and the index are
computed from the particle volumes summed over the snapshots of that window (a time average).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from demcal.application.chute_cooler.box_layers import (
    LAYERS,
    Box,
    layer_class_volumes,
    layer_table,
)
from demcal.application.chute_cooler.segregation import (
    SegregationIndex,
    index_from_radii,
    mean_radii,
    segregation_index,
)
from demcal.core.steady_state import detect_plateau

__all__ = [
    "SegregationResult",
    "SteadyWindow",
    "analyse_segregation",
    "segregation_time_series",
    "steady_window",
]


def segregation_time_series(
    snapshots: Iterable[tuple[float, np.ndarray, np.ndarray, Box]],
    class_radii: Sequence[float],
) -> tuple[pd.DataFrame, np.ndarray, np.ndarray]:
    """Layer contents and segregation index of a moving box over time.

    Parameters
    ----------
    snapshots : iterable of (time, positions, radii, box)
        Time (s), particle centres (shape (n, 3), m), radii (shape (n,), m) and the box at
        that time, in increasing time.
    class_radii : sequence of float, shape (k,)
        Class radii, m.

    Returns
    -------
    series : pandas.DataFrame, shape (n_snapshots, 9)
        Columns time (s), n_particles, solid_volume (m^3), solid_fraction (-), r_top,
        r_middle, r_bottom, r_box (m) and segregation_index (-; NaN while the top or bottom
        layer is empty).
    volumes : numpy.ndarray, shape (n_snapshots, 3, k)
        Particle volume per snapshot, layer and class, m^3.
    counts : numpy.ndarray, shape (n_snapshots, 3, k)
        Particles per snapshot, layer and class.
    """
    rows, all_volumes, all_counts = [], [], []
    k = len(class_radii)
    for time, positions, radii, box in snapshots:
        volumes, counts = layer_class_volumes(positions, radii, box, class_radii)
        per_layer, whole = mean_radii(volumes, class_radii)
        rows.append(
            {
                "time": float(time),
                "n_particles": int(counts.sum()),
                "solid_volume": float(volumes.sum()),
                "solid_fraction": float(volumes.sum() / box.volume),
                "r_top": float(per_layer[0]),
                "r_middle": float(per_layer[1]),
                "r_bottom": float(per_layer[2]),
                "r_box": whole,
                "segregation_index": index_from_radii(per_layer, whole),
            }
        )
        all_volumes.append(volumes)
        all_counts.append(counts)
    series = pd.DataFrame(
        rows,
        columns=[
            "time",
            "n_particles",
            "solid_volume",
            "solid_fraction",
            "r_top",
            "r_middle",
            "r_bottom",
            "r_box",
            "segregation_index",
        ],
    )
    shape = (len(rows), len(LAYERS), k)
    volumes_arr = np.array(all_volumes, dtype=float).reshape(shape)
    counts_arr = np.array(all_counts, dtype=np.int64).reshape(shape)
    return series, volumes_arr, counts_arr


@dataclass(frozen=True)
class SteadyWindow:
    """The window of snapshots over which the layers are averaged.

    Attributes
    ----------
    start_index, end_index : int
        Rows ``start_index:end_index`` of the time series.
    start_time, end_time : float
        Times of the first and last snapshot of the window, s.
    steady : bool
        Whether both the index and the solid fraction passed the trend test.
    reason : str
        Short explanation.
    """

    start_index: int
    end_index: int
    start_time: float
    end_time: float
    steady: bool
    reason: str


def steady_window(series: pd.DataFrame, min_fraction: float = 0.2) -> SteadyWindow:
    """Steady tail of a segregation time series.

    The record starts at the first snapshot from which on the index is finite (all layers
    filled). Both the segregation index and the solid fraction are tested with
    :func:`demcal.core.steady_state.detect_plateau`; the window starts at the later of the
    two
    plateau starts. If either is unsteady (or the record is too short), the window is the last
    ``min_fraction`` of the record (at least one snapshot) and ``steady`` is False.

    Parameters
    ----------
    series : pandas.DataFrame
        Output of :func:`segregation_time_series`.
    min_fraction : float
        Shortest plateau accepted, as a fraction of the record, in (0, 1).

    Raises
    ------
    ValueError
        No snapshot has particles in the top and bottom layers.
    """
    index = series["segregation_index"].to_numpy(dtype=float)
    finite = np.isfinite(index)
    if not finite.any():
        raise ValueError(
            "steady_window: no snapshot has particles in both the top and bottom layer"
        )
    # the record starts after the last snapshot with an empty top or bottom layer
    bad = np.flatnonzero(~finite)
    first = int(bad[-1]) + 1 if bad.size else 0
    if first >= len(index):
        raise ValueError("steady_window: the last snapshot has an empty top or bottom layer")
    t = series["time"].to_numpy(dtype=float)[first:]
    n = t.size
    fallback_start = first + max(0, n - max(1, math.ceil(min_fraction * n)))
    if n < 10:
        return SteadyWindow(
            fallback_start,
            len(index),
            float(series["time"].iloc[fallback_start]),
            float(series["time"].iloc[-1]),
            False,
            f"only {n} snapshots with filled layers (10 needed to test for a trend)",
        )
    plateaus = {
        name: detect_plateau(
            t, series[name].to_numpy(dtype=float)[first:], min_fraction=min_fraction
        )
        for name in ("segregation_index", "solid_fraction")
    }
    if all(p.steady for p in plateaus.values()):
        start = first + max(p.start_index for p in plateaus.values())
        reason = "; ".join(f"{name}: {p.reason}" for name, p in plateaus.items())
        steady = True
    else:
        start = fallback_start
        reason = "; ".join(f"{name}: {p.reason}" for name, p in plateaus.items() if not p.steady)
        steady = False
    return SteadyWindow(
        start,
        len(index),
        float(series["time"].iloc[start]),
        float(series["time"].iloc[-1]),
        steady,
        reason,
    )


@dataclass(frozen=True)
class SegregationResult:
    """Everything the chute-cooler analysis reports.

    Attributes
    ----------
    table : pandas.DataFrame
        :func:`layer_table` of the volumes summed over the steady window (counts averaged).
    index : SegregationIndex
        Index of the same volumes.
    series : pandas.DataFrame
        :func:`segregation_time_series` output.
    window : SteadyWindow
        The averaging window.
    """

    table: pd.DataFrame
    index: SegregationIndex
    series: pd.DataFrame
    window: SteadyWindow


def analyse_segregation(
    snapshots: Iterable[tuple[float, np.ndarray, np.ndarray, Box]],
    class_radii: Sequence[float],
    min_fraction: float = 0.2,
) -> SegregationResult:
    """Time series, steady window, layer table and segregation index of a box.

    Parameters
    ----------
    snapshots : iterable of (time, positions, radii, box)
        See :func:`segregation_time_series`.
    class_radii : sequence of float, shape (k,)
        Class radii, m.
    min_fraction : float
        Shortest steady window, as a fraction of the record.

    Returns
    -------
    SegregationResult
    """
    boxes: list[Box] = []

    def remember(items: Iterable[tuple[float, np.ndarray, np.ndarray, Box]]):
        for item in items:
            boxes.append(item[3])
            yield item

    series, volumes, counts = segregation_time_series(remember(snapshots), class_radii)
    if series.empty:
        raise ValueError("analyse_segregation: no snapshots")
    window = steady_window(series, min_fraction)
    sl = slice(window.start_index, window.end_index)
    v = volumes[sl].sum(axis=0)
    c = counts[sl].mean(axis=0)
    # fractions are ratios, so summed volumes give the time average; the solid fraction
    # needs the mean volume
    n_window = window.end_index - window.start_index
    table = layer_table(v / n_window, c, class_radii, boxes[-1])
    return SegregationResult(
        table=table, index=segregation_index(v, class_radii), series=series, window=window
    )
