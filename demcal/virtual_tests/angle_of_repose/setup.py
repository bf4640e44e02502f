"""Derived quantities of the virtual static angle-of-repose test (lifted cylinder).

A tube of diameter ``D = dCylDp * d_max`` (``d_max`` the largest particle diameter,
PHYSICS.md section 5) stands on a circular base plate of radius ``plate_radius * D / 2`` at
``z = 0``. It is filled with ``N = packing_fraction * pi (D/2)^2 * fill_height * D/2 / v_p``
particles (``v_p`` the number-weighted mean particle volume), inserted at a lower volume fraction
into a taller cylinder; they fall and settle. The tube is then lifted at constant speed by
``lift_height * D`` in ``lift_time``, and the heap settles for ``final_settle_fall_times`` free-fall
times of the fill height. Particles that roll off the plate fall through the bottom of the
simulation box and are deleted there (``thermo_modify lost ignore``). SI units throughout.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from functools import partial
from typing import Any

from demcal.core import config_values
from demcal.core.config_values import SetupError
from demcal.core.parameters import GRAVITY
from demcal.particles.material import MaterialSetup
from demcal.particles.run_setup import RunSetup, insertion_seeds, steps_for
from demcal.particles.size_distribution import SizeDistribution

__all__ = ["ReposeSetup", "lift_froude_number", "repose_setup"]

# Configuration access with errors naming angle_of_repose.<key>.
_get = partial(config_values.required, where="angle_of_repose")
_positive = partial(config_values.positive, where="angle_of_repose")
_fraction = partial(config_values.fraction, where="angle_of_repose")
_count = partial(config_values.count, where="angle_of_repose")


@dataclass(frozen=True, kw_only=True)
class ReposeSetup(RunSetup):
    """Every derived number of one angle-of-repose deck (SI units); the run fields are those of
    :class:`~demcal.particles.run_setup.RunSetup`.

    Attributes
    ----------
    radius : float
        Tube radius D/2, m.
    dCylDp : float
        Tube diameter over the largest particle diameter, -.
    fill_height : float
        Nominal fill height, m.
    tube_height : float
        Height of the tube, m (bottom at the plate, z = 0).
    plate_radius : float
        Base plate radius, m.
    n_segments : int
        Polygon sides of the meshed circles.
    n_particles : int
        Particles inserted.
    insertion_radius, insertion_zlo, insertion_zhi : float
        Insertion cylinder, m.
    lift_distance, lift_speed : float
        m, m/s.
    fill_steps, lift_steps, settle_steps : int
        Steps of filling/settling, lifting and the final settling.
    lift_froude : float
        ``v_lift / sqrt(g d_mean)`` with the mass-weighted mean diameter, -.
    n_slices, n_sectors, min_contacts : int
        Readout settings (slice / convex-hull method).
    """

    radius: float
    dCylDp: float
    fill_height: float
    tube_height: float
    plate_radius: float
    n_segments: int
    n_particles: int
    insertion_radius: float
    insertion_zlo: float
    insertion_zhi: float
    lift_distance: float
    lift_speed: float
    fill_steps: int
    lift_steps: int
    settle_steps: int
    lift_froude: float
    n_slices: int
    n_sectors: int
    min_contacts: int


def lift_froude_number(lift_speed: float, diameter: float) -> float:
    """Froude number ``v / sqrt(g d)`` of the lift (speed m/s, particle diameter m), -."""
    return lift_speed / math.sqrt(GRAVITY * diameter)


def repose_setup(
    dCylDp: float,
    dist: SizeDistribution,
    material: MaterialSetup,
    aor: Mapping[str, Any],
    seed: int,
    skin_factor: float = 1.0,
) -> ReposeSetup:
    """Derived quantities of one angle-of-repose case.

    Parameters
    ----------
    dCylDp : float
        Tube diameter over the largest particle diameter, -.
    dist : SizeDistribution
        Particle sizes.
    material : MaterialSetup
        Material of the case (time step).
    aor : mapping
        Configuration section ``angle_of_repose``.
    seed : int
        Configuration seed (insertion randomness).
    skin_factor : float
        Neighbour skin in units of the smallest particle radius.

    Returns
    -------
    ReposeSetup

    Raises
    ------
    SetupError
        A setting that cannot work; the message names the configuration key.
    """
    r_max = dist.max_radius
    radius = float(dCylDp) * r_max
    n_seg = _count(aor, "n_segments", 12)
    fill_height = _positive(aor, "fill_height") * radius
    phi = _fraction(aor, "packing_fraction")
    phi_ins = _fraction(aor, "insertion_fraction")
    plate_radius = _positive(aor, "plate_radius") * radius
    if plate_radius <= radius:
        raise SetupError("configuration: 'angle_of_repose.plate_radius' must be > 1 (tube radii)")

    n_particles = round(phi * math.pi * radius**2 * fill_height / dist.mean_particle_volume)
    flat = radius * math.cos(math.pi / n_seg)
    ins_radius = flat - 1.05 * r_max
    if ins_radius <= 2.0 * r_max:
        raise SetupError(
            f"dCylDp = {dCylDp:g} leaves no room to insert particles of radius {r_max:g} m"
        )
    solid = n_particles * dist.mean_particle_volume
    ins_zlo = 1.05 * r_max
    ins_zhi = ins_zlo + solid / (phi_ins * math.pi * ins_radius**2)
    tube_height = ins_zhi + 2.0 * r_max

    dt = material.timestep
    lift_distance = _positive(aor, "lift_height") * 2.0 * radius
    lift_time = _positive(aor, "lift_time")
    lift_speed = lift_distance / lift_time
    t_fall_fill = math.sqrt(2.0 * ins_zhi / GRAVITY)
    t_fall_heap = math.sqrt(2.0 * fill_height / GRAVITY)
    fill_steps = steps_for(_positive(aor, "settle_fall_times") * t_fall_fill, dt)
    lift_steps = steps_for(lift_time, dt)
    settle_steps = steps_for(_positive(aor, "final_settle_fall_times") * t_fall_heap, dt)
    total = fill_steps + lift_steps + settle_steps

    margin = 4.0 * r_max
    half = plate_radius + margin
    box_lo = (-half, -half, -margin)
    box_hi = (half, half, tube_height + lift_distance + margin)
    samples = _count(aor, "print_samples", 20)
    return ReposeSetup(
        radius=radius,
        dCylDp=float(dCylDp),
        fill_height=fill_height,
        tube_height=tube_height,
        plate_radius=plate_radius,
        n_segments=n_seg,
        n_particles=int(n_particles),
        insertion_radius=ins_radius,
        insertion_zlo=ins_zlo,
        insertion_zhi=ins_zhi,
        box_lo=box_lo,
        box_hi=box_hi,
        lift_distance=lift_distance,
        lift_speed=lift_speed,
        timestep=dt,
        skin=skin_factor * dist.min_radius,
        fill_steps=fill_steps,
        lift_steps=lift_steps,
        settle_steps=settle_steps,
        print_every=max(1, total // samples),
        thermo_every=max(1, total // 50),
        total_steps=total,
        lift_froude=lift_froude_number(lift_speed, 2.0 * dist.mass_mean_radius),
        n_slices=_count(aor, "n_slices", 4),
        n_sectors=_count(aor, "n_sectors", 1),
        min_contacts=_count(aor, "min_contacts", 0),
        seeds=insertion_seeds(seed, dist.n_classes),
    )
