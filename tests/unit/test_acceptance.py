"""Tests of the acceptance criteria (paper eqs. 3 and 4)."""

from __future__ import annotations

import numpy as np
import pytest

from demcal.core.experiments import MeasuredCondition
from demcal.identification.acceptance import (
    acceptance_band,
    relative_deviation,
    sequential_filter,
    within_tolerance,
)
from demcal.identification.screening import screen
from demcal.identification.screening_stages import stage_from_condition


def test_relative_deviation_values() -> None:
    dev = relative_deviation(np.array([0.5, 1.0, 1.1, 0.0, -1.0]), 1.0)
    np.testing.assert_allclose(dev, [0.5, 0.0, 0.1, 1.0, 2.0])
    assert float(relative_deviation(1900.0, 1760.0)) == pytest.approx(140.0 / 1760.0)


def test_relative_deviation_rejects_zero_measurement() -> None:
    with pytest.raises(ValueError, match="experimental value 0"):
        relative_deviation(np.array([1.0]), 0.0)


def test_within_tolerance_boundary_just_inside_and_outside() -> None:
    exp = {"rho_b": 1760.0}
    # 5 % of 1760 kg/m^3 is 88 kg/m^3.
    rho = np.array([1760.0 + 87.9, 1760.0 + 88.1, 1760.0 - 87.9, 1760.0 - 88.1, 1760.0])
    mask = within_tolerance({"rho_b": rho}, exp, tol=0.05)
    np.testing.assert_array_equal(mask, [True, False, True, False, True])


def test_within_tolerance_requires_all_measured_observables() -> None:
    pred = {
        "mu_psh": np.array([0.60, 0.60, 0.70, 0.60]),
        "mu_sh": np.array([0.50, 0.56, 0.50, 0.50]),
        "rho_b": np.array([1760.0, 1760.0, 1760.0, 1500.0]),
    }
    measured = {"mu_psh": 0.6, "mu_sh": 0.5, "rho_b": 1760.0}
    np.testing.assert_array_equal(
        within_tolerance(pred, measured, 0.05), [True, False, False, False]
    )


def test_within_tolerance_partial_data_ignores_unmeasured_outputs() -> None:
    # Only the bulk density is measured: the far-off friction predictions do not matter.
    pred = {"mu_psh": np.array([9.0, 0.1, 5.0]), "rho_b": np.array([1760.0, 1700.0, 1900.0])}
    np.testing.assert_array_equal(within_tolerance(pred, {"rho_b": 1760.0}), [True, True, False])


def test_within_tolerance_nan_never_accepted() -> None:
    mask = within_tolerance({"aor": np.array([np.nan, 38.85])}, {"aor": 38.85})
    np.testing.assert_array_equal(mask, [False, True])


def test_band_widened_by_measurement_sd_in_quadrature() -> None:
    # mu_sh 0.60 +- 0.015 (2.5 %): with two standard deviations the band is
    # sqrt(5 %^2 + 5 %^2) = 7.07 %, i.e. +-0.0424 around 0.60.
    assert acceptance_band(0.60, 0.05, 0.015, 2.0) == pytest.approx(0.05 * np.sqrt(2.0))
    assert acceptance_band(0.60, 0.05, None, 2.0) == 0.05
    assert acceptance_band(0.60, 0.05, 0.015, 0.0) == 0.05
    pred = {"mu_sh": np.array([0.60 + 0.0420, 0.60 + 0.0428, 0.60 - 0.0420, 0.60 + 0.031])}
    measured = {"mu_sh": 0.60}
    widened = within_tolerance(pred, measured, 0.05, {"mu_sh": 0.015}, coverage=2.0)
    np.testing.assert_array_equal(widened, [True, False, True, True])
    # The paper's rule: without coverage, or without an sd, only the 5 % band (+-0.030).
    paper = [False, False, False, False]
    np.testing.assert_array_equal(within_tolerance(pred, measured, 0.05), paper)
    np.testing.assert_array_equal(within_tolerance(pred, measured, 0.05, {}, 2.0), paper)
    np.testing.assert_array_equal(
        within_tolerance(pred, measured, 0.05, {"mu_sh": 0.015}, coverage=0.0), paper
    )
    with pytest.raises(ValueError, match="coverage"):
        within_tolerance(pred, measured, 0.05, {"mu_sh": 0.015}, coverage=-1.0)


def test_condition_stage_uses_each_values_own_sd() -> None:
    # rho_b states an sd of 42 kg/m^3 (band sqrt(88^2 + 84^2) = 121.7 kg/m^3), mu_psh none.
    cond = MeasuredCondition(
        {"mu_psh": 0.6, "rho_b": 1760.0}, {"rho_b": 42.0}, normal_stress=10070.0, P=1.0
    )
    stage = stage_from_condition(cond, 0.05, coverage=2.0)
    pred = {
        "mu_psh": np.array([0.6, 0.6, 0.6 * 1.049, 0.6 * 1.051]),
        "rho_b": np.array([1760.0 + 121.0, 1760.0 + 122.5, 1760.0, 1760.0]),
    }
    np.testing.assert_array_equal(stage.accept(pred), [True, False, True, False])


def test_within_tolerance_errors() -> None:
    with pytest.raises(KeyError, match="mu_sh"):
        within_tolerance({"mu_psh": np.ones(2)}, {"mu_sh": 0.5})
    with pytest.raises(ValueError, match="no measured values"):
        within_tolerance({"mu_psh": np.ones(2)}, {})
    with pytest.raises(ValueError, match="rows"):
        within_tolerance({"a": np.ones(2), "b": np.ones(3)}, {"a": 1.0, "b": 1.0})


def test_measured_condition_label_load_and_validation() -> None:
    cond = MeasuredCondition({"mu_psh": 0.6}, normal_stress=10070.0, P=1.0)
    assert cond.label == "normal_stress=10070,P=1"
    assert cond.load == {"normal_stress": 10070.0, "P": 1.0}
    repose = MeasuredCondition({"aor": 38.85}, uncertainties={"aor": 0.2})
    assert repose.load == {}
    assert repose.label == "aor"
    with pytest.raises(ValueError, match="together"):
        MeasuredCondition({"mu_psh": 0.6}, normal_stress=10070.0)
    with pytest.raises(ValueError, match="non-zero"):
        MeasuredCondition({"rho_b": 0.0})
    with pytest.raises(ValueError, match="no measured values"):
        MeasuredCondition({})
    with pytest.raises(KeyError, match="rho_b"):
        MeasuredCondition({"aor": 38.85}, uncertainties={"rho_b": 42.0})


class Lookup:
    """Predictions read from a table: candidate ``k`` (first input), at the load ``normal_stress``
    (second input, when given); records the candidates it was asked about."""

    def __init__(self, by_load: dict[float | None, np.ndarray]) -> None:
        self.by_load = by_load
        self.calls: list[np.ndarray] = []

    def predict(self, X: np.ndarray) -> np.ndarray:
        k = X[:, 0].astype(int)
        self.calls.append(k.copy())
        if X.shape[1] == 1:
            return self.by_load[None][k]
        return np.array([self.by_load[float(s)][i] for i, s in zip(k, X[:, 1], strict=True)])


def candidates(n: int) -> dict[str, np.ndarray]:
    """A one-axis grid whose values are the candidate numbers 0 .. n-1."""
    return {"k": np.arange(n, dtype=np.float64)}


def test_several_conditions_are_anded() -> None:
    # The screening of the pipeline, two shear-cell load conditions: a set must match both.
    low = MeasuredCondition({"mu_psh": 0.70}, normal_stress=1068.0, P=1.0)
    high = MeasuredCondition({"mu_psh": 0.60}, normal_stress=10070.0, P=1.0)
    mu_psh = Lookup(
        {1068.0: np.array([0.70, 0.70, 0.60, 0.60]), 10070.0: np.array([0.60, 0.70, 0.60, 0.70])}
    )
    result = screen(
        {"mu_psh": (mu_psh, ["k", "normal_stress"])}, candidates(4), {"P": 1.0}, [low, high]
    )
    np.testing.assert_array_equal(result.indices, [0])
    assert result.stage_counts == {low.label: 2, high.label: 1}
    assert result.predictions[high.label]["mu_psh"].tolist() == [0.60]


def test_sequential_filter_passes_only_survivors_on() -> None:
    seen: list[np.ndarray] = []

    def even(ids: np.ndarray) -> np.ndarray:
        seen.append(ids.copy())
        return ids % 2 == 0

    def below_five(ids: np.ndarray) -> np.ndarray:
        seen.append(ids.copy())
        return ids < 5

    passed = sequential_filter(np.arange(10), [even, below_five])
    np.testing.assert_array_equal(passed[0], [0, 2, 4, 6, 8])
    np.testing.assert_array_equal(passed[1], [0, 2, 4])
    np.testing.assert_array_equal(seen[1], [0, 2, 4, 6, 8])


def test_sequential_filter_rejects_bad_mask() -> None:
    with pytest.raises(ValueError, match="bool"):
        sequential_filter(np.arange(3), [lambda ids: ids.astype(float)])


def test_repose_is_evaluated_only_on_marked_sets() -> None:
    # Eq. 3 marks sets on the shear cell, eq. 4 checks only those on the angle of repose.
    shear = MeasuredCondition(
        {"mu_psh": 0.6, "mu_sh": 0.5, "rho_b": 1760.0}, normal_stress=10070.0, P=1.0
    )
    repose = MeasuredCondition({"aor": 38.85})
    shear_values = {
        "mu_psh": np.array([0.60, 0.61, 0.80, 0.59, 0.60]),
        "mu_sh": np.array([0.50, 0.49, 0.50, 0.51, 0.50]),
        "rho_b": np.array([1760.0, 1800.0, 1760.0, 1700.0, 2000.0]),
    }
    predictors = {
        name: (Lookup({10070.0: values}), ["k", "normal_stress"])
        for name, values in shear_values.items()
    }
    aor = Lookup({None: np.array([38.0, 45.0, 38.85, 39.5, 38.85])})
    predictors["aor"] = (aor, ["k"])
    result = screen(predictors, candidates(5), {"P": 1.0}, [shear, repose], tol=0.05)
    assert result.stage_counts == {shear.label: 3, repose.label: 2}
    np.testing.assert_array_equal(result.indices, [0, 3])
    assert len(aor.calls) == 1
    np.testing.assert_array_equal(aor.calls[0], [0, 1, 3])
    np.testing.assert_allclose(result.predictions[repose.label]["aor"], [38.0, 39.5])


def test_repose_is_not_evaluated_when_nothing_is_marked() -> None:
    shear = MeasuredCondition({"rho_b": 1760.0}, normal_stress=10070.0, P=1.0)
    rho_b = Lookup({10070.0: np.array([1000.0, 3000.0])})
    aor = Lookup({None: np.array([38.0, 38.0])})
    predictors = {"rho_b": (rho_b, ["k", "normal_stress"]), "aor": (aor, ["k"])}
    stages = [shear, MeasuredCondition({"aor": 38.0})]
    result = screen(predictors, candidates(2), {"P": 1.0}, stages)
    assert result.n_accepted == 0 and result.n_total == 2
    assert result.stage_counts == {shear.label: 0, "aor": 0}
    assert aor.calls == []
