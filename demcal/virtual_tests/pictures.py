"""Off-screen pictures of the virtual bulk tests from the engine's VTK output (pyvista).

* :func:`heap_picture`: the settled heap of an angle-of-repose case seen from the side, with the
  plate, the lifted tube and the measured slope (the cone through the slice radii a quarter of
  the heap height below and above its middle) drawn in front of the heap.
* :func:`shear_cell_picture`: the shear cell at the end of the first pre-shear, cut in half along
  the shear direction, particles coloured by speed (the shear zone shows), the walls at their
  positions of that moment (lower part offset, lid height from the print file).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyvista

from demcal.bulk.values import MissingOutputError, read_case_record
from demcal.engine_io.fix_output import read_print_file
from demcal.engine_io.vtk_file import read_vtk_particles
from demcal.virtual_tests.angle_of_repose.readout import angle_of_repose

pyvista.OFF_SCREEN = True

__all__ = ["heap_picture", "shear_cell_picture"]

_WINDOW = (1400, 900)
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
    result = angle_of_repose(
        vtk.points,
        radii,
        tuple(readout["centre_xy"]),
        float(readout["base_z"]),
        contacts=None if contacts is None else contacts.reshape(-1),
        n_slices=int(readout["n_slices"]),
        n_sectors=int(readout["n_sectors"]),
        min_contacts=int(readout["min_contacts"]),
    )
    base = float(readout["base_z"])
    plotter = pyvista.Plotter(off_screen=True, window_size=_WINDOW)
    plotter.set_background("white")
    plotter.add_mesh(
        _spheres(vtk.points, radii, vtk.points[:, 2] - base, "height (m)"),
        scalars="height (m)",
        cmap="viridis",
        scalar_bar_args=_BAR | {"title": "height above plate (m)"},
    )
    plate = pyvista.read(str(_existing(case_dir, files["plate"])))
    plotter.add_mesh(plate, color="lightgray", opacity=0.6)

    # The measured cone: r(z) through (r_low, z_low) with slope angle aor, in front of the heap.
    angle = np.radians(result.angle_deg)
    ok = np.isfinite(result.slice_radii)
    r_low = float(np.interp(result.z_low, result.slice_z[ok], result.slice_radii[ok]))
    z_apex = result.z_low + r_low * np.tan(angle)
    r_base = r_low + (result.z_low - base) / np.tan(angle)
    front = -1.05 * float(setup["plate_radius"])
    for side in (-1.0, 1.0):
        line = pyvista.Line((side * r_base, front, base), (0.0, front, z_apex))
        plotter.add_mesh(line, color="red", line_width=4)
    for z in (result.z_low, result.z_high):
        r = float(np.interp(z, result.slice_z[ok], result.slice_radii[ok]))
        plotter.add_mesh(pyvista.Line((-r, front, z), (r, front, z)), color="orange", line_width=2)
    spread = result.sector_angles_deg[np.isfinite(result.sector_angles_deg)]
    text = (
        f"case {record['case_id']}: angle of repose {result.angle_deg:.1f} deg "
        f"(slice mean {result.angle_mean_slices_deg:.1f}, sectors "
        f"{spread.min():.1f}-{spread.max():.1f} deg), heap height "
        f"{1e3 * result.heap_height:.1f} mm"
    )
    plotter.add_text(text, font_size=10, color="black")
    plotter.enable_parallel_projection()
    plotter.view_xz()
    width = float(setup["plate_radius"])
    plotter.reset_camera(bounds=(-width, width, front, -front, base, base + 0.8 * width))
    png = Path(png)
    png.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(png))
    plotter.close()
    return png


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
    walls = {"lower": (travel, 0.0, 0.0), "upper": (0.0, 0.0, 0.0)}
    colours = {"lower": "steelblue", "upper": "gray"}
    for name, offset in walls.items():
        mesh = pyvista.read(str(_existing(case_dir, files[name]))).translate(offset, inplace=False)
        mesh = mesh.clip(normal=(0.0, -1.0, 0.0), origin=(0.0, 0.0, 0.0))
        plotter.add_mesh(mesh, color=colours[name], opacity=0.25, show_edges=True)
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
        f"{float(setup['normal_stress']):.0f} Pa, offset {1e3 * travel:.2f} mm, "
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
