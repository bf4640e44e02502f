"""Tests of demcal.surrogates.network (split, MLP, persistence, sweep) and
demcal.surrogates.figures."""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import torch
from sklearn.utils.estimator_checks import parametrize_with_checks
from threadpoolctl import threadpool_limits

from demcal.surrogates.data_split import split_indices
from demcal.surrogates.figures import parity_plot, r2_vs_hidden_size
from demcal.surrogates.hidden_size_sweep import sweep_hidden_sizes
from demcal.surrogates.log_inputs import log_columns
from demcal.surrogates.metrics import regression_metrics
from demcal.surrogates.network import MLPSurrogate
from tests.figures import ink, read_png, saved_figures

FEATURES = [
    "coefficientFriction",
    "coefficientRollingFriction",
    "coefficientRestitution",
    "density",
    "dCylDp",
]


@pytest.fixture(autouse=True)
def _one_blas_thread() -> Iterator[None]:
    # Small matrix products slow down sharply when BLAS threads compete for 2 shared cores.
    with threadpool_limits(limits=1):
        yield


def smooth_data(n: int, seed: int, noise: float = 0.005) -> tuple[pd.DataFrame, np.ndarray]:
    """Five DEM-like inputs in their natural ranges and a smooth friction-like response."""
    rng = np.random.default_rng(seed)
    X = pd.DataFrame(
        {
            "coefficientFriction": rng.uniform(0.1, 1.0, n),
            "coefficientRollingFriction": rng.uniform(0.1, 1.0, n),
            "coefficientRestitution": rng.uniform(0.5, 0.9, n),
            "density": rng.uniform(2500.0, 3500.0, n),
            "dCylDp": rng.uniform(20.0, 40.0, n),
        }
    )
    mu_s, mu_r, cor, rho = (X[c].to_numpy() for c in FEATURES[:4])
    y = (
        0.4
        + 0.3 * np.tanh(3.0 * (mu_s - 0.4))
        + 0.15 * mu_r * mu_s
        - 0.1 * (cor - 0.7) ** 2
        + 0.05 * (rho - 3000.0) / 500.0
        + noise * rng.normal(size=n)
    )
    return X, y


# ------------------------------------------------------------------- split
@pytest.mark.parametrize(
    ("n", "sizes"), [(100, (70, 15, 15)), (546, (382, 82, 82)), (3, (1, 1, 1))]
)
def test_split_sizes_disjoint_and_covering(n: int, sizes: tuple[int, int, int]) -> None:
    train, val, test = split_indices(n, seed=1)
    assert (len(train), len(val), len(test)) == sizes
    joined = np.concatenate([train, val, test])
    assert np.array_equal(np.sort(joined), np.arange(n))


def test_split_is_seeded() -> None:
    a = split_indices(200, seed=5)
    b = split_indices(200, seed=5)
    c = split_indices(200, seed=6)
    for x, y in zip(a, b, strict=True):
        assert np.array_equal(x, y)
    assert not np.array_equal(a[0], c[0])


@pytest.mark.parametrize(
    ("n", "fractions", "message"),
    [
        (2, (0.7, 0.15, 0.15), "n >= 3"),
        (10, (0.7, 0.3), "three positive"),
        (10, (0.7, -0.1, 0.4), "three positive"),
        (4, (0.01, 0.5, 0.5), "no training samples"),
    ],
)
def test_split_rejects_bad_input(n: int, fractions: tuple[float, ...], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        split_indices(n, seed=0, fractions=fractions)


# --------------------------------------------------------------------- MLP
def test_mlp_fits_smooth_function() -> None:
    X, y = smooth_data(400, seed=0)
    train, val, test = split_indices(len(y), seed=0)
    model = MLPSurrogate(hidden_size=10).fit(X.iloc[train], y[train], X.iloc[val], y[val])
    r2 = regression_metrics(y[test], model.predict(X.iloc[test]))["r2"]
    assert r2 > 0.98
    assert list(model.feature_names_in_) == FEATURES
    assert model.n_train_ == len(train) and model.n_val_ == len(val)


def test_early_stopping_keeps_best_validation_weights() -> None:
    rng = np.random.default_rng(11)
    X = rng.uniform(-1.0, 1.0, size=(120, 4))
    y = X[:, 0] + rng.normal(0.0, 0.7, size=120)  # noise dominates: a large net overfits
    Xt, yt, Xv, yv = X[:80], y[:80], X[80:], y[80:]
    model = MLPSurrogate(hidden_size=40, max_epochs=2000, patience=15).fit(Xt, yt, Xv, yv)
    assert model.stopped_early_
    assert model.n_epochs_ < 2000
    assert model.n_epochs_ - model.best_epoch_ == 15
    curve = np.asarray(model.validation_curve_)
    assert len(curve) == model.n_epochs_ + 1
    assert model.val_mse_ == pytest.approx(curve.min(), rel=1e-12)
    assert curve[-1] > model.val_mse_
    # The kept weights are those of the best epoch: their error on the generalisation set is
    # the minimum of the curve, not the error at the last epoch.
    assert np.mean((model.predict(Xv) - yv) ** 2) == pytest.approx(model.val_mse_, rel=1e-9)
    assert np.mean((model.predict(Xt) - yt) ** 2) == pytest.approx(model.train_mse_, rel=1e-9)


def test_internal_holdout_without_generalisation_set() -> None:
    X, y = smooth_data(100, seed=2)
    model = MLPSurrogate(hidden_size=5, max_epochs=50).fit(X, y)
    assert (model.n_train_, model.n_val_) == (85, 15)
    assert len(model.loss_curve_) == model.n_epochs_ + 1


def test_same_seed_same_predictions() -> None:
    X, y = smooth_data(150, seed=3)
    a = MLPSurrogate(hidden_size=8, max_epochs=100, random_state=4).fit(X, y).predict(X)
    b = MLPSurrogate(hidden_size=8, max_epochs=100, random_state=4).fit(X, y).predict(X)
    c = MLPSurrogate(hidden_size=8, max_epochs=100, random_state=5).fit(X, y).predict(X)
    assert np.array_equal(a, b)
    assert not np.allclose(a, c, rtol=0.0, atol=1e-9)


def test_standardisation_makes_units_irrelevant() -> None:
    X, y = smooth_data(150, seed=6)
    in_g_per_cm3 = X.assign(density=X["density"] / 1000.0)
    a = MLPSurrogate(hidden_size=6, max_epochs=40).fit(X, y).predict(X)
    b = MLPSurrogate(hidden_size=6, max_epochs=40).fit(in_g_per_cm3, y).predict(in_g_per_cm3)
    np.testing.assert_allclose(a, b, rtol=0.0, atol=1e-6)


def test_predict_torch_equals_predict() -> None:
    X, y = smooth_data(200, seed=7)
    model = MLPSurrogate(hidden_size=12, max_epochs=100).fit(X, y)
    grid, _ = smooth_data(1000, seed=8)
    expected = model.predict(grid)
    got = model.predict_torch(torch.tensor(grid.to_numpy()), chunk_size=300)
    assert got.dtype == torch.float32 and got.shape == (1000,)
    assert not got.requires_grad
    np.testing.assert_allclose(got.numpy(), expected, rtol=0.0, atol=2e-5)
    with pytest.raises(ValueError, match=r"shape \(n, 5\)"):
        model.predict_torch(torch.zeros(3, 4))


def test_log_inputs_are_taken_inside_the_network(tmp_path: Path) -> None:
    X, y = smooth_data(200, seed=11)
    logs = log_columns(FEATURES)
    assert logs == (0,)
    model = MLPSurrogate(hidden_size=10, max_epochs=100, log_inputs=logs)
    model.fit(X.iloc[:170], y[:170], X_val=X.iloc[170:], y_val=y[170:])
    # The network standardises ln(mu_s): its input mean is that of the logarithm.
    assert model.x_mean_[0] == pytest.approx(np.log(X["coefficientFriction"][:170]).mean())
    grid, _ = smooth_data(500, seed=12)
    values = torch.tensor(grid.to_numpy())
    before = values.clone()
    got = model.predict_torch(values, chunk_size=128)
    np.testing.assert_allclose(got.numpy(), model.predict(grid), rtol=0.0, atol=2e-5)
    assert torch.equal(values, before), "the caller's grid must keep its SI values"
    loaded = MLPSurrogate.load(model.save(tmp_path / "m.pt"))
    assert loaded.log_inputs == logs
    assert np.array_equal(loaded.predict(grid), model.predict(grid))
    bad = X.assign(coefficientFriction=0.0)
    with pytest.raises(ValueError, match=r"log columns \[0\] must be positive"):
        model.predict(bad)


def test_bad_parameters_and_inputs() -> None:
    X, y = smooth_data(20, seed=9)
    with pytest.raises(ValueError, match="hidden_size"):
        MLPSurrogate(hidden_size=0).fit(X, y)
    with pytest.raises(ValueError, match="together"):
        MLPSurrogate().fit(X, y, X_val=X)
    with pytest.raises(ValueError, match="n_samples=1"):
        MLPSurrogate().fit(X.iloc[:1], y[:1])


def test_save_load_round_trip(tmp_path: Path) -> None:
    X, y = smooth_data(150, seed=10)
    model = MLPSurrogate(hidden_size=9, max_epochs=80, random_state=3).fit(X, y)
    path = model.save(tmp_path / "mu_psh.pt", metadata={"target": "mu_psh"})
    loaded = MLPSurrogate.load(path)
    assert np.array_equal(loaded.predict(X), model.predict(X))
    assert loaded.get_params() == model.get_params()
    sidecar = json.loads(Path(f"{path}.json").read_text())
    assert sidecar["hidden_size"] == 9
    assert sidecar["seed"] == 3
    assert sidecar["feature_names"] == FEATURES
    assert sidecar["training"]["n_epochs"] == model.n_epochs_
    assert sidecar["training"]["val_mse"] == pytest.approx(model.val_mse_)
    assert sidecar["versions"]["torch"] == torch.__version__
    assert sidecar["versions"]["numpy"] == np.__version__
    assert sidecar["metadata"] == {"target": "mu_psh"}


def test_load_rejects_bad_files(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="no saved network"):
        MLPSurrogate.load(tmp_path / "missing.pt")
    foreign = tmp_path / "foreign.pt"
    torch.save({"weights": torch.zeros(2)}, foreign)
    with pytest.raises(ValueError, match=r"foreign\.pt"):
        MLPSurrogate.load(foreign)
    X, y = smooth_data(30, seed=1)
    good = MLPSurrogate(hidden_size=3, max_epochs=5).fit(X, y).save(tmp_path / "good.pt")
    state = torch.load(good, weights_only=True)
    del state["x_scale"]
    torch.save(state, tmp_path / "cut.pt")
    with pytest.raises(KeyError, match="x_scale"):
        MLPSurrogate.load(tmp_path / "cut.pt")


@parametrize_with_checks([MLPSurrogate(hidden_size=8, max_epochs=200)])
def test_sklearn_estimator_checks(estimator: object, check: object) -> None:
    check(estimator)  # type: ignore[operator]


# ------------------------------------------------------------------- sweep
def test_sweep_covers_36_sizes_and_selects_consistently() -> None:
    X, y = smooth_data(120, seed=12, noise=0.02)
    train, val, test = split_indices(len(y), seed=0)
    result = sweep_hidden_sizes(X, y, train, val, test, max_epochs=30)
    table = result.table
    assert len(table) == 36
    assert list(table["hidden_size"]) == list(range(5, 41))
    assert 5 <= result.selected_size <= 40 and 5 <= result.paper_rule_size <= 40
    assert result.selected_size == int(table.loc[table["val_mse"].idxmin(), "hidden_size"])
    assert result.paper_rule_size == int(table.loc[table["test_r2"].idxmax(), "hidden_size"])
    assert result.model.hidden_size == result.selected_size
    assert result.paper_rule_model.hidden_size == result.paper_rule_size
    row = table.set_index("hidden_size").loc[result.selected_size]
    r2 = regression_metrics(y[test], result.model.predict(X.iloc[test]))["r2"]
    assert row["test_r2"] == pytest.approx(r2, rel=1e-12)
    assert row["val_mse"] == pytest.approx(result.model.val_mse_, rel=1e-12)
    assert (table["epochs"] <= 30).all()


def test_sweep_rejects_overlapping_split() -> None:
    X, y = smooth_data(30, seed=13)
    with pytest.raises(ValueError, match="'test' overlaps"):
        sweep_hidden_sizes(X, y, np.arange(20), np.arange(20, 25), np.arange(24, 30), sizes=[5])


def test_full_paper_sweep_runs_within_a_minute() -> None:
    # The paper's workload: 36 networks on 500 samples of 7 inputs, default training settings.
    rng = np.random.default_rng(14)
    X = rng.uniform(size=(500, 7))
    y = np.tanh(2.0 * X[:, 0] - X[:, 1]) + 0.5 * X[:, 2] ** 2 + 0.3 * np.sin(3.0 * X[:, 4])
    y += 0.02 * rng.normal(size=500)
    train, val, test = split_indices(500, seed=0)
    start = time.process_time()
    result = sweep_hidden_sizes(X, y, train, val, test)
    elapsed = time.process_time() - start
    assert elapsed < 60.0
    assert result.table["test_r2"].max() > 0.98


# ----------------------------------------------------------------- figures
def test_parity_plot_draws_the_samples_against_the_diagonal(tmp_path: Path) -> None:
    rng = np.random.default_rng(15)
    y = rng.uniform(0.4, 0.8, 60)
    pred = y + rng.normal(0.0, 0.02, 60)
    with saved_figures() as figures:
        out = parity_plot(y, pred, "ANN, mu_psh", tmp_path / "f" / "p.png")
    ((ax,),) = [f.axes for f in figures]
    (points,) = ax.collections
    np.testing.assert_array_equal(points.get_offsets(), np.column_stack([y, pred]))
    (diagonal,) = ax.lines
    np.testing.assert_array_equal(diagonal.get_xdata(), diagonal.get_ydata())
    # Equal axes that hold every sample with a margin, the diagonal from corner to corner.
    low, high = ax.get_xlim()
    assert ax.get_ylim() == (low, high)
    assert low < min(y.min(), pred.min()) < max(y.max(), pred.max()) < high
    assert tuple(diagonal.get_xdata()) == (low, high)
    r2 = regression_metrics(y, pred)["r2"]
    assert r2 == pytest.approx(1.0 - 0.02**2 / (0.4**2 / 12.0), abs=0.02)  # noise / spread
    assert ax.get_title() == f"ANN, mu_psh: $R^2$ = {r2:.3f}"
    image = read_png(out)
    assert image.shape == (675, 675, 3)  # 4.5 in at 150 dpi
    assert 0.02 < ink(image).mean() < 0.5


def test_r2_vs_hidden_size_marks_both_selected_networks(tmp_path: Path) -> None:
    sizes = np.arange(5, 41)
    table = pd.DataFrame(
        {
            "hidden_size": sizes,
            "test_r2": 0.95 - 0.0001 * (sizes - 15) ** 2,
            "val_mse": 0.001 + 1e-6 * (sizes - 12) ** 2,
        }
    )
    shuffled = table.sample(frac=1.0, random_state=3)
    with saved_figures() as figures:
        out = r2_vs_hidden_size(shuffled, tmp_path / "r2.png")
    ((ax,),) = [f.axes for f in figures]
    (curve,) = ax.lines
    np.testing.assert_array_equal(curve.get_xdata(), sizes)  # in order of size
    np.testing.assert_allclose(curve.get_ydata(), table["test_r2"])
    # Lowest generalisation error at 12 neurons (circle), highest test R^2 at 15 (star).
    circle, star = ax.collections
    np.testing.assert_allclose(circle.get_offsets(), [[12, 0.95 - 0.0009]])
    np.testing.assert_allclose(star.get_offsets(), [[15, 0.95]])
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["lowest generalisation error: 12", "highest test $R^2$ (paper rule): 15"]
    assert read_png(out).shape == (600, 900, 3)  # 6 x 4 in at 150 dpi
    with pytest.raises(KeyError, match="val_mse"):
        r2_vs_hidden_size(table.drop(columns="val_mse"), tmp_path / "bad.png")


def test_split_groups_keeps_groups_together():
    from demcal.surrogates.data_split import split_groups

    groups = np.repeat([f"c{k:04d}" for k in range(20)], 4)  # 20 parameter sets x 4 loads
    train, val, test = split_groups(groups, seed=3)
    assert len(train) + len(val) + len(test) == 80
    sets = [set(groups[idx]) for idx in (train, val, test)]
    assert not (sets[0] & sets[1] or sets[0] & sets[2] or sets[1] & sets[2])
    assert [len(s) for s in sets] == [14, 3, 3]
    again = split_groups(groups, seed=3)
    assert all(np.array_equal(a, b) for a, b in zip((train, val, test), again, strict=True))
