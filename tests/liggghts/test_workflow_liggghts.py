"""The whole workflow with LIGGGHTS 3.8 as the DEM engine, and its verification on two engines.

The study is the tiny profile made smaller, to keep it short on two cores: 6 parameter sets, one
normal stress, two P values in one shear run per set (``separate_runs: false``), a smaller
angle-of-repose tube lifted faster, and smaller surrogates and screening grid. It still writes
every output of the default target.

Ranks: the design cases (and the chute cooler) run on one rank each, ``liggghts -in {deck}``,
two at a time. On two oversubscribed MPI ranks a case takes several times as long as on one (see
the verification times below), too slow for the whole design. The verification runs the
identified set on two engines, ``verification.engines``: LIGGGHTS on two MPI ranks (``mpirun
--allow-run-as-root --oversubscribe -np {threads} liggghts -in {deck}``,
``verification.threads: 2``) and the bundled engine, and the verification table reports both
side by side.

Run time: 8 min in each of two runs while other jobs kept the load average of the two cores at
10-16: the 12 design cases 10-43 s each on one rank (2.4-3.5 min with the chute cooler), the
surrogates and the screening 1.5 min, the verification 2.7-3.9 min (LIGGGHTS on two ranks
98-124 s for the shear cell and 32-72 s for the angle of repose, the bundled engine 15-17 s).
Oversubscribed MPI ranks suffer most from other load, so the verification shrinks most on idle
cores.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from tests.workflow.test_tiny_workflow import snakemake

from .conftest import LIGGGHTS, liggghts_env

pytestmark = [pytest.mark.liggghts, pytest.mark.workflow, pytest.mark.slow]

ROOT = Path(__file__).resolve().parents[2]

MPI_LIGGGHTS = "mpirun --allow-run-as-root --oversubscribe -np {threads} liggghts -in {deck}"
ENGINES = {"liggghts": MPI_LIGGGHTS, "bundled": "dem_engine -in {deck}"}
N_SETS = 6

#: The tiny profile, smaller (sections merged key by key over config/tiny.yaml).
OVERLAY = {
    "engine": {"command": "liggghts -in {deck}", "threads": 1},
    "verification": {"engines": ENGINES, "threads": 2},
    "design": {"kind": "lhs", "n": N_SETS, "seed": 3},
    # The shear cell keeps tiny's 10 particle diameters.
    "shear_cell": {"P": [0.5, 1.0], "separate_runs": False},
    "angle_of_repose": {"dCylDp": 8, "lift_time": 0.6},
    "surrogate": {"hidden_sizes": [4, 6], "max_epochs": 200, "patience": 20},
    "screening": {
        "axes": {
            "coefficientFriction": [0.1, 1.0, 30],
            "coefficientRollingFriction": [0.1, 1.0, 30],
            "coefficientRestitution": [0.5, 0.9, 8],
            "density": [2500.0, 3500.0, 8],
        }
    },
}


def smaller_than_tiny() -> dict:
    """config/tiny.yaml with :data:`OVERLAY` merged into its sections."""
    config = yaml.safe_load((ROOT / "config" / "tiny.yaml").read_text())
    for section, values in OVERLAY.items():
        config[section] = {**config.get(section, {}), **values}
    return config


@pytest.fixture(scope="module")
def study(tmp_path_factory, monkeypatch_module) -> Path:
    """Run the study once in a scratch directory."""
    work = tmp_path_factory.mktemp("liggghts_study")
    for item in ("config", "templates", "workflow"):
        shutil.copytree(ROOT / item, work / item)
    # In the order written: LIGGGHTS, the engine of the study, is the verification's reference.
    (work / "config.yaml").write_text(yaml.safe_dump(smaller_than_tiny(), sort_keys=False))
    res = snakemake(work, timeout=900)
    assert res.returncode == 0, res.stderr[-6000:]
    return work


@pytest.fixture(scope="module")
def monkeypatch_module():
    """Open MPI as root (CI containers) and one OpenMP thread, for the whole module."""
    with pytest.MonkeyPatch.context() as patch:
        for key, value in liggghts_env().items():
            patch.setenv(key, value)
        yield patch


def _status(case_dir: Path) -> dict:
    return json.loads((case_dir / "status.json").read_text())


def test_dataset_from_liggghts(study):
    results = study / "results"
    data = pd.read_csv(results / "bulk" / "dataset.csv")
    assert len(data) == N_SETS * (2 + 1)  # per set: 2 P values of one shear run + 1 AoR
    assert (data["status"] == "ok").all(), data.loc[data["status"] != "ok"].to_string()
    assert pd.read_csv(results / "bulk" / "failed_cases.csv").empty
    shear = data[data["test"] == "shear_cell"]
    values = shear[["mu_psh", "mu_sh", "rho_b"]].to_numpy()
    assert np.isfinite(values).all()
    assert (shear["rho_b"] / shear["density"]).between(0.4, 0.7).all()
    assert shear[["mu_psh", "mu_sh"]].gt(0.05).all().all()
    # Friction of a bulk solid; the tiny cell (10 particle diameters) reads high, and an
    # over-consolidated sample sheared at half its pre-shear load (P 0.5) higher still.
    assert shear["mu_psh"].lt(1.5).all(), shear[["mu_psh", "mu_sh"]]
    assert shear["mu_sh"].lt(2.5).all(), shear[["mu_psh", "mu_sh"]]
    aor = data.loc[data["test"] == "angle_of_repose", "aor"]
    assert np.isfinite(aor).all() and aor.between(5.0, 50.0).all()
    # Every design case ran LIGGGHTS on one rank: its command, its log and its banner.
    cases = sorted((results / "cases").glob("*/*/status.json"))
    assert len(cases) == 2 * N_SETS
    for path in cases:
        status = _status(path.parent)
        assert status["status"] == "ok" and status["command"][0] == str(LIGGGHTS), path
        assert (path.parent / "log.liggghts").is_file(), path
        assert "LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8" in (path.parent / "engine.out").read_text()
    run_times = pd.read_csv(results / "bulk" / "run_times.csv")
    assert len(run_times) == 2 * N_SETS and (run_times["seconds"] > 0).all()


def test_identification_outputs(study):
    results = study / "results"
    table5 = pd.read_csv(results / "identification" / "table5.csv")
    assert list(table5.columns) == ["parameter", "statistic", "SSC", "AoR", "SSC & AoR"]
    assert "| valid sets | number |" in (results / "identification" / "table5.md").read_text()
    identified = json.loads((results / "identification" / "identified_parameters.json").read_text())
    material = (results / "identification" / "material.in").read_text()
    for name in ("coefficientFriction", "coefficientRollingFriction", "coefficientRestitution"):
        mean = identified["parameters"][name]["mean"]
        assert f"{name} peratomtypepair 2 " + " ".join([repr(mean)] * 4) in material, name
    for output in ("mu_psh", "mu_sh", "rho_b", "aor"):
        assert (results / "surrogates" / output / "model.pt").is_file(), output
    assert (results / "surrogates" / "table4.md").is_file()
    assert len(pd.read_csv(results / "application" / "segregation.csv")) > 0
    assert (results / "application" / "fig11_segregation.png").is_file()


def test_verification_on_two_engines(study):
    results = study / "results"
    # Each engine ran the identified set in its own directory, LIGGGHTS on two MPI ranks, and
    # both finish: the bundled engine, like LIGGGHTS, carries on through a contact pinched at
    # the rim of the split (it only warns, see docs/virtual-tests.md, known limits).
    for engine, program in (("liggghts", "mpirun"), ("bundled", "dem_engine")):
        runs = sorted((results / "verification" / engine).glob("*/*/status.json"))
        assert len(runs) == 2, engine  # one shear run (both P), one angle of repose
        for path in runs:
            status = _status(path.parent)
            assert status["status"] == "ok", (path, status["error"])
            assert Path(status["command"][0]).name == program, status["command"]
            assert status["threads"] == 2
    for path in (results / "verification" / "liggghts").glob("*/*/status.json"):
        command = _status(path.parent)["command"]
        assert command[command.index("-np") + 1] == "2", command
        assert Path(command[command.index("-in") - 1]).name == "liggghts", command
        out = (path.parent / "engine.out").read_text()
        assert "LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8" in out
        grid = re.search(r"(\d+) by (\d+) by (\d+) MPI processor grid", out)
        assert grid is not None and np.prod([int(n) for n in grid.groups()]) == 2, out[:2000]
    table = pd.read_csv(results / "verification" / "verification.csv")
    assert list(table["observable"]) == ["mu_psh", "rho_b", "aor"]
    for engine in ("liggghts", "bundled"):
        dem = table[f"dem_{engine}"]
        assert np.isfinite(dem).all(), engine
        deviation = (1.0 - dem / table["measured"]).abs()
        np.testing.assert_allclose(table[f"deviation_{engine}"], deviation)
        assert list(table[f"within_tolerance_{engine}"]) == list(deviation < 0.05)
    assert list(table.columns[5:10]) == [
        f"{c}_liggghts" for c in ("dem", "dem_sd", "runs", "deviation", "within_tolerance")
    ]
    # one verification seed in this study: every finished value is one run, without scatter
    assert table["runs_liggghts"].eq(1).all() and table["dem_sd_liggghts"].isna().all()
    difference = (1.0 - table["dem_bundled"] / table["dem_liggghts"]).abs()
    np.testing.assert_allclose(table["engine_difference"], difference)
    text = (results / "verification" / "verification.md").read_text()
    assert "dem_liggghts" in text and "dem_bundled" in text and "engine_difference" in text
    assert MPI_LIGGGHTS in text
    print("\n" + text)
