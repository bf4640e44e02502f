"""Derived quantities of the virtual Schulze shear test, and the particle and material set-up
that both virtual tests share.

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

Filling: ``N = packing_fraction * pi R^2 (h_fill + overfill R) / v_p`` particles (``v_p`` the
number-weighted mean particle volume) are inserted at a lower volume fraction into a taller
cylinder, fall and settle; the bed is scraped level at ``h_fill`` (particles above are deleted,
as the real cell is overfilled and scraped), the lid is placed just above the bed and the servo
compresses it.

Schulze sequence
----------------
Phase 0: settle, scrape, compress with the servo lid to the pre-shear load. Then one cycle per
value of P: pre-shear at the full load (phase 1), unload the lid to ``unload_force_fraction`` of
that load with the lower part at rest (phase 2), shear at ``P`` times the pre-shear load
(phase 3). The lower part moves at ``shear_speed * r_ref`` per second; a pre-shear lasts
``preshear_travel * R / v`` and a shear ``shear_travel_ratio`` of that (the authors' 0.1875 R and
19/20). A case row with a ``P`` column runs that single cycle (one deck per load condition);
otherwise all values of ``shear_cell.P`` follow each other in one deck, in one of two ways
(``shear_cell.cycles``, see :func:`shear_cell_setup`): "return" (every cycle starts at zero
offset; in between the lower part returns with the lid unloaded and the sample is compressed
again) or "alternate" (the direction alternates, the offset swings between +h and -h).

Time step
---------
``dt = rayleigh_fraction * t_R`` with the Rayleigh time of the smallest particle
``t_R = pi r sqrt(rho / G) / (0.1631 nu + 0.8766)``, ``G = Y / (2 (1 + nu))``, rounded down to
three significant digits (so the deck holds exactly the value used here), unless a fixed
``material.timestep`` is given.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

from demcal.core import config_values
from demcal.core.config_values import SetupError
from demcal.particles.size_distribution import SizeDistribution, monodisperse, sinter_fines

__all__ = [
    "GRAVITY",
    "MaterialSetup",
    "SetupError",
    "ShearCellSetup",
    "ShearCycle",
    "inertial_number",
    "material_setup",
    "prime_seed",
    "rayleigh_time",
    "round_down_sig",
    "shear_cell_setup",
    "shear_cell_youngs_modulus",
    "size_distribution",
    "steps_for",
    "time_step",
]

#: Gravitational acceleration, m/s^2.
GRAVITY = 9.81


# ----------------------------------------------------------------------------------------------
# shared helpers: particles, material, time step, seeds

_get = config_values.required
_positive = config_values.positive_value
_fraction = config_values.fraction_value


def size_distribution(particles: Mapping[str, Any]) -> SizeDistribution:
    """Particle size distribution of the ``particles`` configuration section.

    Parameters
    ----------
    particles : mapping
        ``distribution`` ("monodisperse" or "sinter_fines"), ``radius`` (m, monodisperse),
        ``scale`` (-, factor on the sinter-fines radii) and ``classes`` (number of the largest
        sieve classes kept, 1-6).

    Returns
    -------
    SizeDistribution
        Radii (m) and mass fractions.
    """
    kind = _get(particles, "distribution", "particles")
    if kind == "monodisperse":
        return monodisperse(_positive(_get(particles, "radius", "particles"), "particles.radius"))
    if kind == "sinter_fines":
        scale = _positive(_get(particles, "scale", "particles"), "particles.scale")
        classes = int(_get(particles, "classes", "particles"))
        if not 1 <= classes <= 6:
            raise SetupError(f"configuration: 'particles.classes' must be in 1..6, got {classes}")
        return sinter_fines(scale=scale, n_largest=classes)
    raise SetupError(
        f"configuration: 'particles.distribution' must be 'monodisperse' or 'sinter_fines', "
        f"got {kind!r}"
    )


def rayleigh_time(radius: float, density: float, youngs_modulus: float, poisson: float) -> float:
    """Rayleigh time ``pi r sqrt(rho / G) / (0.1631 nu + 0.8766)``, s.

    Parameters
    ----------
    radius : float
        Particle radius, m.
    density : float
        Particle density, kg/m^3.
    youngs_modulus : float
        Young's modulus, Pa.
    poisson : float
        Poisson's ratio, -.
    """
    shear_modulus = youngs_modulus / (2.0 * (1.0 + poisson))
    return math.pi * radius * math.sqrt(density / shear_modulus) / (0.1631 * poisson + 0.8766)


def round_down_sig(x: float, digits: int = 3) -> float:
    """``x > 0`` rounded down to ``digits`` significant digits (exactly representable text)."""
    if not (math.isfinite(x) and x > 0.0):
        raise ValueError(f"round_down_sig needs a positive finite number, got {x}")
    exponent = math.floor(math.log10(x)) - digits + 1
    mantissa = math.floor(x / 10.0**exponent * (1.0 + 1e-12))
    # Through the decimal text, so that repr() of the result is short and exact.
    return float(f"{mantissa}e{exponent}")


@dataclass(frozen=True)
class MaterialSetup:
    """Material constants and contact-model switches of one case.

    Attributes
    ----------
    youngs_modulus : float
        Young's modulus of particles and walls, Pa.
    poissons_ratio : float
        Poisson's ratio, -.
    soft_particles : bool
        Deck needs ``soft_particles yes`` (Young's modulus below 5e6 Pa).
    rolling_friction : bool
        ``rolling_friction epsd2`` in the contact model.
    cohesion : bool
        ``cohesion sjkr`` (the case has cohesionEnergyDensity > 0).
    friction, rolling_friction_coefficient, restitution, cohesion_energy_density : float
        Particle-particle values (-, -, -, J/m^3).
    wall_friction : float
        Particle-wall sliding friction (case column wallFriction, else the particle value), -.
    density : float
        Particle density, kg/m^3.
    timestep : float
        Time step, s.
    rayleigh_time : float
        Rayleigh time of the smallest particle, s.
    """

    youngs_modulus: float
    poissons_ratio: float
    soft_particles: bool
    rolling_friction: bool
    cohesion: bool
    friction: float
    rolling_friction_coefficient: float
    restitution: float
    cohesion_energy_density: float
    wall_friction: float
    density: float
    timestep: float
    rayleigh_time: float

    def pair_matrix(self, particle: float, wall: float) -> list[float]:
        """Row-major 2x2 type-pair matrix (type 1 particles, type 2 walls), shape (4,)."""
        return [particle, wall, wall, wall]


def time_step(
    dist: SizeDistribution,
    density: float,
    youngs_modulus: float,
    poissons_ratio: float,
    fixed: float,
    rayleigh_fraction: float,
) -> float:
    """Time step of a case, s.

    Parameters
    ----------
    dist : SizeDistribution
        Particle sizes; the smallest radius sets the Rayleigh time.
    density : float
        Particle density, kg/m^3.
    youngs_modulus, poissons_ratio : float
        Pa, -.
    fixed : float
        A fixed time step (s), or 0 to derive it from the Rayleigh time.
    rayleigh_fraction : float
        Fraction of the Rayleigh time used when ``fixed`` is 0.

    Returns
    -------
    float
        ``fixed`` or ``rayleigh_fraction * t_R`` rounded down to three significant digits.
    """
    if fixed > 0.0:
        return float(fixed)
    t_r = rayleigh_time(dist.min_radius, density, youngs_modulus, poissons_ratio)
    return round_down_sig(rayleigh_fraction * t_r)


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


def material_setup(
    case: Mapping[str, Any],
    material: Mapping[str, Any],
    dist: SizeDistribution,
    youngs_modulus: float | None = None,
) -> MaterialSetup:
    """Material constants of a case: contact parameters from the case row, the rest from the
    ``material`` configuration section (a case column youngsModulus / poissonsRatio overrides
    the configuration).

    Parameters
    ----------
    case : mapping
        Design row with coefficientFriction, coefficientRollingFriction,
        coefficientRestitution, density and optionally cohesionEnergyDensity, wallFriction,
        youngsModulus, poissonsRatio.
    material : mapping
        Configuration section ``material``.
    dist : SizeDistribution
        Particle sizes (for the time step).
    youngs_modulus : float, optional
        Young's modulus to use (Pa), e.g. from :func:`shear_cell_youngs_modulus`.
    """
    if youngs_modulus is None:
        youngs_modulus = case.get("youngsModulus", _get(material, "youngsModulus", "material"))
    youngs = float(youngs_modulus)
    poisson = float(case.get("poissonsRatio", _get(material, "poissonsRatio", "material")))
    density = float(case["density"])
    friction = float(case["coefficientFriction"])
    cohesion = float(case.get("cohesionEnergyDensity", 0.0))
    wall_friction = case.get("wallFriction", friction)
    if wall_friction is None or (isinstance(wall_friction, float) and math.isnan(wall_friction)):
        wall_friction = friction
    fixed = float(_get(material, "timestep", "material"))
    fraction = _positive(
        _get(material, "rayleigh_fraction", "material"), "material.rayleigh_fraction"
    )
    return MaterialSetup(
        youngs_modulus=youngs,
        poissons_ratio=poisson,
        soft_particles=bool(_get(material, "soft_particles", "material")),
        rolling_friction=bool(_get(material, "rolling_friction", "material")),
        cohesion=cohesion > 0.0,
        friction=friction,
        rolling_friction_coefficient=float(case["coefficientRollingFriction"]),
        restitution=float(case["coefficientRestitution"]),
        cohesion_energy_density=cohesion,
        wall_friction=float(wall_friction),
        density=density,
        timestep=time_step(dist, density, youngs, poisson, fixed, fraction),
        rayleigh_time=rayleigh_time(dist.min_radius, density, youngs, poisson),
    )


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


def steps_for(duration: float, dt: float) -> int:
    """Whole number of steps (at least 1) covering ``duration`` (s) at time step ``dt`` (s)."""
    if not (duration > 0.0 and dt > 0.0):
        raise ValueError(f"duration and dt must be positive, got {duration}, {dt}")
    return max(1, math.ceil(duration / dt - 1e-9))


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


# ----------------------------------------------------------------------------------------------
# shear cell


@dataclass(frozen=True)
class DeckSegment:
    """One ``run`` of the shear-cell deck with constant settings.

    Attributes
    ----------
    label : str
        What the segment does (written as a comment into the deck).
    phase, cycle : int
        Values of the print columns ``phase`` and ``cycle``.
    target_force : float
        Lid force the servo holds, N (positive).
    target_val : float
        The servo's ``target_val``, ``-target_force`` (the lid pushes towards -z), N.
    ctrl : tuple of float
        Servo gains (kp, ki, kd): the configured gains times ``target_force`` over the
        pre-shear force. LIGGGHTS divides the force error by the target, so this keeps the lid's
        response to a given force error the same in every segment (a tiny unload target would
        otherwise make the lid chatter at full speed).
    moving : bool
        Whether the lower part moves.
    velocity : float
        x velocity of the lower part, m/s (0 at rest).
    travel_per_step : float
        x displacement of the lower part per step, m.
    offset_start : float
        x offset of the lower part against the upper ring at the first step, m.
    start_step, steps : int
        First step and number of steps.
    snapshot : bool
        Write the particle snapshot (VTK) at the end of the segment.
    """

    label: str
    phase: int
    cycle: int
    target_force: float
    target_val: float
    ctrl: tuple[float, float, float]
    moving: bool
    velocity: float
    travel_per_step: float
    offset_start: float
    start_step: int
    steps: int
    snapshot: bool = False

    @property
    def end_step(self) -> int:
        """Last step of the segment."""
        return self.start_step + self.steps

    @property
    def offset_end(self) -> float:
        """x offset of the lower part at the last step, m."""
        return self.offset_start + self.steps * self.travel_per_step


@dataclass(frozen=True)
class ShearCycle:
    """One pre-shear / unload / shear cycle (the readout's view of the deck).

    Attributes
    ----------
    index : int
        Cycle number (0, 1, ...).
    P : float
        Shear load as a fraction of the pre-shear load, -.
    direction : int
        -1 (lower part moves towards -x) or +1.
    preshear_force, shear_force : float
        Servo target lid forces of pre-shear and shear, N.
    preshear_start_step, preshear_end_step, shear_start_step, shear_end_step : int
        First and last steps of the pre-shear and the shear phase.
    offset_preshear_start, offset_shear_end : float
        x offset of the lower part at the start of the pre-shear and at the end of the shear, m.
    """

    index: int
    P: float
    direction: int
    preshear_force: float
    shear_force: float
    preshear_start_step: int
    preshear_end_step: int
    shear_start_step: int
    shear_end_step: int
    offset_preshear_start: float
    offset_shear_end: float


@dataclass(frozen=True)
class ShearCellSetup:
    """Every derived number of one shear-cell deck (SI units).

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
        "alternate" or "return" (see :func:`shear_cell_setup`).
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
    box_lo, box_hi : tuple of float
        Simulation box corners, m.
    lid_gap : float
        Lid start height above the highest particle centre, m.
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
    timestep, skin : float
        s, m.
    fill_steps : int
        Steps of the free fall and settling before the lid is placed.
    segments : tuple of DeckSegment
        Every later ``run`` of the deck, in order (phase 0 compression onwards).
    cycles : tuple of ShearCycle
        One per value of P, in order.
    print_every, thermo_every : int
        Steps between rows of the print file and of the thermo output.
    snapshot_step : int
        Step of the particle snapshot at the end of the first pre-shear.
    total_steps : int
        Steps of the whole run.
    preshear_time, shear_time, unload_time : float
        Durations, s.
    inertial_number_min_stress : float
        Inertial number of the shear band (10 particle diameters wide) at the smallest shear
        normal stress, -.
    seeds : dict of str to int
        Prime seeds of the insertion and template fixes.
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
    box_lo: tuple[float, float, float]
    box_hi: tuple[float, float, float]
    lid_gap: float
    normal_stress: float
    preshear_force: float
    lid_target_val: float
    shear_speed: float
    servo_vel_max: float
    servo_kp: float
    servo_ki: float
    servo_kd: float
    timestep: float
    skin: float
    fill_steps: int
    segments: tuple[DeckSegment, ...]
    cycles: tuple[ShearCycle, ...]
    print_every: int
    thermo_every: int
    snapshot_step: int
    total_steps: int
    preshear_time: float
    shear_time: float
    unload_time: float
    inertial_number_min_stress: float
    seeds: dict[str, int] = field(default_factory=dict)

    @property
    def cross_section(self) -> float:
        """Cell cross-section pi R^2, m^2."""
        return math.pi * self.radius**2

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON-ready dict (segments and cycles as lists of dicts)."""
        out = asdict(self)
        out["box_lo"] = list(self.box_lo)
        out["box_hi"] = list(self.box_hi)
        out["cross_section"] = self.cross_section
        for seg in out["segments"]:
            seg["ctrl"] = list(seg["ctrl"])
        return out


def _p_values(values: Sequence[Any]) -> list[float]:
    ps = [float(p) for p in values]
    if not ps:
        raise SetupError("configuration: 'shear_cell.P' must hold at least one value")
    for p in ps:
        if not (math.isfinite(p) and 0.0 < p <= 1.0):
            raise SetupError(f"configuration: 'shear_cell.P' values must lie in (0, 1], got {p!r}")
    return ps


class _Timeline:
    """Appends deck segments one after the other, tracking step and offset."""

    def __init__(self, start_step: int, force: float, gains: tuple[float, float, float]):
        self.step = start_step
        self.offset = 0.0
        self.force = force
        self.gains = gains
        self.segments: list[DeckSegment] = []

    def add(
        self,
        label: str,
        phase: int,
        cycle: int,
        target: float,
        steps: int,
        velocity: float = 0.0,
        dt: float = 0.0,
        snapshot: bool = False,
    ) -> DeckSegment:
        factor = target / self.force
        seg = DeckSegment(
            label=label,
            phase=phase,
            cycle=cycle,
            target_force=target,
            target_val=-target,
            ctrl=(self.gains[0] * factor, self.gains[1] * factor, self.gains[2] * factor),
            moving=velocity != 0.0,
            velocity=velocity,
            travel_per_step=velocity * dt,
            offset_start=self.offset,
            start_step=self.step,
            steps=steps,
            snapshot=snapshot,
        )
        self.segments.append(seg)
        self.step = seg.end_step
        self.offset = seg.offset_end
        return seg


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

    Two ways of running several cycles (``shear_cell.cycles``):

    * ``"alternate"``: after the compression the lower part moves under load to ``+h``, half
      the travel of one cycle; cycle k then moves towards -x for even k and +x for odd k, so the
      offset swings between ``+h`` and ``-h``, every cycle starts after a reversal and sweeps
      the same, mirrored geometry.
    * ``"return"``: every cycle moves towards -x from zero offset; between cycles the lid is
      unloaded to ``unload_force_fraction`` of the pre-shear force, the lower part returns to
      zero offset at ``return_speed`` times the shear speed, and the lid compresses the sample
      again (phase 0 of the next cycle). Every cycle then starts like a fresh test.

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
    if mode not in ("alternate", "return"):
        raise SetupError(
            f"configuration: 'shear_cell.cycles' must be 'alternate' or 'return', got {mode!r}"
        )
    r_ref = dist.mass_mean_radius
    r_max = dist.max_radius
    radius = float(dCylDp) * r_ref
    n_seg = int(_get(cell, "n_segments", where))
    if n_seg < 12:
        raise SetupError(f"configuration: 'shear_cell.n_segments' must be >= 12, got {n_seg}")
    fill_height = _positive(_get(cell, "fill_height", where), f"{where}.fill_height") * radius
    phi = _fraction(_get(cell, "packing_fraction", where), f"{where}.packing_fraction")
    phi_ins = _fraction(_get(cell, "insertion_fraction", where), f"{where}.insertion_fraction")
    shear_plane = _fraction(_get(cell, "shear_plane", where), f"{where}.shear_plane", high=0.9)

    overfill = float(_get(cell, "overfill", where)) * radius
    if not (math.isfinite(overfill) and overfill >= 0.0):
        raise SetupError(f"configuration: '{where}.overfill' must be >= 0, got {overfill!r}")
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
    ins_zlo = 1.05 * r_max
    ins_zhi = ins_zlo + solid / (phi_ins * math.pi * ins_radius**2)
    wall_top = ins_zhi + 2.0 * r_max
    z_shear = shear_plane * fill_height

    dt = material.timestep
    skin = skin_factor * dist.min_radius
    speed = _positive(_get(cell, "shear_speed", where), f"{where}.shear_speed") * r_ref
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

    force = normal_stress * math.pi * radius**2
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
    n_unload = steps_for(t_unload, dt)
    n_sh = steps_for(t_sh, dt)
    n_cycle_travel = n_psh + n_sh

    line = _Timeline(fill_steps, force, (kp, ki, kd))
    line.add("phase 0: compress to the pre-shear load", 0, 0, force, compress_steps)
    if mode == "alternate":
        n_pos = max(1, n_cycle_travel // 2)
        line.add("phase 0: move the lower part to +h under load", 0, 0, force, n_pos, speed, dt)
    cycles = []
    for k, p in enumerate(p_values):
        direction = -1 if (mode == "return" or k % 2 == 0) else 1
        towards = "-x" if direction < 0 else "+x"
        if mode == "return" and k > 0:
            line.add(f"cycle {k}: unload", 0, k, unload_fraction * force, n_unload)
            back = (n_cycle_travel * speed * dt) / return_speed
            n_back = steps_for(back, dt)
            # Exactly back to zero offset in whole steps.
            v_back = -line.offset / (n_back * dt)
            line.add(
                f"cycle {k}: return to zero offset",
                0,
                k,
                unload_fraction * force,
                n_back,
                v_back,
                dt,
            )
            line.add(f"cycle {k}: compress to the pre-shear load", 0, k, force, compress_steps)
        pre = line.add(
            f"cycle {k}: pre-shear (P = {p:g}), lower part towards {towards}",
            1,
            k,
            force,
            n_psh,
            direction * speed,
            dt,
            snapshot=k == 0,
        )
        line.add(f"cycle {k}: unload", 2, k, unload_fraction * force, n_unload)
        sh = line.add(
            f"cycle {k}: shear at P = {p:g}", 3, k, p * force, n_sh, direction * speed, dt
        )
        cycles.append(
            ShearCycle(
                index=k,
                P=p,
                direction=direction,
                preshear_force=force,
                shear_force=p * force,
                preshear_start_step=pre.start_step,
                preshear_end_step=pre.end_step,
                shear_start_step=sh.start_step,
                shear_end_step=sh.end_step,
                offset_preshear_start=pre.offset_start,
                offset_shear_end=sh.offset_end,
            )
        )

    max_offset = max(max(abs(seg.offset_start), abs(seg.offset_end)) for seg in line.segments)
    flange = max_offset + 4.0 * r_max
    margin = 4.0 * r_max
    half_x = radius + flange + max_offset + margin
    half_y = radius + flange + margin
    box_lo = (-half_x, -half_y, -margin)
    box_hi = (half_x, half_y, wall_top + margin)

    samples = int(_get(cell, "samples_per_preshear", where))
    if samples < 20:
        raise SetupError(
            f"configuration: 'shear_cell.samples_per_preshear' must be >= 20, got {samples}"
        )
    smallest_stress = normal_stress * min(p_values)
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
        lid_gap=1.05 * r_max,
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
        segments=tuple(line.segments),
        cycles=tuple(cycles),
        print_every=max(1, n_psh // samples),
        thermo_every=max(1, (line.step - fill_steps) // 50),
        snapshot_step=cycles[0].preshear_end_step,
        total_steps=line.step,
        preshear_time=t_psh,
        shear_time=t_sh,
        unload_time=t_unload,
        inertial_number_min_stress=inertial_number(speed, 10.0, smallest_stress, material.density),
        seeds={
            "insert": prime_seed(seed, 0),
            "distribution": prime_seed(seed, 1),
            **{f"template{i + 1}": prime_seed(seed, 2 + i) for i in range(dist.n_classes)},
        },
    )
