"""What every DEM deck sets up the same way: simulation box, time step, neighbour skin, output
intervals, run length and the seeds of the particle insertion.

Each deck's set-up record (shear cell, angle of repose, chute cooler) extends
:class:`RunSetup` with its own geometry and schedule. SI units throughout.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

__all__ = ["RunSetup", "insertion_seeds", "prime_seed", "steps_for"]


@dataclass(frozen=True, kw_only=True)
class RunSetup:
    """The fields every deck's set-up has.

    Attributes
    ----------
    box_lo, box_hi : tuple of float
        Simulation box corners, m.
    timestep : float
        Time step, s.
    skin : float
        Neighbour skin, m.
    print_every, thermo_every : int
        Steps between rows of the print file and of the thermo output.
    total_steps : int
        Steps of the whole run.
    seeds : dict of str to int
        Prime seeds of the insertion and template fixes (:func:`insertion_seeds`).
    """

    box_lo: tuple[float, float, float]
    box_hi: tuple[float, float, float]
    timestep: float
    skin: float
    print_every: int
    thermo_every: int
    total_steps: int
    seeds: dict[str, int] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON-ready dict (tuples as lists)."""
        out = asdict(self)
        for key, value in out.items():
            if isinstance(value, tuple):
                out[key] = list(value)
        return out


def _is_prime(n: int) -> bool:
    if n < 2:
        return False
    if n % 2 == 0:
        return n == 2
    k = 3
    while k * k <= n:
        if n % k == 0:
            return False
        k += 2
    return True


def prime_seed(seed: int, k: int) -> int:
    """The k-th (k >= 0) prime above ``10007 + 1000 * (seed mod 10**6)``.

    LIGGGHTS insertion and template fixes take large primes as seeds; this maps the
    configuration seed to distinct, reproducible primes.
    """
    if k < 0:
        raise ValueError(f"k must be >= 0, got {k}")
    n = 10007 + 1000 * (int(seed) % 1_000_000)
    found = -1
    while True:
        n += 1
        if _is_prime(n):
            found += 1
            if found == k:
                return n


def insertion_seeds(seed: int, n_classes: int) -> dict[str, int]:
    """Seeds of the insertion fix, the particle distribution and one template per size class.

    Parameters
    ----------
    seed : int
        Configuration seed.
    n_classes : int
        Size classes of the distribution.

    Returns
    -------
    dict of str to int
        ``insert``, ``distribution``, ``template1`` ... ``template<n_classes>``: distinct
        primes (:func:`prime_seed` 0, 1, 2, ...).
    """
    return {
        "insert": prime_seed(seed, 0),
        "distribution": prime_seed(seed, 1),
        **{f"template{i + 1}": prime_seed(seed, 2 + i) for i in range(n_classes)},
    }


def steps_for(duration: float, dt: float) -> int:
    """Whole number of steps (at least 1) covering ``duration`` (s) at time step ``dt`` (s)."""
    if not (duration > 0.0 and dt > 0.0):
        raise ValueError(f"duration and dt must be positive, got {duration}, {dt}")
    return max(1, math.ceil(duration / dt - 1e-9))
