"""The Gaussian process as a screening surrogate (demcal.surrogates.process_surrogate) and the
choice of the surrogate that screens (surrogate.screen_with)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import torch

from demcal.surrogates.baselines import gaussian_process_regression
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


def test_screen_with_best_takes_the_higher_cross_validated_r2() -> None:
    table = pd.DataFrame({"cv_r2": [0.5, 0.77, -0.01]}, index=["Bayesian", "Gaussian", "ANN"])
    assert screening_method(table, "best") == "Gaussian"
    assert screening_method(table, "network") == "ANN"
    table.loc["ANN", "cv_r2"] = 0.9
    assert screening_method(table, "best") == "ANN"
    assert screening_method(table, "process") == "Gaussian"
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
    best = load_screening_surrogate(model_path, "best")[2]
    table = trained.table4
    expected = "Gaussian" if table.loc["Gaussian", "cv_r2"] > table.loc["ANN", "cv_r2"] else "ANN"
    assert best == expected
    # Both screen with the same inputs and agree where the data are (rho_b ~ 1500-2000).
    grid = torch.tensor([[0.5, 0.5, 3000.0, 1.0]], dtype=torch.float32)
    assert features == ["coefficientFriction", "coefficientRollingFriction", "density", "P"]
    a, b = float(network.predict_torch(grid)[0]), float(process.predict_torch(grid)[0])
    assert abs(a - b) < 0.05 * a
