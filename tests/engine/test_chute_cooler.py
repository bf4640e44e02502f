"""The tiny chute-cooler case end to end on the real engine, through the rule scripts:
render, run, analyse, figures and ParaView files."""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from demcal.application.chute_cooler.deck import load_case
from demcal.core.config import load_config
from demcal.engine_io.output import read_dump, read_print_file

from .conftest import engine_path

pytestmark = pytest.mark.engine

ROOT = Path(__file__).resolve().parents[2]
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def script(name: str):
    """Import a rule script from scripts/ as a module."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """The tiny case rendered, run and analysed, with its figures."""
    root = tmp_path_factory.mktemp("chute")
    config = load_config(ROOT / "config" / "tiny.yaml")
    assert config["application"]["parameters"] is not None
    run = root / "run"
    logs = root / "logs"
    script("render_chute_cooler").main(config, None, str(run / "in.chute_cooler"), str(logs / "r"))
    command = f"{engine_path()} -in {{deck}} -noprogress"
    script("run_chute_cooler").main(str(run / "in.chute_cooler"), command, 1, str(logs / "run"))
    out = root / "application"
    outputs = {
        "table": str(out / "segregation.csv"),
        "index": str(out / "segregation_index.json"),
        "series": str(out / "segregation_time_series.csv"),
        "steady": str(out / "steady_state.png"),
    }
    script("analyse_chute_cooler").main(str(run / "status.json"), outputs, config, str(logs / "a"))
    figures = {
        "fig11": str(out / "fig11_segregation.png"),
        "fig10": str(out / "fig10_layout.png"),
        "vtk": str(out / "vtk"),
    }
    inputs = {"status": str(run / "status.json"), "table": outputs["table"]}
    script("chute_cooler_figures").main(inputs, figures, str(logs / "f"))
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
    run, out, _ = finished
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
    assert (out / "segregation.csv.json").is_file()


def test_figures_and_paraview_files(finished):
    _, out, config = finished
    for name in ("fig11_segregation.png", "fig10_layout.png", "steady_state.png"):
        data = (out / name).read_bytes()
        assert data.startswith(PNG_MAGIC) and len(data) > 10_000
    vtk = out / "vtk"
    particles = sorted(vtk.glob("particles_*.vtk"))
    boxes = sorted(vtk.glob("boxes_*.vtk"))
    # one file at step 0 and n_vtk more
    assert len(particles) == config["application"]["n_vtk"] + 1
    assert {p.name.split("_")[1] for p in particles} == {p.name.split("_")[1] for p in boxes}
    assert (vtk / "chute.vtk").is_file()
