"""Material constants, contact-model switches and the time step of one DEM case.

Shared by every deck (virtual bulk tests and the application). The contact parameters come from
the case row, the rest from the ``material`` configuration section; a case column youngsModulus
or poissonsRatio overrides the configuration. SI units throughout.

Time step
---------
``dt = rayleigh_fraction * t_R`` with the Rayleigh time of the smallest particle
``t_R = pi r sqrt(rho / G) / (0.1631 nu + 0.8766)``, ``G = Y / (2 (1 + nu))``, rounded down to
three significant digits (so the deck holds exactly the value used here), unless a fixed
``material.timestep`` is given.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from demcal.core import config_values
from demcal.particles.size_distribution import SizeDistribution

__all__ = [
    "MaterialSetup",
    "material_record",
    "material_setup",
    "rayleigh_time",
    "round_down_sig",
    "time_step",
]

_get = config_values.required


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
        Young's modulus to use (Pa), e.g. a stress-scaled one of the shear cell.
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
    fraction = config_values.positive_value(
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


def material_record(mat: MaterialSetup, cohesion: bool = True) -> dict[str, Any]:
    """The material of a case as written to ``case.json`` (LIGGGHTS names for the values).

    Parameters
    ----------
    mat : MaterialSetup
        The material of the case.
    cohesion : bool
        Include the cohesion switch and cohesionEnergyDensity (decks without cohesion omit
        them).
    """
    record: dict[str, Any] = {
        "youngsModulus": mat.youngs_modulus,
        "poissonsRatio": mat.poissons_ratio,
        "soft_particles": mat.soft_particles,
        "rolling_friction": mat.rolling_friction,
        "coefficientFriction": mat.friction,
        "wallFriction": mat.wall_friction,
        "coefficientRollingFriction": mat.rolling_friction_coefficient,
        "coefficientRestitution": mat.restitution,
        "density": mat.density,
        "timestep": mat.timestep,
        "rayleigh_time": mat.rayleigh_time,
    }
    if cohesion:
        record["cohesion"] = mat.cohesion
        record["cohesionEnergyDensity"] = mat.cohesion_energy_density
    return record
