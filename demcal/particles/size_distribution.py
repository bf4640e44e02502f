"""Particle size distributions: discrete radius classes with mass fractions.

LIGGGHTS inserts polydisperse material through ``fix particledistribution/discrete``, whose
weights are mass fractions; a sieve analysis also reports mass fractions. For classes of the
same particle density the number fraction of class i is proportional to ``w_i / r_i^3``.

Sinter fines (PHYSICS.md section 2)
-----------------------------------
Sieve analysis, opening in mm: mass fraction retained
2.0: 0.4539, 1.6: 0.1571, 1.25: 0.1033, 1.0: 0.2264, 0.8: 0.0284, 0.63: 0.0309.

Mapping of a sieve class to a particle size: the mass retained on a sieve of opening ``a`` is
represented by spheres of diameter ``a`` (radius ``a / 2``), i.e. by the lower bound of the
class. The upper bound of the coarsest class (retained on 2.0 mm) is not published, so a class
mid-point cannot be formed for all classes alike; the lower bound can. Resulting radii are
1.0, 0.8, 0.625, 0.5, 0.4 and 0.315 mm, and:

==========================  =========  =======
statistic                   mean (mm)  sd (mm)
==========================  =========  =======
number-weighted (this one)  0.533      0.202
mass-weighted               0.778      0.230
paper Table 1               0.732      0.410
==========================  =========  =======

The mass-weighted mean is 6 % above the paper's mean radius; the paper's standard deviation is
not reproduced. Other mappings do not reproduce Table 1 either: class mid-points with an assumed
2.5 mm sieve above the coarsest class give 0.877 / 0.258 mm (mass-weighted) and
0.602 / 0.228 mm (number-weighted); a larger representative radius for the coarsest class
raises the mass-weighted sd only together with the mean (sd 0.41 mm needs a coarsest-class
radius of about 1.4 mm, where the mean is 0.96 mm). Table 1 was evidently computed from other
data than these six classes, so the plain lower-bound mapping is kept.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from demcal.core import config_values
from demcal.core.config_values import SetupError

__all__ = [
    "SINTER_FINES_SIEVE_MM",
    "SizeDistribution",
    "from_sieve_analysis",
    "monodisperse",
    "sinter_fines",
    "size_distribution",
]

#: Sieve analysis of the sinter fines: (sieve opening in mm, mass fraction retained).
SINTER_FINES_SIEVE_MM: tuple[tuple[float, float], ...] = (
    (2.0, 0.4539),
    (1.6, 0.1571),
    (1.25, 0.1033),
    (1.0, 0.2264),
    (0.8, 0.0284),
    (0.63, 0.0309),
)

_SUM_TOLERANCE = 1e-6


@dataclass(frozen=True, eq=False)
class SizeDistribution:
    """Discrete distribution of sphere radii with mass fractions.

    Parameters
    ----------
    radii : array_like, shape (k,)
        Distinct class radii, m (> 0).
    mass_fractions : array_like, shape (k,)
        Mass fraction of each class (>= 0, summing to 1 within 1e-6; stored renormalised to
        sum exactly to 1).

    Notes
    -----
    All classes share one particle density, so mass and volume fractions coincide.
    """

    radii: np.ndarray
    mass_fractions: np.ndarray

    def __post_init__(self) -> None:
        radii = np.array(self.radii, dtype=float).reshape(-1)
        fractions = np.array(self.mass_fractions, dtype=float).reshape(-1)
        if radii.size == 0:
            raise ValueError("SizeDistribution: at least one radius class is required")
        if radii.shape != fractions.shape:
            raise ValueError(
                f"SizeDistribution: {radii.size} radii but {fractions.size} mass_fractions"
            )
        if not np.all(np.isfinite(radii)) or np.any(radii <= 0):
            raise ValueError(f"SizeDistribution: radii must be positive (m), got {radii}")
        if len(np.unique(radii)) != radii.size:
            raise ValueError(f"SizeDistribution: radii must be distinct, got {radii}")
        if not np.all(np.isfinite(fractions)) or np.any(fractions < 0):
            raise ValueError(f"SizeDistribution: mass_fractions must be >= 0, got {fractions}")
        total = float(fractions.sum())
        if abs(total - 1.0) > _SUM_TOLERANCE:
            raise ValueError(f"SizeDistribution: mass_fractions sum to {total:.6g}, not 1")
        fractions = fractions / total
        radii.setflags(write=False)
        fractions.setflags(write=False)
        object.__setattr__(self, "radii", radii)
        object.__setattr__(self, "mass_fractions", fractions)

    @property
    def n_classes(self) -> int:
        """Number of radius classes."""
        return int(self.radii.size)

    @property
    def number_fractions(self) -> np.ndarray:
        """Number fraction of each class, shape (k,): ``(w_i / r_i^3) / sum_j (w_j / r_j^3)``."""
        weights = self.mass_fractions / self.radii**3
        return weights / weights.sum()

    @property
    def mean_radius(self) -> float:
        """Number-weighted mean radius, m."""
        return float(np.dot(self.number_fractions, self.radii))

    @property
    def sd_radius(self) -> float:
        """Number-weighted (population) standard deviation of the radius, m."""
        dev = self.radii - self.mean_radius
        return float(math.sqrt(np.dot(self.number_fractions, dev**2)))

    @property
    def mass_mean_radius(self) -> float:
        """Mass-weighted mean radius, m."""
        return float(np.dot(self.mass_fractions, self.radii))

    @property
    def mass_sd_radius(self) -> float:
        """Mass-weighted (population) standard deviation of the radius, m."""
        dev = self.radii - self.mass_mean_radius
        return float(math.sqrt(np.dot(self.mass_fractions, dev**2)))

    @property
    def max_radius(self) -> float:
        """Largest radius among classes with a non-zero fraction, m."""
        return float(self.radii[self.mass_fractions > 0].max())

    @property
    def min_radius(self) -> float:
        """Smallest radius among classes with a non-zero fraction, m."""
        return float(self.radii[self.mass_fractions > 0].min())

    @property
    def mean_particle_volume(self) -> float:
        """Expected volume of one particle (number-weighted), m^3."""
        return float(np.dot(self.number_fractions, 4.0 / 3.0 * np.pi * self.radii**3))

    def particles_for_volume(self, solid_volume: float) -> float:
        """Expected number of particles whose volumes add up to ``solid_volume``.

        Parameters
        ----------
        solid_volume : float
            Volume of solid material (not bulk volume), m^3 (>= 0).

        Returns
        -------
        float
            ``solid_volume / mean_particle_volume`` (not rounded).
        """
        if not (math.isfinite(solid_volume) and solid_volume >= 0):
            raise ValueError(f"solid_volume must be a finite volume >= 0 m^3, got {solid_volume}")
        return solid_volume / self.mean_particle_volume

    def scaled(self, factor: float) -> SizeDistribution:
        """All radii multiplied by ``factor`` (coarse graining for factor > 1); same fractions."""
        if not (math.isfinite(factor) and factor > 0):
            raise ValueError(f"scale factor must be positive, got {factor}")
        return SizeDistribution(self.radii * factor, self.mass_fractions)

    def truncated(self, k: float) -> SizeDistribution:
        """The ``k`` largest classes, mass fractions renormalised to sum to 1.

        A fractional ``k`` keeps ``floor(k)`` classes whole and the share ``k - floor(k)`` of
        the mass of the next finer class, so that the amount of fines, and with it the size
        spread, grows continuously with ``k`` (a sieve cut between two sieves).

        Parameters
        ----------
        k : float
            Number of classes kept, ``1 <= k <= n_classes``.

        Returns
        -------
        SizeDistribution
            ``ceil(k)`` classes in the original order.

        Raises
        ------
        ValueError
            For ``k`` outside ``[1, n_classes]`` or not a finite number, or no mass kept.
        """
        if isinstance(k, bool) or not isinstance(k, int | float | np.integer | np.floating):
            raise ValueError(f"number of classes to keep must be a number >= 1, got {k!r}")
        if not (math.isfinite(k) and k >= 1):
            raise ValueError(f"number of classes to keep must be a number >= 1, got {k!r}")
        if k > self.n_classes:
            raise ValueError(f"cannot keep {k} classes of a {self.n_classes}-class distribution")
        whole = math.floor(k)
        share = float(k) - whole
        n_kept = whole + (1 if share > 0 else 0)
        order = np.argsort(self.radii)[::-1][:n_kept]  # largest first
        fractions = self.mass_fractions.copy()
        if share > 0:
            fractions[order[-1]] *= share
        keep = np.sort(order)  # original order
        fractions = fractions[keep]
        if fractions.sum() <= 0:
            raise ValueError(f"the {k} largest classes hold no mass")
        return SizeDistribution(self.radii[keep], fractions / fractions.sum())


def monodisperse(radius: float) -> SizeDistribution:
    """A single class of radius ``radius`` (m)."""
    return SizeDistribution(np.array([radius], dtype=float), np.array([1.0]))


def from_sieve_analysis(
    sieve: Sequence[tuple[float, float]], *, unit: float = 1e-3
) -> SizeDistribution:
    """Distribution from a sieve analysis, one class per sieve, diameter = sieve opening.

    Parameters
    ----------
    sieve : sequence of (opening, mass fraction)
        Sieve openings (in ``unit``) with the mass fraction retained on each.
    unit : float
        Length of one opening unit in m (1e-3 for mm).

    Returns
    -------
    SizeDistribution
        Radii ``opening * unit / 2``, m, in the order given.
    """
    if not sieve:
        raise ValueError("sieve analysis has no classes")
    openings = np.array([float(a) for a, _ in sieve])
    fractions = np.array([float(w) for _, w in sieve])
    return SizeDistribution(openings * unit / 2.0, fractions)


def sinter_fines(scale: float = 1.0, n_largest: float | None = None) -> SizeDistribution:
    """The sinter-fines distribution of the paper (see the module notes for the size mapping).

    Parameters
    ----------
    scale : float
        Factor applied to all radii (coarse graining), default 1.
    n_largest : float, optional
        Keep only this many of the largest classes (mass fractions renormalised; a fractional
        part keeps that share of the next finer class, see `SizeDistribution.truncated`).

    Returns
    -------
    SizeDistribution
        Radii in m: 1.0, 0.8, 0.625, 0.5, 0.4, 0.315 mm times ``scale``.
    """
    dist = from_sieve_analysis(SINTER_FINES_SIEVE_MM)
    if n_largest is not None:
        dist = dist.truncated(n_largest)
    if scale != 1.0:
        dist = dist.scaled(scale)
    return dist


def size_distribution(particles: Mapping[str, Any]) -> SizeDistribution:
    """Particle size distribution of the ``particles`` configuration section.

    Parameters
    ----------
    particles : mapping
        ``distribution`` ("monodisperse" or "sinter_fines"), ``radius`` (m, monodisperse),
        ``scale`` (-, factor on the sinter-fines radii) and ``classes`` (number of the largest
        sieve classes kept, 1-6; a fractional part keeps that share of the next finer class).

    Returns
    -------
    SizeDistribution
        Radii (m) and mass fractions.

    Raises
    ------
    SetupError
        A value out of range (the message names the key).
    """
    get = config_values.required
    positive = config_values.positive_value
    kind = get(particles, "distribution", "particles")
    if kind == "monodisperse":
        return monodisperse(positive(get(particles, "radius", "particles"), "particles.radius"))
    if kind == "sinter_fines":
        scale = positive(get(particles, "scale", "particles"), "particles.scale")
        classes = float(get(particles, "classes", "particles"))
        if not 1 <= classes <= 6:
            raise SetupError(f"configuration: 'particles.classes' must be in 1..6, got {classes}")
        return sinter_fines(scale=scale, n_largest=classes)
    raise SetupError(
        f"configuration: 'particles.distribution' must be 'monodisperse' or 'sinter_fines', "
        f"got {kind!r}"
    )
