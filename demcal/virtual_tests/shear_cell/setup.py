"""Derived quantities of the virtual Schulze shear test.

Everything a shear-cell deck needs is computed here from the case row (contact parameters,
``dCylDp``, ``normal_stress``) and the configuration sections ``particles``, ``material`` and
``shear_cell``; the template only formats the numbers. SI units throughout.

Geometry (PHYSICS.md section 4)
-------------------------------
A split cylinder of radius ``R = dCylDp * r_ref`` with ``r_ref`` the mass-weighted mean particle
radius (the "particle diameter" of dCylDp is its double). The floor is at ``z = 0``, the shear
plane at ``z_shear = shear_plane * fill_height * R``. The moving lower part is the floor, the
lower tube (``0 <= z <= z_shear``) and a horizontal flange at the shear plane reaching outwards;
the fixed upper ring is the upper tube and a flange at the same height. The flanges cover the
crescents that open between the two tubes when they are offset, so no particle leaves the cell
through the split. The lid is a disc of radius ``R`` on a force servo.

Ring geometry (``shear_cell.geometry: ring``)
---------------------------------------------
An annular cell between the radii ``R_i = R / ring_radius_ratio`` and ``R``, split
horizontally at ``z_shear`` instead of across the axis: the lower part (floor with
``n_bars`` radial bars of height ``bar_height * r_ref`` and both walls up to the shear plane)
rotates about the z axis, the upper bands of both walls and the lid (with the same bars
hanging down) are held. The shear plane keeps its area while the lower part turns, so no
crescent opens and no particle is pinched between a moving and a fixed edge. The speed and
the travel are those at the mean radius ``(R + R_i) / 2``. The core inside ``R_i`` is filled
like the rest and its particles are deleted right after the insertion, before the inner wall
joins the walls.

Filling: ``N = packing_fraction * pi R^2 (h_fill + overfill R) / v_p`` particles (``v_p`` the
number-weighted mean particle volume) are inserted at a lower volume fraction into a taller
cylinder, fall and settle; the bed is scraped level at ``h_fill`` (particles above are deleted,
as the real cell is overfilled and scraped), the lid is placed just above the bed and the servo
compresses it.

Schulze sequence
----------------
The phases and cycles are laid out by :mod:`demcal.virtual_tests.shear_cell.schedule`. The
lower part moves at v = ``shear_speed * r_ref`` per second (times :func:`shear_speed_factor`);
a pre-shear lasts ``preshear_travel * R / v`` and a shear ``shear_travel_ratio`` of that (the
authors' 0.1875 R and 19/20). A case row with a ``P`` column runs that single cycle (one deck
per load condition); otherwise all values of ``shear_cell.P`` follow each other in one deck.

The time step and the material come from :mod:`demcal.particles.material`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import Any

from demcal.core import config_values
from demcal.core.config_values import SetupError
from demcal.core.parameters import GRAVITY
from demcal.particles.material import MaterialSetup
from demcal.particles.run_setup import RunSetup, insertion_seeds, steps_for
from demcal.particles.size_distribution import SizeDistribution
from demcal.virtual_tests.shear_cell.schedule import (
    DeckSegment,
    ShearCycle,
    schulze_schedule,
)

__all__ = [
    "ShearCellSetup",
    "inertial_number",
    "shear_cell_setup",
    "shear_cell_youngs_modulus",
    "shear_speed_factor",
]

_get = config_values.required
_positive = config_values.positive_value
_non_negative = config_values.non_negative_value
_fraction = config_values.fraction_value


def shear_cell_youngs_modulus(
    case: Mapping[str, Any], material: Mapping[str, Any], cell: Mapping[str, Any]
) -> float:
    """Young's modulus of a shear-cell case, Pa.

    A case column youngsModulus wins; otherwise, when ``shear_cell.youngs_modulus_per_stress``
    (k) is positive, ``Y = min(k * normal_stress, shear_cell.youngs_modulus_max)``, so that the
    stiffness number ``(Y / sigma)^(2/3)``, which sets the contact overlaps relative to the
    particle size, is the same at every pre-shear stress up to the cap; otherwise
    ``material.youngsModulus``.
    """
    if "youngsModulus" in case:
        return float(case["youngsModulus"])
    ratio = float(_get(cell, "youngs_modulus_per_stress", "shear_cell"))
    if ratio > 0.0:
        cap = float(_get(cell, "youngs_modulus_max", "shear_cell"))
        return min(ratio * float(case["normal_stress"]), cap)
    return float(_get(material, "youngsModulus", "material"))


def shear_speed_factor(cell: Mapping[str, Any], normal_stress: float) -> float:
    """Factor on ``shear_cell.shear_speed`` at a pre-shear stress, -.

    With ``shear_cell.shear_speed_reference_stress`` (sigma_ref) positive the lower part moves
    ``sqrt(sigma / sigma_ref)`` times faster at a pre-shear stress sigma, which keeps the
    inertial number of the shear band (:func:`inertial_number`) that of sigma_ref at every
    stress; with ``youngs_modulus_per_stress`` the stiffness number is also the same, so the
    decks of different stresses differ only by gravity and all take the steps of sigma_ref.
    Otherwise 1.
    """
    reference = float(_get(cell, "shear_speed_reference_stress", "shear_cell"))
    if reference > 0.0:
        return math.sqrt(float(normal_stress) / reference)
    return 1.0


def inertial_number(
    shear_speed: float, band_width: float, pressure: float, density: float
) -> float:
    """Inertial number ``I = gamma_dot d / sqrt(p / rho_p)`` of a shear band.

    With the shear rate ``gamma_dot = v / w`` of a band of width ``w = band_width`` particle
    diameters, ``I = v / (w_in_diameters * sqrt(p / rho_p))`` (the diameter cancels).

    Parameters
    ----------
    shear_speed : float
        Speed of the moving part, m/s.
    band_width : float
        Shear-band width in particle diameters, -.
    pressure : float
        Normal stress, Pa.
    density : float
        Particle density, kg/m^3.
    """
    return shear_speed / (band_width * math.sqrt(pressure / density))


@dataclass(frozen=True, kw_only=True)
class ShearCellSetup(RunSetup):
    """Every derived number of one shear-cell deck (SI units); the run fields are those of
    :class:`~demcal.particles.run_setup.RunSetup`.

    Attributes
    ----------
    radius : float
        Cell radius R, m.
    reference_radius : float
        Mass-weighted mean particle radius r_ref, m (dCylDp = R / r_ref).
    dCylDp : float
        Cell diameter over the reference particle diameter, -.
    fill_height, z_shear, wall_top : float
        Nominal fill height, shear-plane height and top of the upper ring, m (floor at 0).
    flange_width : float
        Radial width of the flanges at the shear plane, m.
    cycle_mode : str
        "alternate", "return" or "continue" (see :func:`shear_cell_setup`).
    max_offset : float
        Largest misalignment of the lower part against the upper ring, m.
    n_segments : int
        Polygon sides of the meshed circles.
    n_particles : int
        Particles inserted (the cell is overfilled, see ``scrape_height``).
    scrape_height : float
        After settling, particles with centres above this height (the nominal fill height)
        are deleted, m.
    insertion_radius, insertion_zlo, insertion_zhi : float
        Insertion cylinder, m.
    lid_gap : float
        Lid start height above the highest particle centre, m (ring: plus the bar height).
    normal_stress : float
        Pre-shear normal stress, Pa.
    preshear_force : float
        Servo target force ``normal_stress * pi R^2``, N.
    lid_target_val : float
        The servo's initial ``target_val``, ``-preshear_force``, N.
    shear_speed : float
        Speed of the lower part during pre-shear and shear, m/s.
    servo_vel_max, servo_kp, servo_ki, servo_kd : float
        Servo parameters (m/s, -, -, -).
    fill_steps : int
        Steps of the free fall and settling before the lid is placed.
    segments : tuple of DeckSegment
        Every later ``run`` of the deck, in order (phase 0 compression onwards).
    cycles : tuple of ShearCycle
        One per value of P, in order.
    snapshot_step : int
        Step of the particle snapshot at the end of the first pre-shear.
    preshear_time, shear_time, unload_time : float
        Durations, s.
    inertial_number_min_stress : float
        Nominal inertial number of a shear band 10 particle diameters wide at the smallest
        shear normal stress, -. The quick ring shears across the 4 diameters between its bars,
        at about three times this in its interior (measured from a run's velocity profile by
        :mod:`demcal.bulk.shear_zone_check`).
    contact_dump_every : int
        Steps between contact snapshots (``shear_cell.contact_snapshots`` per pre-shear), 0 for
        none.
    geometry : str
        "split" (split cylinder) or "ring" (annular cell, see the module docstring).
    inner_radius : float
        Ring: radius R_i of the inner wall, m (0 for the split cell).
    core_radius : float
        Ring: particles with centres closer than this to the axis are deleted after the
        insertion, m.
    mean_radius : float
        Ring: (R + R_i) / 2, where speed and travel are taken, m.
    n_bars : int
        Ring: radial bars on the floor and under the lid.
    bar_height : float
        Ring: height of the bars, m.
    rotation : tuple of (float, int)
        Ring: per segment the period of the lower part's rotation (s, 0 at rest) and the sign
        of the rotation axis (+1 anticlockwise seen from above).
    bulk_density : str
        "cell" (rho_b of the whole cell) or "interior" (of the ring's interior region).
    interior_r_lo, interior_r_hi, interior_z_lo, interior_z_hi : float
        Interior region, an annulus between these radii and heights whose particle mass the
        deck prints when ``bulk_density`` is "interior" (all 0 otherwise), m.
    """

    radius: float
    reference_radius: float
    dCylDp: float
    fill_height: float
    z_shear: float
    wall_top: float
    flange_width: float
    cycle_mode: str
    max_offset: float
    n_segments: int
    n_particles: int
    scrape_height: float
    insertion_radius: float
    insertion_zlo: float
    insertion_zhi: float
    lid_gap: float
    normal_stress: float
    preshear_force: float
    lid_target_val: float
    shear_speed: float
    servo_vel_max: float
    servo_kp: float
    servo_ki: float
    servo_kd: float
    fill_steps: int
    segments: tuple[DeckSegment, ...]
    cycles: tuple[ShearCycle, ...]
    snapshot_step: int
    preshear_time: float
    shear_time: float
    unload_time: float
    inertial_number_min_stress: float
    contact_dump_every: int = 0
    geometry: str = "split"
    inner_radius: float = 0.0
    core_radius: float = 0.0
    mean_radius: float = 0.0
    n_bars: int = 0
    bar_height: float = 0.0
    rotation: tuple[tuple[float, int], ...] = ()
    bulk_density: str = "cell"
    interior_r_lo: float = 0.0
    interior_r_hi: float = 0.0
    interior_z_lo: float = 0.0
    interior_z_hi: float = 0.0

    @property
    def settle_steps(self) -> int:
        """Ring: steps of the settling after the one step that inserts the particles."""
        return self.fill_steps - 1

    @property
    def cross_section(self) -> float:
        """Cell cross-section pi (R^2 - R_i^2), m^2 (R_i = 0 for the split cell)."""
        return math.pi * (self.radius**2 - self.inner_radius**2)

    @property
    def interior_volume(self) -> float:
        """Volume of the interior region, m^3 (0 without one)."""
        return (
            math.pi
            * (self.interior_r_hi**2 - self.interior_r_lo**2)
            * (self.interior_z_hi - self.interior_z_lo)
        )

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON-ready dict (segments and cycles as lists of dicts)."""
        out = super().as_dict()
        out["cross_section"] = self.cross_section
        out["interior_volume"] = self.interior_volume
        for seg in out["segments"]:
            seg["ctrl"] = list(seg["ctrl"])
        return out


def _odd_at_most(steps: int) -> int:
    """The largest odd number of steps not above ``steps`` (>= 1): a lid oscillating at every
    time step then alternates between print rows, where an even interval would print it at one
    phase of the swing only, a constant offset that neither the readout nor its ringing flag
    could see."""
    return steps if steps % 2 else max(1, steps - 1)


def _p_values(values: Sequence[Any]) -> list[float]:
    ps = [float(p) for p in values]
    if not ps:
        raise SetupError("configuration: 'shear_cell.P' must hold at least one value")
    for p in ps:
        if not (math.isfinite(p) and 0.0 < p <= 1.0):
            raise SetupError(f"configuration: 'shear_cell.P' values must lie in (0, 1], got {p!r}")
    return ps


def shear_cell_setup(
    dCylDp: float,
    normal_stress: float,
    dist: SizeDistribution,
    material: MaterialSetup,
    cell: Mapping[str, Any],
    seed: int,
    skin_factor: float = 1.0,
) -> ShearCellSetup:
    """Derived quantities of one shear-cell case.

    Several cycles follow each other as ``shear_cell.cycles`` says ("alternate", "return" or
    "continue", see :func:`demcal.virtual_tests.shear_cell.schedule.schulze_schedule`).

    Parameters
    ----------
    dCylDp : float
        Cell diameter over the reference (mass-weighted mean) particle diameter, -.
    normal_stress : float
        Pre-shear normal stress, Pa.
    dist : SizeDistribution
        Particle sizes.
    material : MaterialSetup
        Material of the case (time step, density).
    cell : mapping
        Configuration section ``shear_cell``.
    seed : int
        Configuration seed (insertion randomness).
    skin_factor : float
        Neighbour skin in units of the smallest particle radius.

    Returns
    -------
    ShearCellSetup

    Raises
    ------
    SetupError
        A setting that cannot work (e.g. a servo speed above skin / (2 dt)); the message
        names the configuration key.
    """
    where = "shear_cell"
    if not (math.isfinite(normal_stress) and normal_stress > 0.0):
        raise SetupError(f"normal_stress must be a positive stress (Pa), got {normal_stress!r}")
    mode = _get(cell, "cycles", where)
    if mode not in ("alternate", "return", "continue"):
        raise SetupError(
            "configuration: 'shear_cell.cycles' must be 'alternate', 'return' or 'continue', "
            f"got {mode!r}"
        )
    geometry = _get(cell, "geometry", where)
    if geometry not in ("split", "ring"):
        raise SetupError(
            f"configuration: 'shear_cell.geometry' must be 'split' or 'ring', got {geometry!r}"
        )
    if mode == "continue" and geometry != "ring":
        # The lower part of a split cell would move one cycle's travel further per cycle.
        raise SetupError(
            "configuration: 'shear_cell.cycles: continue' needs 'shear_cell.geometry: ring' "
            "(a split cell cannot keep shearing in one direction)"
        )
    r_ref = dist.mass_mean_radius
    r_max = dist.max_radius
    radius = float(dCylDp) * r_ref
    is_ring = geometry == "ring"
    # The split cell has no inner wall and no bars: all ring lengths are zero.
    ring = _ring_geometry(cell, radius, r_ref, r_max) if is_ring else _NO_RING
    n_seg = int(_get(cell, "n_segments", where))
    if n_seg < 12:
        raise SetupError(f"configuration: 'shear_cell.n_segments' must be >= 12, got {n_seg}")
    fill_height = _positive(_get(cell, "fill_height", where), f"{where}.fill_height") * radius
    phi = _fraction(_get(cell, "packing_fraction", where), f"{where}.packing_fraction")
    phi_ins = _fraction(_get(cell, "insertion_fraction", where), f"{where}.insertion_fraction")
    shear_plane = _fraction(_get(cell, "shear_plane", where), f"{where}.shear_plane", high=0.9)

    overfill = _non_negative(_get(cell, "overfill", where), f"{where}.overfill") * radius
    # The cell is overfilled and scraped level at the fill height, as in the real test: a
    # poured bed has a conical top, which a flat lid would load on a few particles only.
    n_particles = round(
        phi * math.pi * radius**2 * (fill_height + overfill) / dist.mean_particle_volume
    )
    # Particle centres must stay inside the flat faces of the polygonal tube.
    flat = radius * math.cos(math.pi / n_seg)
    ins_radius = flat - 1.05 * r_max
    if ins_radius <= 2.0 * r_max:
        raise SetupError(
            f"dCylDp = {dCylDp:g} leaves no room to insert particles of radius {r_max:g} m"
        )
    solid = n_particles * dist.mean_particle_volume
    # Inserted particles clear the floor and, in the ring, its bars.
    ins_zlo = 1.05 * r_max + ring.bar_height
    ins_zhi = ins_zlo + solid / (phi_ins * math.pi * ins_radius**2)
    wall_top = ins_zhi + 2.0 * r_max
    if is_ring:
        # The lid starts above the scraped bed with its bars clear of the particles.
        wall_top = max(wall_top, fill_height + ring.bar_height + 3.05 * r_max)
    z_shear = shear_plane * fill_height
    if is_ring:
        clear = ring.bar_height + 2.0 * r_max
        if min(z_shear, fill_height - z_shear) < clear:
            raise SetupError(
                f"configuration: the bars ({ring.bar_height:.4g} m) reach within one particle "
                f"diameter of the shear plane at {z_shear:.4g} m in a bed {fill_height:.4g} m "
                f"high; raise '{where}.fill_height' or lower '{where}.bar_height'"
            )

    dt = material.timestep
    skin = skin_factor * dist.min_radius
    speed = (
        _positive(_get(cell, "shear_speed", where), f"{where}.shear_speed")
        * r_ref
        * shear_speed_factor(cell, normal_stress)
    )
    preshear_travel = _positive(_get(cell, "preshear_travel", where), f"{where}.preshear_travel")
    ratio = _positive(_get(cell, "shear_travel_ratio", where), f"{where}.shear_travel_ratio")
    t_psh = preshear_travel * radius / speed
    t_sh = ratio * t_psh
    t_unload = _positive(_get(cell, "unload_time", where), f"{where}.unload_time") * t_psh
    unload_fraction = _fraction(
        _get(cell, "unload_force_fraction", where), f"{where}.unload_force_fraction"
    )
    return_speed = _positive(_get(cell, "return_speed", where), f"{where}.return_speed") * speed

    vel_max = _positive(_get(cell, "servo_speed", where), f"{where}.servo_speed") * speed
    if vel_max >= skin / (2.0 * dt):
        raise SetupError(
            f"configuration: 'shear_cell.servo_speed' gives a lid speed of {vel_max:.4g} m/s, "
            f"not below skin / (2 dt) = {skin / (2.0 * dt):.4g} m/s (LIGGGHTS requirement)"
        )
    kp = float(_get(cell, "servo_kp", where))
    ki = float(_get(cell, "servo_ki", where))
    kd = float(_get(cell, "servo_kd", where))
    if min(kp, ki, kd) < 0.0 or kp + ki + kd <= 0.0:
        raise SetupError("configuration: servo_kp, servo_ki, servo_kd must be >= 0, not all 0")

    force = normal_stress * math.pi * (radius**2 - ring.inner_radius**2)
    p_values = _p_values(_get(cell, "P", where))

    # Free fall from the top of the insertion region, then settling.
    t_fall = math.sqrt(2.0 * ins_zhi / GRAVITY)
    fill_steps = steps_for(
        _positive(_get(cell, "settle_fall_times", where), f"{where}.settle_fall_times") * t_fall,
        dt,
    )
    compress_steps = steps_for(
        _positive(_get(cell, "compress_time", where), f"{where}.compress_time") * t_psh, dt
    )
    n_psh = steps_for(t_psh, dt)
    run_in = _non_negative(_get(cell, "run_in_travel", where), f"{where}.run_in_travel")
    n_run_in = steps_for(run_in * radius / speed, dt) if run_in > 0.0 else 0
    n_unload = steps_for(t_unload, dt)
    n_sh = steps_for(t_sh, dt)
    schedule = schulze_schedule(
        mode=mode,
        p_values=p_values,
        force=force,
        gains=(kp, ki, kd),
        start_step=fill_steps,
        compress_steps=compress_steps,
        preshear_steps=n_psh,
        run_in_steps=n_run_in,
        unload_steps=n_unload,
        shear_steps=n_sh,
        speed=speed,
        return_speed=return_speed,
        unload_fraction=unload_fraction,
        dt=dt,
    )
    cycles = schedule.cycles
    max_offset = schedule.max_offset
    margin = 4.0 * r_max
    if not is_ring:
        flange = max_offset + 4.0 * r_max
        half_x = radius + flange + max_offset + margin
        half_y = radius + flange + margin
        rotation: tuple[tuple[float, int], ...] = ()
    else:
        # The ring turns in place: no flange, no offset.
        flange = 0.0
        half_x = half_y = radius + margin
        rotation = tuple(
            (2.0 * math.pi * ring.mean_radius / abs(g.velocity), 1 if g.velocity > 0 else -1)
            if g.moving
            else (0.0, 0)
            for g in schedule.segments
        )
    box_lo = (-half_x, -half_y, -margin)
    box_hi = (half_x, half_y, wall_top + margin)

    samples = int(_get(cell, "samples_per_preshear", where))
    if samples < 20:
        raise SetupError(
            f"configuration: 'shear_cell.samples_per_preshear' must be >= 20, got {samples}"
        )
    snapshots = int(_get(cell, "contact_snapshots", where))
    if snapshots < 0:
        raise SetupError(
            f"configuration: 'shear_cell.contact_snapshots' must be >= 0, got {snapshots}"
        )
    smallest_stress = normal_stress * min(p_values)
    interior = _interior_region(cell, radius, fill_height, z_shear, r_ref, r_max, ring)
    return ShearCellSetup(
        radius=radius,
        reference_radius=r_ref,
        dCylDp=float(dCylDp),
        fill_height=fill_height,
        z_shear=z_shear,
        wall_top=wall_top,
        flange_width=flange,
        cycle_mode=mode,
        max_offset=max_offset,
        n_segments=n_seg,
        n_particles=int(n_particles),
        scrape_height=fill_height,
        insertion_radius=ins_radius,
        insertion_zlo=ins_zlo,
        insertion_zhi=ins_zhi,
        box_lo=box_lo,
        box_hi=box_hi,
        lid_gap=1.05 * r_max + ring.bar_height,
        normal_stress=float(normal_stress),
        preshear_force=force,
        lid_target_val=-force,
        shear_speed=speed,
        servo_vel_max=vel_max,
        servo_kp=kp,
        servo_ki=ki,
        servo_kd=kd,
        timestep=dt,
        skin=skin,
        fill_steps=fill_steps,
        segments=schedule.segments,
        cycles=cycles,
        print_every=_odd_at_most(max(1, n_psh // samples)),
        thermo_every=max(1, (schedule.end_step - fill_steps) // 50),
        snapshot_step=cycles[0].preshear_end_step,
        total_steps=schedule.end_step,
        preshear_time=t_psh,
        shear_time=t_sh,
        unload_time=t_unload,
        inertial_number_min_stress=inertial_number(speed, 10.0, smallest_stress, material.density),
        contact_dump_every=max(1, n_psh // snapshots) if snapshots else 0,
        seeds=insertion_seeds(seed, dist.n_classes),
        geometry=geometry,
        # The ring record's fields are the set-up's ring fields.
        **asdict(ring),
        rotation=rotation,
        **asdict(interior),
    )


@dataclass(frozen=True)
class _Ring:
    inner_radius: float
    core_radius: float
    mean_radius: float
    n_bars: int
    bar_height: float


_NO_RING = _Ring(inner_radius=0.0, core_radius=0.0, mean_radius=0.0, n_bars=0, bar_height=0.0)


@dataclass(frozen=True)
class _Interior:
    bulk_density: str
    interior_r_lo: float
    interior_r_hi: float
    interior_z_lo: float
    interior_z_hi: float


def _interior_region(
    cell: Mapping[str, Any],
    radius: float,
    fill_height: float,
    z_shear: float,
    r_ref: float,
    r_max: float,
    ring: _Ring,
) -> _Interior:
    """Where rho_b is measured: the whole cell, or the ring's interior (lengths in m).

    The interior annulus keeps ``interior_margin`` mean diameters from both walls, from the
    floor bars' tips and from the lid bars' tips, which hang from a lid that rests on the bed
    scraped at the fill height.
    """
    where = "shear_cell"
    mode = _get(cell, "bulk_density", where)
    if mode not in ("cell", "interior"):
        raise SetupError(
            f"configuration: '{where}.bulk_density' must be 'cell' or 'interior', got {mode!r}"
        )
    if mode == "cell":
        return _Interior("cell", 0.0, 0.0, 0.0, 0.0)
    if not ring.inner_radius:
        raise SetupError(
            f"configuration: '{where}.bulk_density: interior' needs '{where}.geometry: ring' "
            "(the split cell's bed moves against its walls)"
        )
    margin = (
        _positive(_get(cell, "interior_margin", where), f"{where}.interior_margin") * 2.0 * r_ref
    )
    region = _Interior(
        "interior",
        interior_r_lo=ring.inner_radius + margin,
        interior_r_hi=radius - margin,
        interior_z_lo=ring.bar_height + margin,
        interior_z_hi=fill_height - ring.bar_height - margin,
    )
    # The region must hold at least one largest particle across and up, and straddle the
    # shear plane, where the pre-shear takes place.
    width = region.interior_r_hi - region.interior_r_lo
    height = region.interior_z_hi - region.interior_z_lo
    if min(width, height) < 2.0 * r_max or not (
        region.interior_z_lo < z_shear < region.interior_z_hi
    ):
        raise SetupError(
            f"configuration: '{where}.interior_margin' leaves an interior region "
            f"{width:.4g} m wide and {height:.4g} m high (z {region.interior_z_lo:.4g} to "
            f"{region.interior_z_hi:.4g} m, shear plane at {z_shear:.4g} m): it must be at "
            f"least one largest particle diameter ({2.0 * r_max:.4g} m) each way and contain "
            "the shear plane; lower the margin or widen the ring"
        )
    return region


def _ring_geometry(cell: Mapping[str, Any], radius: float, r_ref: float, r_max: float) -> _Ring:
    """Radii and bars of the annular cell (lengths in m), checked against the particle size."""
    where = "shear_cell"
    ratio = float(_get(cell, "ring_radius_ratio", where))
    if not (math.isfinite(ratio) and ratio > 1.0):
        raise SetupError(
            f"configuration: '{where}.ring_radius_ratio' must be > 1 (outer over inner radius), "
            f"got {ratio!r}"
        )
    inner = radius / ratio
    if radius - inner < 6.0 * r_max:
        raise SetupError(
            f"configuration: the ring is {radius - inner:.4g} m wide, less than three largest "
            f"particle diameters ({6.0 * r_max:.4g} m); raise 'shear_cell.dCylDp' or lower "
            f"'{where}.ring_radius_ratio'"
        )
    n_bars = int(_get(cell, "n_bars", where))
    if n_bars < 0:
        raise SetupError(f"configuration: '{where}.n_bars' must be >= 0, got {n_bars}")
    bar_height = _non_negative(_get(cell, "bar_height", where), f"{where}.bar_height") * r_ref
    return _Ring(
        inner_radius=inner,
        # Vertices of the inner polygon lie on R_i: a centre this far out cannot touch it.
        core_radius=inner + 1.05 * r_max,
        mean_radius=0.5 * (radius + inner),
        n_bars=n_bars,
        bar_height=bar_height,
    )
