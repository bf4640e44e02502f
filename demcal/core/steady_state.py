"""Automatic detection of the steady plateau at the end of a time series.

The shear-cell readouts (mu during pre-shear and during shear) rise through a transient and then
fluctuate about a steady level until the phase ends. The plateau is therefore sought as a tail
``y[start:]`` of the record, with a fixed end and a detected start, in two steps:

1. **Truncation of the transient (MSER-m).** The samples are grouped into batches of ``m``
   consecutive values (default ``max(5, n // 100)``), aligned to the end of the record. For
   every candidate truncation point ``d`` (in batches) the marginal standard error rule
   evaluates

   ``MSER(d) = sum_{j >= d} (b_j - mean(b_d, ..., b_{k-1}))^2 / (k - d)^2``

   (``b_j`` batch means, ``k`` batches), the squared standard error of the mean of the kept
   tail. Its minimum balances dropping biased transient samples against keeping enough samples.
   Candidates are restricted so that at least ``min_fraction`` of the record is kept.
2. **Trend test on the kept window.** A straight line is fitted to ``y(t)`` over the window and
   its drift ``|slope| * duration`` is compared with three scales:

   * the level: ``drift <= rel_drift_tol * |mean|`` is negligible whatever the noise (this
     accepts nearly noise-free signals that have converged);
   * the fluctuation: ``drift <= trend_tol * std`` of the residuals about the line;
   * its own uncertainty: ``drift <= trend_z * se``, with ``se`` from a line fitted to 20
     batch means, which stay nearly independent when successive samples are correlated
     (stick-slip sawtooth, slow fluctuations).

   The window is steady if the drift is negligible against the level, or both small against
   the fluctuation and not significant. If the MSER window fails, later windows (start moved
   in steps of 2 % of the record, down to the shortest allowed window) are tested, because
   MSER tends to stop too early when the fluctuations are strongly correlated.

A steady ramp fails: MSER keeps a window over which the ramp rises by several residual standard
deviations, and every later window still carries a significant drift. A signal still rising at
the end of the record fails the same way. Low signal-to-noise ramps (a rise of a few noise
standard deviations over the whole record) can pass, since over a short window they cannot be
told apart from noise.

The standard error of the plateau mean is estimated from batch means (up to 20 non-overlapping
batches of the window), which accounts for correlation between successive samples.

Sampling is assumed (nearly) uniform in time, as for engine output printed every N steps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Plateau", "batch_means_sem", "detect_plateau", "mser_truncation"]

# Fewest samples for which a plateau is sought at all.
_MIN_SAMPLES = 10


@dataclass(frozen=True)
class Plateau:
    """The plateau found in a time series and whether it is steady.

    Attributes
    ----------
    start_index, end_index : int
        Window ``y[start_index:end_index]`` (end exclusive) used for the statistics.
    start_time, end_time : float
        ``t[start_index]`` and ``t[end_index - 1]`` (units of ``t``, s for engine output).
    mean, std, sem : float
        Mean, sample standard deviation and standard error of the mean (batch means) of the
        window (units of ``y``).
    drift : float
        ``|slope| * duration`` of the least-squares line over the window (units of ``y``).
    steady : bool
        Whether the window passed the trend test.
    reason : str
        Short explanation of the decision.
    """

    start_index: int
    end_index: int
    start_time: float
    end_time: float
    mean: float
    std: float
    sem: float
    drift: float
    steady: bool
    reason: str

    @property
    def n_samples(self) -> int:
        """Number of samples in the window."""
        return self.end_index - self.start_index


def mser_truncation(y: np.ndarray, batch_size: int = 5, max_fraction: float = 0.5) -> int:
    """Truncation point (sample index) of the initial transient by the MSER-m rule.

    Parameters
    ----------
    y : numpy.ndarray
        Shape (n,), the series.
    batch_size : int
        Samples per batch (``m`` of MSER-m); batches are aligned with the end of ``y``.
    max_fraction : float
        Largest fraction of the record that may be truncated, in (0, 1).

    Returns
    -------
    int
        Index of the first sample kept.
    """
    y = np.asarray(y, dtype=np.float64)
    if batch_size < 1:
        raise ValueError(f"batch_size must be >= 1, got {batch_size}")
    if not 0.0 < max_fraction < 1.0:
        raise ValueError(f"max_fraction must be in (0, 1), got {max_fraction}")
    n = y.size
    k = n // batch_size
    if k < 2:
        return 0
    offset = n - k * batch_size
    batches = y[offset:].reshape(k, batch_size).mean(axis=1)
    # Centring keeps the suffix sums below free of cancellation for large offsets.
    batches = batches - batches.mean()
    # Suffix sums give mean and sum of squares of every tail batches[d:] in O(k).
    s1 = np.cumsum(batches[::-1])[::-1]
    s2 = np.cumsum((batches**2)[::-1])[::-1]
    count = np.arange(k, 0, -1, dtype=np.float64)
    sq_dev = np.maximum(s2 - s1**2 / count, 0.0)
    d_max = min(int(np.floor(max_fraction * k)), k - 2)
    mser = sq_dev[: d_max + 1] / count[: d_max + 1] ** 2
    # Ties go to the smallest truncation (keeps most data); exact zeros mean a constant tail.
    d_best = int(np.argmin(mser))
    return offset + d_best * batch_size if d_best > 0 else 0


def detect_plateau(
    t: np.ndarray,
    y: np.ndarray,
    min_fraction: float = 0.2,
    batch_size: int | None = None,
    trend_tol: float = 1.0,
    rel_drift_tol: float = 0.02,
    trend_z: float = 3.0,
) -> Plateau:
    """Find the steady plateau at the end of ``y(t)`` and test it for a remaining trend.

    See the module docstring for the method (MSER-m truncation, then a linear-trend test on
    the kept window and, if that fails, on successively later windows).

    Parameters
    ----------
    t : numpy.ndarray
        Shape (n,), strictly increasing sample times (s).
    y : numpy.ndarray
        Shape (n,), finite sample values (any unit).
    min_fraction : float
        Shortest plateau accepted, as a fraction of the record length, in (0, 1).
    batch_size : int, optional
        Batch size ``m`` of the MSER-m rule; default ``max(5, n // 100)``.
    trend_tol : float
        A drift up to ``trend_tol`` residual standard deviations counts as small against the
        fluctuation.
    rel_drift_tol : float
        A drift up to ``rel_drift_tol * |mean|`` counts as negligible whatever the noise.
    trend_z : float
        A drift below ``trend_z`` standard errors (batch-means estimate) is not significant.

    Returns
    -------
    Plateau
        The window, its statistics and the steady flag. For an unsteady record the window is
        the last ``min_fraction`` of it. With fewer than 10 samples the whole record is
        returned as unsteady (NaN statistics for an empty record).

    Raises
    ------
    ValueError
        Shapes differ, values are not finite, ``t`` is not strictly increasing, or a tuning
        parameter is out of range.
    """
    t = np.asarray(t, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    if t.ndim != 1 or y.ndim != 1 or t.shape != y.shape:
        raise ValueError(f"t and y must be 1-D of equal length, got {t.shape} and {y.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(y))):
        raise ValueError("t and y must be finite (found NaN or inf)")
    if np.any(np.diff(t) <= 0.0):
        raise ValueError("t must be strictly increasing")
    if not 0.0 < min_fraction < 1.0:
        raise ValueError(f"min_fraction must be in (0, 1), got {min_fraction}")
    if trend_tol < 0.0 or rel_drift_tol < 0.0 or trend_z < 0.0:
        raise ValueError("trend_tol, rel_drift_tol and trend_z must be non-negative")

    n = y.size
    if n < _MIN_SAMPLES:
        return _window_stats(t, y, 0, n, False, f"too few samples ({n} < {_MIN_SAMPLES})")
    m = max(5, n // 100) if batch_size is None else batch_size
    n_min = max(int(np.ceil(min_fraction * n)), _MIN_SAMPLES)
    last_start = n - n_min
    mser_start = min(mser_truncation(y, batch_size=m, max_fraction=1.0 - min_fraction), last_start)
    # Correlated noise can make MSER stop too early; later windows get a chance before the
    # record is declared unsteady.
    step = max(m, n // 50)
    starts = [*range(mser_start, last_start, step), last_start]
    for start in starts:
        trend = _linear_trend(t[start:], y[start:])
        noise_ok = trend.drift <= trend_tol * trend.resid_std
        level_ok = trend.drift <= rel_drift_tol * abs(trend.mean)
        chance_ok = trend.drift <= trend_z * trend.drift_se
        if level_ok or (noise_ok and chance_ok):
            where = "MSER window" if start == mser_start else "window after the MSER point"
            basis = "the level" if level_ok else "the fluctuation and not significant"
            reason = f"steady over {where}: drift {trend.drift:.3g} small against {basis}"
            return _window_stats(t, y, start, n, True, reason, drift=trend.drift)
    reason = (
        f"no steady window of at least {min_fraction:g} of the record: over the last one the "
        f"drift {trend.drift:.3g} exceeds {rel_drift_tol:g} x |mean| {abs(trend.mean):.3g} "
        f"and {trend_tol:g} x residual std {trend.resid_std:.3g} or {trend_z:g} x its "
        f"standard error {trend.drift_se:.3g}"
    )
    return _window_stats(t, y, last_start, n, False, reason, drift=trend.drift)


@dataclass(frozen=True)
class _Trend:
    mean: float
    drift: float
    resid_std: float
    drift_se: float


def _linear_trend(t: np.ndarray, y: np.ndarray) -> _Trend:
    """Least-squares line through ``y(t)``: drift over the window and its uncertainty."""
    tc = t - t.mean()
    slope = float(np.dot(tc, y - y.mean()) / np.dot(tc, tc))
    resid = y - y.mean() - slope * tc
    resid_std = float(np.sqrt(np.dot(resid, resid) / max(y.size - 2, 1)))
    return _Trend(
        mean=float(y.mean()),
        drift=abs(slope) * float(t[-1] - t[0]),
        resid_std=resid_std,
        drift_se=_batch_drift_se(t, y),
    )


def _batch_drift_se(t: np.ndarray, y: np.ndarray, n_batches: int = 20) -> float:
    """Standard error of ``slope * duration`` from a line fitted to batch means.

    Batch means of correlated fluctuations are close to independent, so the residual scatter
    of the batch means about the line gives an honest slope uncertainty.
    """
    n = y.size
    nb = min(n_batches, n // 3)
    if nb < 4:
        return float("inf")
    size = n // nb
    tb = t[n - nb * size :].reshape(nb, size).mean(axis=1)
    yb = y[n - nb * size :].reshape(nb, size).mean(axis=1)
    tc = tb - tb.mean()
    slope = float(np.dot(tc, yb - yb.mean()) / np.dot(tc, tc))
    resid = yb - yb.mean() - slope * tc
    se_slope = np.sqrt(np.dot(resid, resid) / (nb - 2) / np.dot(tc, tc))
    return float(se_slope * (t[-1] - t[0]))


def _window_stats(
    t: np.ndarray,
    y: np.ndarray,
    start: int,
    stop: int,
    steady: bool,
    reason: str,
    drift: float = float("nan"),
) -> Plateau:
    yw = y[start:stop]
    if yw.size == 0:
        nan = float("nan")
        return Plateau(0, 0, nan, nan, nan, nan, nan, nan, False, reason)
    std = float(np.std(yw, ddof=1)) if yw.size > 1 else 0.0
    return Plateau(
        start_index=start,
        end_index=stop,
        start_time=float(t[start]),
        end_time=float(t[stop - 1]),
        mean=float(np.mean(yw)),
        std=std,
        sem=batch_means_sem(yw),
        drift=drift,
        steady=steady,
        reason=reason,
    )


def batch_means_sem(y: np.ndarray, max_batches: int = 20) -> float:
    """Standard error of the mean of a correlated series from non-overlapping batch means.

    Parameters
    ----------
    y : numpy.ndarray
        Shape (n,), the series (any units).
    max_batches : int
        Most batches; fewer when ``n`` is small (at least two samples per batch).

    Returns
    -------
    float
        Standard error of ``y.mean()`` (units of ``y``); NaN with fewer than two batches.
    """
    n = y.size
    n_batches = min(max_batches, n // 2)
    if n_batches < 2:
        return float("nan")
    size = n // n_batches
    means = y[n - n_batches * size :].reshape(n_batches, size).mean(axis=1)
    return float(np.std(means, ddof=1) / np.sqrt(n_batches))
