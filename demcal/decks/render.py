"""Rendering of the virtual bulk-test decks: one directory per case with the LIGGGHTS deck, its
STL meshes and ``case.json`` (every derived quantity the readout needs).

The templates in ``templates/`` only format numbers; everything is computed in
:mod:`demcal.virtual_tests.shear_cell.setup` and :mod:`demcal.virtual_tests.angle_of_repose.setup`.
Rendering is byte-stable: floats
are written with ``repr`` (the shortest text that reads back to the same double), STL files in
ASCII with a fixed format, and ``case.json`` with sorted keys, so an unchanged case gives
unchanged files.

The engine must run in the case directory (all file names in the deck are relative to it):
``cd OUT_DIR && dem_engine -in in.shear_cell``.
"""

from __future__ import annotations

import json
import math
import numbers
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import jinja2
import numpy as np

from demcal.decks.case_validation import ValidationRules, validate_case
from demcal.decks.stl_mesh import annulus, cylinder_shell, disc, merge, write_stl_ascii
from demcal.particles.size_distribution import SizeDistribution
from demcal.virtual_tests.angle_of_repose.setup import ReposeSetup, repose_setup
from demcal.virtual_tests.shear_cell.setup import (
    MaterialSetup,
    ShearCellSetup,
    material_setup,
    shear_cell_setup,
    shear_cell_youngs_modulus,
    size_distribution,
)

__all__ = [
    "CASE_FILE",
    "DECK_NAMES",
    "TEMPLATE_DIR",
    "TESTS",
    "case_parameters",
    "format_number",
    "render_case",
    "template_environment",
]

TEMPLATE_DIR = Path(__file__).resolve().parents[2] / "templates"
TESTS = ("shear_cell", "angle_of_repose")
DECK_NAMES = {"shear_cell": "in.shear_cell", "angle_of_repose": "in.angle_of_repose"}
CASE_FILE = "case.json"

# Output files the decks write (relative to the case directory).
SHEAR_FILES = {
    "lower": "meshes/shear_lower.stl",
    "upper": "meshes/shear_upper.stl",
    "lid": "meshes/shear_lid.stl",
    "table": "shear_cell.txt",
    "snapshot": "shear_preshear_end.vtk",
}
REPOSE_FILES = {
    "plate": "meshes/aor_plate.stl",
    "tube": "meshes/aor_tube.stl",
    "table": "repose.txt",
    "dump": "heap.dump",
    "vtk": "heap.vtk",
}

# Case columns written into the deck header, in this order (others follow sorted).
_HEADER_ORDER = (
    "coefficientFriction",
    "coefficientRollingFriction",
    "coefficientRestitution",
    "density",
    "cohesionEnergyDensity",
    "wallFriction",
    "youngsModulus",
    "poissonsRatio",
    "dCylDp",
    "normal_stress",
)


def format_number(value: Any) -> str:
    """The one number format of the decks.

    Integers as integers; floats as ``repr`` (shortest round-trip text, so the engine reads
    exactly the double computed here); -0.0 as 0.0.

    Raises
    ------
    ValueError
        For NaN, infinities, booleans and non-numbers.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"deck number expected, got {value!r}")
    if isinstance(value, numbers.Integral):
        return str(int(value))
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"deck number must be finite, got {x!r}")
    return repr(x + 0.0)


def _num_filter(value: Any) -> str:
    if isinstance(value, jinja2.Undefined):
        str(value)  # StrictUndefined raises UndefinedError naming the variable
    return format_number(value)


def _format_list(values: Any) -> str:
    if isinstance(values, jinja2.Undefined):
        str(values)
    return " ".join(format_number(v) for v in values)


def template_environment() -> jinja2.Environment:
    """Jinja environment of the deck templates (StrictUndefined, filters ``num``, ``nums``)."""
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(TEMPLATE_DIR)),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        autoescape=False,
    )
    env.filters["num"] = _num_filter
    env.filters["nums"] = _format_list
    return env


def case_parameters(case: Mapping[str, Any]) -> list[tuple[str, float]]:
    """Numeric case columns for the deck header: known names first, then the rest sorted."""
    numeric = {
        k: v
        for k, v in case.items()
        if k != "case_id" and isinstance(v, numbers.Real) and not isinstance(v, bool)
    }
    ordered = [k for k in _HEADER_ORDER if k in numeric]
    ordered += sorted(k for k in numeric if k not in _HEADER_ORDER)
    return [(k, numeric[k]) for k in ordered]


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

    def non_negative_wall_friction(row: Mapping[str, object]) -> str | None:
        value = row.get("wallFriction")
        if value is None:
            return None
        if not isinstance(value, numbers.Real) or not float(value) >= 0.0:
            return f"wallFriction = {value!r} must be a number >= 0"
        return None

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

    checks: list = [non_negative_wall_friction]
    required = [
        "coefficientFriction",
        "coefficientRollingFriction",
        "coefficientRestitution",
        "density",
    ]
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
    return {
        "lower": merge(
            disc(r, 0.0, n, normal_up=True),
            cylinder_shell(r, 0.0, s.z_shear, n, normals="inward"),
            annulus(r, outer, s.z_shear, n, normal_up=True),
        ),
        "upper": merge(
            cylinder_shell(r, s.z_shear, s.wall_top, n, normals="inward"),
            annulus(r, outer, s.z_shear, n, normal_up=False),
        ),
        # The lid is placed by the deck (`move`) just above the settled bed.
        "lid": disc(r, 0.0, n, normal_up=False),
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


def _material_record(mat: MaterialSetup) -> dict[str, Any]:
    return {
        "youngsModulus": mat.youngs_modulus,
        "poissonsRatio": mat.poissons_ratio,
        "soft_particles": mat.soft_particles,
        "rolling_friction": mat.rolling_friction,
        "cohesion": mat.cohesion,
        "coefficientFriction": mat.friction,
        "wallFriction": mat.wall_friction,
        "coefficientRollingFriction": mat.rolling_friction_coefficient,
        "coefficientRestitution": mat.restitution,
        "cohesionEnergyDensity": mat.cohesion_energy_density,
        "density": mat.density,
        "timestep": mat.timestep,
        "rayleigh_time": mat.rayleigh_time,
    }


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
    demcal.virtual_tests.shear_cell.setup.SetupError
        For settings that make the set-up impossible (names the configuration key).
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
    seed = int(settings["seed"])
    skin = float(settings["material"]["skin"])
    if test == "shear_cell":
        # A case row with a load condition P runs that single cycle.
        cell = dict(section)
        if "P" in plain:
            cell["P"] = [float(plain["P"])]
        setup: ShearCellSetup | ReposeSetup = shear_cell_setup(
            dCylDp, float(plain["normal_stress"]), dist, mat, cell, seed, skin
        )
        files = dict(SHEAR_FILES)
        meshes = _shear_meshes(setup)
        template = "shear_cell.in.j2"
        readout: dict[str, Any] = {
            "radius": setup.radius,
            "z_floor": 0.0,
            "z_shear": setup.z_shear,
            "gravity": 9.81,
            "min_fraction": float(section["plateau_min_fraction"]),
        }
    else:
        setup = repose_setup(dCylDp, dist, mat, section, seed, skin)
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
    classes = [
        (float(r), float(w))
        for r, w in zip(dist.radii, dist.mass_fractions, strict=True)
        if w > 0.0
    ]
    deck = (
        template_environment()
        .get_template(template)
        .render(
            case_id=str(plain["case_id"]),
            parameters=case_parameters({**plain, "dCylDp": dCylDp}),
            s=setup,
            mat=mat,
            files=files,
            classes=classes,
        )
    )
    record: dict[str, Any] = {
        "test": test,
        "case_id": str(plain["case_id"]),
        "case": {k: v for k, v in plain.items()},
        "deck": DECK_NAMES[test],
        "files": files,
        "particles": _distribution_record(dist),
        "material": _material_record(mat),
        "setup": setup.as_dict(),
        "readout": readout,
    }
    record["case"]["dCylDp"] = dCylDp

    out_dir = Path(out_dir)
    (out_dir / "meshes").mkdir(parents=True, exist_ok=True)
    for name, triangles in meshes.items():
        write_stl_ascii(out_dir / files[name], triangles, name=name)
    (out_dir / DECK_NAMES[test]).write_text(deck, encoding="utf-8")
    (out_dir / CASE_FILE).write_text(
        json.dumps(record, indent=1, sort_keys=True, allow_nan=False) + "\n", encoding="utf-8"
    )
    return record
