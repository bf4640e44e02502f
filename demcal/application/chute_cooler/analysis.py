"""Analysis of a finished chute-cooler run: the analysed box's layers over time, the steady-state
table and the segregation index, and the files the workflow publishes.

Reads the run directory written by :func:`demcal.application.chute_cooler.deck.render_chute_cooler`
after
the engine has run in it (``case.json``, the text dump, the print file, the VTK dumps); the
computation is :mod:`demcal.application.chute_cooler.steady_segregation`.
"""

from __future__ import annotations

import json
import math
import re
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from demcal.application.chute_cooler.box_layers import Box
from demcal.application.chute_cooler.deck import load_case
from demcal.application.chute_cooler.figures import render_fig10, write_mesh_vtk
from demcal.application.chute_cooler.layout import ChuteCoolerSetup
from demcal.application.chute_cooler.meshes import box_row_triangles, chute_triangles
from demcal.application.chute_cooler.steady_segregation import (
    SegregationResult,
    analyse_segregation,
)
from demcal.decks.triangle_surface import translate
from demcal.engine_io.dump_file import read_dump
from demcal.engine_io.fix_output import read_print_file
from demcal.engine_io.vtk_file import read_vtk_particles

__all__ = [
    "INDEX_DEFINITION",
    "analyse_run",
    "analysed_box",
    "export_paraview",
    "index_summary",
    "read_system_table",
    "render_layout",
    "vtk_steps",
    "write_json",
]

INDEX_DEFINITION = (
    "S = (r_bottom - r_top) / r_box with volume-weighted mean radii of the bottom and top "
    "layers and of the whole analysed box; S_sorted is S of the completely sorted box with the "
    "same particles and layer volumes; normalised = S / S_sorted (1 sorted, 0 mixed)"
)

_VTK_STEP = re.compile(r"_(\d+)\.vtk$")


def analysed_box(setup: ChuteCoolerSetup, time: float) -> Box:
    """Interior of the analysed box (``setup.analysed_box``) at ``time`` (s)."""
    return Box(*setup.box_bounds(setup.analysed_box, time))


def _snapshots(
    dump: Path, setup: ChuteCoolerSetup
) -> Iterator[tuple[float, np.ndarray, np.ndarray, Box]]:
    for snap in read_dump(dump, columns=["x", "y", "z", "radius"]):
        time = snap.timestep * setup.timestep
        atoms = snap.atoms
        yield (
            time,
            atoms[["x", "y", "z"]].to_numpy(dtype=float),
            atoms["radius"].to_numpy(dtype=float),
            analysed_box(setup, time),
        )


def analyse_run(case_dir: str | Path) -> tuple[SegregationResult, dict[str, Any], ChuteCoolerSetup]:
    """Segregation analysis of the analysed box of a finished run.

    Parameters
    ----------
    case_dir : str or Path
        The run directory (``case.json``, the text dump named there).

    Returns
    -------
    result : SegregationResult
        Table, index, time series and averaging window.
    record : dict
        ``case.json``.
    setup : ChuteCoolerSetup
        The set-up of the run.
    """
    case_dir = Path(case_dir)
    record, setup = load_case(case_dir)
    dump = case_dir / record["files"]["dump"]
    min_fraction = float(record.get("analysis", {}).get("plateau_min_fraction", 0.2))
    result = analyse_segregation(_snapshots(dump, setup), setup.radii, min_fraction)
    return result, record, setup


def read_system_table(case_dir: str | Path) -> pd.DataFrame:
    """The print file of a run (columns step, time, stage, atoms, mass, mass_inserted, ke)."""
    case_dir = Path(case_dir)
    record, _ = load_case(case_dir)
    return read_print_file(case_dir / record["files"]["table"], columns=["time", "atoms"])


def index_summary(
    result: SegregationResult, record: dict[str, Any], status: dict[str, Any] | None = None
) -> dict[str, Any]:
    """The content of ``segregation_index.json``.

    Parameters
    ----------
    result : SegregationResult
        Output of :func:`analyse_run`.
    record : dict
        ``case.json`` of the run.
    status : dict, optional
        ``status.json`` of the run (run time).
    """

    def clean(x: float) -> float | None:
        return float(x) if math.isfinite(x) else None

    idx = result.index
    table = result.table
    last = result.series.iloc[-1]
    summary: dict[str, Any] = {
        "definition": INDEX_DEFINITION,
        "segregation_index": clean(idx.index),
        "sorted_index": clean(idx.sorted_index),
        "normalised_index": clean(idx.normalised),
        "mean_radius_m": {k: clean(v) for k, v in idx.mean_radius.items()},
        "steady": bool(result.window.steady),
        "steady_reason": result.window.reason,
        "window_s": [result.window.start_time, result.window.end_time],
        "snapshots_averaged": result.window.end_index - result.window.start_index,
        "particles_in_box": round(float(table["n_particles"].sum())),
        # equal layer volumes: the box value is the mean over the layers
        "solid_fraction_of_box": clean(
            float(table.groupby("layer")["solid_fraction"].first().mean())
        ),
        "solid_fraction_last_snapshot": clean(float(last["solid_fraction"])),
        "parameters": record.get("parameters", {}),
        "parameters_source": record.get("parameters_source"),
        "particles_fed_expected": record["setup"]["expected_particles"],
    }
    if status is not None:
        summary["run_seconds"] = status.get("seconds")
        summary["threads"] = status.get("threads")
    return summary


def vtk_steps(case_dir: str | Path) -> list[tuple[int, Path]]:
    """The particle VTK files of a run as (step, path), by step."""
    case_dir = Path(case_dir)
    record, _ = load_case(case_dir)
    pattern = record["files"]["vtk"]
    found = []
    for path in (case_dir / pattern).parent.glob(Path(pattern).name.replace("*", "[0-9]*")):
        m = _VTK_STEP.search(path.name)
        if m:
            found.append((int(m.group(1)), path))
    return sorted(found)


def export_paraview(case_dir: str | Path, out_dir: str | Path) -> list[Path]:
    """Copy the particle VTK files and write the walls for ParaView.

    ``out_dir`` receives ``particles_<step>.vtk`` (copies of the engine's dumps), one
    ``boxes_<step>.vtk`` per particle file with the row where it was at that step, and
    ``chute.vtk``. ParaView groups the numbered files into time series.

    Returns
    -------
    list of Path
        The files written.
    """
    case_dir, out_dir = Path(case_dir), Path(out_dir)
    _, setup = load_case(case_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written = [write_mesh_vtk(chute_triangles(setup), out_dir / "chute.vtk")]
    boxes = box_row_triangles(setup)
    for step, path in vtk_steps(case_dir):
        target = out_dir / path.name
        shutil.copyfile(path, target)
        offset = setup.row_offset(step * setup.timestep)
        moved = translate(boxes, np.array([offset, 0.0, 0.0]))
        written += [target, write_mesh_vtk(moved, out_dir / f"boxes_{step}.vtk")]
    return written


def render_layout(case_dir: str | Path, path: str | Path) -> Path:
    """Fig. 10 from the last particle VTK file of a run.

    Raises
    ------
    FileNotFoundError
        The run wrote no particle VTK file.
    """
    case_dir = Path(case_dir)
    _, setup = load_case(case_dir)
    steps = vtk_steps(case_dir)
    if not steps:
        raise FileNotFoundError(f"{case_dir}: no particle VTK files")
    step, vtk = steps[-1]
    particles = read_vtk_particles(vtk)
    if "radius" not in particles.arrays:
        raise KeyError(f"{vtk}: no 'radius' array")
    time = step * setup.timestep
    boxes = translate(box_row_triangles(setup), np.array([setup.row_offset(time), 0.0, 0.0]))
    return render_fig10(
        particles.points,
        particles.arrays["radius"],
        [chute_triangles(setup), boxes],
        analysed_box(setup, time),
        path,
    )


def write_json(data: dict[str, Any], path: str | Path) -> Path:
    """Write ``data`` as indented JSON (NaN not allowed)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data, indent=2, sort_keys=True, allow_nan=False) + "\n")
    return path
