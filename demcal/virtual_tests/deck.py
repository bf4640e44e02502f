"""The case directory of one virtual bulk-test run: deck, STL meshes and ``case.json``.

Every number comes from :mod:`demcal.virtual_tests.shear_cell.setup` or
:mod:`demcal.virtual_tests.angle_of_repose.setup`; the case is validated first
(:mod:`demcal.decks.case_validation`) and nothing is written for an invalid one. The deck is
rendered and written by :mod:`demcal.decks.render` (byte-stable). The engine runs in the case
directory: ``cd OUT_DIR && dem_engine -in in.shear_cell``.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from demcal.core.parameters import CONTACT_PARAMETERS, GRAVITY, TESTS
from demcal.decks.case_validation import ValidationRules, validate_case
from demcal.decks.mesh_primitives import annulus, cylinder_shell, disc, quad
from demcal.decks.render import render_deck, write_case_directory
from demcal.decks.triangle_surface import merge
from demcal.particles.material import MaterialSetup, material_record, material_setup
from demcal.particles.size_distribution import SizeDistribution, size_distribution
from demcal.virtual_tests.angle_of_repose.setup import ReposeSetup, repose_setup
from demcal.virtual_tests.shear_cell.setup import (
    ShearCellSetup,
    shear_cell_setup,
    shear_cell_youngs_modulus,
)

__all__ = [
    "DECK_NAMES",
    "REPOSE_FILES",
    "RING_FILES",
    "SHEAR_FILES",
    "TESTS",
    "case_setup",
    "particle_steps",
    "render_case",
]

DECK_NAMES = {"shear_cell": "in.shear_cell", "angle_of_repose": "in.angle_of_repose"}

# Output files the decks write (relative to the case directory).
SHEAR_FILES = {
    "lower": "meshes/shear_lower.stl",
    "lower_flange": "meshes/shear_lower_flange.stl",
    "upper": "meshes/shear_upper.stl",
    "upper_flange": "meshes/shear_upper_flange.stl",
    "lid": "meshes/shear_lid.stl",
    "table": "shear_cell.txt",
    "snapshot": "shear_preshear_end.vtk",
    "contacts": "contacts.dump",
}
RING_FILES = {
    "lower": "meshes/ring_lower.stl",
    "lower_inner": "meshes/ring_lower_inner.stl",
    "upper": "meshes/ring_upper.stl",
    "upper_inner": "meshes/ring_upper_inner.stl",
    "lid": "meshes/ring_lid.stl",
    "table": "shear_cell.txt",
    "snapshot": "shear_preshear_end.vtk",
    "contacts": "contacts.dump",
}
REPOSE_FILES = {
    "plate": "meshes/aor_plate.stl",
    "tube": "meshes/aor_tube.stl",
    "table": "repose.txt",
    "dump": "heap.dump",
    "vtk": "heap.vtk",
}


def _plain_case(case: Mapping[str, Any]) -> dict[str, Any]:
    """The case as a plain dict of str/float (numpy and pandas scalars unwrapped)."""
    out: dict[str, Any] = {}
    for key, value in dict(case).items():
        if isinstance(value, np.generic):
            value = value.item()
        if isinstance(value, numbers.Integral) and not isinstance(value, bool):
            value = float(value)
        out[str(key)] = value
    return out


def _validate(
    test: str, case: Mapping[str, Any], settings: Mapping[str, Any], youngs: float
) -> None:
    section = settings[test]
    material = settings["material"]

    def load_fraction(row: Mapping[str, object]) -> str | None:
        value = row.get("P")
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            return f"P = {value!r} is not a number"
        if not 0.0 < float(value) <= 1.0:
            return f"P = {value!r} is outside (0, 1]"
        return None

    def positive_normal_stress(row: Mapping[str, object]) -> str | None:
        value = row.get("normal_stress")
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            return f"normal_stress = {value!r} is not a number"
        if not (math.isfinite(float(value)) and float(value) > 0.0):
            return f"normal_stress = {value!r} must be a positive stress (Pa)"
        return None

    checks: list = []
    required = list(CONTACT_PARAMETERS)
    if test == "shear_cell":
        checks += [positive_normal_stress, load_fraction]
        required.append("normal_stress")
    rules = ValidationRules(
        min_dCylDp=float(section["min_dCylDp"]),
        allow_soft_particles=bool(material["soft_particles"]),
        required=tuple(required),
        extra_checks=tuple(checks),
    )
    # Configuration values count as part of the case (a too soft modulus is rejected too).
    row = {
        "youngsModulus": youngs,
        "poissonsRatio": material["poissonsRatio"],
        "dCylDp": section["dCylDp"],
        **case,
    }
    validate_case(row, rules)


def _shear_meshes(s: ShearCellSetup) -> dict[str, np.ndarray]:
    n = s.n_segments
    r = s.radius
    outer = r + s.flange_width
    # The flanges are meshes of their own: the readout separates the force carried across the
    # shear plane by the bulk from the friction and load of the flanges on the crescents.
    return {
        "lower": merge(
            disc(r, 0.0, n, normal_up=True),
            cylinder_shell(r, 0.0, s.z_shear, n, normals="inward"),
        ),
        "lower_flange": annulus(r, outer, s.z_shear, n, normal_up=True),
        "upper": cylinder_shell(r, s.z_shear, s.wall_top, n, normals="inward"),
        "upper_flange": annulus(r, outer, s.z_shear, n, normal_up=False),
        # The lid is placed by the deck (`move`) just above the settled bed.
        "lid": disc(r, 0.0, n, normal_up=False),
    }


def _bars(s: ShearCellSetup, z0: float, z1: float) -> np.ndarray:
    """Radial plates from R_i to R between the heights z0 and z1, evenly spaced."""
    plates = []
    for k in range(s.n_bars):
        # Half a spacing off the polygon vertices at angle 0.
        angle = 2.0 * math.pi * (k + 0.5) / s.n_bars
        c, d = math.cos(angle), math.sin(angle)
        inner = (s.inner_radius * c, s.inner_radius * d)
        outer = (s.radius * c, s.radius * d)
        corners = [(*inner, z0), (*outer, z0), (*outer, z1), (*inner, z1)]
        plates.append(quad(*(np.array(p, dtype=float) for p in corners)))
    return merge(*plates)


def _ring_meshes(s: ShearCellSetup) -> dict[str, np.ndarray]:
    n = s.n_segments
    r, ri = s.radius, s.inner_radius
    lower = [
        annulus(ri, r, 0.0, n, normal_up=True),
        cylinder_shell(r, 0.0, s.z_shear, n, normals="inward"),
    ]
    lid = [annulus(ri, r, 0.0, n, normal_up=False)]
    if s.n_bars and s.bar_height > 0.0:
        lower.append(_bars(s, 0.0, s.bar_height))
        lid.append(_bars(s, -s.bar_height, 0.0))
    # The inner bands are meshes of their own: they join the walls only once the core has
    # been emptied after the insertion.
    return {
        "lower": merge(*lower),
        "lower_inner": cylinder_shell(ri, 0.0, s.z_shear, n, normals="outward"),
        "upper": cylinder_shell(r, s.z_shear, s.wall_top, n, normals="inward"),
        "upper_inner": cylinder_shell(ri, s.z_shear, s.wall_top, n, normals="outward"),
        # The lid is placed by the deck (`move`) with its bars just above the settled bed.
        "lid": merge(*lid),
    }


def _repose_meshes(s: ReposeSetup) -> dict[str, np.ndarray]:
    return {
        "plate": disc(s.plate_radius, 0.0, s.n_segments, normal_up=True),
        "tube": cylinder_shell(s.radius, 0.0, s.tube_height, s.n_segments, normals="inward"),
    }


def _distribution_record(dist: SizeDistribution) -> dict[str, Any]:
    return {
        "radii": [float(r) for r in dist.radii],
        "mass_fractions": [float(w) for w in dist.mass_fractions],
        "mass_mean_radius": dist.mass_mean_radius,
        "number_mean_radius": dist.mean_radius,
        "max_radius": dist.max_radius,
        "min_radius": dist.min_radius,
        "mean_particle_volume": dist.mean_particle_volume,
    }


def case_setup(
    test: str, case: Mapping[str, Any], settings: Mapping[str, Any]
) -> tuple[dict[str, Any], float, SizeDistribution, MaterialSetup, ShearCellSetup | ReposeSetup]:
    """The validated case and every derived quantity of its deck, nothing written.

    Parameters
    ----------
    test, case, settings
        As for :func:`render_case`.

    Returns
    -------
    tuple
        The case as plain values, the cell size dCylDp, the size distribution, the material
        set-up and the test's set-up.

    Raises
    ------
    ValueError, CaseValidationError, MissingColumnError, SetupError
        As :func:`render_case`.
    """
    if test not in TESTS:
        raise ValueError(f"unknown test {test!r}; expected one of {', '.join(TESTS)}")
    plain = _plain_case(case)
    section = settings[test]
    material = settings["material"]
    youngs = float(plain.get("youngsModulus", material["youngsModulus"]))
    if test == "shear_cell" and isinstance(plain.get("normal_stress"), numbers.Real):
        youngs = shear_cell_youngs_modulus(plain, material, section)
    _validate(test, plain, settings, youngs)
    dCylDp = float(plain.get("dCylDp", section["dCylDp"]))
    dist = size_distribution(settings["particles"])
    mat = material_setup(plain, material, dist, youngs)
    # A replicate run (verification) carries its own insertion seed.
    seed = int(plain.get("seed", settings["seed"]))
    skin = float(settings["material"]["skin"])
    if test == "shear_cell":
        # A case row with a load condition P runs that single cycle.
        cell = dict(section)
        if "P" in plain:
            cell["P"] = [float(plain["P"])]
        setup: ShearCellSetup | ReposeSetup = shear_cell_setup(
            dCylDp, float(plain["normal_stress"]), dist, mat, cell, seed, skin
        )
    else:
        setup = repose_setup(dCylDp, dist, mat, section, seed, skin)
    return plain, dCylDp, dist, mat, setup


def particle_steps(test: str, case: Mapping[str, Any], settings: Mapping[str, Any]) -> float:
    """What a case costs to run: particles inserted times time steps of its deck.

    Parameters
    ----------
    test : str
        One of :data:`TESTS`.
    case : mapping
        The case row (contact parameters, load condition, optional seed).
    settings : mapping
        The validated configuration.

    Returns
    -------
    float
        Particle-steps, from the set-up alone (a DEM run's time is about proportional to them).
    """
    setup = case_setup(test, case, settings)[-1]
    return float(setup.n_particles) * float(setup.total_steps)


def render_case(
    test: str, case: Mapping[str, Any], settings: Mapping[str, Any], out_dir: Path
) -> dict[str, Any]:
    """Write the deck, meshes and ``case.json`` of one case of a virtual bulk test.

    Parameters
    ----------
    test : {"shear_cell", "angle_of_repose"}
        Which test.
    case : mapping
        A design row with ``case_id``, the contact parameters (coefficientFriction,
        coefficientRollingFriction, coefficientRestitution, density; optionally
        cohesionEnergyDensity, wallFriction, youngsModulus, poissonsRatio, dCylDp) and, for the
        shear cell, ``normal_stress`` (Pa) and optionally ``P``: with ``P`` the deck runs that
        single load condition from a fresh sample, without it one cycle per value of
        ``settings["shear_cell"]["P"]``. A missing dCylDp is taken from
        ``settings[test]["dCylDp"]``.
    settings : mapping
        The whole validated configuration (sections ``seed``, ``particles``, ``material``,
        ``shear_cell``, ``angle_of_repose``).
    out_dir : Path
        Case directory; created if missing.

    Returns
    -------
    dict
        The content of ``out_dir/case.json``: test, case_id, case, deck, files, particles,
        material, setup (every derived quantity) and readout settings.

    Raises
    ------
    ValueError
        For an unknown test.
    demcal.decks.case_validation.CaseValidationError
        For a physically invalid case (the message names the case and the field); raised
        before anything is written.
    demcal.decks.case_validation.MissingColumnError
        For a missing required field.
    demcal.core.config_values.SetupError
        For settings that make the set-up impossible (names the configuration key).
    """
    plain, dCylDp, dist, mat, setup = case_setup(test, case, settings)
    section = settings[test]
    if isinstance(setup, ShearCellSetup):
        if setup.geometry == "ring":
            files = dict(RING_FILES)
            meshes = _ring_meshes(setup)
            template = "ring_shear_cell.in.j2"
        else:
            files = dict(SHEAR_FILES)
            meshes = _shear_meshes(setup)
            template = "shear_cell.in.j2"
        readout: dict[str, Any] = {
            "geometry": setup.geometry,
            "radius": setup.radius,
            "inner_radius": setup.inner_radius,
            "bulk_density": setup.bulk_density,
            "interior_volume": setup.interior_volume,
            "z_floor": 0.0,
            "z_shear": setup.z_shear,
            "gravity": GRAVITY,
            "min_fraction": float(section["plateau_min_fraction"]),
        }
    else:
        files = dict(REPOSE_FILES)
        meshes = _repose_meshes(setup)
        template = "angle_of_repose.in.j2"
        readout = {
            "base_z": 0.0,
            "centre_xy": [0.0, 0.0],
            "n_slices": setup.n_slices,
            "n_sectors": setup.n_sectors,
            "min_contacts": setup.min_contacts,
        }
    deck = render_deck(
        template, str(plain["case_id"]), {**plain, "dCylDp": dCylDp}, setup, mat, files, dist
    )
    record: dict[str, Any] = {
        "test": test,
        "case_id": str(plain["case_id"]),
        "case": {k: v for k, v in plain.items()},
        "deck": DECK_NAMES[test],
        "files": files,
        "particles": _distribution_record(dist),
        "material": material_record(mat),
        "setup": setup.as_dict(),
        "readout": readout,
    }
    record["case"]["dCylDp"] = dCylDp

    write_case_directory(out_dir, DECK_NAMES[test], deck, files, meshes, record)
    return record
