"""The Gaussian process and the linear regression as screening surrogates
(demcal.surrogates.process_surrogate, demcal.surrogates.linear_surrogate) and the choice of the
surrogate that screens (surrogate.screen_with)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import torch
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, Kernel, Matern, WhiteKernel

from demcal.surrogates.baselines import (
    AnisotropicGaussianProcess,
    bayesian_linear_regression,
    gaussian_process_regression,
)
from demcal.surrogates.linear_surrogate import LinearSurrogate
from demcal.surrogates.network import MLPSurrogate
from demcal.surrogates.process_surrogate import ProcessSurrogate
from demcal.surrogates.training import (
    load_screening_surrogate,
    screening_method,
    train_output,
)
from tests.unit.test_cross_validation import SETTINGS, bulk_dataset

FEATURES = ["coefficientFriction", "coefficientRollingFriction", "density", "normal_stress"]


def _inputs(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.c_[
        rng.uniform(0.1, 1.0, n),
        rng.uniform(0.1, 1.0, n),
        rng.uniform(2500.0, 3500.0, n),
        rng.choice([1068.0, 2029.0, 10070.0], n),
    ]


def test_process_predicts_as_the_fitted_pipeline(tmp_path: Path) -> None:
    X = _inputs(40, seed=1)
    y = 0.45 + 0.08 * np.log(X[:, 0]) + 0.2 * X[:, 1] + 2e-6 * X[:, 3]
    pipeline = gaussian_process_regression(seed=0, log_inputs=(0,)).fit(X, y)
    process = ProcessSurrogate.from_pipeline(pipeline, FEATURES)
    assert process.log_inputs == (0,)
    grid = _inputs(3000, seed=2)
    expected = pipeline.predict(grid)
    np.testing.assert_allclose(process.predict(grid), expected, rtol=0.0, atol=1e-8)
    values = torch.tensor(grid, dtype=torch.float32)
    before = values.clone()
    got = process.predict_torch(values, chunk_size=700)
    assert got.dtype == torch.float32 and got.shape == (3000,)
    # float32 only in the inputs and the result: within 1e-5 of the response's span
    np.testing.assert_allclose(got.numpy(), expected, rtol=0.0, atol=1e-5 * np.ptp(expected))
    assert torch.equal(values, before), "the caller's grid must keep its SI values"
    loaded = ProcessSurrogate.load(process.save(tmp_path / "process.json", {"output": "mu_psh"}))
    np.testing.assert_array_equal(loaded.predict(grid), process.predict(grid))
    assert json.loads((tmp_path / "process.json").read_text())["metadata"] == {"output": "mu_psh"}
    (tmp_path / "bad.json").write_text(json.dumps({"format": "other"}))
    with pytest.raises(ValueError, match=r"bad\.json: not a Gaussian-process file"):
        ProcessSurrogate.load(tmp_path / "bad.json")
    with pytest.raises(ValueError, match=r"shape \(n, 4\)"):
        process.predict_torch(torch.zeros(3, 5))


class _RBFProcess(AnisotropicGaussianProcess):
    """The squared-exponential process the files written before the Matern kernel hold."""

    def _kernel(self, n_features: int) -> Kernel:
        return ConstantKernel(1.0, (1e-3, 1e3)) * RBF(np.ones(n_features), (1e-2, 1e3)) + (
            WhiteKernel(1e-2, (1e-8, 1.0))
        )


class _Matern32Process(AnisotropicGaussianProcess):
    """A kernel the process file cannot describe (Matern derives from RBF in scikit-learn)."""

    def _kernel(self, n_features: int) -> Kernel:
        return ConstantKernel() * Matern(np.ones(n_features), nu=1.5) + WhiteKernel()


def test_the_process_file_names_its_kernel_and_reads_older_files_as_rbf(tmp_path: Path) -> None:
    X = _inputs(40, seed=6)
    y = 0.45 + 0.08 * np.log(X[:, 0]) + 0.2 * X[:, 1] ** 2 + 2e-6 * X[:, 3]
    grid = _inputs(500, seed=7)
    matern = gaussian_process_regression(seed=0, log_inputs=(0,)).fit(X, y)
    assert ProcessSurrogate.from_pipeline(matern, FEATURES).kernel == "matern52"
    rbf = gaussian_process_regression(seed=0, log_inputs=(0,))
    rbf.set_params(regressor=_RBFProcess(random_state=0)).fit(X, y)
    process = ProcessSurrogate.from_pipeline(rbf, FEATURES)
    assert process.kernel == "rbf"
    np.testing.assert_allclose(process.predict(grid), rbf.predict(grid), rtol=0.0, atol=1e-8)
    # The field is read: the same weights under the other kernel predict something else.
    fields = {k: v for k, v in process.to_dict().items() if k != "format"}
    misread = ProcessSurrogate(**(fields | {"kernel": "matern52"}))
    assert np.abs(misread.predict(grid) - rbf.predict(grid)).max() > 1e-2
    path = process.save(tmp_path / "process.json")
    data = json.loads(path.read_text())
    assert data["kernel"] == "rbf"
    del data["kernel"]  # a file written before the field existed
    path.write_text(json.dumps(data))
    old = ProcessSurrogate.load(path)
    assert old.kernel == "rbf"
    np.testing.assert_allclose(old.predict(grid), rbf.predict(grid), rtol=0.0, atol=1e-8)
    other = gaussian_process_regression(seed=0, log_inputs=(0,))
    other.set_params(regressor=_Matern32Process(random_state=0)).fit(X, y)
    with pytest.raises(ValueError, match="no process file for the kernel Matern"):
        ProcessSurrogate.from_pipeline(other, FEATURES)
    data["kernel"] = "cubic"
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match="unknown process kernel 'cubic'"):
        ProcessSurrogate.load(path)


def test_linear_surrogate_predicts_as_the_fitted_pipeline(tmp_path: Path) -> None:
    X = _inputs(40, seed=3)
    # A bulk density that is a plane in ln(mu_s), mu_r, rho_p and sigma, with 10 kg/m^3 scatter.
    y = 1700.0 - 60.0 * np.log(X[:, 0]) - 150.0 * X[:, 1] + 0.3 * X[:, 2] + 4e-3 * X[:, 3]
    y += np.random.default_rng(4).normal(0.0, 10.0, len(y))
    pipeline = bayesian_linear_regression(log_inputs=(0,)).fit(X, y)
    plane = LinearSurrogate.from_pipeline(pipeline, FEATURES)
    X_new = _inputs(500, seed=5)
    expected = pipeline.predict(X_new)
    np.testing.assert_allclose(plane.predict(X_new), expected, rtol=1e-10)
    grid = torch.from_numpy(X_new).to(torch.float32)
    got = plane.predict_torch(grid, chunk_size=64).numpy()
    # float32 inputs and output: a few 1e-7 of ~2000 kg/m^3
    np.testing.assert_allclose(got, expected, rtol=2e-6)
    assert float(grid[0, 0]) == pytest.approx(X_new[0, 0], rel=1e-6)  # the grid is untouched
    # The slopes are the plane's: -60 per unit ln(mu_s), 0.3 per kg/m^3 of particle density.
    assert plane.coef[0] == pytest.approx(-60.0, rel=0.15)
    assert plane.coef[2] == pytest.approx(0.3, rel=0.15)
    loaded = LinearSurrogate.load(plane.save(tmp_path / "linear.json", {"output": "rho_b"}))
    np.testing.assert_allclose(loaded.predict(X_new), expected, rtol=1e-10)
    assert json.loads((tmp_path / "linear.json").read_text())["metadata"] == {"output": "rho_b"}
    (tmp_path / "other.json").write_text(json.dumps({"format": "demcal-gaussian-process-1"}))
    with pytest.raises(ValueError, match=r"other\.json: not a linear-regression file"):
        LinearSurrogate.load(tmp_path / "other.json")
    with pytest.raises(ValueError, match=r"X must have shape \(n, 4\)"):
        plane.predict_torch(torch.zeros(3, 5))


def test_screen_with_best_takes_the_highest_cross_validated_r2() -> None:
    table = pd.DataFrame(
        {"cv_r2": [0.5, 0.77, -0.01], "cv_rmse": [38.5, 53.5, 56.2]},
        index=["Bayesian", "Gaussian", "ANN"],
    )
    assert screening_method(table, "best") == "Gaussian"
    assert screening_method(table, "network") == "ANN"
    table.loc["ANN", "cv_r2"] = 0.9
    assert screening_method(table, "best") == "ANN"
    assert screening_method(table, "process") == "Gaussian"
    assert screening_method(table, "linear") == "Bayesian"
    # The quick bulk density's case: the plane cross-validates best and its CV RMSE (38.5
    # kg/m^3) is below the acceptance band (5 % of 1 760): it screens.
    table.loc["Bayesian", "cv_r2"] = 0.963
    assert screening_method(table, "best", tolerance=88.0) == "Bayesian"
    # A plane that misses by more than the band does not, however its R^2 compares; nor
    # without a band.
    assert screening_method(table, "best", tolerance=30.0) == "ANN"
    assert screening_method(table, "best") == "ANN"
    # On a tie the network, then the process, is preferred.
    table.loc["Gaussian", "cv_r2"] = 0.963
    assert screening_method(table, "best", tolerance=88.0) == "Gaussian"
    # Without cross-validation the paper's network screens.
    table["cv_r2"] = np.nan
    assert screening_method(table, "best") == "ANN"
    with pytest.raises(ValueError, match="screen_with"):
        screening_method(table, "gp")


def test_training_writes_the_process_the_screening_loads(tmp_path: Path) -> None:
    trained = train_output(
        bulk_dataset(14, seed=0), "rho_b", SETTINGS | {"cv_folds": 4}, tmp_path / "rho_b"
    )
    model_path = tmp_path / "rho_b" / "model.pt"
    network, features, method = load_screening_surrogate(model_path, "network")
    assert isinstance(network, MLPSurrogate) and method == "ANN"
    process, features_gp, method = load_screening_surrogate(model_path, "process")
    assert isinstance(process, ProcessSurrogate) and method == "Gaussian"
    assert features_gp == features == trained.features
    # The process learnt from every usable row: 14 sets at four P (this rho_b varies with P).
    assert process.x_train.shape == (56, len(features))
    plane, features_lin, method = load_screening_surrogate(model_path, "linear")
    assert isinstance(plane, LinearSurrogate) and method == "Bayesian"
    assert features_lin == features
    table = trained.table4
    best = load_screening_surrogate(model_path, "best")[2]
    assert best == table.loc[["ANN", "Gaussian"], "cv_r2"].idxmax()
    # With a band wider than every CV RMSE the plane competes too.
    wide = 2.0 * float(table["cv_rmse"].max()) / float(table["y_mean"].iloc[0])
    best = load_screening_surrogate(model_path, "best", experiment=None, tolerance=wide)[2]
    assert best == table.loc[["ANN", "Gaussian", "Bayesian"], "cv_r2"].idxmax()
    # Both screen with the same inputs and agree where the data are (rho_b ~ 1500-2000).
    grid = torch.tensor([[0.5, 0.5, 3000.0, 1.0]], dtype=torch.float32)
    assert features == ["coefficientFriction", "coefficientRollingFriction", "density", "P"]
    a, b = float(network.predict_torch(grid)[0]), float(process.predict_torch(grid)[0])
    assert abs(a - b) < 0.05 * a
