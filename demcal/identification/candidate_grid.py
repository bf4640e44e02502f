"""The candidate grid: sorted uniform random draws per parameter and their Cartesian product.

The candidate grid (paper Table 3, ``screening.axes`` of the configuration) has one sorted array
of uniform random draws per parameter; the candidate sets are the Cartesian product of these
axes (100 x 100 x 25 x 25 = 6.25 M sets in the paper). Sets are addressed by a flat C-order
index (the last axis varies fastest), so any chunk of the product can be built by index
arithmetic without materialising the grid.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping

import numpy as np
import pandas as pd

DEFAULT_CHUNK_SIZE = 1 << 18
"""Candidate sets evaluated at once by default; bounds the memory of a screening run."""


def draw_axes(spec: Mapping[str, tuple[float, float, int]], seed: int) -> dict[str, np.ndarray]:
    """Draw the grid axes: per parameter, sorted uniform random values in [low, high).

    Each axis gets its own child stream of ``numpy.random.SeedSequence(seed)`` (in the order
    of ``spec``), so an axis depends only on the seed and its position.

    Parameters
    ----------
    spec : Mapping[str, tuple[float, float, int]]
        Per parameter name: (low, high, count), SI units of the parameter.
    seed : int
        Seed of the draws.

    Returns
    -------
    dict[str, numpy.ndarray]
        Per parameter, a sorted float64 array of shape (count,).
    """
    if not spec:
        raise ValueError("draw_axes: empty axis specification")
    children = np.random.SeedSequence(seed).spawn(len(spec))
    axes: dict[str, np.ndarray] = {}
    for (name, entry), child in zip(spec.items(), children, strict=True):
        if len(entry) != 3:
            raise ValueError(f"draw_axes: axis {name!r} needs (low, high, count), got {entry!r}")
        low, high, count = entry
        if not (math.isfinite(low) and math.isfinite(high) and low < high):
            raise ValueError(f"draw_axes: axis {name!r} needs finite low < high, got {entry!r}")
        if int(count) != count or count < 1:
            raise ValueError(f"draw_axes: axis {name!r} needs an integer count >= 1, got {count!r}")
        rng = np.random.default_rng(child)
        axes[name] = np.sort(rng.uniform(low, high, int(count)))
    return axes


def grid_size(axes: Mapping[str, np.ndarray]) -> int:
    """Number of candidate sets, i.e. the product of the axis lengths."""
    return math.prod(grid_shape(axes))


def grid_shape(axes: Mapping[str, np.ndarray]) -> tuple[int, ...]:
    if not axes:
        raise ValueError("grid: no axes given")
    shape = tuple(len(values) for values in axes.values())
    for name, n in zip(axes, shape, strict=True):
        if n == 0:
            raise ValueError(f"grid: axis {name!r} is empty")
    return shape


def axis_positions(shape: tuple[int, ...], indices: np.ndarray) -> tuple[np.ndarray, ...]:
    """Per axis, the position of each flat index in C order (last axis fastest)."""
    total = math.prod(shape)
    if indices.size and (indices.min() < 0 or indices.max() >= total):
        raise ValueError(f"grid: flat indices must lie in [0, {total}), got out-of-range values")
    return np.unravel_index(indices, shape)


def grid_values(axes: Mapping[str, np.ndarray], indices: np.ndarray) -> np.ndarray:
    """Parameter values of candidate sets given by flat indices.

    Parameters
    ----------
    axes : Mapping[str, numpy.ndarray]
        Grid axes, each of shape (n_k,).
    indices : numpy.ndarray of int, shape (m,)
        Flat C-order indices into the Cartesian product.

    Returns
    -------
    numpy.ndarray, shape (m, n_axes)
        Row j holds the parameter values of set ``indices[j]`` in axis order.
    """
    shape = grid_shape(axes)
    positions = axis_positions(shape, np.asarray(indices, dtype=np.int64))
    out = np.empty((len(positions[0]), len(shape)), dtype=np.float64)
    for k, (values, pos) in enumerate(zip(axes.values(), positions, strict=True)):
        out[:, k] = np.asarray(values, dtype=np.float64)[pos]
    return out


def grid_rows(axes: Mapping[str, np.ndarray], indices: np.ndarray) -> pd.DataFrame:
    """Candidate sets given by flat indices as a DataFrame.

    Returns
    -------
    pandas.DataFrame, shape (m, n_axes)
        One column per axis name; the index (named ``grid_index``) holds the flat indices.
    """
    idx = np.asarray(indices, dtype=np.int64)
    values = grid_values(axes, idx)
    return pd.DataFrame(values, columns=list(axes), index=pd.Index(idx, name="grid_index"))


def iter_grid_chunks(
    axes: Mapping[str, np.ndarray],
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    start: int = 0,
    stop: int | None = None,
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Iterate over the Cartesian product in chunks of at most ``chunk_size`` sets.

    Parameters
    ----------
    axes : Mapping[str, numpy.ndarray]
        Grid axes, each of shape (n_k,).
    chunk_size : int
        Largest number of sets per chunk; bounds the memory use.
    start, stop : int
        Range of flat indices to visit (``stop`` defaults to the grid size).

    Yields
    ------
    indices : numpy.ndarray of int64, shape (m,)
        Flat indices of the chunk.
    values : numpy.ndarray, shape (m, n_axes)
        Parameter values of these sets.
    """
    total = grid_size(axes)
    stop = total if stop is None else stop
    if chunk_size < 1:
        raise ValueError(f"iter_grid_chunks: chunk_size must be >= 1, got {chunk_size}")
    if not 0 <= start <= stop <= total:
        raise ValueError(f"iter_grid_chunks: need 0 <= start <= stop <= {total}")
    for lo in range(start, stop, chunk_size):
        indices = np.arange(lo, min(lo + chunk_size, stop), dtype=np.int64)
        yield indices, grid_values(axes, indices)
