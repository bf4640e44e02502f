"""Plateau detection on synthetic signals with a known steady level (or none)."""

from __future__ import annotations

import numpy as np
import pytest

from demcal.core.steady_state import detect_plateau, mser_truncation

T = np.linspace(0.0, 10.0, 2000)
SEEDS = range(5)


def _correlated_noise(rng: np.random.Generator, sd: float, length: int) -> np.ndarray:
    """Moving-average noise of standard deviation ``sd`` and correlation ``length`` samples."""
    white = rng.standard_normal(T.size + length)
    return sd * np.convolve(white, np.ones(length) / np.sqrt(length), "valid")[: T.size]


@pytest.mark.parametrize("seed", SEEDS)
def test_exponential_rise_recovers_level(seed: int) -> None:
    rng = np.random.default_rng(seed)
    level, tau = 0.6, 0.8
    y = level * (1.0 - np.exp(-T / tau)) + 0.02 * rng.standard_normal(T.size)
    p = detect_plateau(T, y)
    assert p.steady, p.reason
    assert abs(p.mean - level) < 0.005
    # The window starts once the transient (0.6 exp(-t/0.8)) has fallen to the noise level.
    assert 2.0 < p.start_time < 8.0
    assert p.end_index == T.size
    assert 0.0 < p.sem < 0.003


@pytest.mark.parametrize("seed", SEEDS)
def test_exponential_rise_with_correlated_noise(seed: int) -> None:
    rng = np.random.default_rng(seed)
    y = 0.6 * (1.0 - np.exp(-T / 0.8)) + _correlated_noise(rng, 0.02, 40)
    p = detect_plateau(T, y)
    assert p.steady, p.reason
    assert abs(p.mean - 0.6) < 0.015
    # Batch means see the correlation: the error estimate exceeds the white-noise value.
    assert p.sem > p.std / np.sqrt(p.n_samples)


@pytest.mark.parametrize("seed", SEEDS)
def test_step_down_recovers_second_level(seed: int) -> None:
    rng = np.random.default_rng(seed)
    y = np.where(T < 4.0, 0.8, 0.5) + 0.02 * rng.standard_normal(T.size)
    p = detect_plateau(T, y)
    assert p.steady, p.reason
    assert abs(p.mean - 0.5) < 0.004
    assert p.start_time >= 4.0
    assert p.start_time < 4.5


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("period", [0.37, 1.1, 2.3])
def test_stick_slip_sawtooth_with_stationary_mean(seed: int, period: float) -> None:
    rng = np.random.default_rng(seed)
    phase = rng.random()
    # Slow build-up and sudden slip, amplitude 0.08 about the mean 0.45, after a rise.
    saw = 0.08 * (((T / period) + phase) % 1.0 - 0.5)
    y = 0.45 * (1.0 - np.exp(-T / 0.5)) + saw + 0.005 * rng.standard_normal(T.size)
    p = detect_plateau(T, y)
    assert p.steady, p.reason
    assert abs(p.mean - 0.45) < 0.005


def test_noise_free_convergence_is_steady_by_level() -> None:
    y = 0.6 * (1.0 - np.exp(-T / 0.8))
    p = detect_plateau(T, y)
    assert p.steady
    assert p.mean == pytest.approx(0.6, abs=1e-4)
    assert "level" in p.reason


@pytest.mark.parametrize("seed", SEEDS)
def test_steady_ramp_is_not_steady(seed: int) -> None:
    rng = np.random.default_rng(seed)
    y = 0.2 + 0.04 * T + 0.02 * rng.standard_normal(T.size)
    p = detect_plateau(T, y)
    assert not p.steady
    assert "no steady window" in p.reason
    # The reported window is the last min_fraction of the record; its drift is the ramp's.
    assert p.start_index == T.size - 400
    assert p.drift == pytest.approx(0.04 * (T[-1] - T[p.start_index]), rel=0.2)


@pytest.mark.parametrize("seed", SEEDS)
def test_signal_still_rising_is_not_steady(seed: int) -> None:
    rng = np.random.default_rng(seed)
    y = 0.6 * (1.0 - np.exp(-T / 6.0)) + 0.01 * rng.standard_normal(T.size)
    assert not detect_plateau(T, y).steady
    y_corr = 0.6 * (1.0 - np.exp(-T / 6.0)) + _correlated_noise(rng, 0.01, 40)
    assert not detect_plateau(T, y_corr).steady


def test_late_plateau_shorter_than_min_fraction_is_not_steady() -> None:
    # Rises until t = 9 (90 % of the record): the flat part is too short for min_fraction=0.2
    # but long enough for min_fraction=0.05.
    y = np.minimum(T, 9.0) * 0.05
    assert not detect_plateau(T, y, min_fraction=0.2).steady
    p = detect_plateau(T, y, min_fraction=0.05)
    assert p.steady
    assert p.start_time >= 9.0 - 1e-9
    assert p.mean == pytest.approx(0.45)


def test_mser_truncation_finds_step_position() -> None:
    rng = np.random.default_rng(0)
    y = np.concatenate([np.full(300, 5.0), np.zeros(700)]) + 0.1 * rng.standard_normal(1000)
    d = mser_truncation(y, batch_size=5, max_fraction=0.8)
    assert 300 <= d <= 305


def test_too_few_samples_and_bad_input() -> None:
    p = detect_plateau(T[:5], np.ones(5))
    assert not p.steady
    assert "too few" in p.reason
    with pytest.raises(ValueError, match="strictly increasing"):
        detect_plateau(T[::-1], np.ones(T.size))
    with pytest.raises(ValueError, match="finite"):
        detect_plateau(T, np.where(T > 5, np.nan, 1.0))
    with pytest.raises(ValueError, match="equal length"):
        detect_plateau(T, np.ones(10))
    with pytest.raises(ValueError, match="min_fraction"):
        detect_plateau(T, np.ones(T.size), min_fraction=1.5)
