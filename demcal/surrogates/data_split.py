"""Random splits of samples into training, generalisation (early stopping) and test sets.

The surrogates are trained on 70 %, early-stopped on 15 % and scored on the remaining 15 % of
the DEM results. Rows that share a DEM parameter set are kept in one set by
:func:`split_groups`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def split_indices(
    n: int, seed: int, fractions: Sequence[float] = (0.7, 0.15, 0.15)
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random split of ``n`` samples into training, generalisation and test indices.

    Parameters
    ----------
    n : int
        Number of samples; at least 3.
    seed : int
        Seed of the permutation; the same seed gives the same split.
    fractions : sequence of 3 floats, default (0.7, 0.15, 0.15)
        Positive shares of training, generalisation (early stopping) and test sets; they are
        normalised to sum to one.

    Returns
    -------
    train, val, test : numpy.ndarray of int64, shapes (n_train,), (n_val,), (n_test,)
        Sorted, disjoint indices that together cover ``range(n)``; each part is non-empty.
        The generalisation and test sizes are ``round(n * fraction)`` (at least 1) and the
        training set takes the rest.

    Raises
    ------
    ValueError
        If ``n < 3``, the fractions are not three positive finite numbers, or they leave the
        training set empty.
    """
    if isinstance(n, bool) or int(n) != n:
        raise ValueError(f"n must be an integer, got {n!r}")
    n = int(n)
    if n < 3:
        raise ValueError(f"split_indices needs n >= 3 to fill three sets, got n={n}")
    shares = np.asarray(fractions, dtype=np.float64)
    if shares.shape != (3,) or not np.all(np.isfinite(shares)) or np.any(shares <= 0.0):
        raise ValueError(f"fractions must be three positive numbers, got {fractions!r}")
    shares = shares / shares.sum()
    n_val = max(1, round(n * shares[1]))
    n_test = max(1, round(n * shares[2]))
    n_train = n - n_val - n_test
    if n_train < 1:
        raise ValueError(f"fractions {tuple(fractions)} leave no training samples for n={n}")
    order = np.random.default_rng(seed).permutation(n)
    train = np.sort(order[:n_train])
    val = np.sort(order[n_train : n_train + n_val])
    test = np.sort(order[n_train + n_val :])
    return train.astype(np.int64), val.astype(np.int64), test.astype(np.int64)


def split_groups(
    groups: Sequence[object], seed: int, fractions: Sequence[float] = (0.7, 0.15, 0.15)
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random split that keeps all samples of a group in the same set.

    Rows that share a DEM parameter set (e.g. the load conditions of one case, whose pre-shear
    values coincide) must not be split between training and test, or the test set would
    measure memory instead of prediction.

    Parameters
    ----------
    groups : sequence, shape (n,)
        Group label of every sample.
    seed, fractions
        As in :func:`split_indices`, applied to the distinct groups.

    Returns
    -------
    train, val, test : numpy.ndarray of int64
        Sorted sample indices.
    """
    labels = np.asarray(groups)
    unique, inverse = np.unique(labels, return_inverse=True)
    parts = split_indices(len(unique), seed, fractions)
    return tuple(np.flatnonzero(np.isin(inverse, part)).astype(np.int64) for part in parts)
