"""LIGGGHTS 3.8 runs every deck the project renders, and the project's readers parse what it
writes into bulk values.

The decks are rendered from ``config/tiny.yaml`` exactly as the workflow renders them: the shear
cell in both cycle modes (two load conditions each, to keep the runs short), single load
conditions (a ``P`` column) with cohesion and wall friction and without rolling friction, the
angle of repose and the chute cooler; the ring shear cell runs on two MPI ranks. Each run must exit
with 0, print no WARNING except those in ``conftest.ALLOWED_WARNINGS``, and give finite bulk
values in physical ranges.

Typical values on LIGGGHTS (tiny, rho_p = 2500 kg/m^3): mu_psh 0.4-1.2, mu_sh 0.6-1.5, rho_b
1150-1450 kg/m^3, angle of repose about 19 deg, solid fraction of the analysed chute-cooler box
about 0.5. About 1.5 minutes on one core, plus the two-rank run (10-60 s, depending on how busy the
cores are).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from demcal.application.chute_cooler.analysis import analyse_run, index_summary, vtk_steps
from demcal.application.chute_cooler.deck import DECK_NAME as CHUTE_DECK
from demcal.application.chute_cooler.deck import render_chute_cooler
from demcal.bulk.plane_check import plane_check
from demcal.bulk.shear_zone_check import shear_zone_check
from demcal.bulk.values import extract
from demcal.core.config import load_config
from demcal.engine_io.fix_output import read_print_file
from demcal.engine_io.local_dump import read_local_dump
from demcal.engine_io.vtk_file import read_vtk_particles
from demcal.robustness.base_decks import with_quick_ring
from demcal.virtual_tests.deck import DECK_NAMES, render_case
from tests.engine.conftest import TEST_RAYLEIGH_FRACTION

from .conftest import LiggghtsRun, run_liggghts, unexpected_warnings

pytestmark = pytest.mark.liggghts

ROOT = Path(__file__).resolve().parents[2]
DENSITY = 2500.0
BASE = {
    "case_id": "c0001",
    "coefficientFriction": 0.3,
    "coefficientRollingFriction": 0.1,
    "coefficientRestitution": 0.6,
    "density": DENSITY,
}
STRESS = 2029.0  # the tiny profile's pre-shear stress, Pa
TWO_CYCLES = [0.6, 1.0]

# name: (test, case row, configuration overrides per section)
SHEAR_CASES: dict[str, tuple[dict[str, Any], dict[str, dict[str, Any]]]] = {
    "return": (
        {**BASE, "normal_stress": STRESS},
        {"shear_cell": {"cycles": "return", "P": TWO_CYCLES}},
    ),
    "alternate": (
        {**BASE, "normal_stress": STRESS},
        {"shear_cell": {"cycles": "alternate", "P": TWO_CYCLES}},
    ),
    "cohesion_wall_friction": (
        {
            **BASE,
            "normal_stress": STRESS,
            "P": 0.8,
            "cohesionEnergyDensity": 5000.0,
            "wallFriction": 0.5,
        },
        {},
    ),
    "no_rolling_friction": (
        {**BASE, "normal_stress": STRESS, "P": 0.8},
        {"material": {"rolling_friction": False}, "shear_cell": {"contact_snapshots": 25}},
    ),
}


def settings(overrides: dict[str, dict[str, Any]] | None = None) -> dict[str, Any]:
    """The tiny profile at the tests' time step, with ``overrides`` merged per section."""
    cfg = load_config(ROOT / "config" / "tiny.yaml")
    cfg["material"]["rayleigh_fraction"] = TEST_RAYLEIGH_FRACTION
    for section, values in (overrides or {}).items():
        cfg[section].update(values)
    return cfg


def check_clean_run(run: LiggghtsRun) -> None:
    """Exit 0, a finished last run, and no WARNING but the allowed ones (screen and log)."""
    assert run.returncode == 0, run.describe()
    assert "ERROR" not in run.output, run.describe()
    assert "Loop time of" in run.log(), run.describe()
    unexpected = unexpected_warnings(run.output) + unexpected_warnings(run.log())
    assert not unexpected, "LIGGGHTS warned:\n" + "\n".join(sorted(set(unexpected)))


def check_shear_values(table: pd.DataFrame, expected_p: list[float]) -> None:
    assert table["P"].tolist() == expected_p
    assert (table["status"] == "ok").all()
    for key in ("mu_psh", "mu_sh", "rho_b"):
        assert np.isfinite(table[key].to_numpy()).all(), table
    assert ((table["mu_psh"] > 0.0) & (table["mu_psh"] < 1.5)).all(), table
    assert ((table["mu_sh"] > 0.0) & (table["mu_sh"] < 1.5)).all(), table
    # A granular bed: solid fraction between a loose (cohesive) and a dense random packing.
    fraction = table["rho_b"] / DENSITY
    assert ((fraction > 0.4) & (fraction < 0.7)).all(), table


def check_shear_snapshot(case_dir: Path) -> None:
    """The VTK snapshot LIGGGHTS writes at the end of the first pre-shear reads with pyvista."""
    vtk = read_vtk_particles(case_dir / "shear_preshear_end.vtk", arrays=["radius", "v"])
    assert 300 < len(vtk.points) < 2000
    assert vtk.arrays["v"].reshape(-1, 3).shape == vtk.points.shape
    radius = float(settings()["particles"]["radius"])
    assert np.allclose(vtk.arrays["radius"], radius, rtol=1e-5)


@pytest.mark.parametrize("name", list(SHEAR_CASES))
def test_shear_cell_deck_runs(name: str, tmp_path: Path) -> None:
    case, overrides = SHEAR_CASES[name]
    cfg = settings(overrides)
    render_case("shear_cell", case, cfg, tmp_path)
    run = run_liggghts(tmp_path, DECK_NAMES["shear_cell"])
    check_clean_run(run)
    expected_p = [case["P"]] if "P" in case else list(cfg["shear_cell"]["P"])
    table = extract("shear_cell", tmp_path)
    check_shear_values(table, expected_p)
    check_shear_snapshot(tmp_path)
    if cfg["shear_cell"]["contact_snapshots"]:
        check_shear_plane(tmp_path)


def check_shear_plane(case_dir: Path) -> None:
    """The wall-force readout and the contacts crossing the shear plane give the same mu in
    every cycle (the ring's torque readout against the contacts' torque about the axis)."""
    # Each contact once per snapshot, also when MPI ranks share it as a ghost pair (a double
    # count would cancel in mu, so it is checked on its own).
    for step, contacts in read_local_dump(case_dir / "contacts.dump"):
        pairs = np.sort(contacts.iloc[:, [6, 7]].to_numpy(), axis=1)
        assert len(np.unique(pairs, axis=0)) == len(pairs), step
    compared = plane_check(case_dir).windows
    # Snapshots sample the same plateaus as the print rows, more sparsely.
    assert (compared["snapshots"] >= 3).all(), compared
    assert np.allclose(compared["mu_plane"], compared["mu_wall"], rtol=0.1), compared


def test_ring_shear_cell_deck_runs_on_two_mpi_ranks(tmp_path: Path) -> None:
    # The ring cell (6 particle diameters wide) on two ranks: its turning floor, bars and
    # bands cross the sub-domain boundary. Two cycles in the quick profile's "continue" mode
    # (the next pre-shear follows the shear in the same direction). A shorter settling keeps
    # the run short when the two ranks share busy cores. Contact snapshots cross-check the
    # torque readout inside the bulk (each contact is dumped once, by the rank owning it).
    cfg = with_quick_ring(ROOT / "config" / "tiny.yaml")
    cfg["material"]["rayleigh_fraction"] = TEST_RAYLEIGH_FRACTION
    assert cfg["shear_cell"]["cycles"] == "continue"
    cfg["shear_cell"].update(settle_fall_times=1.0, P=TWO_CYCLES, contact_snapshots=25)
    record = render_case("shear_cell", {**BASE, "normal_stress": STRESS}, cfg, tmp_path)
    run = run_liggghts(tmp_path, DECK_NAMES["shear_cell"], ranks=2)
    check_clean_run(run)
    assert re.search(r"(1 by 1 by 2|1 by 2 by 1|2 by 1 by 1) MPI processor grid", run.stdout)
    values = extract("shear_cell", tmp_path)
    check_shear_values(values, TWO_CYCLES)
    check_shear_plane(tmp_path)
    # Sheared sphere packings: a macroscopic friction well below 1 (PHYSICS.md); the split
    # cell of the same size reads 1.5 and more at the quick scale.
    assert values["mu_psh"].between(0.3, 0.9).all(), values
    # The lower part turned one way through both cycles: the printed travel only falls.
    travel = read_print_file(tmp_path / "shear_cell.txt", columns=["phase", "travel"])
    sheared = travel[travel["phase"] >= 1]["travel"].to_numpy()
    assert np.all(np.diff(sheared) <= 0.0) and sheared[-1] < sheared[0], sheared
    vtk = read_vtk_particles(tmp_path / "shear_preshear_end.vtk", arrays=["radius", "v"])
    # Every particle stays in the annulus (none lost through the turning floor or the bands).
    reach = np.hypot(vtk.points[:, 0], vtk.points[:, 1])
    setup = record["setup"]
    assert reach.min() > setup["inner_radius"] and reach.max() < setup["radius"]
    assert vtk.points[:, 2].min() > 0.0
    table = read_print_file(tmp_path / "shear_cell.txt", columns=["phase", "mass"])
    sheared = table[table["phase"] >= 1]["mass"]
    assert sheared.min() == sheared.max()
    # rho_b of the quick ring is the interior annulus': LIGGGHTS' mass(all,region) at the
    # printed step next to the snapshot equals the snapshot's particles counted by centre
    # (a particle or two may cross the region's edge in between), and the interior packs
    # denser than the whole cell with its looser wall layers.
    assert setup["bulk_density"] == "interior"
    rows = read_print_file(tmp_path / "shear_cell.txt", columns=["step", "interior_mass"])
    near = rows.iloc[int((rows["step"] - setup["snapshot_step"]).abs().argmin())]
    r, z = np.hypot(vtk.points[:, 0], vtk.points[:, 1]), vtk.points[:, 2]
    inside = (
        (r > setup["interior_r_lo"])
        & (r < setup["interior_r_hi"])
        & (z > setup["interior_z_lo"])
        & (z < setup["interior_z_hi"])
    )
    counted = DENSITY * 4.0 / 3.0 * math.pi * float(np.sum(vtk.arrays["radius"][inside] ** 3))
    assert near["interior_mass"] == pytest.approx(counted, rel=0.03), (inside.sum(), near)
    assert (values["rho_b"] > values["rho_b_cell"]).all(), values
    # The turning floor's bars carry the bed's bottom, the lid's hold its top: the zone where
    # the speed falls from 0.9 to 0.1 of the floor's lies between the bar tips (engine, one
    # rank: 1.7-2.3 to 4.6-5.1 of 6 diameters).
    zone = shear_zone_check(tmp_path).summary
    assert 0.8 < zone["zone_lo_d"] < zone["zone_hi_d"] < zone["bed_d"] - 0.8, zone
    assert 1.0 < zone["width_d"] < 4.5 and zone["I_interior"] > zone["I_bed"], zone


def test_angle_of_repose_deck_runs(tmp_path: Path) -> None:
    case = {**BASE, "coefficientRollingFriction": 0.2}
    render_case("angle_of_repose", case, settings(), tmp_path)
    run = run_liggghts(tmp_path, DECK_NAMES["angle_of_repose"])
    check_clean_run(run)
    row = extract("angle_of_repose", tmp_path).iloc[0]
    assert row["status"] == "ok"
    assert bool(row["settled"])
    assert row["n_particles_heap"] > 800
    for key in ("aor", "aor_mean_slices", "aor_fit"):
        assert 8.0 < row[key] < 40.0, (key, row[key])
    assert row["aor_sector_spread"] < 5.0
    # LIGGGHTS' VTK dump (legacy format 5.1, velocities as one vector) carries the same heap.
    vtk = read_vtk_particles(tmp_path / "heap.vtk", arrays=["radius", "c_cn"])
    assert len(vtk.points) == row["n_particles_final"]


def test_chute_cooler_deck_runs(tmp_path: Path) -> None:
    cfg = settings()
    record = render_chute_cooler(cfg, tmp_path)
    run = run_liggghts(tmp_path, CHUTE_DECK)
    check_clean_run(run)
    table = read_print_file(tmp_path / record["files"]["table"], columns=["atoms", "mass"])
    last = table.iloc[-1]
    assert last["mass"] >= 0.9 * last["mass_inserted"]
    result, rec, _ = analyse_run(tmp_path)
    summary = index_summary(result, rec)
    assert summary["particles_in_box"] > 50
    assert 0.3 < summary["solid_fraction_of_box"] < 0.74
    for key in ("segregation_index", "sorted_index", "normalised_index"):
        assert summary[key] is not None and math.isfinite(summary[key]), (key, summary)
    assert abs(summary["normalised_index"]) <= 1.0
    # One VTK file per dump step (LIGGGHTS adds *_boundingBox_* files, which are not read).
    setup = record["setup"]
    steps = vtk_steps(tmp_path)
    every = int(setup["vtk_every"])
    assert [s for s, _ in steps] == list(range(0, int(setup["total_steps"]) + 1, every))
    vtk = read_vtk_particles(steps[-1][1], arrays=["radius"])
    assert len(vtk.points) == int(last["atoms"])
