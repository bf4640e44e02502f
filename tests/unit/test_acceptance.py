"""Tests of the acceptance criteria (paper eqs. 3 and 4)."""

from __future__ import annotations

import numpy as np
import pytest

from demcal.identification.acceptance import (
    MeasuredCondition,
    marked_then_valid,
    relative_deviation,
    sequential_filter,
    within_all_conditions,
    within_tolerance,
)


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


def test_several_conditions_are_anded() -> None:
    low = MeasuredCondition({"mu_psh": 0.70}, normal_stress=1068.0, P=1.0)
    high = MeasuredCondition({"mu_psh": 0.60}, normal_stress=10070.0, P=1.0)
    pred_low = {"mu_psh": np.array([0.70, 0.70, 0.60, 0.60])}
    pred_high = {"mu_psh": np.array([0.60, 0.70, 0.60, 0.70])}
    np.testing.assert_array_equal(
        within_all_conditions([pred_low, pred_high], [low, high]), [True, False, False, False]
    )
    with pytest.raises(ValueError, match="2 conditions"):
        within_all_conditions([pred_low], [low, high])


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


def test_marked_then_valid_evaluates_repose_only_on_marked_sets() -> None:
    shear = MeasuredCondition(
        {"mu_psh": 0.6, "mu_sh": 0.5, "rho_b": 1760.0}, normal_stress=10070.0, P=1.0
    )
    repose = MeasuredCondition({"aor": 38.85})
    pred = {
        "mu_psh": np.array([0.60, 0.61, 0.80, 0.59, 0.60]),
        "mu_sh": np.array([0.50, 0.49, 0.50, 0.51, 0.50]),
        "rho_b": np.array([1760.0, 1800.0, 1760.0, 1700.0, 2000.0]),
    }
    aor_all = np.array([38.0, 45.0, 38.85, 39.5, 38.85])
    calls: list[np.ndarray] = []

    def predict_repose(rows: np.ndarray) -> dict[str, np.ndarray]:
        calls.append(rows.copy())
        return {"aor": aor_all[rows]}

    result = marked_then_valid([pred], [shear], predict_repose, repose, tol=0.05)
    np.testing.assert_array_equal(result.marked, [True, True, False, True, False])
    np.testing.assert_array_equal(result.valid, [True, False, False, True, False])
    assert len(calls) == 1
    np.testing.assert_array_equal(calls[0], [0, 1, 3])


def test_marked_then_valid_skips_repose_when_nothing_marked() -> None:
    shear = MeasuredCondition({"rho_b": 1760.0}, normal_stress=10070.0, P=1.0)

    def never(rows: np.ndarray) -> dict[str, np.ndarray]:
        raise AssertionError("repose predictor called without marked sets")

    result = marked_then_valid(
        [{"rho_b": np.array([1000.0, 3000.0])}], [shear], never, MeasuredCondition({"aor": 38.0})
    )
    assert not result.marked.any()
    assert not result.valid.any()
