"""Screening of a Cartesian grid of candidate contact-parameter sets with surrogate models.

The candidate grid (paper Table 3) has one sorted array of uniform random draws per parameter;
the candidate sets are the Cartesian product of these axes (100 x 100 x 25 x 25 = 6.25 M sets
in the paper). Sets are addressed by a flat C-order index (the last axis varies fastest), so
any chunk of the product can be built by index arithmetic without materialising the grid.

:func:`screen` streams the grid chunk by chunk through a sequence of acceptance stages (e.g.
eq. 3 at one or more shear-cell load conditions, then eq. 4 for the angle of repose); each
stage evaluates its predictors only on the sets that survived the earlier stages, and only the
accepted sets and their predictions are kept.

Predictors are duck-typed: ``predict(X: ndarray (n, d)) -> ndarray (n,)``, and optionally
``predict_torch(X: Tensor float32 (n, d)) -> Tensor (n,)`` which is preferred for speed.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import Protocol

import numpy as np
import pandas as pd
import torch

from demcal.identification.acceptance import (
    DEFAULT_TOLERANCE,
    MeasuredCondition,
    sequential_filter,
    within_tolerance,
)

TABLE3_SPEC: dict[str, tuple[float, float, int]] = {
    "coefficientFriction": (0.1, 1.0, 100),
    "coefficientRollingFriction": (0.1, 1.0, 100),
    "coefficientRestitution": (0.5, 0.9, 25),
    "density": (2500.0, 3500.0, 25),
}
"""Paper Table 3: per parameter (low, high, number of uniform draws); SI units."""

DEFAULT_CHUNK_SIZE = 1 << 18


class Predictor(Protocol):
    """A fitted surrogate mapping input features (n, d) to one bulk value (n,)."""

    def predict(self, X: np.ndarray) -> np.ndarray: ...


PredictorEntry = tuple[Predictor, Sequence[str]]
"""A predictor together with its ordered list of input feature names."""


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
    return math.prod(_grid_shape(axes))


def _grid_shape(axes: Mapping[str, np.ndarray]) -> tuple[int, ...]:
    if not axes:
        raise ValueError("grid: no axes given")
    shape = tuple(len(values) for values in axes.values())
    for name, n in zip(axes, shape, strict=True):
        if n == 0:
            raise ValueError(f"grid: axis {name!r} is empty")
    return shape


def _axis_positions(shape: tuple[int, ...], indices: np.ndarray) -> tuple[np.ndarray, ...]:
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
    shape = _grid_shape(axes)
    positions = _axis_positions(shape, np.asarray(indices, dtype=np.int64))
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


@dataclass(frozen=True)
class Stage:
    """One acceptance step of a screening run.

    Attributes
    ----------
    name : str
        Unique label of the stage (keys the predictions of the result).
    outputs : tuple[str, ...]
        Predictor names evaluated in this stage.
    accept : Callable[[Mapping[str, numpy.ndarray]], numpy.ndarray]
        Receives the stage's predictions (each of shape (m,)) and returns a bool mask (m,).
    fixed : Mapping[str, float]
        Feature values held fixed in this stage (e.g. the load condition); they override the
        run-wide fixed values.
    """

    name: str
    outputs: tuple[str, ...]
    accept: Callable[[Mapping[str, np.ndarray]], np.ndarray]
    fixed: Mapping[str, float] = field(default_factory=dict)


def stage_from_condition(condition: MeasuredCondition, tol: float = DEFAULT_TOLERANCE) -> Stage:
    """Stage that accepts sets within ``tol`` of every value measured at ``condition``.

    The outputs evaluated are the measured observables (predictor names must equal the output
    names) and the condition's load (``normal_stress``, ``P``) is held fixed.
    """
    return Stage(
        name=condition.label,
        outputs=tuple(condition.values),
        accept=partial(within_tolerance, measured=dict(condition.values), tol=tol),
        fixed=condition.load,
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


class _GridAxes:
    """Axis values of the grid in float64 (numpy) and float32 (torch)."""

    def __init__(self, axes: Mapping[str, np.ndarray]) -> None:
        self.names = list(axes)
        self.shape = _grid_shape(axes)
        self.values64 = {k: np.asarray(v, dtype=np.float64) for k, v in axes.items()}
        self.values32 = {
            k: torch.from_numpy(v.astype(np.float32)) for k, v in self.values64.items()
        }


class _StageInputs:
    """Predictor input matrices for one set of flat indices and fixed values.

    Matrices are built once per distinct feature list (the shear-cell networks share theirs)
    and handed out as copies, so a predictor that modifies its input cannot affect another.
    """

    def __init__(self, grid: _GridAxes, indices: np.ndarray, fixed: Mapping[str, float]) -> None:
        self.grid = grid
        self.n = int(indices.size)
        self.fixed = fixed
        pos = _axis_positions(grid.shape, indices)
        self.positions = dict(zip(grid.names, pos, strict=True))
        self._numpy: dict[tuple[str, ...], np.ndarray] = {}
        self._torch: dict[tuple[str, ...], torch.Tensor] = {}

    def numpy(self, features: Sequence[str]) -> np.ndarray:
        """Float64 matrix of shape (n, len(features))."""
        key = tuple(features)
        if key not in self._numpy:
            X = np.empty((self.n, len(key)), dtype=np.float64)
            for j, name in enumerate(key):
                if name in self.positions:
                    X[:, j] = self.grid.values64[name][self.positions[name]]
                else:
                    X[:, j] = self.fixed[name]
            self._numpy[key] = X
        return self._numpy[key].copy()

    def torch(self, features: Sequence[str]) -> torch.Tensor:
        """Float32 tensor of shape (n, len(features))."""
        key = tuple(features)
        if key not in self._torch:
            X = torch.empty((self.n, len(key)), dtype=torch.float32)
            for j, name in enumerate(key):
                if name in self.positions:
                    X[:, j] = self.grid.values32[name][torch.from_numpy(self.positions[name])]
                else:
                    X[:, j] = float(self.fixed[name])
            self._torch[key] = X
        return self._torch[key].clone()


def _check_setup(
    predictors: Mapping[str, PredictorEntry],
    axes: Mapping[str, np.ndarray],
    fixed: Mapping[str, float],
    stages: Sequence[Stage],
) -> None:
    clash = set(fixed) & set(axes)
    if clash:
        raise ValueError(f"screen: features {sorted(clash)} are both grid axes and fixed")
    names = [stage.name for stage in stages]
    if len(set(names)) != len(names):
        raise ValueError(f"screen: stage names must be unique, got {names}")
    if not stages:
        raise ValueError("screen: no acceptance stages given")
    for stage in stages:
        clash = set(stage.fixed) & set(axes)
        if clash:
            raise ValueError(
                f"screen: stage {stage.name!r} fixes {sorted(clash)} which are grid axes"
            )
        if not stage.outputs:
            raise ValueError(f"screen: stage {stage.name!r} evaluates no outputs")
        for output in stage.outputs:
            if output not in predictors:
                raise KeyError(f"screen: stage {stage.name!r} needs predictor {output!r}")
            model, features = predictors[output]
            if not hasattr(model, "predict"):
                raise TypeError(f"screen: predictor {output!r} has no predict method")
            for feature in features:
                if feature not in axes and feature not in stage.fixed and feature not in fixed:
                    raise KeyError(
                        f"screen: feature {feature!r} of predictor {output!r} is neither a "
                        f"grid axis nor fixed (stage {stage.name!r})"
                    )


def _predict(
    model: Predictor, features: Sequence[str], inputs: _StageInputs, name: str
) -> np.ndarray:
    if hasattr(model, "predict_torch"):
        with torch.inference_mode():
            y = model.predict_torch(inputs.torch(features))
        out = y.detach().cpu().numpy().astype(np.float64).reshape(-1)
    else:
        out = np.asarray(model.predict(inputs.numpy(features)), dtype=np.float64).reshape(-1)
    if out.shape != (inputs.n,):
        raise ValueError(
            f"screen: predictor {name!r} returned {out.size} values for {inputs.n} rows"
        )
    return out


def _run_stage(
    rows: np.ndarray,
    stage: Stage,
    predictors: Mapping[str, PredictorEntry],
    grid: _GridAxes,
    fixed: Mapping[str, float],
    store: dict[str, dict[str, np.ndarray]],
) -> np.ndarray:
    """Evaluate one stage on the sets ``rows`` (m,); return its bool mask (m,).

    ``store`` holds the predictions of earlier stages for the same rows; they are filtered
    with the mask so that all stored arrays stay aligned with the survivors.
    """
    inputs = _StageInputs(grid, rows, {**fixed, **stage.fixed})
    pred = {
        out: _predict(predictors[out][0], predictors[out][1], inputs, out) for out in stage.outputs
    }
    mask = np.asarray(stage.accept(pred))
    if mask.dtype != np.bool_ or mask.shape != rows.shape:
        raise ValueError(
            f"screen: stage {stage.name!r} accept returned dtype {mask.dtype} "
            f"shape {mask.shape}, expected bool of shape {rows.shape}"
        )
    for name, values in list(store.items()):
        store[name] = {o: v[mask] for o, v in values.items()}
    store[stage.name] = {o: v[mask] for o, v in pred.items()}
    return mask


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
        ones. A :class:`~demcal.identification.acceptance.MeasuredCondition` is matched within
        ``tol`` on its
        measured observables at its load.
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
    _check_setup(predictors, axes, fixed, stage_list)
    if chunk_size < 1:
        raise ValueError(f"screen: chunk_size must be >= 1, got {chunk_size}")
    if num_threads < 1:
        raise ValueError(f"screen: num_threads must be >= 1, got {num_threads}")
    grid = _GridAxes(axes)
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
                    _run_stage,
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


class RandomTanhNetwork:
    """Stand-in surrogate with random weights: one tanh hidden layer, one linear output.

    Inputs are standardised with the given means and scales and the output is mapped to
    ``out_mean + out_scale * y``, as a trained surrogate would do, so its cost per set equals
    that of a real network of the same size.

    Parameters
    ----------
    n_features : int
        Number of inputs d.
    n_hidden : int
        Number of tanh units.
    seed : int
        Seed of the weights.
    in_mean, in_scale : array_like, shape (d,)
        Input standardisation (SI units of each feature).
    out_mean, out_scale : float
        Output mapping, in the units of the predicted bulk value.
    """

    def __init__(
        self,
        n_features: int,
        n_hidden: int,
        seed: int,
        in_mean: np.ndarray,
        in_scale: np.ndarray,
        out_mean: float,
        out_scale: float,
    ) -> None:
        gen = torch.Generator().manual_seed(seed)
        self.w1 = torch.randn(n_features, n_hidden, generator=gen) / math.sqrt(n_features)
        self.b1 = 0.1 * torch.randn(n_hidden, generator=gen)
        self.w2 = torch.randn(n_hidden, 1, generator=gen) / math.sqrt(n_hidden)
        self.b2 = float(0.1 * torch.randn(1, generator=gen))
        self.in_mean = torch.as_tensor(np.asarray(in_mean, dtype=np.float32))
        self.in_scale = torch.as_tensor(np.asarray(in_scale, dtype=np.float32))
        self.out_mean = float(out_mean)
        self.out_scale = float(out_scale)

    def predict_torch(self, X: torch.Tensor) -> torch.Tensor:
        """Predictions, float32 tensor of shape (n,), for inputs of shape (n, d)."""
        with torch.no_grad():
            Z = (X - self.in_mean) / self.in_scale
            H = torch.tanh(torch.addmm(self.b1, Z, self.w1))
            y = torch.addmm(torch.tensor([self.b2]), H, self.w2).reshape(-1)
            return y.mul_(self.out_scale).add_(self.out_mean)

    def predict(self, X: np.ndarray) -> np.ndarray:
        """Predictions, float64 array of shape (n,), for inputs of shape (n, d)."""
        X32 = torch.from_numpy(np.asarray(X, dtype=np.float32))
        return self.predict_torch(X32).numpy().astype(np.float64)


SHEAR_FEATURES = (
    "coefficientFriction",
    "coefficientRollingFriction",
    "coefficientRestitution",
    "density",
    "dCylDp",
    "normal_stress",
    "P",
)
"""Input features of the shear-cell networks, in order."""

REPOSE_FEATURES = SHEAR_FEATURES[:5]
"""Input features of the angle-of-repose network, in order."""


def benchmark_screening(
    n_hidden: int = 15,
    seed: int = 0,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    num_threads: int = 2,
    sequential: bool = False,
    spec: Mapping[str, tuple[float, float, int]] | None = None,
) -> ScreeningResult:
    """Time the screening of the Table-3 grid with four random-weight tanh networks.

    The networks stand for mu_psh, mu_sh, rho_b (7 inputs) and the angle of repose
    (5 inputs). The measured values are the networks' predictions at the middle of the grid
    with 5 % tolerance. With ``sequential=False`` all four networks run on every set (one
    stage, the worst case); with ``sequential=True`` the repose network runs only on marked
    sets (eq. 3 then eq. 4).

    Returns
    -------
    ScreeningResult
        Its ``sets_per_second`` is the throughput; a summary line is printed.
    """
    spec = TABLE3_SPEC if spec is None else spec
    axes = draw_axes(spec, seed)
    fixed = {"dCylDp": 20.0, "normal_stress": 10070.0, "P": 1.0}
    mean = np.array([0.55, 0.55, 0.7, 3000.0, 20.0, 5000.0, 0.7])
    scale = np.array([0.26, 0.26, 0.12, 290.0, 5.0, 4000.0, 0.2])
    outputs = {"mu_psh": (0.6, 0.1), "mu_sh": (0.5, 0.1), "rho_b": (1700.0, 100.0)}
    predictors: dict[str, PredictorEntry] = {}
    for k, (name, (m, s)) in enumerate(outputs.items()):
        net = RandomTanhNetwork(7, n_hidden, seed + k, mean, scale, m, s)
        predictors[name] = (net, SHEAR_FEATURES)
    aor_net = RandomTanhNetwork(5, n_hidden, seed + 3, mean[:5], scale[:5], 35.0, 5.0)
    predictors["aor"] = (aor_net, REPOSE_FEATURES)

    centre = {name: float(np.median(values)) for name, values in axes.items()}
    measured: dict[str, float] = {}
    for name, (model, features) in predictors.items():
        row = np.array([[centre.get(f, fixed.get(f, 0.0)) for f in features]])
        measured[name] = float(model.predict(row)[0])

    shear = {k: measured[k] for k in outputs}
    if sequential:
        stages: list[Stage | MeasuredCondition] = [
            MeasuredCondition(shear, normal_stress=10070.0, P=1.0),
            MeasuredCondition({"aor": measured["aor"]}),
        ]
    else:
        stages = [MeasuredCondition(measured, normal_stress=10070.0, P=1.0, name="all")]
    result = screen(predictors, axes, fixed, stages, chunk_size=chunk_size, num_threads=num_threads)
    mode = "sequential" if sequential else "all four networks on every set"
    print(
        f"benchmark ({mode}, {n_hidden} hidden, {num_threads} threads): "
        f"{result.n_total} sets in {result.elapsed_s:.2f} s = "
        f"{result.sets_per_second:.3g} sets/s, {result.n_accepted} accepted"
    )
    return result
