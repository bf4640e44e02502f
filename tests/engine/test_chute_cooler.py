"""The tiny chute-cooler case end to end on the real engine, through the steps the rule scripts
call: render, run, analyse, figures and ParaView files."""

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import pyvista
from matplotlib.figure import Figure

from demcal.application.chute_cooler.deck import load_case
from demcal.application.chute_cooler.steps import render_from_config, write_analysis, write_figures
from demcal.core.config import load_config
from demcal.engine_io.dump_file import read_dump
from demcal.engine_io.fix_output import read_print_file
from demcal.engine_io.run import run_deck
from tests.figures import bbox, colour_mask, distinct_colours, ink, read_png, saved_figures

from .conftest import engine_path

pytestmark = pytest.mark.engine

ROOT = Path(__file__).resolve().parents[2]
# The matplotlib figures the steps saved, by file name (filled by the fixture).
FIGURES: dict[str, Figure] = {}


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """The tiny case rendered, run and analysed, with its figures."""
    root = tmp_path_factory.mktemp("chute")
    config = load_config(ROOT / "config" / "tiny.yaml")
    # The tiny profile names its parameters, so the case runs without an identification.
    assert set(config["application"]["parameters"]) >= {
        "coefficientFriction",
        "coefficientRollingFriction",
        "coefficientRestitution",
        "density",
    }
    run = root / "run"
    render_from_config(config, None, run / "in.chute_cooler")
    command = f"{engine_path()} -in {{deck}} -noprogress"
    status = run_deck(run, "in.chute_cooler", command, 1)
    assert status["status"] == "ok", status["error"]
    out = root / "application"
    outputs = {
        "table": str(out / "segregation.csv"),
        "index": str(out / "segregation_index.json"),
        "series": str(out / "segregation_time_series.csv"),
        "steady": str(out / "steady_state.png"),
    }
    figures = {
        "fig11": str(out / "fig11_segregation.png"),
        "fig10": str(out / "fig10_layout.png"),
        "vtk": str(out / "vtk"),
    }
    with saved_figures() as drawn:
        write_analysis(run / "status.json", config, **outputs)
        write_figures(run / "status.json", outputs["table"], **figures)
    FIGURES.update({path.name: figure for figure, path in zip(drawn, drawn.paths, strict=True)})
    return run, out, config


def test_run_finishes_quickly_and_feeds_at_the_set_rate(finished):
    run, _, _ = finished
    status = json.loads((run / "status.json").read_text())
    assert status["status"] == "ok"
    assert status["seconds"] < 60
    record, setup = load_case(run)
    table = read_print_file(
        run / record["files"]["table"], columns=["time", "mass", "mass_inserted"]
    )
    last = table.iloc[-1]
    # the insertion follows the mass rate (within one insertion event)
    event = setup.mass_rate * setup.insert_every * setup.timestep
    assert abs(last["mass_inserted"] - setup.mass_rate * last["time"]) <= event + 1e-12
    # nearly everything fed stays on the row; what leaves the box is deleted
    assert (table["mass"] <= table["mass_inserted"] * (1 + 1e-12)).all()
    assert last["mass"] >= 0.9 * last["mass_inserted"]


def test_the_row_carries_the_bed_at_the_box_speed(finished):
    run, _, _ = finished
    record, setup = load_case(run)
    snaps = read_dump(run / record["files"]["dump"], columns=["id", "x", "z"])
    a, b = snaps[-2].atoms.set_index("id"), snaps[-1].atoms.set_index("id")
    x0, x1, *_ = setup.box_bounds(setup.analysed_box, snaps[-2].timestep * setup.timestep)
    inside = a[(a.x > x0) & (a.x < x1) & (a.z < setup.box_height)].index.intersection(b.index)
    assert len(inside) > 50
    dx = (b.loc[inside, "x"] - a.loc[inside, "x"]).median()
    dt = (snaps[-1].timestep - snaps[-2].timestep) * setup.timestep
    assert dx == pytest.approx(setup.box_speed * dt, rel=0.02)
    # every particle left is inside the simulation box
    lo, hi = np.array(setup.box_lo), np.array(setup.box_hi)
    assert b.x.between(lo[0], hi[0]).all() and b.z.between(lo[2], hi[2]).all()


def test_analysis_outputs(finished):
    run, out, config = finished
    _, setup = load_case(run)
    table = pd.read_csv(out / "segregation.csv")
    assert len(table) == 3 * len(setup.radii)
    assert set(table["layer"]) == {"top", "middle", "bottom"}
    for _, rows in table.groupby("layer"):
        assert rows["volume_fraction"].sum() == pytest.approx(1.0)
    for _, rows in table.groupby("radius"):
        assert rows["share_of_class"].sum() == pytest.approx(1.0)
    index = json.loads((out / "segregation_index.json").read_text())
    assert index["steady"] is True
    assert -1.0 <= index["normalised_index"] <= 1.0
    assert index["sorted_index"] > 0
    # the analysed box is filled to a packed bed
    assert 0.4 < index["solid_fraction_of_box"] < 0.7
    assert index["particles_in_box"] >= 0.7 * setup.particles_per_box
    series = pd.read_csv(out / "segregation_time_series.csv")
    assert series["time"].is_monotonic_increasing
    assert series["solid_fraction"].iloc[0] == 0.0
    # the averaging window lies in the record and covers the snapshots it names
    start, end = index["window_s"]
    assert series["time"].iloc[0] <= start < end == pytest.approx(series["time"].iloc[-1])
    inside = series[(series["time"] >= start - 1e-12) & (series["time"] <= end + 1e-12)]
    assert len(inside) == index["snapshots_averaged"] >= 3
    # the table's sidecar: seed and configuration of the run, and the index it summarises
    sidecar = json.loads((out / "segregation.csv.json").read_text())
    assert sidecar["artifact"] == "segregation.csv" and sidecar["seed"] == config["seed"]
    assert len(sidecar["config_sha256"]) == 64
    assert sidecar["index"] == index


def test_fig11_bars_are_the_layer_table(finished):
    _, out, _ = finished
    table = pd.read_csv(out / "segregation.csv")
    index = json.loads((out / "segregation_index.json").read_text())
    figure = FIGURES["fig11_segregation.png"]
    radii = sorted(table["radius"].unique(), reverse=True)
    for ax, column in zip(figure.axes, ("volume_fraction", "share_of_class"), strict=True):
        # one group of bars per size class (largest first), one bar per layer in each group
        heights = np.array([b.get_height() for b in ax.patches]).reshape(3, len(radii))
        for k, layer in enumerate(("top", "middle", "bottom")):
            rows = table[table["layer"] == layer].set_index("radius").loc[radii, column]
            np.testing.assert_allclose(heights[k], 100.0 * rows.to_numpy(), rtol=1e-12)
        labels = [t.get_text() for t in ax.get_xticklabels()]
        assert labels == [f"{1e3 * r:.3g}" for r in radii]
    assert f"S = {index['segregation_index']:.3f}" in figure.get_suptitle()
    assert read_png(out / "fig11_segregation.png").shape == (630, 1650, 3)  # 11 x 4.2 in


def test_steady_state_figure_shows_the_series_and_the_window(finished):
    _, out, _ = finished
    series = pd.read_csv(out / "segregation_time_series.csv")
    index = json.loads((out / "segregation_index.json").read_text())
    figure = FIGURES["steady_state.png"]
    index_ax, radius_ax, fill_ax, system_ax = figure.axes
    (s_line,) = index_ax.lines[:1]
    np.testing.assert_allclose(s_line.get_xdata(), series["time"])
    np.testing.assert_allclose(s_line.get_ydata(), series["segregation_index"])
    np.testing.assert_allclose(fill_ax.lines[0].get_ydata(), series["solid_fraction"])
    layers = {line.get_label(): line for line in radius_ax.lines}
    np.testing.assert_allclose(layers["top"].get_ydata(), 1e3 * series["r_top"])
    np.testing.assert_allclose(layers["box"].get_ydata(), 1e3 * series["r_box"])
    atoms = system_ax.lines[0].get_ydata()
    assert atoms[-1] > 0.5 * index["particles_fed_expected"]
    # every panel shades the averaging window of the index record
    for ax in figure.axes:
        (window,) = ax.patches
        shaded = (window.get_x(), window.get_x() + window.get_width())
        assert shaded == pytest.approx(tuple(index["window_s"]))
    assert "steady over" in index_ax.get_title()
    # four panels of 2.1 in and 0.6 in for the axis labels, 7.5 in wide, at 150 dpi
    assert read_png(out / "steady_state.png").shape == (1350, 1125, 3)


def test_fig10_shows_the_row_with_the_analysed_box_outlined(finished):
    _, out, _ = finished
    image = read_png(out / "fig10_layout.png")
    assert image.shape == (1000, 1600, 3)
    # the layers of the analysed box outlined and named in red, inside the picture of chute,
    # row and particles, in its lower half (the row under the chute); the box holds particles
    top, bottom, left, right = bbox(ink(image))
    red = colour_mask(image, "red", tol=0.25)
    r_top, r_bottom, r_left, r_right = bbox(red)
    assert red.sum() > 2000
    assert top < r_top < r_bottom < bottom and left < r_left < r_right < right
    assert r_top > 0.5 * (top + bottom)
    assert ink(image)[r_top:r_bottom, r_left:r_right].mean() > 0.5
    assert 0.1 < ink(image).mean() < 0.7
    assert distinct_colours(image) > 1000  # shaded spheres coloured by radius


def test_paraview_files(finished):
    run, out, config = finished
    _, setup = load_case(run)
    vtk = out / "vtk"
    # by step (not by name: particles_7760 would follow particles_31040)
    particles, boxes = (
        sorted(vtk.glob(f"{kind}_*.vtk"), key=lambda p: int(p.stem.split("_")[1]))
        for kind in ("particles", "boxes")
    )
    # one file at step 0 and n_vtk more
    assert len(particles) == config["application"]["n_vtk"] + 1
    assert {p.name.split("_")[1] for p in particles} == {p.name.split("_")[1] for p in boxes}
    # the chute: inclined floor from its lower edge to its top, side walls, back wall
    chute = pyvista.read(vtk / "chute.vtk")
    (xe, ze), (xu, zu) = setup.chute_edge, setup.chute_top
    (y0, y1) = setup.chute_y
    assert chute.n_cells == 8
    np.testing.assert_allclose(chute.bounds, (xe, xu, y0, y1, ze, zu + setup.chute_wall_height))
    # the row of boxes where it was at each step: its front moves with the row
    for path in boxes:
        step = int(path.stem.split("_")[1])
        front = setup.box_front_x0 + setup.row_offset(step * setup.timestep)
        assert pyvista.read(path).bounds[1] == pytest.approx(front, abs=1e-9)
    last = pyvista.read(particles[-1])
    assert (
        last.n_points
        > 0.5 * json.loads((out / "segregation_index.json").read_text())["particles_fed_expected"]
    )
