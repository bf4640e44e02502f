"""Random splits of samples into training, generalisation (early stopping) and test sets.

The surrogates are trained on 70 %, early-stopped on 15 % and scored on the remaining 15 % of
the DEM results. Rows that share a DEM parameter set are kept in one set by
:func:`split_groups`, and in one fold of the cross-validation by :func:`grouped_folds` (with
:func:`holdout_groups` setting aside the generalisation sets inside a fold's training part).
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


def grouped_folds(groups: Sequence[object], n_folds: int, seed: int) -> list[np.ndarray]:
    """K folds of the samples in which every group lies in exactly one fold.

    The distinct groups (DEM parameter sets) are shuffled with ``seed`` and dealt into
    ``n_folds`` parts whose numbers of groups differ by at most one
    (:func:`numpy.array_split`); a fold holds every sample of its groups.

    Parameters
    ----------
    groups : sequence, shape (n,)
        Group label of every sample.
    n_folds : int
        Number of folds, ``2 <= n_folds <= number of distinct groups``.
    seed : int
        Seed of the shuffle; the same seed gives the same folds.

    Returns
    -------
    list of numpy.ndarray of int64, length n_folds
        Sorted sample indices of each fold; disjoint, non-empty, together ``range(n)``.

    Raises
    ------
    ValueError
        If ``n_folds < 2`` or exceeds the number of distinct groups.
    """
    labels = np.asarray(groups)
    unique, inverse = np.unique(labels, return_inverse=True)
    if isinstance(n_folds, bool) or int(n_folds) != n_folds or n_folds < 2:
        raise ValueError(f"n_folds must be an integer >= 2, got {n_folds!r}")
    if n_folds > len(unique):
        raise ValueError(f"n_folds={n_folds} exceeds the {len(unique)} distinct groups")
    order = np.random.default_rng(seed).permutation(len(unique))
    return [
        np.flatnonzero(np.isin(inverse, part)).astype(np.int64)
        for part in np.array_split(order, int(n_folds))
    ]


def holdout_groups(
    groups: Sequence[object], seed: int | Sequence[int], fraction: float
) -> tuple[np.ndarray, np.ndarray]:
    """Random two-way split that keeps all samples of a group on one side.

    Used inside the training part of a cross-validation fold to set aside the generalisation
    (early stopping) groups.

    Parameters
    ----------
    groups : sequence, shape (n,)
        Group label of every sample; at least two distinct labels.
    seed : int or sequence of int
        Seed of the shuffle (anything :func:`numpy.random.default_rng` accepts as entropy).
    fraction : float
        Share of the groups held out, in (0, 1); ``round(n_groups * fraction)`` groups, at
        least one and at most ``n_groups - 1``.

    Returns
    -------
    kept, held : numpy.ndarray of int64
        Sorted sample indices of the kept (training) and held-out groups; both non-empty.

    Raises
    ------
    ValueError
        If fewer than two groups exist or ``fraction`` is not in (0, 1).
    """
    if not 0.0 < float(fraction) < 1.0:
        raise ValueError(f"fraction must lie in (0, 1), got {fraction!r}")
    labels = np.asarray(groups)
    unique, inverse = np.unique(labels, return_inverse=True)
    if len(unique) < 2:
        raise ValueError(f"holdout_groups needs at least 2 groups, got {len(unique)}")
    n_held = min(len(unique) - 1, max(1, round(len(unique) * float(fraction))))
    order = np.random.default_rng(seed).permutation(len(unique))
    held = np.isin(inverse, order[:n_held])
    return np.flatnonzero(~held).astype(np.int64), np.flatnonzero(held).astype(np.int64)
