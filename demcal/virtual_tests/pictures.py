"""Off-screen pictures of the virtual bulk tests from the engine's VTK output (pyvista).

* :func:`heap_picture`: the settled heap of an angle-of-repose case seen from the side, with the
  plate and the measured slope (the cone through the slice radii a quarter of
  the heap height below and above its middle) drawn in front of the heap; without a heap, what
  is on the plate and why no angle was read.
* :func:`shear_cell_picture`: the shear cell at the end of the first pre-shear, cut in half along
  the shear direction, particles coloured by speed (the shear zone shows), the walls at their
  positions of that moment (lower part offset, lid height from the print file).
* :func:`mu_series_figure`: mu(t) of a shear-cell run (matplotlib), pre-shear and shear in two
  colours, with the steady windows the readout averaged and their means.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pyvista
from matplotlib.figure import Figure

from demcal.bulk.values import MissingOutputError, extract, read_case_record
from demcal.engine_io.fix_output import read_print_file
from demcal.engine_io.vtk_file import read_vtk_particles
from demcal.virtual_tests.angle_of_repose.readout import (
    NotAHeapError,
    ReposeResult,
    angle_of_repose,
)
from demcal.virtual_tests.shear_cell.readout import (
    PHASE_PRE_SHEAR,
    PHASE_SHEAR,
    required_columns,
    shear_stress_series,
)

pyvista.OFF_SCREEN = True

__all__ = ["heap_picture", "mu_series_figure", "shear_cell_picture"]

_WINDOW = (1400, 900)
# Characters per line of a picture's caption at font size 10 in that window.
_TEXT_WIDTH = 150
# Vertical colour bar on the right, clear of the heap and the cell.
_BAR = {
    "color": "black",
    "vertical": True,
    "position_x": 0.86,
    "position_y": 0.15,
    "width": 0.05,
    "height": 0.7,
}


def _record(case_dir: Path, test: str) -> dict:
    record = read_case_record(case_dir)
    if record["test"] != test:
        raise ValueError(f"{Path(case_dir) / 'case.json'}: a {record['test']!r} case, not {test!r}")
    return record


def _existing(case_dir: Path, name: str) -> Path:
    path = Path(case_dir) / name
    if not path.is_file():
        raise MissingOutputError(f"{path}: engine output missing (did the run fail?)")
    return path


def _spheres(points: np.ndarray, radii: np.ndarray, scalars: np.ndarray, name: str):
    """Sphere glyphs of shape-(n, 3) centres (m) with shape-(n,) radii (m) and point scalars."""
    cloud = pyvista.PolyData(np.asarray(points, dtype=float))
    cloud["radius"] = np.asarray(radii, dtype=float)
    cloud[name] = np.asarray(scalars, dtype=float)
    ball = pyvista.Sphere(radius=1.0, theta_resolution=10, phi_resolution=10)
    return cloud.glyph(geom=ball, scale="radius", orient=False, factor=1.0)


def heap_picture(case_dir: Path, png: Path) -> Path:
    """Side view of the settled heap with the measured slope.

    Where the readout finds no heap (:class:`NotAHeapError`: particles spread over the plate,
    or too few left on it) the picture shows what is there, without a slope, and its caption
    gives the readout's reason.

    Parameters
    ----------
    case_dir : Path
        An angle-of-repose case directory after the engine run (``case.json``, ``heap.vtk``).
    png : Path
        Output image; parent directories are created.

    Returns
    -------
    Path
        ``png``.

    Raises
    ------
    MissingOutputError
        If ``case.json``, the VTK dump or a mesh file is missing (names the file).
    """
    case_dir = Path(case_dir)
    record = _record(case_dir, "angle_of_repose")
    files, setup, readout = record["files"], record["setup"], record["readout"]
    vtk = read_vtk_particles(_existing(case_dir, files["vtk"]), arrays=["radius"])
    radii = vtk.arrays["radius"].reshape(-1)
    contacts = vtk.arrays.get("c_cn")
    base = float(readout["base_z"])
    try:
        result = angle_of_repose(
            vtk.points,
            radii,
            tuple(readout["centre_xy"]),
            base,
            contacts=None if contacts is None else contacts.reshape(-1),
            n_slices=int(readout["n_slices"]),
            n_sectors=int(readout["n_sectors"]),
            min_contacts=int(readout["min_contacts"]),
        )
    except NotAHeapError as exc:
        # The user sees what the lift left instead: a layer, a few particles or a bare plate.
        result, text = None, f"case {record['case_id']}: {exc}"
    plotter = pyvista.Plotter(off_screen=True, window_size=_WINDOW)
    plotter.set_background("white")
    if len(radii):
        plotter.add_mesh(
            _spheres(vtk.points, radii, vtk.points[:, 2] - base, "height (m)"),
            scalars="height (m)",
            cmap="viridis",
            scalar_bar_args=_BAR | {"title": "height above plate (m)"},
        )
    plate = pyvista.read(str(_existing(case_dir, files["plate"])))
    plotter.add_mesh(plate, color="lightgray", opacity=0.6)
    front = -1.05 * float(setup["plate_radius"])
    if result is not None:
        _draw_cone(plotter, result, base, front)
        spread = result.sector_angles_deg[np.isfinite(result.sector_angles_deg)]
        text = (
            f"case {record['case_id']}: angle of repose {result.angle_deg:.1f} deg "
            f"(slice mean {result.angle_mean_slices_deg:.1f}, sectors "
            f"{spread.min():.1f}-{spread.max():.1f} deg), heap height "
            f"{1e3 * result.heap_height:.1f} mm"
        )
    plotter.add_text(textwrap.fill(text, _TEXT_WIDTH), font_size=10, color="black")
    plotter.enable_parallel_projection()
    plotter.view_xz()
    width = float(setup["plate_radius"])
    plotter.reset_camera(bounds=(-width, width, front, -front, base, base + 0.8 * width))
    png = Path(png)
    png.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(png))
    plotter.close()
    return png


def _draw_cone(plotter: pyvista.Plotter, result: ReposeResult, base: float, front: float) -> None:
    """The measured cone in front of the heap: r(z) through (r_low, z_low) at the slope angle
    (red), and the hull radii at the two readout heights (orange); lengths in m."""
    angle = np.radians(result.angle_deg)
    ok = np.isfinite(result.slice_radii)
    r_low = float(np.interp(result.z_low, result.slice_z[ok], result.slice_radii[ok]))
    z_apex = result.z_low + r_low * np.tan(angle)
    r_base = r_low + (result.z_low - base) / np.tan(angle)
    for side in (-1.0, 1.0):
        line = pyvista.Line((side * r_base, front, base), (0.0, front, z_apex))
        plotter.add_mesh(line, color="red", line_width=4)
    for z in (result.z_low, result.z_high):
        r = float(np.interp(z, result.slice_z[ok], result.slice_radii[ok]))
        plotter.add_mesh(pyvista.Line((-r, front, z), (r, front, z)), color="orange", line_width=2)


def _state_at(table, step: int) -> tuple[float, float]:
    """(travel, lid_z) of the last print row at or before ``step``."""
    rows = table[table["step"] <= step]
    if rows.empty:
        raise MissingOutputError(f"print file has no row at or before step {step}")
    last = rows.iloc[-1]
    return float(last["travel"]), float(last["lid_z"])


def shear_cell_picture(case_dir: Path, png: Path) -> Path:
    """The shear cell at the end of the first pre-shear, cut along the shear direction.

    Parameters
    ----------
    case_dir : Path
        A shear-cell case directory after the engine run (``case.json``, the pre-shear VTK
        snapshot, the print file and the meshes).
    png : Path
        Output image; parent directories are created.

    Returns
    -------
    Path
        ``png``.

    Raises
    ------
    MissingOutputError
        If an input file is missing (names the file).
    """
    case_dir = Path(case_dir)
    record = _record(case_dir, "shear_cell")
    files, setup = record["files"], record["setup"]
    vtk = read_vtk_particles(_existing(case_dir, files["snapshot"]), arrays=["radius", "v"])
    table = read_print_file(
        _existing(case_dir, files["table"]), columns=["step", "travel", "lid_z"]
    )
    travel, lid_z = _state_at(table, int(setup["snapshot_step"]))

    # Back half only (y >= 0): the cut face shows the velocity field across the shear plane.
    keep = vtk.points[:, 1] >= 0.0
    speed = np.linalg.norm(vtk.arrays["v"].reshape(-1, 3), axis=1)
    plotter = pyvista.Plotter(off_screen=True, window_size=_WINDOW)
    plotter.set_background("white")
    plotter.add_mesh(
        _spheres(vtk.points[keep], vtk.arrays["radius"].reshape(-1)[keep], speed[keep], "speed"),
        scalars="speed",
        cmap="plasma",
        clim=(0.0, 1.5 * float(setup["shear_speed"])),
        scalar_bar_args=_BAR | {"title": "particle speed (m/s)"},
    )
    # The ring's lower part turns in place (drawn at its starting angle).
    split = setup.get("geometry", "split") == "split"
    shift = travel if split else 0.0
    moved = "offset" if split else "travel at the mean radius"
    walls = {
        "lower": (shift, 0.0, 0.0),
        "lower_flange": (shift, 0.0, 0.0),
        "lower_inner": (0.0, 0.0, 0.0),
        "upper": (0.0, 0.0, 0.0),
        "upper_flange": (0.0, 0.0, 0.0),
        "upper_inner": (0.0, 0.0, 0.0),
    }
    colours = {
        "lower": "steelblue",
        "lower_flange": "steelblue",
        "lower_inner": "steelblue",
        "upper": "gray",
    }
    for name, offset in walls.items():
        if name not in files:  # a case rendered before the flanges were meshes of their own
            continue
        mesh = pyvista.read(str(_existing(case_dir, files[name]))).translate(offset, inplace=False)
        mesh = mesh.clip(normal=(0.0, -1.0, 0.0), origin=(0.0, 0.0, 0.0))
        plotter.add_mesh(mesh, color=colours.get(name, "gray"), opacity=0.25, show_edges=True)
    radius = float(setup["radius"])
    z_shear = float(setup["z_shear"])
    front = -1.1 * radius
    # The lid is a disc seen edge-on: drawn as a thick line at its height.
    plotter.add_mesh(
        pyvista.Line((-radius, front, lid_z), (radius, front, lid_z)),
        color="darkred",
        line_width=6,
    )
    plotter.add_mesh(
        pyvista.Line((-1.3 * radius, front, z_shear), (1.3 * radius, front, z_shear)),
        color="black",
        line_width=2,
    )
    text = (
        f"case {record['case_id']}: end of pre-shear, normal stress "
        f"{float(setup['normal_stress']):.0f} Pa, {moved} {1e3 * travel:.2f} mm, "
        f"lid at {1e3 * lid_z:.1f} mm, {len(vtk.points)} particles"
    )
    plotter.add_text(text, font_size=10, color="black")
    plotter.enable_parallel_projection()
    plotter.view_xz()
    half = 1.6 * radius
    plotter.reset_camera(bounds=(-half, half, front, radius, -0.1 * radius, lid_z + 0.3 * radius))
    png = Path(png)
    png.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(png))
    plotter.close()
    return png


# Phases of the mu(t) figure: readout column suffix, print-file phase, label and colours (line
# and shaded window, mean segment).
_MU_PHASES = (
    ("psh", PHASE_PRE_SHEAR, "pre-shear", "tab:blue", "navy"),
    ("sh", PHASE_SHEAR, "shear", "tab:orange", "saddlebrown"),
)


def _mu_axes(figure: Figure, series: pd.DataFrame, values: pd.DataFrame, title: str) -> None:
    """Draw mu(t) of the pre-shear and shear rows of ``series`` and the windows of ``values``.

    The artists carry a ``gid`` (phase ``psh`` or ``sh``): ``series_<phase>_<cycle>`` for the
    mu(t) line, ``window_<phase>_<cycle>`` for the shaded readout window and
    ``mean_<phase>_<cycle>`` for the mean segment across it.
    """
    ax = figure.add_subplot()
    shown = []
    for key, phase, label, colour, _ in _MU_PHASES:
        rows = series[series["phase"] == phase]
        for k, (_, part) in enumerate(rows.groupby("cycle", sort=True)):
            ax.plot(
                part["time"],
                part["mu"],
                color=colour,
                linewidth=0.9,
                label=f"{label} (phase {phase})" if k == 0 else None,
                gid=f"series_{key}_{int(part['cycle'].iloc[0])}",
            )
        shown.append(rows["mu"].to_numpy(dtype=np.float64))
    means = []
    for _, row in values.iterrows():
        cycle = int(row["cycle"])
        for key, _, label, colour, dark in _MU_PHASES:
            start, end = float(row[f"{key}_t_start"]), float(row[f"{key}_t_end"])
            mean = float(row[f"mu_{key}"])
            if not (np.isfinite(start) and np.isfinite(end) and np.isfinite(mean)):
                continue
            means.append(mean)
            first = cycle == int(values["cycle"].min())
            ax.axvspan(
                start,
                end,
                color=colour,
                alpha=0.2,
                linewidth=0,
                label=f"{label} window averaged by the readout" if first else None,
                gid=f"window_{key}_{cycle}",
            )
            ax.plot(
                [start, end], [mean, mean], color=dark, linewidth=2.2, gid=f"mean_{key}_{cycle}"
            )
            verdict = "steady" if bool(row[f"steady_{key}"]) else "not steady"
            ax.annotate(
                f"{mean:.3f}\n{verdict}",
                xy=(0.5 * (start + end), mean),
                xytext=(0, 4),
                textcoords="offset points",
                ha="center",
                va="bottom",
                fontsize=7,
                color=dark,
                bbox={
                    "boxstyle": "round,pad=0.15",
                    "facecolor": "white",
                    "edgecolor": "none",
                    "alpha": 0.7,
                },
            )
    finite = np.concatenate([*shown, np.asarray(means)])
    finite = finite[np.isfinite(finite)]
    if finite.size:
        # Start-up spikes of a phase (tiny overlap area, lid not yet loaded) would flatten the
        # plateaus; the top leaves room for the labels above the means.
        top = max(float(np.percentile(finite, 99)), max(means, default=0.0))
        ax.set_ylim(min(0.0, float(np.percentile(finite, 1))), 1.3 * top if top > 0 else 1.0)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("mu = tau / sigma (-)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, linewidth=0.3, alpha=0.5)
    # Outside the axes: the start of every phase (mu rising from 0) stays visible.
    figure.legend(loc="outside lower center", ncols=4, fontsize=8, frameon=False)


def mu_series_figure(case_dir: Path, png: Path) -> Path:
    """mu(t) of a shear-cell run with the steady windows the readout averaged.

    The pre-shear (phase 1) and shear (phase 3) rows of the print file are drawn in two colours
    (mu from :func:`demcal.virtual_tests.shear_cell.readout.shear_stress_series` with the
    geometry of ``case.json``). For every cycle the windows found by the readout
    (:func:`demcal.bulk.values.extract`) are shaded, their mean ``mu_psh`` / ``mu_sh`` drawn as
    a horizontal segment across the window and labelled with its value and whether the window
    is steady.

    Parameters
    ----------
    case_dir : Path
        A shear-cell case directory after the engine run (``case.json`` and the print file
        named in its ``files.table``).
    png : Path
        Output image; parent directories are created.

    Returns
    -------
    Path
        ``png``.

    Raises
    ------
    MissingOutputError
        If ``case.json`` or the print file is missing or truncated (names the file).
    ValueError
        If the case is not a shear-cell case or the print file is inconsistent (see
        :func:`demcal.virtual_tests.shear_cell.readout.shear_stress_series`).
    """
    case_dir = Path(case_dir)
    record = _record(case_dir, "shear_cell")
    readout, setup = record["readout"], record["setup"]
    inner = float(readout.get("inner_radius", 0.0))
    table = read_print_file(
        _existing(case_dir, record["files"]["table"]), columns=list(required_columns(inner))
    )
    series = shear_stress_series(
        table,
        float(readout["radius"]),
        float(readout["z_floor"]),
        float(readout["z_shear"]),
        float(readout["gravity"]),
        inner,
    )
    values = extract("shear_cell", case_dir)
    p_values = ", ".join(f"{float(p):g}" for p in values["P"])
    title = (
        f"case {record['case_id']}: mu(t), normal stress "
        f"{float(setup['normal_stress']):.0f} Pa, P = {p_values}"
    )
    figure = Figure(figsize=(10.0, 4.8), dpi=150, layout="constrained")
    _mu_axes(figure, series, values, title)
    png = Path(png)
    png.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(png, dpi=figure.dpi)
    return png
