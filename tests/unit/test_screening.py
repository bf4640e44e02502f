"""Tests of the streaming grid screening against brute-force loops."""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence

import numpy as np
import pytest
import torch

from demcal.core.experiments import MeasuredCondition
from demcal.identification.acceptance import (
    relative_deviation,
    within_tolerance,
)
from demcal.identification.candidate_grid import (
    draw_axes,
    grid_rows,
    grid_size,
    grid_values,
    iter_grid_chunks,
)
from demcal.identification.screening import screen
from demcal.identification.screening_stages import Stage
from tests.screening_bench import (
    IN_MEAN,
    IN_SCALE,
    REPOSE_FEATURES,
    SHEAR_FEATURES,
    RandomTanhNetwork,
    paper_axes_spec,
    screen_stand_ins,
)

SMALL_SPEC = {
    "coefficientFriction": (0.1, 1.0, 4),
    "coefficientRollingFriction": (0.1, 1.0, 5),
    "coefficientRestitution": (0.5, 0.9, 3),
    "density": (2500.0, 3500.0, 3),
}
NAMES = list(SMALL_SPEC)


class NumpyPredictor:
    """Wraps a numpy function of the feature matrix (n, d) -> (n,)."""

    def __init__(self, func) -> None:
        self.func = func

    def predict(self, X: np.ndarray) -> np.ndarray:
        return self.func(X)


class TorchPredictor:
    """Same analytic function evaluated in torch (float32) and numpy (float64)."""

    def __init__(self, weights: Sequence[float], offset: float) -> None:
        self.w = np.asarray(weights, dtype=np.float64)
        self.offset = offset
        self.torch_calls = 0

    def predict(self, X: np.ndarray) -> np.ndarray:
        return self.offset + np.tanh(X @ self.w)

    def predict_torch(self, X: torch.Tensor) -> torch.Tensor:
        self.torch_calls += 1
        return self.offset + torch.tanh(X @ torch.from_numpy(self.w.astype(np.float32)))


# Analytic stand-ins: shear values depend on the load, AoR does not.
def _mu_psh(X: np.ndarray) -> np.ndarray:
    return 0.3 + 0.4 * X[:, 0] + 0.1 * X[:, 1] - 0.05 * X[:, 2] + 1e-6 * X[:, 5]


def _mu_sh(X: np.ndarray) -> np.ndarray:
    return X[:, 6] * (0.2 + 0.3 * X[:, 0] + 0.2 * X[:, 1])


def _rho_b(X: np.ndarray) -> np.ndarray:
    return 0.6 * X[:, 3] * (1.0 - 0.1 * X[:, 0]) + 0.01 * X[:, 5]


def _aor(X: np.ndarray) -> np.ndarray:
    return 20.0 + 15.0 * X[:, 1] + 10.0 * X[:, 0] - 5.0 * X[:, 2] + 0.0 * X[:, 4]


def numpy_predictors() -> dict[str, tuple[NumpyPredictor, Sequence[str]]]:
    return {
        "mu_psh": (NumpyPredictor(_mu_psh), SHEAR_FEATURES),
        "mu_sh": (NumpyPredictor(_mu_sh), SHEAR_FEATURES),
        "rho_b": (NumpyPredictor(_rho_b), SHEAR_FEATURES),
        "aor": (NumpyPredictor(_aor), REPOSE_FEATURES),
    }


FIXED = {"dCylDp": 20.0, "normal_stress": 5000.0, "P": 1.0}


def brute_force(
    predictors: Mapping[str, tuple[object, Sequence[str]]],
    axes: Mapping[str, np.ndarray],
    fixed: Mapping[str, float],
    conditions: Sequence[MeasuredCondition],
    tol: float,
    method: str = "predict",
) -> tuple[list[int], list[dict[str, dict[str, float]]], list[float]]:
    """Row-by-row loop over the product; returns accepted flat indices, their predictions
    per condition, and the smallest distance of any relative deviation to the tolerance.

    Each row is accepted by the pipeline's own rule (:func:`within_tolerance`) on one set."""
    accepted: list[int] = []
    preds: list[dict[str, dict[str, float]]] = []
    margins: list[float] = []
    for flat, combo in enumerate(itertools.product(*axes.values())):
        params = dict(zip(axes, combo, strict=True))
        ok = True
        row_pred: dict[str, dict[str, float]] = {}
        for cond in conditions:
            env = {**fixed, **cond.load, **params}
            row_pred[cond.label] = {}
            for out, exp in cond.values.items():
                model, features = predictors[out]
                x = np.array([[env[f] for f in features]], dtype=np.float64)
                if method == "predict_torch":
                    value = float(model.predict_torch(torch.from_numpy(x.astype(np.float32)))[0])
                else:
                    value = float(model.predict(x)[0])
                row_pred[cond.label][out] = value
                margins.append(abs(float(relative_deviation(value, exp)) - tol))
            measured = dict(cond.values)
            single = {out: np.array([v]) for out, v in row_pred[cond.label].items()}
            ok = ok and bool(within_tolerance(single, measured, tol)[0])
            if not ok:
                break
        if ok:
            accepted.append(flat)
            preds.append(row_pred)
    return accepted, preds, margins


def test_draw_axes_sorted_in_range_and_seeded() -> None:
    spec = paper_axes_spec()  # paper Table 3
    axes = draw_axes(spec, seed=3)
    assert list(axes) == list(spec)
    for name, (low, high, count) in spec.items():
        values = axes[name]
        assert values.shape == (count,)
        assert np.all(np.diff(values) >= 0.0)
        assert values.min() >= low and values.max() < high
    assert grid_size(axes) == 6_250_000
    again = draw_axes(spec, seed=3)
    other = draw_axes(spec, seed=4)
    for name in spec:
        np.testing.assert_array_equal(axes[name], again[name])
        assert not np.array_equal(axes[name], other[name])


def test_draw_axes_uniform_spread() -> None:
    values = draw_axes({"x": (0.0, 1.0, 20000)}, seed=0)["x"]
    assert abs(values.mean() - 0.5) < 0.01
    assert abs(values.var() - 1.0 / 12.0) < 0.003


def test_draw_axes_axis_independent_of_other_counts() -> None:
    a = draw_axes({"x": (0.0, 1.0, 10), "y": (0.0, 1.0, 5)}, seed=1)
    b = draw_axes({"x": (0.0, 1.0, 10), "y": (0.0, 1.0, 50)}, seed=1)
    np.testing.assert_array_equal(a["x"], b["x"])


@pytest.mark.parametrize(
    "spec",
    [{"x": (1.0, 0.0, 3)}, {"x": (0.0, 1.0, 0)}, {"x": (0.0, 1.0, 2.5)}, {"x": (0.0, 1.0)}, {}],
)
def test_draw_axes_rejects_bad_spec(spec) -> None:
    with pytest.raises(ValueError):
        draw_axes(spec, seed=0)


def test_grid_values_follow_cartesian_product_order() -> None:
    axes = draw_axes(SMALL_SPEC, seed=0)
    expected = np.array(list(itertools.product(*axes.values())))
    idx = np.arange(grid_size(axes))
    np.testing.assert_array_equal(grid_values(axes, idx), expected)
    frame = grid_rows(axes, np.array([7, 0, 179]))
    assert list(frame.columns) == NAMES
    np.testing.assert_array_equal(frame.index.to_numpy(), [7, 0, 179])
    np.testing.assert_array_equal(frame.to_numpy(), expected[[7, 0, 179]])
    with pytest.raises(ValueError, match="range"):
        grid_values(axes, np.array([180]))


def test_iter_grid_chunks_cover_grid_once() -> None:
    axes = draw_axes(SMALL_SPEC, seed=0)
    expected = np.array(list(itertools.product(*axes.values())))
    chunks = list(iter_grid_chunks(axes, chunk_size=37))
    assert [len(i) for i, _ in chunks] == [37, 37, 37, 37, 32]
    np.testing.assert_array_equal(np.concatenate([i for i, _ in chunks]), np.arange(180))
    np.testing.assert_array_equal(np.concatenate([v for _, v in chunks]), expected)
    part = list(iter_grid_chunks(axes, chunk_size=10, start=15, stop=33))
    np.testing.assert_array_equal(np.concatenate([i for i, _ in part]), np.arange(15, 33))


def _conditions() -> list[MeasuredCondition]:
    return [
        MeasuredCondition(
            {"mu_psh": 0.62, "mu_sh": 0.45, "rho_b": 1700.0}, normal_stress=10070.0, P=0.8
        ),
        MeasuredCondition({"mu_psh": 0.66, "mu_sh": 0.62}, normal_stress=1068.0, P=1.0),
        MeasuredCondition({"aor": 31.0}),
    ]


@pytest.mark.parametrize("chunk_size", [1, 7, 64, 10_000])
def test_screen_equals_brute_force_numpy_predictors(chunk_size: int) -> None:
    axes = draw_axes(SMALL_SPEC, seed=2)
    predictors = numpy_predictors()
    conditions = _conditions()
    tol = 0.15
    expected, expected_pred, margins = brute_force(predictors, axes, FIXED, conditions, tol)
    assert 0 < len(expected) < grid_size(axes) // 4  # the criteria actually filter
    assert min(margins) > 1e-9  # no set sits on the boundary

    result = screen(predictors, axes, FIXED, conditions, tol=tol, chunk_size=chunk_size)
    np.testing.assert_array_equal(result.indices, expected)
    assert result.n_total == 180
    for cond in conditions:
        for out in cond.values:
            np.testing.assert_allclose(
                result.predictions[cond.label][out],
                [p[cond.label][out] for p in expected_pred],
                rtol=1e-12,
            )
    assert result.elapsed_s > 0.0


def test_screen_stage_counts_match_brute_force_per_prefix() -> None:
    axes = draw_axes(SMALL_SPEC, seed=2)
    predictors = numpy_predictors()
    conditions = _conditions()
    result = screen(predictors, axes, FIXED, conditions, tol=0.15, chunk_size=50)
    for k, cond in enumerate(conditions):
        prefix, _, _ = brute_force(predictors, axes, FIXED, conditions[: k + 1], 0.15)
        assert result.stage_counts[cond.label] == len(prefix)
    counts = list(result.stage_counts.values())
    assert counts[0] < 180
    assert all(a > b for a, b in itertools.pairwise(counts))  # every stage filters
    assert counts[-1] == result.n_accepted


def test_screen_equals_brute_force_torch_predictors() -> None:
    axes = draw_axes(SMALL_SPEC, seed=5)
    mean, scale = IN_MEAN, IN_SCALE
    predictors = {
        "mu_psh": (RandomTanhNetwork(7, 15, 11, mean, scale, 0.6, 0.1), SHEAR_FEATURES),
        "rho_b": (RandomTanhNetwork(7, 15, 12, mean, scale, 1700.0, 100.0), SHEAR_FEATURES),
        "aor": (RandomTanhNetwork(5, 15, 13, mean[:5], scale[:5], 35.0, 5.0), REPOSE_FEATURES),
    }
    conditions = [
        MeasuredCondition({"mu_psh": 0.6, "rho_b": 1700.0}, normal_stress=10070.0, P=1.0),
        MeasuredCondition({"aor": 33.0}),
    ]
    tol = 0.05
    expected, expected_pred, margins = brute_force(
        predictors, axes, FIXED, conditions, tol, method="predict_torch"
    )
    assert min(margins) > 1e-5  # far above float32 round-off
    for chunk_size in (13, 1000):
        result = screen(predictors, axes, FIXED, conditions, tol=tol, chunk_size=chunk_size)
        shear_count, valid_count = result.stage_counts.values()
        assert 0 < valid_count < shear_count < 180
        np.testing.assert_array_equal(result.indices, expected)
        np.testing.assert_allclose(
            result.predictions["aor"]["aor"],
            [p["aor"]["aor"] for p in expected_pred],
            rtol=1e-6,
        )


def test_screen_prefers_predict_torch_and_matches_numpy_path() -> None:
    axes = draw_axes(SMALL_SPEC, seed=1)
    both = TorchPredictor([0.5, 0.3, -0.2, 1e-4, 0.0, 0.0, 0.1], offset=1.0)
    numpy_only = NumpyPredictor(both.predict)
    cond = [MeasuredCondition({"mu_psh": 1.5}, normal_stress=10070.0, P=1.0)]
    r_torch = screen({"mu_psh": (both, SHEAR_FEATURES)}, axes, FIXED, cond, tol=0.1)
    r_numpy = screen({"mu_psh": (numpy_only, SHEAR_FEATURES)}, axes, FIXED, cond, tol=0.1)
    assert both.torch_calls > 0
    assert 0 < r_numpy.n_accepted < 180
    np.testing.assert_array_equal(r_torch.indices, r_numpy.indices)
    np.testing.assert_allclose(
        r_torch.predictions[cond[0].label]["mu_psh"],
        r_numpy.predictions[cond[0].label]["mu_psh"],
        rtol=1e-6,
    )


def test_screen_custom_stage_callback_and_frame() -> None:
    axes = draw_axes(SMALL_SPEC, seed=0)
    predictors = numpy_predictors()
    stages = [
        Stage("friction", ("mu_psh",), lambda p: p["mu_psh"] > 0.6),
        Stage("repose", ("aor",), lambda p: p["aor"] < 30.0),
    ]
    result = screen(predictors, axes, FIXED, stages, chunk_size=17)
    values = grid_values(axes, np.arange(180))
    x = np.column_stack([values, np.tile([20.0, 5000.0, 1.0], (180, 1))])
    expected = np.flatnonzero((_mu_psh(x) > 0.6) & (_aor(x[:, :5]) < 30.0))
    assert expected.size > 0
    np.testing.assert_array_equal(result.indices, expected)
    frame = result.to_frame(axes)
    assert list(frame.columns) == [*NAMES, "mu_psh", "aor"]
    np.testing.assert_allclose(frame["aor"].to_numpy(), _aor(x[expected, :5]))


def test_screen_frame_names_repeated_outputs_by_stage() -> None:
    axes = draw_axes(SMALL_SPEC, seed=0)
    conditions = [
        MeasuredCondition({"mu_sh": 0.5}, normal_stress=10070.0, P=1.0),
        MeasuredCondition({"mu_sh": 0.4}, normal_stress=10070.0, P=0.8),
    ]
    result = screen(numpy_predictors(), axes, FIXED, conditions, tol=0.3)
    frame = result.to_frame(axes)
    assert "mu_sh@normal_stress=10070,P=1" in frame.columns
    # mu_sh is proportional to P in the analytic stand-in.
    np.testing.assert_allclose(
        frame["mu_sh@normal_stress=10070,P=0.8"], 0.8 * frame["mu_sh@normal_stress=10070,P=1"]
    )


def test_screen_restores_thread_count() -> None:
    before = torch.get_num_threads()
    axes = draw_axes(SMALL_SPEC, seed=0)
    screen(numpy_predictors(), axes, FIXED, _conditions(), num_threads=1)
    assert torch.get_num_threads() == before


def test_screen_setup_errors() -> None:
    axes = draw_axes(SMALL_SPEC, seed=0)
    predictors = numpy_predictors()
    cond = [MeasuredCondition({"mu_psh": 0.6}, normal_stress=10070.0, P=1.0)]
    with pytest.raises(KeyError, match="dCylDp"):
        screen(predictors, axes, {"normal_stress": 1.0, "P": 1.0}, cond)
    with pytest.raises(KeyError, match="porosity"):
        screen(predictors, axes, FIXED, [MeasuredCondition({"porosity": 0.4})])
    with pytest.raises(ValueError, match="both grid axes and fixed"):
        screen(predictors, axes, {**FIXED, "density": 2500.0}, cond)
    with pytest.raises(ValueError, match="unique"):
        screen(predictors, axes, FIXED, cond + cond)
    bad = [Stage("bad", ("mu_psh",), lambda p: p["mu_psh"])]
    with pytest.raises(ValueError, match="bool"):
        screen(predictors, axes, FIXED, bad)


def test_one_stage_and_marked_then_valid_accept_the_same_sets() -> None:
    # All four networks in one stage on every set, or the repose network only on the sets the
    # shear networks marked: the same valid sets, fewer repose evaluations.
    spec = {
        "coefficientFriction": (0.1, 1.0, 12),
        "coefficientRollingFriction": (0.1, 1.0, 12),
        "coefficientRestitution": (0.5, 0.9, 6),
        "density": (2500.0, 3500.0, 6),
    }
    together = screen_stand_ins(spec, chunk_size=1000, num_threads=1)
    sequential = screen_stand_ins(spec, chunk_size=1000, num_threads=1, sequential=True)
    assert together.n_total == sequential.n_total == 12 * 12 * 6 * 6
    marked, valid = sequential.stage_counts.values()
    assert 0 < valid < marked < together.n_total
    assert together.n_accepted == valid
    np.testing.assert_array_equal(together.indices, sequential.indices)


class InPlacePredictor:
    """Overwrites its input before predicting, as a careless model might."""

    def predict(self, X: np.ndarray) -> np.ndarray:
        X[:, 0] = 0.0
        return X[:, 1] + 1.0

    def predict_torch(self, X: torch.Tensor) -> torch.Tensor:
        X[:, 0] = 0.0
        return X[:, 1] + 1.0


class FirstColumn:
    def predict(self, X: np.ndarray) -> np.ndarray:
        return X[:, 0].copy()

    def predict_torch(self, X: torch.Tensor) -> torch.Tensor:
        return X[:, 0].clone()


def test_shared_inputs_protected_from_in_place_changes() -> None:
    axes = draw_axes(SMALL_SPEC, seed=0)
    values = grid_values(axes, np.arange(180))
    numpy_only = NumpyPredictor(InPlacePredictor().predict)
    pairs = [
        (InPlacePredictor(), FirstColumn()),  # both on the torch path
        (numpy_only, NumpyPredictor(FirstColumn().predict)),  # both on the numpy path
    ]
    for careless, mu_s in pairs:
        predictors = {"first": (careless, SHEAR_FEATURES), "mu_s": (mu_s, SHEAR_FEATURES)}
        stage = Stage("s", ("first", "mu_s"), lambda p: np.ones(p["mu_s"].size, dtype=bool))
        result = screen(predictors, axes, FIXED, [stage], chunk_size=50)
        np.testing.assert_allclose(result.predictions["s"]["mu_s"], values[:, 0], rtol=1e-6)
