"""Add step: the extended training data, the extended surrogates and the Show tables."""

import json
import math

import numpy as np
import pandas as pd
import pytest
from matplotlib.container import BarContainer

from demcal.bulk.synthetic import replicate_record
from demcal.discrepancy.candidates import Candidate
from demcal.discrepancy.extension import (
    extended_training_data,
    rmse_of,
    train_extended_surrogate,
)
from demcal.discrepancy.report import gap_figure, gap_of, gap_table, markdown_table
from demcal.discrepancy.run_results import read_runs, replicate_statistics, run_values
from demcal.surrogates.training import load_surrogate
from tests.figures import read_png, saved_figures

COHESION = Candidate(
    "cohesion", "d", {}, "cohesionEnergyDensity", None, 0.0, (0.0, 5e4), (4e4,), False
)
WALL = Candidate(
    "wallfriction", "d", {}, "wallFriction", None, "coefficientFriction", (0.1, 1.0), (0.8,)
)


def shear_rows(case: str, mu: float, **extra) -> pd.DataFrame:
    return pd.DataFrame(
        {
            "test": "shear_cell",
            "case_id": [f"{case}_s1", f"{case}_s1"],
            "run": [f"{case}_s1", f"{case}_s1"],
            "coefficientFriction": mu,
            "normal_stress": 1068.0,
            "P": [0.5, 1.0],
            "mu_psh": [0.6, 0.7],
            "status": "ok",
            **extra,
        }
    )


def test_extended_data_fills_the_magnitude_of_every_source():
    base = pd.concat([shear_rows("c0001", 0.3), shear_rows("c0002", 0.6)])
    probes = pd.concat(
        [
            shear_rows("ref", 0.4, discrepancy_candidate="none"),
            shear_rows(
                "cohesion1", 0.4, discrepancy_candidate="cohesion", cohesionEnergyDensity=4e4
            ),
            shear_rows("rolling1", 0.4, discrepancy_candidate="rolling"),
        ]
    )
    ext = shear_rows("e0001", 0.5, discrepancy_candidate="cohesion", cohesionEnergyDensity=1e4)
    data = extended_training_data(base, probes, ext, COHESION, ["shear_cell"])
    assert data["source"].value_counts().to_dict() == {"base": 4, "probe": 4, "extended": 2}
    assert "rolling1_s1" not in set(data["run"])
    by_run = data.groupby("run")["cohesionEnergyDensity"].first()
    assert by_run["c0001_s1"] == 0.0 and by_run["ref_s1"] == 0.0
    assert by_run["cohesion1_s1"] == 4e4 and by_run["e0001_s1"] == 1e4


def test_extended_data_absent_value_from_another_parameter():
    base = shear_rows("c0001", 0.3)
    data = extended_training_data(base, pd.DataFrame(), pd.DataFrame(), WALL, ["shear_cell"])
    assert (data["wallFriction"] == 0.3).all()


def test_read_runs_joins_the_case_description(tmp_path):
    case_dir = tmp_path / "probes" / "shear_cell" / "polydispersity1_s1"
    case_dir.mkdir(parents=True)
    shear_rows("polydispersity1", 0.4).drop(columns=["run"]).to_csv(case_dir / "bulk.csv")
    (case_dir / "case.json").write_text(
        json.dumps({"case": {"case_id": "x", "sizeClasses": 3.0, "discrepancy_candidate": "p"}})
    )
    runs = read_runs([case_dir / "bulk.csv"])
    assert (runs["sizeClasses"] == 3.0).all() and (runs["discrepancy_candidate"] == "p").all()
    assert (runs["run"] == "polydispersity1_s1").all()
    with pytest.raises(FileNotFoundError, match=r"case\.json"):
        read_runs([tmp_path / "nowhere" / "bulk.csv"])


def test_run_values_match_observations_by_load():
    runs = pd.concat([shear_rows("ref", 0.4), shear_rows("cohesion1", 0.4, mu_psh=[0.9, 1.0])])
    runs.loc[runs["run"] == "cohesion1_s1", "mu_psh"] = [0.9, 1.0]
    obs = pd.DataFrame(
        {
            "observable": ["mu_psh", "mu_psh", "mu_psh"],
            "normal_stress": [1068.0] * 3,
            "P": [1.0, 0.5, 0.8],
        }
    )
    assert run_values(runs, "ref", obs)[:2] == pytest.approx([0.7, 0.6])
    assert math.isnan(run_values(runs, "ref", obs)[2])
    assert run_values(runs, "cohesion1", obs)[:2] == pytest.approx([1.0, 0.9])


def test_extended_surrogate_learns_the_new_input(tmp_path):
    rng = np.random.default_rng(4)
    n = 120
    data = pd.DataFrame(
        {
            "test": "shear_cell",
            "coefficientFriction": rng.uniform(0.1, 0.9, n),
            "density": rng.uniform(2500, 3500, n),
            "cohesionEnergyDensity": rng.uniform(0, 5e4, n),
            "normal_stress": rng.choice([1068.0, 2029.0], n),
            "P": rng.choice([0.5, 1.0], n),
            "status": "ok",
            "source": "extended",
        }
    )
    data["rho_b"] = (
        data["density"]
        * 0.55
        * (1 + 0.1 * data["cohesionEnergyDensity"] / 5e4 * 1068.0 / data["normal_stress"])
    )
    settings = {
        "seed": 3,
        "split": [0.7, 0.15, 0.15],
        "hidden_sizes": [3, 4],
        "max_epochs": 400,
        "patience": 30,
    }
    path = tmp_path / "rho_b" / "model.pt"
    meta = train_extended_surrogate(data, "rho_b", settings, ["cohesionEnergyDensity"], path)
    assert "cohesionEnergyDensity" in meta["features"]
    assert meta["test_metrics"]["r2"] > 0.97
    model, features = load_surrogate(path)
    assert features == meta["features"]
    # Held-out RMSE: generalisation and test sets pooled.
    val_rmse = math.sqrt(
        json.loads(path.with_name("model.pt.json").read_text())["training"]["val_mse"]
    )
    test_rmse = meta["test_metrics"]["rmse"]
    assert min(val_rmse, test_rmse) <= rmse_of(path) <= max(val_rmse, test_rmse)
    X = data[features].to_numpy()
    assert np.sqrt(np.mean((model.predict(X) - data["rho_b"]) ** 2)) < 0.02 * 1650


def test_gap_table_and_figure(tmp_path):
    # Two fitted observations and one at a held-out load (no surrogate value there).
    before = pd.DataFrame(
        {
            "observable": ["mu_psh", "rho_b", "mu_psh"],
            "normal_stress": [1068.0, 1068.0, 1500.0],
            "P": [1.0, 1.0, 0.5],
            "measured": [0.7, 1700.0, 0.65],
            "sigma": [0.1, 10.0, 0.05],
            "at_best": [0.5, 1660.0, math.nan],
            "z_at_best": [-2.0, -4.0, math.nan],
            "held_out": [False, False, True],
        }
    )
    after = before.iloc[:2].assign(at_best=[0.68, 1705.0], z_at_best=[-0.2, 0.5], sigma=[0.1, 12.0])
    dem_before = (np.array([0.45, 1650.0, 0.55]), np.array([0.02, 5.0, 0.01]), np.array([3, 3, 3]))
    dem_after = (
        np.array([0.72, 1710.0, 0.66]),
        np.array([0.03, 4.0, math.nan]),
        np.array([3, 3, 1]),
    )
    table = gap_table(before, after, dem_before, dem_after)
    assert table["z_dem_before"].to_numpy() == pytest.approx([-2.5, -5.0, -2.0])
    assert table["z_dem_after"].to_numpy() == pytest.approx([0.2, 1.0, 0.2])
    assert list(table["held_out"]) == [False, False, True]
    assert list(table["dem_after_runs"]) == [3, 3, 1]
    assert gap_of(table["z_before"]) == pytest.approx(math.sqrt(10.0))
    assert math.isnan(gap_of([math.nan]))  # nothing is finite
    with saved_figures() as figures:
        gap_figure(table, "test", tmp_path / "gap.png")
    ((dem, surrogate),) = [f.axes for f in figures]
    assert figures[0].get_suptitle() == "test"
    # DEM panel first: |z| of the replicate means on the current sigma, error bars one
    # replicate sd in sigma units (none where a single run finished).
    bars = [b for b in dem.patches if b.get_width() == pytest.approx(0.4)]
    assert [b.get_x() + 0.2 for b in bars] == pytest.approx([-0.2, 0.8, 1.8, 0.2, 1.2, 2.2])
    assert [b.get_height() for b in bars] == pytest.approx([2.5, 5.0, 2.0, 0.2, 1.0, 0.2])
    errors = [c for c in dem.containers if isinstance(c, BarContainer) and c.errorbar]
    segments = [seg for c in errors for seg in c.errorbar.lines[2][0].get_segments()]
    lengths = [seg[1][1] - seg[0][1] for seg in segments]
    assert lengths == pytest.approx([0.4, 1.0, 0.4, 0.6, 0.8, 0.0])
    legend = [t.get_text() for t in dem.get_legend().get_texts()]
    fitted = table[~table["held_out"]]
    assert legend == [
        f"before (gap {gap_of(fitted['z_dem_before']):.2f}, held out 2.00)",
        f"after (gap {gap_of(fitted['z_dem_after']):.2f}, held out 0.20)",
    ]
    # Surrogate panel: the common sigma (0.1 for mu_psh, the after model's 12 kg/m^3 for
    # rho_b); nothing at the held-out load.
    heights = [b.get_height() for b in surrogate.patches if b.get_width() == pytest.approx(0.4)]
    assert heights[:2] == pytest.approx([2.0, 40.0 / 12.0])
    assert heights[3:5] == pytest.approx([0.2, 5.0 / 12.0])
    labels = [t.get_text() for t in surrogate.get_xticklabels()]
    assert labels == [
        "mu_psh\n1068 Pa, P=1",
        "rho_b\n1068 Pa, P=1",
        "mu_psh\n1500 Pa, P=0.5\n(held out)",
    ]
    assert read_png(tmp_path / "gap.png").shape == (840, 720, 3)  # 6 x 7 in at 120 dpi
    text = markdown_table(table[["observable", "z_before"]])
    assert text.splitlines()[2] == "| mu_psh | -2 |"


def test_replicate_statistics_over_seeds():
    obs = pd.DataFrame({"observable": ["mu_psh"], "normal_stress": [1068.0], "P": [0.5]})
    runs = pd.DataFrame(
        {
            "test": "shear_cell",
            "run": ["ref_s1", "ref_r2_s1", "ref_r3_s1", "ref_r4_s1", "ref_h1"],
            "normal_stress": [1068.0, 1068.0, 1068.0, 1068.0, 1500.0],
            "P": 0.5,
            "mu_psh": [0.60, 0.64, 0.68, 0.99, 0.5],
            "status": ["ok", "ok", "ok", "failed", "ok"],
        }
    )
    mean, sd, n = replicate_statistics(runs, ["ref", "ref_r2", "ref_r3", "ref_r4"], obs)
    assert mean == pytest.approx([0.64])
    assert sd == pytest.approx([0.04])
    assert list(n) == [3]
    mean, sd, n = replicate_statistics(runs, ["ref"], obs)
    assert mean == pytest.approx([0.60]) and math.isnan(sd[0]) and list(n) == [1]


def test_replicate_record_states_mean_and_scatter():
    bulk = pd.DataFrame(
        {
            "test": "shear_cell",
            "normal_stress": 1068.0,
            "P": 0.5,
            "replicate": [0, 1, 2],
            "mu_psh": [0.5, 0.6, 0.7],
            "mu_sh": [0.4, 0.4, 0.4],
            "rho_b": [1700.0, 1710.0, np.nan],
        }
    )
    record = replicate_record(bulk, "m", {}, 1, "test")
    (entry,) = record["shear_cell"]
    # Standard error of the mean of three: 0.1 / sqrt(3).
    se = 0.1 / math.sqrt(3.0)
    assert entry["mu_psh"] == pytest.approx(0.6) and entry["mu_psh_sd"] == pytest.approx(se)
    assert entry["mu_sh_sd"] == 0.0
    assert entry["rho_b"] == pytest.approx(1705.0)
    # The run without a density is left out of the mean, and the source says so.
    assert record["source"] == "test; runs with a value: rho_b at 1068 Pa, P 0.5: 2 of 3"
    noisy = replicate_record(bulk, "m", {"mu_psh": 0.01, "rho_b": 0.02}, 1, "test")
    noisy = noisy["shear_cell"][0]
    # The sd also covers the added noise: sqrt(se^2 + (0.01 * 0.6)^2).
    assert noisy["mu_psh_sd"] == pytest.approx(math.hypot(se, 0.006), rel=1e-5)
    assert noisy["mu_psh"] != pytest.approx(0.6, abs=1e-9)
    # Each observable gets its own level; one without a level gets none.
    assert noisy["rho_b_sd"] == pytest.approx(math.hypot(5.0, 0.02 * 1705.0), rel=1e-5)
    assert noisy["mu_sh"] == pytest.approx(0.4) and noisy["mu_sh_sd"] == 0.0
    assert "angle_of_repose" not in record


def test_replicate_record_keeps_the_readings_and_loads_asked_for():
    bulk = pd.DataFrame(
        {
            "test": ["shear_cell"] * 4 + ["angle_of_repose"],
            "normal_stress": [1068.0, 1068.0, 2029.0, 2029.0, np.nan],
            "P": [0.6, 1.0, 0.6, 1.0, np.nan],
            "replicate": 0,
            "mu_psh": [0.7, 0.6, 0.68, 0.58, np.nan],
            "mu_sh": [0.5, 0.55, 0.48, 0.52, np.nan],
            "rho_b": [1500.0, 1510.0, 1520.0, 1530.0, np.nan],
            "aor": [np.nan] * 4 + [31.0],
        }
    )
    record = replicate_record(bulk, "m", {}, 1, "t", observables=["mu_psh", "rho_b"], p_values=[1])
    assert [(c["normal_stress"], c["P"]) for c in record["shear_cell"]] == [
        (1068.0, 1.0),
        (2029.0, 1.0),
    ]
    assert [c["mu_psh"] for c in record["shear_cell"]] == [0.6, 0.58]
    assert record["source"] == "t"
    assert all("mu_sh" not in c for c in record["shear_cell"])
    assert record["angle_of_repose"]["value"] == 31.0
