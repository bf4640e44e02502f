"""Training loop of the one-hidden-layer tanh networks: full-batch L-BFGS with early stopping.

Training uses full-batch L-BFGS with a strong-Wolfe line search in float64 (one L-BFGS
iteration is one epoch). A quasi-Newton method suits these small networks and few hundred
samples: it converges in far fewer epochs than stochastic gradient descent, much as the
Levenberg-Marquardt training customary for such networks does. Inputs and targets arrive
standardised; the caller maps errors and weights back to its units.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np
import torch


@contextmanager
def single_torch_thread() -> Iterator[None]:
    """Run torch on one intra-op thread, so that training is reproducible bit for bit."""
    previous = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(previous)


@dataclass(frozen=True)
class TrainedWeights:
    """Weights of the best epoch and the error history of one training run.

    Attributes
    ----------
    W1 : numpy.ndarray, shape (hidden_size, n_features)
        Input-to-hidden weights (standardised inputs).
    b1 : numpy.ndarray, shape (hidden_size,)
        Hidden biases.
    w2 : numpy.ndarray, shape (hidden_size,)
        Hidden-to-output weights (standardised output).
    b2 : float
        Output bias (standardised output).
    n_epochs : int
        Epochs run.
    best_epoch : int
        Epoch whose weights were kept (0 means the initial weights).
    stopped_early : bool
        Whether training ended because of the patience criterion.
    loss_curve, validation_curve : list of float
        Training and generalisation-set mean squared error of the standardised output after
        every epoch, starting with the initial weights.
    """

    W1: np.ndarray
    b1: np.ndarray
    w2: np.ndarray
    b2: float
    n_epochs: int
    best_epoch: int
    stopped_early: bool
    loss_curve: list[float]
    validation_curve: list[float]


def train_lbfgs(
    xt: torch.Tensor,
    yt_s: torch.Tensor,
    xv: torch.Tensor,
    yv_s: torch.Tensor,
    hidden_size: int,
    learning_rate: float,
    alpha: float,
    max_epochs: int,
    patience: int,
    seed: int,
) -> TrainedWeights:
    """Train ``y = w2 . tanh(W1 x + b1) + b2`` on standardised data with early stopping.

    Parameters
    ----------
    xt : torch.Tensor of float64, shape (n_train, n_features)
        Standardised training inputs.
    yt_s : torch.Tensor of float64, shape (n_train,)
        Standardised training targets.
    xv : torch.Tensor of float64, shape (n_val, n_features)
        Standardised generalisation-set inputs (early stopping).
    yv_s : torch.Tensor of float64, shape (n_val,)
        Standardised generalisation-set targets.
    hidden_size : int
        Number of tanh units.
    learning_rate : float
        Initial step length of the L-BFGS line search.
    alpha : float
        L2 penalty on the weights (not the biases), added as ``alpha * ||W||^2 / n_train``.
    max_epochs : int
        Maximum number of L-BFGS iterations.
    patience : int
        Training stops after this many epochs without a lower generalisation-set error.
    seed : int
        Seed of the Glorot-uniform weight initialisation.

    Returns
    -------
    TrainedWeights
        The weights of the epoch with the lowest generalisation-set error and the histories.
    """
    n_in, n_hidden = xt.shape[1], int(hidden_size)

    # Glorot-uniform weights keep the tanh units out of saturation for standardised inputs.
    gen = torch.Generator().manual_seed(seed)

    def uniform(shape: tuple[int, ...], bound: float) -> torch.Tensor:
        values = (torch.rand(shape, generator=gen, dtype=torch.float64) * 2.0 - 1.0) * bound
        return values.requires_grad_(True)

    W1 = uniform((n_hidden, n_in), float(np.sqrt(6.0 / (n_in + n_hidden))))
    b1 = uniform((n_hidden,), 0.5)
    w2 = uniform((n_hidden,), float(np.sqrt(6.0 / (n_hidden + 1))))
    b2 = torch.zeros((), dtype=torch.float64, requires_grad=True)
    params = [W1, b1, w2, b2]

    def forward(x: torch.Tensor) -> torch.Tensor:
        return torch.tanh(torch.addmm(b1, x, W1.T)) @ w2 + b2

    penalty = float(alpha) / xt.shape[0]
    optimiser = torch.optim.LBFGS(
        params,
        lr=float(learning_rate),
        max_iter=1,
        # torch derives the line-search budget from max_eval; the default (5/4 of
        # max_iter) would leave no evaluations for it.
        max_eval=25,
        history_size=20,
        tolerance_grad=1e-10,
        tolerance_change=1e-14,
        line_search_fn="strong_wolfe",
    )

    def closure() -> torch.Tensor:
        optimiser.zero_grad()
        loss = torch.mean((forward(xt) - yt_s) ** 2)
        if penalty > 0.0:
            loss = loss + penalty * (torch.sum(W1**2) + torch.sum(w2**2))
        loss.backward()
        return loss

    def errors() -> tuple[float, float]:
        with torch.no_grad():
            train = float(torch.mean((forward(xt) - yt_s) ** 2))
            val = float(torch.mean((forward(xv) - yv_s) ** 2))
        return train, val

    def snapshot() -> list[torch.Tensor]:
        return [p.detach().clone() for p in params]

    train_err, val_err = errors()
    loss_curve, val_curve = [train_err], [val_err]
    best_val, best_epoch, best = val_err, 0, snapshot()
    stopped_early = False
    epoch = 0
    for epoch in range(1, int(max_epochs) + 1):
        optimiser.step(closure)
        train_err, val_err = errors()
        if not (np.isfinite(train_err) and np.isfinite(val_err)):
            break
        loss_curve.append(train_err)
        val_curve.append(val_err)
        if val_err < best_val:
            best_val, best_epoch, best = val_err, epoch, snapshot()
        elif epoch - best_epoch >= int(patience):
            stopped_early = True
            break
        # L-BFGS has converged when a step no longer changes the training error.
        if abs(loss_curve[-2] - train_err) <= 1e-14 * max(1.0, train_err):
            break

    return TrainedWeights(
        W1=best[0].numpy().copy(),
        b1=best[1].numpy().copy(),
        w2=best[2].numpy().copy(),
        b2=float(best[3]),
        n_epochs=int(epoch),
        best_epoch=int(best_epoch),
        stopped_early=bool(stopped_early),
        loss_curve=loss_curve,
        validation_curve=val_curve,
    )
