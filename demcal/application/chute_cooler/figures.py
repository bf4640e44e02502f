"""Figures and ParaView files of the chute-cooler application.

* :func:`plot_fig11` - paper Fig. 11: a grouped bar chart of the size classes (groups, by
  radius) in the three layers of the analysed box (bars), as volume fraction of each layer and as
  the share of each class held by each layer.
* :func:`plot_steady_state` - the time series of the segregation index, the layer mean radii
  and the fill of the analysed box, with the averaging window shaded.
* :func:`render_fig10` - paper Fig. 10: a 3-D view of the chute, the boxes and the particles
  coloured by radius, rendered off-screen with pyvista, with the layers of the analysed
  box outlined.
* :func:`write_mesh_vtk` - triangle meshes as legacy VTK files for ParaView.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from demcal.application.chute_cooler.box_layers import LAYERS, Box
from demcal.application.chute_cooler.segregation import SegregationIndex
from demcal.application.chute_cooler.steady_segregation import SteadyWindow

__all__ = [
    "LAYER_COLOURS",
    "plot_fig11",
    "plot_steady_state",
    "render_fig10",
    "triangles_to_polydata",
    "write_mesh_vtk",
]

#: Bar colours of the layers (top, middle, bottom).
LAYER_COLOURS = {"top": "#9ecae1", "middle": "#4292c6", "bottom": "#08306b"}


def _require(table: pd.DataFrame, columns: Sequence[str], what: str) -> None:
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise KeyError(f"{what}: missing column(s) {', '.join(missing)}")


def plot_fig11(
    table: pd.DataFrame, index: SegregationIndex, path: str | Path, box_label: str = "box"
) -> Path:
    """Grouped bar chart of the layer composition of the analysed box (paper Fig. 11).

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`demcal.application.chute_cooler.box_layers.layer_table` output (columns layer,
        radius (m),
        volume_fraction, share_of_class).
    index : SegregationIndex
        Shown in the title.
    path : str or Path
        PNG file to write.
    box_label : str
        Name of the analysed box in the legend and title (e.g. "box 2").

    Returns
    -------
    Path
        ``path``.
    """
    _require(table, ["layer", "radius", "volume_fraction", "share_of_class"], "plot_fig11")
    radii = np.sort(table["radius"].unique())[::-1]
    x = np.arange(radii.size)
    width = 0.8 / len(LAYERS)
    fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.2), sharex=True)
    panels = (
        ("volume_fraction", "volume fraction of the layer (%)"),
        ("share_of_class", "share of the size class in the layer (%)"),
    )
    for ax, (column, label) in zip(axes, panels, strict=True):
        for j, layer in enumerate(LAYERS):
            rows = table[table["layer"] == layer].set_index("radius").reindex(radii)
            ax.bar(
                x + (j - 1) * width,
                100.0 * rows[column].to_numpy(dtype=float),
                width,
                label=layer,
                color=LAYER_COLOURS[layer],
                edgecolor="black",
                linewidth=0.4,
            )
        ax.set_xticks(x, [f"{1e3 * r:.3g}" for r in radii])
        ax.set_xlabel("particle radius (mm)")
        ax.set_ylabel(label)
        ax.grid(axis="y", alpha=0.3)
    axes[1].axhline(100.0 / len(LAYERS), color="grey", linestyle="--", linewidth=0.8)
    axes[0].legend(title=f"layer of {box_label}")
    fig.suptitle(
        f"Size segregation in {box_label}: S = {index.index:.3f}, "
        f"S/S_sorted = {index.normalised:.2f}"
    )
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path


def plot_steady_state(
    series: pd.DataFrame,
    window: SteadyWindow,
    path: str | Path,
    system: pd.DataFrame | None = None,
    box_label: str = "box",
) -> Path:
    """Time series of the analysed box, with the averaging window shaded.

    Parameters
    ----------
    series : pandas.DataFrame
        :func:`demcal.application.chute_cooler.steady_segregation.segregation_time_series` output.
    window : SteadyWindow
        The averaging window.
    path : str or Path
        PNG file to write.
    system : pandas.DataFrame, optional
        Print-file rows with columns time (s) and atoms (particles in the simulation).
    box_label : str
        Name of the analysed box (e.g. "box 2").

    Returns
    -------
    Path
        ``path``.
    """
    _require(
        series,
        ["time", "segregation_index", "r_top", "r_middle", "r_bottom", "r_box", "solid_fraction"],
        "plot_steady_state",
    )
    n_panels = 4 if system is not None else 3
    fig, axes = plt.subplots(n_panels, 1, figsize=(7.5, 2.1 * n_panels + 0.6), sharex=True)
    t = series["time"].to_numpy(dtype=float)
    axes[0].plot(t, series["segregation_index"], "k.-")
    axes[0].axhline(0.0, color="grey", linewidth=0.6)
    axes[0].set_ylabel("S (-)")
    for layer in LAYERS:
        axes[1].plot(t, 1e3 * series[f"r_{layer}"], ".-", color=LAYER_COLOURS[layer], label=layer)
    axes[1].plot(t, 1e3 * series["r_box"], "--", color="grey", label="box")
    axes[1].set_ylabel("mean radius (mm)")
    axes[1].legend(fontsize=8, ncol=4)
    axes[2].plot(t, series["solid_fraction"], "k.-")
    axes[2].set_ylabel(f"solid fraction\nof {box_label} (-)")
    if system is not None:
        _require(system, ["time", "atoms"], "plot_steady_state (system)")
        axes[3].plot(system["time"], system["atoms"], "k-")
        axes[3].set_ylabel("particles in\nthe simulation")
    for ax in axes:
        ax.axvspan(window.start_time, window.end_time, color="tab:green", alpha=0.15)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("time (s)")
    state = "steady" if window.steady else "NOT steady"
    axes[0].set_title(
        f"{box_label.capitalize()}: {state} over {window.start_time:.3g}-{window.end_time:.3g} s "
        "(shaded)",
        fontsize=10,
    )
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path


def triangles_to_polydata(triangles: np.ndarray):
    """A pyvista PolyData of a triangle soup (shape (n, 3, 3), m)."""
    import pyvista

    tri = np.asarray(triangles, dtype=float).reshape(-1, 3, 3)
    points = tri.reshape(-1, 3)
    faces = np.column_stack((np.full(len(tri), 3), np.arange(3 * len(tri)).reshape(-1, 3)))
    return pyvista.PolyData(points, faces.reshape(-1)).clean()


def write_mesh_vtk(triangles: np.ndarray, path: str | Path) -> Path:
    """Write a triangle mesh (shape (n, 3, 3), m) as a legacy VTK file for ParaView."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    triangles_to_polydata(triangles).save(str(path), binary=False)
    return path


def render_fig10(
    points: np.ndarray,
    radii: np.ndarray,
    walls: Sequence[np.ndarray],
    box: Box,
    path: str | Path,
    window_size: tuple[int, int] = (1600, 1000),
) -> Path:
    """3-D picture of the layout with the particles coloured by radius (paper Fig. 10).

    The view looks at the row from its y0 side, cut open along its middle plane: only the
    particles with centres behind the plane ``y = (box.y0 + box.y1) / 2`` are drawn, so the
    section through the bed shows the layering. The walls are translucent; the three layers of
    the analysed box are outlined in the cut plane and labelled.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 3)
        Particle centres, m.
    radii : numpy.ndarray, shape (n,)
        Particle radii, m.
    walls : sequence of numpy.ndarray, each shape (m_i, 3, 3)
        Wall triangles at the time of the snapshot, m.
    box : Box
        Interior of the analysed box.
    path : str or Path
        PNG file to write.
    window_size : (int, int)
        Image size in pixels.

    Returns
    -------
    Path
        ``path``.
    """
    import pyvista

    pyvista.OFF_SCREEN = True
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    r = np.asarray(radii, dtype=float).reshape(-1)
    if pts.shape[0] != r.size:
        raise ValueError(f"render_fig10: {pts.shape[0]} points but {r.size} radii")
    y_cut = 0.5 * (box.y0 + box.y1)
    keep = pts[:, 1] >= y_cut
    pts, r = pts[keep], r[keep]
    plotter = pyvista.Plotter(off_screen=True, window_size=list(window_size))
    plotter.set_background("white")
    for tri in walls:
        plotter.add_mesh(triangles_to_polydata(tri), color="lightgrey", opacity=0.2)
    if r.size:
        cloud = pyvista.PolyData(pts)
        cloud["radius (mm)"] = 1e3 * r
        cloud["diameter"] = 2.0 * r
        # coarser spheres for big clouds keep the rendering affordable
        res = 12 if r.size < 50_000 else 6
        sphere = pyvista.Sphere(radius=0.5, theta_resolution=res, phi_resolution=res)
        glyphs = cloud.glyph(scale="diameter", geom=sphere, orient=False)
        plotter.add_mesh(
            glyphs,
            scalars="radius (mm)",
            cmap="viridis",
            scalar_bar_args={
                "title": "radius (mm)",
                "color": "black",
                "vertical": True,
                "position_x": 0.88,
                "position_y": 0.2,
            },
        )
    # layer outlines just in front of the cut, so the particles do not hide them
    y_line = y_cut - 1.05 * (float(r.max()) if r.size else 0.0)
    edges = box.layer_edges()
    for z in edges:
        plotter.add_mesh(
            pyvista.Line((box.x0, y_line, z), (box.x1, y_line, z)), color="red", line_width=4
        )
    for x in (box.x0, box.x1):
        plotter.add_mesh(
            pyvista.Line((x, y_line, box.z0), (x, y_line, box.z1)), color="red", line_width=4
        )
    labels = [
        [box.x0 - 0.05 * (box.x1 - box.x0), y_line, 0.5 * (edges[i] + edges[i + 1])]
        for i in range(len(LAYERS))
    ]
    plotter.add_point_labels(
        np.array(labels),
        [f"{name}" for name in LAYERS],
        font_size=20,
        point_size=1,
        text_color="red",
        shape_opacity=0.0,
        always_visible=True,
        justification_horizontal="right",
    )
    plotter.view_vector((0.25, -1.0, 0.35), viewup=(0.0, 0.0, 1.0))
    plotter.reset_camera()
    plotter.camera.zoom(1.15)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(path))
    plotter.close()
    return path
