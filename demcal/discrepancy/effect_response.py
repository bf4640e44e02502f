"""The DEM response of the observations to a candidate effect, and its description in words.

Probe runs at theta* (the best point of the current model) with the effect off and at a few
magnitudes a_j measure how every observation k responds:
``R_k(a_j) = DEM_k(theta*, a_j) - DEM_k(theta*, off)``. Between the probed magnitudes the
response is interpolated linearly (:meth:`EffectResponse.at`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from demcal.discrepancy.observations import format_stress

__all__ = ["EffectResponse", "response_signature"]


@dataclass(frozen=True)
class EffectResponse:
    """DEM response of the K observations to one candidate effect around theta*.

    Attributes
    ----------
    candidate : str
        Name of the effect.
    magnitudes : ndarray, shape (L,)
        Effect magnitudes of the probe runs, ascending, including the reference (effect off).
    responses : ndarray, shape (L, K)
        DEM value at each magnitude minus the reference run's value (units of the observable);
        the reference row is zero.
    reference : int
        Row of the reference run.
    integer : bool
        The magnitude only takes whole values.
    """

    candidate: str
    magnitudes: np.ndarray
    responses: np.ndarray
    reference: int
    integer: bool = False

    def __post_init__(self) -> None:
        m = np.asarray(self.magnitudes, dtype=float)
        r = np.asarray(self.responses, dtype=float)
        if m.ndim != 1 or m.size < 2:
            raise ValueError(f"{self.candidate}: need the reference and at least one level")
        if np.any(np.diff(m) <= 0):
            raise ValueError(f"{self.candidate}: probe magnitudes must be strictly ascending")
        if r.shape[0] != m.size:
            raise ValueError(f"{self.candidate}: {r.shape[0]} response rows for {m.size} levels")
        if not 0 <= self.reference < m.size:
            raise ValueError(f"{self.candidate}: reference index out of range")
        if not np.all(np.isfinite(r)):
            raise ValueError(f"{self.candidate}: responses must be finite")

    @classmethod
    def from_runs(
        cls,
        candidate: str,
        magnitudes: Sequence[float],
        values: np.ndarray,
        reference: int,
        integer: bool = False,
    ) -> EffectResponse:
        """From DEM values per probe run (rows) and observation (columns), any order.

        Parameters
        ----------
        magnitudes : sequence of float, length L
            Effect magnitude of each run.
        values : ndarray, shape (L, K)
            DEM value of each observation in each run.
        reference : int
            Row of the run with the effect off.
        """
        mags = np.asarray(magnitudes, dtype=float)
        vals = np.asarray(values, dtype=float)
        # A level that coincides with the reference adds nothing but a duplicate abscissa.
        keep = [j for j in range(mags.size) if j == reference or mags[j] != mags[reference]]
        reference = keep.index(reference)
        mags, vals = mags[keep], vals[keep]
        order = np.argsort(mags, kind="stable")
        responses = vals - vals[reference]
        return cls(
            candidate,
            mags[order],
            responses[order],
            int(np.flatnonzero(order == reference)[0]),
            integer,
        )

    @property
    def off(self) -> float:
        """Magnitude at which the effect is absent."""
        return float(self.magnitudes[self.reference])

    def at(self, magnitude: float) -> np.ndarray:
        """Response of every observation at ``magnitude``, shape (K,).

        Piecewise linear between the probed magnitudes, held at the end values outside them.
        """
        m = self.magnitudes
        a = float(np.clip(magnitude, m[0], m[-1]))
        i = int(np.clip(np.searchsorted(m, a, side="right") - 1, 0, m.size - 2))
        t = (a - m[i]) / (m[i + 1] - m[i])
        return (1.0 - t) * self.responses[i] + t * self.responses[i + 1]

    def trial_magnitudes(self, points: int) -> np.ndarray:
        """Magnitudes tried in the fit: a regular grid over the probed span plus the levels."""
        lo, hi = float(self.magnitudes[0]), float(self.magnitudes[-1])
        if self.integer:
            return np.arange(math.ceil(lo), math.floor(hi) + 1, dtype=float)
        return np.unique(np.concatenate([np.linspace(lo, hi, max(points, 2)), self.magnitudes]))


_FRICTION = ("mu_psh", "mu_sh")


def _change(name: str, value: float, reference: float) -> str:
    if name in _FRICTION:
        return f"{value:+.2f}"
    if name == "aor":
        return f"{value:+.1f} deg"
    return f"{100.0 * value / reference:+.1f} %"


def response_signature(
    observations: pd.DataFrame,
    response: EffectResponse,
    reference_values: np.ndarray,
    noise_sd: np.ndarray,
) -> str:
    """How the observables respond to the effect at its largest probed magnitude, in words.

    Per observable the response is averaged over P at each normal stress; responses within the
    noise are reported as no clear change, and with two or more stresses the trend with normal
    stress is named (e.g. for cohesion: the added friction weakens with normal stress, that is
    the apparent friction falls with normal stress).

    Parameters
    ----------
    observations : DataFrame, shape (K, ...)
        Columns observable, normal_stress, P.
    response : EffectResponse
    reference_values : ndarray, shape (K,)
        DEM values of the reference run (for relative changes).
    noise_sd : ndarray, shape (K,)
        Noise of one DEM run per observation.
    """
    far = int(np.argmax(np.abs(response.magnitudes - response.off)))
    delta = response.responses[far]
    obs = observations.reset_index(drop=True).assign(
        delta=delta, ref=reference_values, noise=noise_sd
    )
    parts = []
    for name, rows in obs.groupby("observable", sort=False):
        if rows["normal_stress"].isna().all():
            level = rows["delta"].mean()
            noise = rows["noise"].mean() * math.sqrt(2.0)
            text = _change(name, level, rows["ref"].mean())
            parts.append(f"{name} {text}" if abs(level) > noise else f"{name} no clear change")
            continue
        per_stress = rows.groupby("normal_stress", sort=True).agg(
            delta=("delta", "mean"), ref=("ref", "mean"), noise=("noise", "mean"), n=("P", "size")
        )
        noise = float((per_stress["noise"] * np.sqrt(2.0 / per_stress["n"])).max())
        items = [
            f"{_change(name, r.delta, r.ref)} at {format_stress(s)}"
            for s, r in per_stress.iterrows()
        ]
        biggest = float(per_stress["delta"].abs().max())
        if biggest <= noise:
            parts.append(f"{name} no clear change")
            continue
        text = f"{name} " + ", ".join(items)
        if len(per_stress) > 1:
            low, high = per_stress["delta"].iloc[0], per_stress["delta"].iloc[-1]
            if abs(low - high) > max(noise, 0.3 * biggest):
                trend = "weakens" if abs(low) > abs(high) else "grows"
                text += f" (the change {trend} with normal stress"
                if name in _FRICTION and trend == "weakens" and low > 0:
                    text += ": apparent friction falls with normal stress"
                text += ")"
        parts.append(text)
    return "; ".join(parts)
