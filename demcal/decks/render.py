"""Rendering of LIGGGHTS decks from the templates, and the case directory they are written to.

The templates in ``templates/`` only format numbers; every number is computed by the set-up of
the deck (:mod:`demcal.virtual_tests`, :mod:`demcal.application.chute_cooler`). Rendering is
byte-stable: floats are written with ``repr`` (the shortest text that reads back to the same
double), STL files in ASCII with a fixed format, and ``case.json`` with sorted keys, so an
unchanged case gives unchanged files.

A case directory holds the deck, its STL meshes and ``case.json`` (every derived quantity the
readout needs). The engine must run in the case directory (all file names in the deck are
relative to it): ``cd OUT_DIR && dem_engine -in in.shear_cell``.
"""

from __future__ import annotations

import json
import math
import numbers
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import jinja2
import numpy as np

from demcal.core.parameters import CASE_PARAMETERS, GRAVITY
from demcal.decks.stl_file import write_stl_ascii
from demcal.particles.material import MaterialSetup
from demcal.particles.run_setup import RunSetup
from demcal.particles.size_distribution import SizeDistribution

__all__ = [
    "CASE_FILE",
    "TEMPLATE_DIR",
    "case_parameters",
    "format_number",
    "render_deck",
    "size_classes",
    "template_environment",
    "write_case_directory",
]

TEMPLATE_DIR = Path(__file__).resolve().parents[2] / "templates"
#: The record of a rendered case, next to its deck.
CASE_FILE = "case.json"

# Case columns written into the deck header, in this order (others follow sorted).
_HEADER_ORDER = (*CASE_PARAMETERS, "normal_stress")


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
    """Jinja environment of the deck templates (StrictUndefined, filters ``num``, ``nums``,
    global ``gravity`` in m/s^2)."""
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
    # A global, so that the macros imported without context see it too.
    env.globals["gravity"] = GRAVITY
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


def size_classes(dist: SizeDistribution) -> list[tuple[float, float]]:
    """(radius in m, mass fraction) of every class that holds mass: one particle template each."""
    return [
        (float(r), float(w))
        for r, w in zip(dist.radii, dist.mass_fractions, strict=True)
        if w > 0.0
    ]


def render_deck(
    template: str,
    case_id: str,
    header: Mapping[str, Any],
    setup: RunSetup,
    material: MaterialSetup,
    files: Mapping[str, str],
    dist: SizeDistribution,
) -> str:
    """Text of one deck.

    Parameters
    ----------
    template : str
        Template file in ``templates/`` (e.g. ``"shear_cell.in.j2"``).
    case_id : str
        Case id, written into the header.
    header : mapping
        Case columns; the numeric ones are listed in the header (:func:`case_parameters`).
    setup : RunSetup
        Every derived number of the deck (``s`` in the template).
    material : MaterialSetup
        Material and time step (``mat`` in the template).
    files : mapping of str to str
        Files the deck reads and writes, relative to the case directory.
    dist : SizeDistribution
        Particle sizes (one particle template per class with mass).
    """
    return (
        template_environment()
        .get_template(template)
        .render(
            case_id=case_id,
            parameters=case_parameters(header),
            s=setup,
            mat=material,
            files=files,
            classes=size_classes(dist),
        )
    )


def write_case_directory(
    out_dir: str | Path,
    deck_name: str,
    deck: str,
    files: Mapping[str, str],
    meshes: Mapping[str, np.ndarray],
    record: Mapping[str, Any],
    subdirs: Iterable[str] = (),
) -> None:
    """Write a case directory: the STL meshes, the deck and ``case.json``.

    Parameters
    ----------
    out_dir : str or Path
        Case directory; created if missing.
    deck_name : str
        File name of the deck (e.g. ``"in.shear_cell"``).
    deck : str
        Deck text (:func:`render_deck`).
    files : mapping of str to str
        Per mesh name its file, relative to ``out_dir`` (in ``meshes/``).
    meshes : mapping of str to numpy.ndarray, each shape (n, 3, 3)
        Triangles of each mesh, m; the mesh name is also the STL solid name.
    record : mapping
        Content of ``case.json`` (JSON-ready; NaN and infinities are rejected).
    subdirs : iterable of str
        Further (empty) directories the engine writes into, relative to ``out_dir``.
    """
    out = Path(out_dir)
    (out / "meshes").mkdir(parents=True, exist_ok=True)
    for sub in subdirs:
        (out / sub).mkdir(parents=True, exist_ok=True)
    for name, triangles in meshes.items():
        write_stl_ascii(out / files[name], triangles, name=name)
    (out / deck_name).write_text(deck, encoding="utf-8")
    (out / CASE_FILE).write_text(
        json.dumps(record, indent=1, sort_keys=True, allow_nan=False) + "\n", encoding="utf-8"
    )
