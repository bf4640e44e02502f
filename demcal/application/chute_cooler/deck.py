"""Rendering of the chute-cooler deck: one directory with the LIGGGHTS deck, its STL meshes,
an empty ``vtk/`` directory for the particle dumps and ``case.json`` (every derived quantity
the analysis needs).

The numbers come from :mod:`demcal.application.chute_cooler.setup`; the template
``templates/chute_cooler.in.j2`` only formats them, with the material, contact-model and
particle macros shared with the bulk tests. Rendering is byte-stable (same input, same files).
The engine runs in the case directory: ``cd OUT_DIR && dem_engine -in in.chute_cooler``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from demcal.application.chute_cooler.contact_parameters import application_parameters
from demcal.application.chute_cooler.layout import ChuteCoolerSetup
from demcal.application.chute_cooler.meshes import box_row_triangles, chute_triangles
from demcal.application.chute_cooler.setup import chute_cooler_setup
from demcal.core.config_values import SetupError
from demcal.decks.render import CASE_FILE, render_deck, write_case_directory
from demcal.particles.material import material_record, material_setup
from demcal.particles.size_distribution import SizeDistribution, sinter_fines

__all__ = [
    "DECK_NAME",
    "FILES",
    "application_distribution",
    "load_case",
    "read_identified_parameters",
    "render_chute_cooler",
]

DECK_NAME = "in.chute_cooler"
TEMPLATE = "chute_cooler.in.j2"

#: Files of the case directory (relative to it).
FILES = {
    "chute": "meshes/chute.stl",
    "boxes": "meshes/boxes.stl",
    "table": "chute_cooler.txt",
    "dump": "chute_cooler.dump",
    "vtk": "vtk/particles_*.vtk",
}


class IdentifiedParametersError(ValueError):
    """The identified-parameter file is unreadable or malformed (the message names it)."""


def read_identified_parameters(path: str | Path) -> dict[str, dict[str, float]]:
    """Read ``identified_parameters.json``.

    Parameters
    ----------
    path : str or Path
        The identification record (``results/identification/identified_parameters.json``):
        a JSON object whose ``parameters`` maps each parameter to its statistics,
        ``{"parameters": {"coefficientFriction": {"mean": .., "sd": .., "min": .., "max": ..},
        ...}, ...}``.

    Returns
    -------
    dict
        Per parameter a dict of statistic name to value (SI units of the parameter).

    Raises
    ------
    IdentifiedParametersError
        Not JSON, no ``parameters`` object (or an empty one: nothing was identified), or a
        statistic is not a finite number.
    """
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        raise IdentifiedParametersError(
            f"{path}: cannot read identified parameters: {exc}"
        ) from exc
    params = data.get("parameters") if isinstance(data, dict) else None
    if not isinstance(params, dict):
        raise IdentifiedParametersError(f"{path}: needs an object 'parameters'")
    if not params:
        raise IdentifiedParametersError(
            f"{path}: no parameter set was identified (no valid sets); set "
            "application.parameters in the configuration instead"
        )
    out: dict[str, dict[str, float]] = {}
    for name, stats in params.items():
        if not isinstance(stats, dict):
            raise IdentifiedParametersError(f"{path}: parameter {name!r} must map to an object")
        entry: dict[str, float] = {}
        for stat, value in stats.items():
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise IdentifiedParametersError(
                    f"{path}: {name}.{stat} = {value!r} is not a number"
                )
            if not math.isfinite(float(value)):
                raise IdentifiedParametersError(f"{path}: {name}.{stat} = {value!r} is not finite")
            entry[str(stat)] = float(value)
        out[str(name)] = entry
    return out


def application_distribution(section: Mapping[str, Any]) -> SizeDistribution:
    """The sinter-fines distribution of the application (keys ``particle_scale``, ``classes``).

    Raises
    ------
    SetupError
        A value out of range (the message names the key).
    """
    scale = float(section["particle_scale"])
    classes = int(section["classes"])
    if not (math.isfinite(scale) and scale > 0.0):
        raise SetupError(f"configuration: 'application.particle_scale' must be > 0, got {scale}")
    if not 1 <= classes <= 6:
        raise SetupError(f"configuration: 'application.classes' must be in 1..6, got {classes}")
    return sinter_fines(scale=scale, n_largest=classes)


def render_chute_cooler(
    settings: Mapping[str, Any],
    out_dir: str | Path,
    identified: Mapping[str, Mapping[str, float]] | None = None,
    identified_source: str = "identified parameters",
) -> dict[str, Any]:
    """Write the chute-cooler deck, meshes and ``case.json`` into ``out_dir``.

    Parameters
    ----------
    settings : mapping
        The validated configuration (sections ``seed``, ``material``, ``application``).
    out_dir : str or Path
        Case directory; created if missing.
    identified : mapping, optional
        Identified parameters (:func:`read_identified_parameters`), used when
        ``application.parameters`` is null.
    identified_source : str
        Name of the identified-parameter file, for error messages.

    Returns
    -------
    dict
        The content of ``case.json``: deck, files, parameters, particles, material, setup.

    Raises
    ------
    SetupError, KeyError
        Impossible or missing settings (the message names the key); raised before anything
        is written.
    """
    section = settings["application"]
    parameters = application_parameters(section, identified, identified_source)
    dist = application_distribution(section)
    mat = material_setup(parameters, settings["material"], dist)
    setup = chute_cooler_setup(
        section,
        dist,
        mat,
        seed=int(settings["seed"]),
        skin_factor=float(settings["material"]["skin"]),
    )
    deck = render_deck(TEMPLATE, "chute_cooler", parameters, setup, mat, FILES, dist)
    record: dict[str, Any] = {
        "deck": DECK_NAME,
        "files": dict(FILES),
        "parameters": dict(parameters),
        "parameters_source": (
            "configuration" if section.get("parameters") is not None else identified_source
        ),
        "particles": {
            "radii": [float(r) for r in dist.radii],
            "mass_fractions": [float(w) for w in dist.mass_fractions],
            "number_fractions": [float(w) for w in dist.number_fractions],
        },
        # The application's parameter set has no cohesion.
        "material": material_record(mat, cohesion=False),
        "setup": setup.as_dict(),
        "analysis": {"plateau_min_fraction": float(section["plateau_min_fraction"])},
    }
    meshes = {"chute": chute_triangles(setup), "boxes": box_row_triangles(setup)}
    write_case_directory(out_dir, DECK_NAME, deck, FILES, meshes, record, subdirs=("vtk",))
    return record


def load_case(case_dir: str | Path) -> tuple[dict[str, Any], ChuteCoolerSetup]:
    """Read ``case.json`` of a rendered case and rebuild its set-up.

    Raises
    ------
    FileNotFoundError
        No ``case.json`` in ``case_dir``.
    KeyError
        A field is missing (the message names the file).
    """
    path = Path(case_dir) / CASE_FILE
    record = json.loads(path.read_text(encoding="utf-8"))
    if "setup" not in record:
        raise KeyError(f"{path}: missing 'setup'")
    return record, ChuteCoolerSetup.from_dict(record["setup"], source=str(path))
