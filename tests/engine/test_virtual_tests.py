"""The virtual bulk tests on the tiny profile with the real engine: physical trends, the bulk
value readout, the pictures, and cycles in one deck against separate runs.

Every case is rendered with :func:`demcal.decks.render.render_case` from ``config/tiny.yaml`` and
run by
the engine binary (``DEM_ENGINE``, else the installed or built one), two runs at a time. Runs
are deterministic (one thread, fixed seeds), so the margins below guard against changes of the
engine or the set-up, not against chance.

Typical values on the tiny profile: angle of repose 12-25 deg, mu_psh
0.5-1.6, mu_sh 0.5-1.5, rho_b about 1400 kg/m^3 at rho_p = 2500 kg/m^3.
"""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterable
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from demcal.bulk.values import extract
from demcal.core.config import load_config
from demcal.decks.render import DECK_NAMES, render_case
from tests.engine.conftest import engine_path

pytestmark = pytest.mark.engine

ROOT = Path(__file__).resolve().parents[2]

BASE = {
    "coefficientFriction": 0.3,
    "coefficientRollingFriction": 0.1,
    "coefficientRestitution": 0.6,
    "density": 2500.0,
}
AOR_BASE = {**BASE, "coefficientRollingFriction": 0.2}
SEEDS = (7, 11, 12, 13)
P_TRENDS = 0.8  # P < 1 for the shear-phase comparison


def _settings(seed: int = 7) -> dict:
    cfg = load_config(ROOT / "config" / "tiny.yaml")
    cfg["seed"] = seed
    return cfg


def _run_all(engine: str, jobs: Iterable[tuple[str, Path]], parallel: int = 2) -> None:
    """Runs the engine in each case directory, ``parallel`` at a time; fails on an error."""
    pending = list(jobs)
    running: list[tuple[subprocess.Popen, Path]] = []
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    while pending or running:
        while pending and len(running) < parallel:
            test, case_dir = pending.pop(0)
            cmd = [engine, "-in", DECK_NAMES[test], "-log", "log.txt", "-noprogress"]
            out = (case_dir / "engine.out").open("w")
            proc = subprocess.Popen(
                cmd, cwd=case_dir, stdout=out, stderr=subprocess.STDOUT, env=env
            )
            running.append((proc, case_dir))
        proc, case_dir = running.pop(0)
        code = proc.wait(timeout=600)
        assert code == 0, f"engine failed in {case_dir}:\n{(case_dir / 'engine.out').read_text()}"


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Renders and runs every case of this module once; returns case directories by name."""
    try:
        engine = engine_path()
    except RuntimeError as exc:
        pytest.skip(str(exc))
    root = tmp_path_factory.mktemp("virtual")
    stress = _settings()["shear_cell"]["normal_stresses"][0]
    shear = {**BASE, "normal_stress": stress}
    cases: dict[str, tuple[str, dict, int]] = {
        "aor_base": ("angle_of_repose", AOR_BASE, 7),
        "aor_mur": ("angle_of_repose", {**AOR_BASE, "coefficientRollingFriction": 0.8}, 7),
        "aor_mus": ("angle_of_repose", {**AOR_BASE, "coefficientFriction": 0.8}, 7),
        "shear_mus_low": ("shear_cell", {**shear, "coefficientFriction": 0.1, "P": P_TRENDS}, 7),
        "shear_mus_high": ("shear_cell", {**shear, "coefficientFriction": 0.8, "P": P_TRENDS}, 7),
        "shear_rho_high": ("shear_cell", {**shear, "density": 3500.0, "P": P_TRENDS}, 7),
        "cycles": ("shear_cell", shear, 7),
        **{f"shear_seed{s}": ("shear_cell", {**shear, "P": P_TRENDS}, s) for s in SEEDS},
        **{f"shear_p{p}": ("shear_cell", {**shear, "P": p}, 7) for p in (0.4, 0.6, 1.0)},
    }
    dirs: dict[str, Path] = {}
    for name, (test, case, seed) in cases.items():
        dirs[name] = root / name
        render_case(test, {"case_id": "c0001", **case}, _settings(seed), dirs[name])
    # Longest runs first, so that two engine processes stay busy to the end.
    order = sorted(cases, key=lambda n: (cases[n][0] != "angle_of_repose", n != "cycles"))
    _run_all(engine, ((cases[n][0], dirs[n]) for n in order))
    return dirs


def _shear(runs: dict[str, Path], name: str) -> pd.Series:
    table = extract("shear_cell", runs[name])
    assert len(table) == 1
    return table.iloc[0]


def _aor(runs: dict[str, Path], name: str) -> pd.Series:
    return extract("angle_of_repose", runs[name]).iloc[0]


# ---------------------------------------------------------------------------------------------
# angle of repose


def test_heaps_settle_and_sectors_agree(runs: dict[str, Path]) -> None:
    for name in ("aor_base", "aor_mur", "aor_mus"):
        row = _aor(runs, name)
        assert bool(row["settled"]), name
        assert row["n_particles_heap"] > 800
        assert 5.0 < row["aor"] < 45.0
        # Per-sector angles scatter by a few degrees around the hull angle.
        assert row["aor_sector_spread"] < 4.0
        assert row["aor_sector_min"] <= row["aor"] + 3.0 <= row["aor_sector_max"] + 6.0


def test_aor_rises_with_rolling_friction(runs: dict[str, Path]) -> None:
    base, rolling = _aor(runs, "aor_base"), _aor(runs, "aor_mur")
    # mu_r 0.2 -> 0.8 raises the tiny heap by 3-5 degrees; one heap scatters by about one degree
    # (round-off alone moves it that much), so the margin asked for is 2 degrees.
    assert rolling["aor"] > base["aor"] + 2.0
    assert rolling["aor_mean_slices"] > base["aor_mean_slices"] + 2.0


def test_aor_rises_with_sliding_friction(runs: dict[str, Path]) -> None:
    base, sliding = _aor(runs, "aor_base"), _aor(runs, "aor_mus")
    assert sliding["aor"] > base["aor"] + 1.5


# ---------------------------------------------------------------------------------------------
# shear cell


def test_mu_psh_rises_with_sliding_friction(runs: dict[str, Path]) -> None:
    low, high = _shear(runs, "shear_mus_low"), _shear(runs, "shear_mus_high")
    base = np.mean([_shear(runs, f"shear_seed{s}")["mu_psh"] for s in SEEDS])
    assert high["mu_psh"] > low["mu_psh"] + 0.3
    assert low["mu_psh"] < base < high["mu_psh"]
    # The shear phase follows the same order.
    assert high["mu_sh"] > low["mu_sh"] + 0.3


def test_bulk_density_scales_with_particle_density(runs: dict[str, Path]) -> None:
    light, heavy = _shear(runs, "shear_seed7"), _shear(runs, "shear_rho_high")
    assert heavy["rho_b"] / light["rho_b"] == pytest.approx(3500.0 / 2500.0, rel=0.03)
    # Packing fraction of the sheared bed: loose but granular.
    assert 0.45 < light["rho_b"] / 2500.0 < 0.65


def test_mu_sh_below_mu_psh_when_the_load_is_reduced(runs: dict[str, Path]) -> None:
    # Cohesionless spheres, P = 0.8: the freshly compressed bed reaches a peak in the
    # pre-shear; after unloading, the shear at the lower load stays below it.
    rows = [_shear(runs, f"shear_seed{s}") for s in SEEDS]
    mu_psh = np.array([r["mu_psh"] for r in rows])
    mu_sh = np.array([r["mu_sh"] for r in rows])
    assert all(r["P"] == P_TRENDS for r in rows)
    assert mu_sh.mean() < mu_psh.mean() - 0.05
    assert np.sum(mu_sh < mu_psh) >= 3


def test_load_condition_and_flags_in_the_table(runs: dict[str, Path]) -> None:
    table = extract("shear_cell", runs["shear_seed7"])
    row = table.iloc[0]
    assert (row["normal_stress"], row["P"], row["status"]) == (2029.0, P_TRENDS, "ok")
    assert row["steady_psh"] in (True, False) and row["steady_sh"] in (True, False)
    assert row["mu_psh_sem"] < 0.05 and row["mu_sh_sem"] < 0.05


# ---------------------------------------------------------------------------------------------
# pictures


def test_pictures_are_written(runs: dict[str, Path], tmp_path: Path) -> None:
    from demcal.virtual_tests.pictures import heap_picture, shear_cell_picture

    heap = heap_picture(runs["aor_base"], tmp_path / "heap.png")
    cell = shear_cell_picture(runs["shear_seed7"], tmp_path / "cell.png")
    for png in (heap, cell):
        data = png.read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
        assert len(data) > 20_000  # a rendered scene, not an empty canvas


# ---------------------------------------------------------------------------------------------
# cycles in one deck against separate runs


@pytest.mark.slow
def test_cycles_in_one_deck_versus_separate_runs(runs: dict[str, Path]) -> None:
    cycles = extract("shear_cell", runs["cycles"])
    assert cycles["P"].tolist() == [0.4, 0.6, 0.8, 1.0]
    separate = {
        0.4: _shear(runs, "shear_p0.4"),
        0.6: _shear(runs, "shear_p0.6"),
        0.8: _shear(runs, "shear_seed7"),
        1.0: _shear(runs, "shear_p1.0"),
    }
    # The first cycle is the same deck as the separate run up to its end: identical numbers.
    first = cycles.iloc[0]
    for key in ("mu_psh", "mu_sh", "rho_b"):
        assert first[key] == pytest.approx(separate[0.4][key], rel=1e-12)
    # Later cycles carry the shear history of the earlier ones: the bed compacts from cycle to
    # cycle and resists the shear phase more than a fresh sample does, beyond the
    # seed-to-seed scatter of fresh runs. This is why the workflow runs each load condition
    # separately (shear_cell.separate_runs).
    fresh = [_shear(runs, f"shear_seed{s}") for s in SEEDS]
    rho_scatter = np.std([r["rho_b"] for r in fresh], ddof=1)
    later = [(cycles.iloc[k], separate[p]) for k, p in ((1, 0.6), (2, 0.8), (3, 1.0))]
    denser = [c["rho_b"] - f["rho_b"] for c, f in later]
    assert all(d > 0 for d in denser)
    assert np.mean(denser) > 2.5 * rho_scatter
    mu_sh_scatter = np.std([r["mu_sh"] for r in fresh], ddof=1)
    stronger = [c["mu_sh"] - f["mu_sh"] for c, f in later]
    assert np.mean(stronger) > mu_sh_scatter
