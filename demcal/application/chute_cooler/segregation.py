"""Segregation index of a box split into three layers (paper Figs. 10-11; layers and volumes
in :mod:`demcal.application.chute_cooler.box_layers`).

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
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from demcal.application.chute_cooler.box_layers import LAYERS

__all__ = [
    "SegregationIndex",
    "index_from_radii",
    "mean_radii",
    "segregation_index",
    "sorted_volumes",
]


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


def index_from_radii(per_layer: np.ndarray, whole: float) -> float:
    """S from the mean radii of the layers (top first, shape (3,), m) and of the box (m); NaN
    for an empty box."""
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
    s = index_from_radii(per_layer, whole)
    sorted_layer, sorted_whole = mean_radii(sorted_volumes(volumes, class_radii), class_radii)
    s_sorted = index_from_radii(sorted_layer, sorted_whole)
    norm = s / s_sorted if math.isfinite(s_sorted) and s_sorted > 1e-12 else math.nan
    radii = {name: float(per_layer[i]) for i, name in enumerate(LAYERS)}
    radii["box"] = whole
    return SegregationIndex(index=s, sorted_index=s_sorted, normalised=norm, mean_radius=radii)
