"""Size segregation in a box split into three equal horizontal layers (paper Figs. 10-11).

A box is the cuboid ``x0 <= x < x1, y0 <= y < y1, z0 <= z < z1`` (m); it is divided into three
layers of equal height: top, middle, bottom (paper: layers 6, 7 and 8). A particle belongs to the
layer that holds its centre; particles whose centres lie above ``z1`` (the heap that the chute
keeps supplying) or outside the box are ignored. Particles are sorted into the discrete size
classes of the feed by their radius.

Per layer and class the particle volume ``V_lk`` (m^3) is summed. Two normalisations are
reported: the *volume fraction* of class k in layer l, ``V_lk / sum_k V_lk`` (sums to 1 over
the classes of a layer; the quantity of paper Fig. 11, "percentage of the total volume of the
particles in each layer"), and the *share of class* k held by layer l, ``V_lk / sum_l V_lk``
(sums to 1 over the layers; 1/3 each for a uniform, mixed box).

Segregation index
-----------------
With the volume-weighted mean radius of layer l, ``r_l = sum_k V_lk r_k / sum_k V_lk``, and of
the whole box, ``r_box``,

    S = (r_bottom - r_top) / r_box.

S is 0 when every layer has the same composition, positive when the coarse particles gather at
the bottom (what the cooler wants: open pores where the air enters) and negative for the
reverse. The largest S possible for the same particles and the same particle volume per layer is
that of the completely sorted box: the bottom layer filled with the coarsest material, then the
middle, then the top (``S_sorted``). The normalised index ``S_norm = S / S_sorted`` is 1 for
complete sorting and 0 for a mixture. Normalising by the completely segregated state follows
Danckwerts' intensity of segregation (P. V. Danckwerts, "The definition and measurement of some
characteristics of mixtures", Appl. Sci. Res. A 3 (1952) 279-296), here applied to the mean
particle size of the layers instead of the concentration of one component.

Steady state
------------
The analysis runs over a time series of snapshots, with the box moved to where it is at each
snapshot. The record counts from the first snapshot at which all three layers hold particles.
Steady state is the tail of that record in which neither S nor the solid fraction of the box
(particle volume over box volume) shows a significant trend
(:func:`demcal.virtual_tests.steady_state.detect_plateau`); the layer table and the index are
computed from
the particle volumes summed over the snapshots of that window (a time average).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from demcal.virtual_tests.steady_state import detect_plateau

__all__ = [
    "LAYERS",
    "Box",
    "SegregationIndex",
    "SegregationResult",
    "SteadyWindow",
    "analyse_segregation",
    "assign_classes",
    "layer_class_volumes",
    "layer_table",
    "mean_radii",
    "segregation_index",
    "segregation_time_series",
    "sorted_volumes",
    "steady_window",
    "table_volumes",
]

#: Layer names from top to bottom (row order of every per-layer array).
LAYERS = ("top", "middle", "bottom")


@dataclass(frozen=True)
class Box:
    """An axis-aligned box, m: ``x0 <= x < x1``, ``y0 <= y < y1``, ``z0 <= z < z1``."""

    x0: float
    x1: float
    y0: float
    y1: float
    z0: float
    z1: float

    def __post_init__(self) -> None:
        for lo, hi, axis in (
            (self.x0, self.x1, "x"),
            (self.y0, self.y1, "y"),
            (self.z0, self.z1, "z"),
        ):
            if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo):
                raise ValueError(f"Box: need finite {axis}0 < {axis}1, got {lo}, {hi}")

    @property
    def volume(self) -> float:
        """Box volume, m^3."""
        return (self.x1 - self.x0) * (self.y1 - self.y0) * (self.z1 - self.z0)

    def layer_edges(self) -> np.ndarray:
        """Heights of the layer boundaries from top to bottom, shape (4,), m."""
        return np.linspace(self.z1, self.z0, len(LAYERS) + 1)


def assign_classes(
    radii: np.ndarray, class_radii: Sequence[float], rtol: float = 1e-6
) -> np.ndarray:
    """Index of the size class of every particle.

    Parameters
    ----------
    radii : numpy.ndarray, shape (n,)
        Particle radii, m.
    class_radii : sequence of float, shape (k,)
        Radii of the classes, m.
    rtol : float
        Largest accepted relative distance to the nearest class radius.

    Returns
    -------
    numpy.ndarray of int, shape (n,)
        Class index in ``0..k-1``.

    Raises
    ------
    ValueError
        A radius matches no class.
    """
    r = np.asarray(radii, dtype=float).reshape(-1)
    c = np.asarray(class_radii, dtype=float).reshape(-1)
    if c.size == 0:
        raise ValueError("assign_classes: no class radii given")
    if r.size == 0:
        return np.zeros(0, dtype=np.int64)
    idx = np.abs(r[:, None] - c[None, :]).argmin(axis=1)
    dev = np.abs(r - c[idx]) / c[idx]
    bad = np.flatnonzero(~(dev <= rtol))
    if bad.size:
        raise ValueError(
            f"assign_classes: radius {r[bad[0]]!r} m matches none of the class radii "
            f"{', '.join(f'{x:g}' for x in c)} m ({bad.size} particle(s))"
        )
    return idx.astype(np.int64)


def layer_class_volumes(
    positions: np.ndarray, radii: np.ndarray, box: Box, class_radii: Sequence[float]
) -> tuple[np.ndarray, np.ndarray]:
    """Particle volume and count per layer and size class.

    Parameters
    ----------
    positions : numpy.ndarray, shape (n, 3)
        Particle centres, m.
    radii : numpy.ndarray, shape (n,)
        Particle radii, m.
    box : Box
        The box at the time of the snapshot.
    class_radii : sequence of float, shape (k,)
        Radii of the size classes, m.

    Returns
    -------
    volumes : numpy.ndarray, shape (3, k)
        Particle volume per layer (rows top, middle, bottom) and class, m^3.
    counts : numpy.ndarray of int, shape (3, k)
        Particles per layer and class.
    """
    x = np.asarray(positions, dtype=float).reshape(-1, 3)
    r = np.asarray(radii, dtype=float).reshape(-1)
    if x.shape[0] != r.size:
        raise ValueError(f"layer_class_volumes: {x.shape[0]} positions but {r.size} radii")
    k = len(class_radii)
    inside = (
        (x[:, 0] >= box.x0)
        & (x[:, 0] < box.x1)
        & (x[:, 1] >= box.y0)
        & (x[:, 1] < box.y1)
        & (x[:, 2] >= box.z0)
        & (x[:, 2] < box.z1)
    )
    xs, rs = x[inside], r[inside]
    cls = assign_classes(rs, class_radii)
    height = (box.z1 - box.z0) / len(LAYERS)
    # each layer is [z_low, z_high); row 0 of the output is the top layer
    from_bottom = np.clip(
        np.floor((xs[:, 2] - box.z0) / height).astype(np.int64), 0, len(LAYERS) - 1
    )
    layer = len(LAYERS) - 1 - from_bottom
    volumes = np.zeros((len(LAYERS), k))
    counts = np.zeros((len(LAYERS), k), dtype=np.int64)
    np.add.at(volumes, (layer, cls), 4.0 / 3.0 * np.pi * rs**3)
    np.add.at(counts, (layer, cls), 1)
    return volumes, counts


def mean_radii(volumes: np.ndarray, class_radii: Sequence[float]) -> tuple[np.ndarray, float]:
    """Volume-weighted mean radius of every layer and of the whole box.

    Parameters
    ----------
    volumes : numpy.ndarray, shape (3, k)
        Particle volume per layer and class, m^3.
    class_radii : sequence of float, shape (k,)
        Class radii, m.

    Returns
    -------
    per_layer : numpy.ndarray, shape (3,)
        m; NaN for an empty layer.
    whole : float
        m; NaN for an empty box.
    """
    v = np.asarray(volumes, dtype=float)
    c = np.asarray(class_radii, dtype=float)
    totals = v.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        per_layer = np.where(
            totals > 0, (v * c).sum(axis=1) / np.where(totals > 0, totals, 1), np.nan
        )
    total = float(v.sum())
    whole = float((v * c).sum() / total) if total > 0 else math.nan
    return per_layer, whole


def sorted_volumes(volumes: np.ndarray, class_radii: Sequence[float]) -> np.ndarray:
    """The completely sorted arrangement of the same particles with the same layer volumes.

    The bottom layer takes the coarsest material up to its particle volume, then the middle
    layer, then the top; a class that does not fit is split between two layers.

    Parameters
    ----------
    volumes : numpy.ndarray, shape (3, k)
        Particle volume per layer (top, middle, bottom) and class, m^3.
    class_radii : sequence of float, shape (k,)
        Class radii, m.

    Returns
    -------
    numpy.ndarray, shape (3, k)
        Sorted volumes, m^3 (same row sums and column sums as ``volumes``).
    """
    v = np.asarray(volumes, dtype=float)
    class_total = v.sum(axis=0)
    capacity = v.sum(axis=1)[::-1].copy()  # bottom first
    out = np.zeros_like(v)
    tiny = 1e-12 * float(class_total.sum())
    layer = 0
    for k in np.argsort(-np.asarray(class_radii, dtype=float), kind="stable"):
        left = class_total[k]
        while left > 0.0 and layer < len(LAYERS):
            take = min(left, capacity[layer])
            out[len(LAYERS) - 1 - layer, k] += take
            capacity[layer] -= take
            left -= take
            if capacity[layer] <= tiny:
                layer += 1
    return out


@dataclass(frozen=True)
class SegregationIndex:
    """Segregation index of one layered box (see the module docstring).

    Attributes
    ----------
    index : float
        ``S = (r_bottom - r_top) / r_box``, -.
    sorted_index : float
        S of the completely sorted arrangement, -.
    normalised : float
        ``S / S_sorted``, - (NaN when ``S_sorted`` is 0, e.g. one size class).
    mean_radius : dict of str to float
        Volume-weighted mean radius of the layers (top, middle, bottom) and the box ("box"), m.
    """

    index: float
    sorted_index: float
    normalised: float
    mean_radius: dict[str, float]


def _index_from_radii(per_layer: np.ndarray, whole: float) -> float:
    if not (math.isfinite(whole) and whole > 0):
        return math.nan
    return float((per_layer[-1] - per_layer[0]) / whole)


def segregation_index(volumes: np.ndarray, class_radii: Sequence[float]) -> SegregationIndex:
    """Segregation index S, its value for complete sorting and the normalised index.

    Parameters
    ----------
    volumes : numpy.ndarray, shape (3, k)
        Particle volume per layer (top, middle, bottom) and class, m^3.
    class_radii : sequence of float, shape (k,)
        Class radii, m.

    Returns
    -------
    SegregationIndex
        NaN values when the top or the bottom layer is empty.
    """
    per_layer, whole = mean_radii(volumes, class_radii)
    s = _index_from_radii(per_layer, whole)
    sorted_layer, sorted_whole = mean_radii(sorted_volumes(volumes, class_radii), class_radii)
    s_sorted = _index_from_radii(sorted_layer, sorted_whole)
    norm = s / s_sorted if math.isfinite(s_sorted) and s_sorted > 1e-12 else math.nan
    radii = {name: float(per_layer[i]) for i, name in enumerate(LAYERS)}
    radii["box"] = whole
    return SegregationIndex(index=s, sorted_index=s_sorted, normalised=norm, mean_radius=radii)


def layer_table(
    volumes: np.ndarray, counts: np.ndarray, class_radii: Sequence[float], box: Box
) -> pd.DataFrame:
    """The per-layer, per-class table (one row per layer and class).

    Parameters
    ----------
    volumes : numpy.ndarray, shape (3, k)
        Particle volume per layer and class, m^3.
    counts : numpy.ndarray, shape (3, k)
        Particles per layer and class (may be averages over snapshots).
    class_radii : sequence of float, shape (k,)
        Class radii, m.
    box : Box
        Gives the layer heights relative to the floor.

    Returns
    -------
    pandas.DataFrame, shape (3 k, 9)
        Columns layer, z_low, z_high (m above the floor), radius (m), n_particles, volume
        (m^3), volume_fraction (of the layer's particle volume, -), share_of_class (of the
        class volume in the box, -), solid_fraction (particle volume of the layer over the
        layer volume, -). Empty layers or classes give NaN fractions.
    """
    v = np.asarray(volumes, dtype=float)
    n = np.asarray(counts, dtype=float)
    edges = box.layer_edges() - box.z0
    layer_volume = box.volume / len(LAYERS)
    per_layer = v.sum(axis=1, keepdims=True)
    per_class = v.sum(axis=0, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = np.where(per_layer > 0, v / np.where(per_layer > 0, per_layer, 1), np.nan)
        share = np.where(per_class > 0, v / np.where(per_class > 0, per_class, 1), np.nan)
    rows = []
    for i, name in enumerate(LAYERS):
        for k, radius in enumerate(class_radii):
            rows.append(
                {
                    "layer": name,
                    "z_low": float(edges[i + 1]),
                    "z_high": float(edges[i]),
                    "radius": float(radius),
                    "n_particles": float(n[i, k]),
                    "volume": float(v[i, k]),
                    "volume_fraction": float(fraction[i, k]),
                    "share_of_class": float(share[i, k]),
                    "solid_fraction": float(per_layer[i, 0] / layer_volume),
                }
            )
    return pd.DataFrame(rows)


def table_volumes(
    table: pd.DataFrame, source: str = "layer table"
) -> tuple[np.ndarray, list[float]]:
    """Volumes per layer and class back from a :func:`layer_table` (e.g. read from CSV).

    Parameters
    ----------
    table : pandas.DataFrame
        Columns layer, radius (m), volume (m^3).
    source : str
        Named in error messages.

    Returns
    -------
    volumes : numpy.ndarray, shape (3, k)
        Rows top, middle, bottom, m^3.
    class_radii : list of float
        The k class radii in ascending order, m.

    Raises
    ------
    KeyError
        A column or a layer is missing.
    """
    missing = [c for c in ("layer", "radius", "volume") if c not in table.columns]
    if missing:
        raise KeyError(f"{source}: missing column(s) {', '.join(missing)}")
    wide = table.pivot(index="layer", columns="radius", values="volume")
    absent = [name for name in LAYERS if name not in wide.index]
    if absent:
        raise KeyError(f"{source}: missing layer(s) {', '.join(absent)}")
    wide = wide.loc[list(LAYERS)].fillna(0.0)
    return wide.to_numpy(dtype=float), [float(r) for r in wide.columns]


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
                "segregation_index": _index_from_radii(per_layer, whole),
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
    :func:`demcal.virtual_tests.steady_state.detect_plateau`; the window starts at the later of the
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
