"""Evaluating a closed-form surrogate over a candidate grid of millions of rows, chunk by chunk.

The grid arrives as float32 in SI units; each chunk is copied to float64 (large weights of both
signs, or a large intercept, lose digits in float32 sums), its log columns are taken, the
surrogate's formula is applied and the result stored as float32.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import torch


def evaluate_in_chunks(
    X: torch.Tensor,
    n_features: int,
    log_inputs: Sequence[int],
    chunk_size: int,
    formula: Callable[[torch.Tensor], torch.Tensor],
) -> torch.Tensor:
    """``formula`` over the rows of ``X``, ``chunk_size`` rows at a time.

    Parameters
    ----------
    X : torch.Tensor, shape (n, n_features)
        Inputs in SI units (log columns as they are); not modified.
    n_features : int
        The number of inputs the surrogate takes.
    log_inputs : sequence of int
        Columns replaced by their natural logarithm before ``formula``.
    chunk_size : int
        Rows per chunk; bounds the float64 copy and whatever ``formula`` allocates per row.
    formula : callable
        float64 tensor of shape (m, n_features) -> tensor of shape (m,), units of the bulk
        value.

    Returns
    -------
    torch.Tensor of float32, shape (n,)

    Raises
    ------
    ValueError
        If ``X`` is not of shape (n, n_features).
    """
    if X.ndim != 2 or X.shape[1] != n_features:
        raise ValueError(f"X must have shape (n, {n_features}), got {tuple(X.shape)}")
    logs = list(log_inputs)
    out = torch.empty(X.shape[0], dtype=torch.float32)
    with torch.no_grad():
        for start in range(0, X.shape[0], chunk_size):
            # A copy: the caller's grid keeps its SI values.
            chunk = X[start : start + chunk_size].to(torch.float64, copy=True)
            if logs:
                chunk[:, logs] = chunk[:, logs].log()
            out[start : start + chunk_size] = formula(chunk).to(torch.float32)
    return out
