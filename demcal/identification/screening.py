"""Screening of a Cartesian grid of candidate contact-parameter sets with surrogate models.

:func:`screen` streams the candidate grid (:mod:`demcal.identification.candidate_grid`) chunk
by chunk through a sequence of acceptance stages (:mod:`demcal.identification.screening_stages`;
e.g. eq. 3 at one or more shear-cell load conditions, then eq. 4 for the angle of repose); each
stage evaluates its predictors only on the sets that survived the earlier stages, and only the
accepted sets and their predictions are kept.

Predictors are duck-typed: ``predict(X: ndarray (n, d)) -> ndarray (n,)``, and optionally
``predict_torch(X: Tensor float32 (n, d)) -> Tensor (n,)`` which is preferred for speed.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import partial

import numpy as np
import pandas as pd
import torch

from demcal.core.experiments import MeasuredCondition
from demcal.identification.acceptance import (
    DEFAULT_TOLERANCE,
    sequential_filter,
)
from demcal.identification.candidate_grid import DEFAULT_CHUNK_SIZE, grid_rows, grid_size
from demcal.identification.screening_stages import (
    GridAxes,
    PredictorEntry,
    Stage,
    check_setup,
    run_stage,
    stage_from_condition,
)


@dataclass
class ScreeningResult:
    """Accepted sets of a screening run.

    Attributes
    ----------
    indices : numpy.ndarray of int64, shape (n_accepted,)
        Flat grid indices of the sets that passed every stage, ascending.
    predictions : dict[str, dict[str, numpy.ndarray]]
        Per stage name and output, the predictions of the accepted sets, shape (n_accepted,).
    stage_counts : dict[str, int]
        Per stage, the number of sets that passed it and all earlier stages.
    n_total : int
        Number of candidate sets screened.
    elapsed_s : float
        Wall-clock time of the run [s].
    """

    indices: np.ndarray
    predictions: dict[str, dict[str, np.ndarray]]
    stage_counts: dict[str, int]
    n_total: int
    elapsed_s: float

    @property
    def n_accepted(self) -> int:
        """Number of sets that passed every stage."""
        return int(self.indices.size)

    @property
    def sets_per_second(self) -> float:
        """Screening throughput [1/s]."""
        return self.n_total / self.elapsed_s if self.elapsed_s > 0 else math.inf

    def to_frame(self, axes: Mapping[str, np.ndarray]) -> pd.DataFrame:
        """Accepted sets with their parameter values and predictions.

        Prediction columns are named after the output; an output evaluated in more than one
        stage gets one column per stage, named ``"<output>@<stage>"``.
        """
        frame = grid_rows(axes, self.indices)
        seen: dict[str, int] = {}
        for outputs in self.predictions.values():
            for output in outputs:
                seen[output] = seen.get(output, 0) + 1
        for stage, outputs in self.predictions.items():
            for output, values in outputs.items():
                column = output if seen[output] == 1 else f"{output}@{stage}"
                frame[column] = values
        return frame


def screen(
    predictors: Mapping[str, PredictorEntry],
    axes: Mapping[str, np.ndarray],
    fixed: Mapping[str, float],
    stages: Sequence[Stage | MeasuredCondition],
    tol: float = DEFAULT_TOLERANCE,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    num_threads: int = 2,
    verbose: bool = False,
) -> ScreeningResult:
    """Stream the candidate grid through sequential acceptance stages.

    Parameters
    ----------
    predictors : Mapping[str, tuple[predictor, Sequence[str]]]
        Per output name (``mu_psh``, ``mu_sh``, ``rho_b``, ``aor``, ...), the predictor and
        its ordered input feature names.
    axes : Mapping[str, numpy.ndarray]
        Grid axes, each of shape (n_k,), e.g. from :func:`draw_axes`.
    fixed : Mapping[str, float]
        Values of features that are not grid axes (e.g. ``dCylDp``, ``normal_stress`` [Pa],
        ``P``); stage-specific values override these.
    stages : Sequence[Stage or MeasuredCondition]
        Acceptance steps applied in order; a stage sees only the survivors of the earlier
        ones. A :class:`~demcal.core.experiments.MeasuredCondition` is matched within
        ``tol`` on its measured observables at its load (the tolerance alone; a stage from
        :func:`stage_from_condition` can widen it by the measurement's standard deviation).
    tol : float
        Relative tolerance used for MeasuredCondition stages.
    chunk_size : int
        Number of candidate sets evaluated at once; bounds the memory use.
    num_threads : int
        torch intra-op threads used during the run (restored afterwards).
    verbose : bool
        Print a one-line summary with the elapsed time.

    Returns
    -------
    ScreeningResult
        Indices and predictions of the accepted sets, per-stage counts, elapsed time.
    """
    stage_list = [s if isinstance(s, Stage) else stage_from_condition(s, tol) for s in stages]
    check_setup(predictors, axes, fixed, stage_list)
    if chunk_size < 1:
        raise ValueError(f"screen: chunk_size must be >= 1, got {chunk_size}")
    if num_threads < 1:
        raise ValueError(f"screen: num_threads must be >= 1, got {num_threads}")
    grid = GridAxes(axes)
    total = grid_size(axes)
    kept_idx: list[np.ndarray] = []
    kept_pred: dict[str, dict[str, list[np.ndarray]]] = {
        s.name: {o: [] for o in s.outputs} for s in stage_list
    }
    counts = dict.fromkeys((s.name for s in stage_list), 0)

    previous_threads = torch.get_num_threads()
    torch.set_num_threads(num_threads)
    t0 = time.perf_counter()
    try:
        for lo in range(0, total, chunk_size):
            indices = np.arange(lo, min(lo + chunk_size, total), dtype=np.int64)
            # Per stage, predictions of this chunk's current survivors.
            chunk_pred: dict[str, dict[str, np.ndarray]] = {}
            tests = [
                partial(
                    run_stage,
                    stage=s,
                    predictors=predictors,
                    grid=grid,
                    fixed=fixed,
                    store=chunk_pred,
                )
                for s in stage_list
            ]
            passed = sequential_filter(indices, tests)
            for stage, survivors in zip(stage_list, passed, strict=True):
                counts[stage.name] += int(survivors.size)
            final = passed[-1]
            if final.size:
                kept_idx.append(final)
                for stage in stage_list:
                    for out in stage.outputs:
                        kept_pred[stage.name][out].append(chunk_pred[stage.name][out])
    finally:
        torch.set_num_threads(previous_threads)
    elapsed = time.perf_counter() - t0

    indices_all = np.concatenate(kept_idx) if kept_idx else np.empty(0, dtype=np.int64)
    predictions = {
        stage: {
            out: np.concatenate(parts) if parts else np.empty(0, dtype=np.float64)
            for out, parts in outs.items()
        }
        for stage, outs in kept_pred.items()
    }
    result = ScreeningResult(
        indices=indices_all,
        predictions=predictions,
        stage_counts=counts,
        n_total=total,
        elapsed_s=elapsed,
    )
    if verbose:
        print(
            f"screened {total} sets in {elapsed:.2f} s ({result.sets_per_second:.3g} sets/s), "
            f"accepted {result.n_accepted}"
        )
    return result
