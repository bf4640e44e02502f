"""Planning and condensing the convergence study of the virtual tests (no DEM runs here)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from demcal.bulk.convergence import (
    FACTORS,
    Factor,
    plan_study,
    restrict_levels,
    summarise,
)
from demcal.core.config import load_config

ROOT = Path(__file__).resolve().parents[2]
MIDDLE = {
    "coefficientFriction": 0.6,
    "coefficientRollingFriction": 0.3,
    "coefficientRestitution": 0.6,
    "density": 2500.0,
}
SET = {
    "coefficientFriction": 0.5,
    "coefficientRollingFriction": 0.2,
    "coefficientRestitution": 0.6,
    "density": 2500.0,
}


def test_levels_are_applied_and_the_base_run_is_shared(tmp_path: Path) -> None:
    settings = load_config(ROOT / "config" / "tiny.yaml")
    base_size = settings["shear_cell"]["dCylDp"]
    size = Factor(
        "size",
        "shear_cell",
        "dCylDp",
        tuple({"shear_cell.dCylDp": d} for d in (6, base_size)),
        "shear_cell.dCylDp",
    )
    speed = Factor(
        "speed",
        "shear_cell",
        "v",
        tuple(
            {"shear_cell.shear_speed": v}
            for v in (
                2 * settings["shear_cell"]["shear_speed"],
                settings["shear_cell"]["shear_speed"],
            )
        ),
        "shear_cell.shear_speed",
    )
    planned = plan_study(
        settings, {"a": SET}, [size, speed], [1, 2], tmp_path, "dem_engine -in {deck}", 2029.0
    )
    assert len(planned) == 2 * 2 * 2
    dirs = {job.case_dir for job, _, _ in planned}
    # The most refined level of both factors is the base configuration: one run per seed.
    assert len(dirs) == 3 * 2
    assert (tmp_path / "shear_cell" / "base" / "a" / "seed1" / "in.shear_cell").is_file()
    small = json.loads(
        (tmp_path / "shear_cell" / "shear_cell.dCylDp=6" / "a" / "seed2" / "case.json").read_text()
    )
    # dCylDp 6 is below the production minimum; the study renders it anyway.
    assert small["case"]["dCylDp"] == 6.0
    assert small["setup"]["radius"] == pytest.approx(6.0 * small["setup"]["reference_radius"])
    assert small["case"]["normal_stress"] == 2029.0
    # A finished run is not rendered again.
    status = tmp_path / "shear_cell" / "base" / "a" / "seed1" / "status.json"
    status.write_text('{"status": "ok"}')
    deck = status.parent / "in.shear_cell"
    deck.write_text("kept\n")
    plan_study(settings, {"a": SET}, [size], [1], tmp_path, "dem_engine -in {deck}", 2029.0)
    assert deck.read_text() == "kept\n"
    # Nor is it taken for a set of the same name with other values: that stops the study.
    other = {**SET, "coefficientFriction": SET["coefficientFriction"] + 0.1}
    with pytest.raises(ValueError, match=r"seed1: made earlier for set a with coefficientFriction"):
        plan_study(settings, {"a": other}, [size], [1], tmp_path, "dem_engine -in {deck}", 2029.0)
    assert deck.read_text() == "kept\n" and status.is_file()


def test_summary_measures_distance_to_the_most_refined_level() -> None:
    factor = FACTORS["shear_dCylDp"]
    levels = [factor.level_value(level) for level in factor.levels]
    rng = np.random.default_rng(3)
    # mu_psh falls from 1.0 towards 0.6 with cell size; the two largest cells differ by 3 %.
    truth = dict(zip(levels, (1.0, 0.8, 0.618, 0.6), strict=True))
    rows = [
        {
            "factor": factor.name,
            "level": lv,
            "set": "mid",
            "seed": s,
            "quantity": "mu_psh",
            "value": truth[lv] + 0.002 * rng.standard_normal(),
        }
        for lv in levels
        for s in (1, 2, 3)
    ]
    rows += [
        {
            "factor": "aor_lift_time",
            "level": lv,
            "set": "mid",
            "seed": 1,
            "quantity": "aor",
            "value": 30.0 + (3.0 if lv == 1.0 else 0.5),
        }
        for lv in (1.0, 2.0, 4.0, 8.0)
    ]
    summary = summarise(pd.DataFrame(rows), FACTORS).set_index(["factor", "level"])
    mu = summary.loc["shear_dCylDp"]
    assert mu.loc[levels[-1], "deviation"] == 0.0
    assert mu.loc[levels[0], "deviation"] == pytest.approx(0.4 / 0.6, abs=0.02)
    assert mu["converged"].tolist() == [False, False, True, True]
    assert (mu["n"] == 3).all() and (mu["sd"] < 0.01).all()
    # Seed noise of 0.002 on 0.6: every deviation but the reference's is beyond it.
    assert (mu["deviation_se"].iloc[:-1] < 0.01).all()
    assert mu["resolved"].tolist() == [True, True, True, False]
    # The angle of repose is judged in degrees: 3 deg off fails, 0 deg passes.
    aor = summary.loc["aor_lift_time"]
    assert aor.loc[1.0, "deviation"] == pytest.approx(2.5)
    assert aor["converged"].tolist() == [False, True, True, True]
    assert np.isnan(aor.loc[1.0, "sd"])


def test_ring_width_levels_keep_height_and_travel_in_particle_sizes(tmp_path: Path) -> None:
    settings = load_config(ROOT / "config" / "tiny.yaml")
    factor = FACTORS["ring_dCylDp"]
    planned = plan_study(
        settings, {"a": SET}, [factor], [1], tmp_path, "dem_engine -in {x}", 2029.0
    )
    assert len(planned) == len(factor.levels) == 4
    for job, _, overrides in planned:
        setup = json.loads((job.case_dir / "case.json").read_text())["setup"]
        r = setup["reference_radius"]
        assert setup["geometry"] == "ring"
        assert setup["radius"] == pytest.approx(overrides["shear_cell.dCylDp"] * r)
        assert setup["radius"] - setup["inner_radius"] == pytest.approx(setup["radius"] / 2)
        # Six diameters of bed and nine of pre-shear travel at every width.
        assert setup["fill_height"] == pytest.approx(12.0 * r)
        travel = setup["shear_speed"] * setup["preshear_time"]
        assert travel == pytest.approx(18.0 * r)
    # The level's words and numbers name its directory.
    assert "shear_cell.geometry=ring" in str(planned[0][0].case_dir)


def test_heap_size_levels_lift_at_the_quick_heaps_speed(tmp_path: Path) -> None:
    # A fixed lift time would raise the tube faster in wider cells, and a faster lift flattens
    # the heap: the size study would measure the lift speed too.
    settings = load_config(ROOT / "config" / "config.yaml")
    planned = plan_study(
        settings, {"a": SET}, [FACTORS["aor_dCylDp"]], [1], tmp_path, "dem_engine -in {x}", 2029.0
    )
    setups = {
        overrides["angle_of_repose.dCylDp"]: json.loads((job.case_dir / "case.json").read_text())[
            "setup"
        ]
        for job, _, overrides in planned
    }
    # The level at the profile's dCylDp is the profile's own heap (its lift time, 6.22 s, is
    # the level's 1.2 x 14 / 2.7 s rounded: the speed within 0.04 %).
    aor = settings["angle_of_repose"]
    assert aor["dCylDp"] == 14
    quick_setup = setups[14.0]
    assert quick_setup["lift_distance"] == pytest.approx(
        aor["lift_height"] * 2.0 * quick_setup["radius"]
    )
    assert quick_setup["lift_speed"] == pytest.approx(
        quick_setup["lift_distance"] / aor["lift_time"], rel=1e-3
    )
    speeds = []
    for d_cyl, setup in setups.items():
        assert setup["radius"] == pytest.approx(d_cyl * quick_setup["radius"] / 14.0)
        speeds.append(setup["lift_speed"])
    assert len(speeds) == 4
    assert speeds == pytest.approx([quick_setup["lift_speed"]] * 4, rel=1e-9)


def test_every_factor_level_renders_on_the_quick_profile(tmp_path: Path) -> None:
    # The study runs on config/config.yaml; a level that pins the split cell must also pin a
    # cycle mode the split cell can run (the quick ring continues, a split cell cannot).
    settings = load_config(ROOT / "config" / "config.yaml")
    factors = list(FACTORS.values())
    planned = plan_study(settings, {"a": SET}, factors, [1], tmp_path, "dem_engine -in {x}", 2029.0)
    assert len(planned) == sum(len(f.levels) for f in factors)
    for job, _, overrides in planned:
        record = json.loads((job.case_dir / "case.json").read_text())
        if record["test"] == "shear_cell":
            geometry = overrides.get("shear_cell.geometry", "ring")
            assert record["setup"]["geometry"] == geometry
            assert record["setup"]["cycle_mode"] == ("continue" if geometry == "ring" else "return")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--sets"], "no parameter sets"),
        (["--sets", "medium"], "unknown parameter sets ['medium']"),
        (["--extra-set", "s=coefficientFriction:0.5"], "--extra-set: parameter set s: missing"),
        (
            ["--factors", "aor_dCylDp", "--levels", "9", "12"],
            "--levels: factor aor_dCylDp: [12.0] are not among its levels ['6', '9', '14', '20']",
        ),
        (
            ["--extra-set", "middle=" + ",".join(f"{k}:{v}" for k, v in MIDDLE.items())],
            "a set named middle is already in the study",
        ),
        (["--set", "shear_cell.contact_snapshot=25"], "contact_snapshot"),
        (["--set", "contact_snapshots=25"], "expected SECTION.KEY=VALUE"),
    ],
)
def test_convergence_script_stops_on_bad_sets_before_any_run(
    tmp_path: Path, args: list[str], message: str
) -> None:
    out = tmp_path / "study"
    res = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "convergence_study.py"), *args, "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode != 0 and message in res.stderr, res.stderr
    assert not out.exists()


def test_restricted_levels_keep_their_order_and_the_most_refined_is_the_reference() -> None:
    heap = restrict_levels(FACTORS["aor_dCylDp"], [14.0, 9.0])
    assert [heap.level_value(v) for v in heap.levels] == [9.0, 14.0]
    assert heap.levels[-1] == FACTORS["aor_dCylDp"].levels[2]
    values = pd.DataFrame(
        {
            "factor": "aor_dCylDp",
            "set": "s",
            "quantity": "aor",
            "level": [9.0, 9.0, 14.0, 14.0],
            "seed": [1, 2, 1, 2],
            "value": [36.0, 34.0, 35.0, 35.0],
        }
    )
    summary = summarise(values, {"aor_dCylDp": heap}).set_index("level")
    assert summary.loc[14.0, "reference"] == 35.0 and summary.loc[9.0, "deviation"] == 0.0
    with pytest.raises(ValueError, match="not among its levels"):
        restrict_levels(FACTORS["aor_lift_time"], [3.0])
