"""Particle volume per layer and size class in a box split into three equal horizontal layers
(paper Figs. 10-11).

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
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

__all__ = [
    "LAYERS",
    "Box",
    "assign_classes",
    "layer_class_volumes",
    "layer_table",
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
