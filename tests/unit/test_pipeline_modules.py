"""Case enumeration, engine runs with status records, the tidy dataset, experiments, calibration."""

import gzip
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import torch
import yaml

from demcal.bulk.dataset import (
    case_rows,
    collect,
    replicate_means,
    ringing_notes,
    training_rows,
    usable,
)
from demcal.core.config import ConfigError, validate_config
from demcal.core.experiments import Experiment, MeasuredCondition, load_experiment
from demcal.design.cases import (
    REPLICATE_SEED_STEP,
    case_ids,
    case_row,
    design_from_config,
    replicate_seed,
    verification_case,
    verification_case_ids,
)
from demcal.engine_io.run import engine_command, run_deck
from demcal.identification.calibration import (
    CalibrationResult,
    ConstantInputs,
    calibrate,
    write_valid_sets,
)
from demcal.identification.identify import mean_set_statement
from demcal.identification.verification import verification_table
from demcal.identification.verification_run import (
    dem_verdict,
    mean_interval,
    undecided,
    verdict_interval,
    write_verification_table,
)
from tests.engine.conftest import engine_path

ROOT_DIR = Path(__file__).resolve().parents[2]


@pytest.fixture
def config():
    return validate_config({"design": {"kind": "lhs", "n": 3, "seed": 2}}, "test")


def test_case_ids_and_rows(config):
    design = design_from_config(config)
    ids = case_ids(config, design, "shear_cell")
    assert ids[:3] == ["c0001_s1_p1", "c0001_s1_p2", "c0001_s1_p3"]
    assert len(ids) == 3 * len(config["shear_cell"]["normal_stresses"]) * len(
        config["shear_cell"]["P"]
    )
    cycles = dict(config, shear_cell=dict(config["shear_cell"], separate_runs=False))
    assert case_ids(cycles, design, "shear_cell")[:2] == ["c0001_s1", "c0001_s2"]
    assert case_row(cycles, design, "shear_cell", "c0001_s2")["normal_stress"] == 2029.0
    assert case_ids(config, design, "angle_of_repose") == ["c0001", "c0002", "c0003"]
    row = case_row(config, design, "shear_cell", "c0002_s3_p2")
    assert row["normal_stress"] == config["shear_cell"]["normal_stresses"][2]
    assert row["P"] == config["shear_cell"]["P"][1]
    assert row["coefficientFriction"] == pytest.approx(design.iloc[1]["coefficientFriction"])
    with pytest.raises(KeyError, match="c0009"):
        case_row(config, design, "angle_of_repose", "c0009")


def test_verification_case_uses_identified_means(config):
    identified = {"parameters": {"coefficientFriction": {"mean": 0.5, "sd": 0.1}}}
    row = verification_case(config, identified, "shear_cell", "identified_s2_p4")
    assert row == {
        "case_id": "identified_s2_p4",
        "coefficientFriction": 0.5,
        "normal_stress": config["shear_cell"]["normal_stresses"][1],
        "P": config["shear_cell"]["P"][3],
        "seed": config["seed"],
    }
    # Replicate 3 of a three-seed verification: same set and load, its own insertion seed.
    third = verification_case(config, identified, "shear_cell", "identified3_s2_p4")
    assert third["seed"] == config["seed"] + 2 * REPLICATE_SEED_STEP
    assert {k: v for k, v in third.items() if k not in ("seed", "case_id")} == {
        k: v for k, v in row.items() if k not in ("seed", "case_id")
    }
    replicated = {**config, "verification": {"seeds": 3}}
    assert verification_case_ids(replicated, "angle_of_repose") == [
        "identified",
        "identified2",
        "identified3",
    ]
    assert len(verification_case_ids(replicated, "shear_cell")) == 3 * len(
        verification_case_ids(config, "shear_cell")
    )
    # Heaps may replicate apart: nine heaps beside three runs of every shear deck.
    heaps = {**config, "verification": {"seeds": 3, "repose_seeds": 9}}
    assert verification_case_ids(heaps, "angle_of_repose")[-2:] == ["identified8", "identified9"]
    assert verification_case_ids(heaps, "shear_cell") == verification_case_ids(
        replicated, "shear_cell"
    )
    assert verification_case(config, identified, "angle_of_repose", "identified9")["seed"] == (
        config["seed"] + 8 * REPLICATE_SEED_STEP
    )
    with pytest.raises(KeyError, match="not a verification case"):
        replicate_seed(config, "c0001")
    with pytest.raises(ValueError, match="no parameter set"):
        verification_case(config, {"parameters": {}}, "angle_of_repose", "identified")


def test_engine_command_template():
    cmd = engine_command("sh -c {threads} -in {deck}", "in.x", 4)
    assert cmd[0].endswith("/sh") and cmd[1:] == ["-c", "4", "-in", "in.x"]
    with pytest.raises(ValueError, match="placeholder"):
        engine_command("dem_engine -in {input}", "in.x", 1)


@pytest.mark.engine
def test_run_deck_records_success_and_failure(tmp_path):
    template = f"{engine_path()} -in {{deck}} -noprogress"
    (tmp_path / "ok.in").write_text('print "hello"\n')
    status = run_deck(tmp_path, "ok.in", template, 1)
    assert status["status"] == "ok" and status["returncode"] == 0
    (tmp_path / "bad.in").write_text("units si\nfrobnicate\n")
    status = run_deck(tmp_path, "bad.in", template, 1)
    assert status["status"] == "failed"
    assert status["error"].startswith("ERROR: bad.in:2: frobnicate:")
    assert json.loads((tmp_path / "status.json").read_text())["status"] == "failed"
    (tmp_path / "status.json").unlink()
    with pytest.raises(FileNotFoundError, match="no_such_engine_binary"):
        run_deck(tmp_path, "ok.in", "no_such_engine_binary -in {deck}", 1)
    assert not (tmp_path / "status.json").exists()


def _case_dir(tmp_path, name, status, test="shear_cell"):
    d = tmp_path / name
    d.mkdir()
    case = {
        "case_id": name,
        "coefficientFriction": 0.4,
        "coefficientRollingFriction": 0.3,
        "coefficientRestitution": 0.6,
        "density": 2600.0,
        "normal_stress": 2029.0,
    }
    (d / "case.json").write_text(json.dumps({"case": case, "setup": {"dCylDp": 10}}))
    (d / "status.json").write_text(
        json.dumps({"status": status, "error": "ERROR: boom", "seconds": 1.5})
    )
    return d


def _shear_extract(mu_psh):
    """A bulk extractor giving two shear loads with these mu_psh values."""

    def extract(test, case_dir):
        return pd.DataFrame(
            {
                "case_id": ["x"] * 2,
                "normal_stress": [2029.0] * 2,
                "P": [0.6, 1.0],
                "mu_psh": mu_psh,
                "mu_sh": [0.5, 0.6],
                "rho_b": [1700.0, 1701.0],
            }
        )

    return extract


def test_case_rows_ok_and_failed(tmp_path):
    extract = _shear_extract([0.6, 0.61])
    ok = case_rows("shear_cell", _case_dir(tmp_path, "c0001_s2", "ok"), extract, [0.6, 1.0])
    bad = case_rows("shear_cell", _case_dir(tmp_path, "c0002_s2", "failed"), extract, [0.6, 1.0])
    assert list(ok["status"]) == ["ok", "ok"] and ok["design_id"].iloc[0] == "c0001"
    assert list(bad["status"]) == ["failed", "failed"]
    assert bad["mu_psh"].isna().all() and bad["error"].iloc[0] == "ERROR: boom"
    data = collect([ok, bad])
    assert list(data.columns[:3]) == ["test", "case_id", "design_id"]
    assert len(usable(data, "mu_psh")) == 2


def test_ringing_notes_name_the_phase_cycles_and_remedy():
    rows = pd.DataFrame(
        {
            "cycle": [0, 1, 2, 3],
            "psh_lid_rings": [True, True, False, True],
            "sh_lid_rings": [False, False, False, False],
        }
    )
    (note,) = ringing_notes(rows)
    assert "pre-shear of cycle(s) 0, 1, 3" in note and "servo_kp" in note
    rows["sh_lid_rings"] = [False, False, True, np.nan]
    assert len(ringing_notes(rows)) == 2 and "shear of cycle(s) 2 " in ringing_notes(rows)[1]
    quiet = rows.assign(psh_lid_rings=False, sh_lid_rings=False)
    assert ringing_notes(quiet) == []
    # A failed case has no flags: nothing to say.
    assert ringing_notes(pd.DataFrame({"case_id": ["c0001"], "mu_psh": [np.nan]})) == []


def test_replicate_runs_train_as_their_mean(tmp_path):
    runs = [
        ("c0001_s2", "ok", [0.60, 0.70]),
        ("c0001_r2_s2", "ok", [0.64, 0.74]),
        ("c0001_r3_s2", "failed", [0.0, 0.0]),
        ("c0002_s2", "ok", [0.50, 0.55]),
    ]
    data = collect(
        case_rows("shear_cell", _case_dir(tmp_path, cid, status), _shear_extract(v), [0.6, 1.0])
        for cid, status, v in runs
    )
    assert set(data["design_id"]) == {"c0001", "c0002"}
    rows = replicate_means(usable(data, "mu_psh"), "mu_psh")
    # One row per case and load: the failed third run is left out of the mean.
    assert rows["case_id"].tolist() == ["c0001_s2", "c0001_s2", "c0002_s2", "c0002_s2"]
    assert rows["P"].tolist() == [0.6, 1.0, 0.6, 1.0]
    assert rows["mu_psh"].tolist() == pytest.approx([0.62, 0.72, 0.50, 0.55], abs=1e-12)
    assert rows["replicates"].tolist() == [2, 2, 1, 1]
    # Without replicates the rows are returned as they are.
    plain = usable(data[~data["case_id"].str.contains("_r")], "mu_psh")
    pd.testing.assert_frame_equal(replicate_means(plain, "mu_psh"), plain)


def _deck_extract(rho_b, mu_sh, P=(0.6, 1.0)):
    """A bulk extractor of one deck: rho_b read once and repeated on every P row."""

    def extract(test, case_dir):
        return pd.DataFrame(
            {
                "case_id": ["x"] * len(P),
                "normal_stress": [2029.0] * len(P),
                "P": list(P),
                "mu_psh": [0.55] * len(P),
                "mu_sh": mu_sh,
                "rho_b": [rho_b] * len(P),
            }
        )

    return extract


def test_training_rows_merge_a_decks_value_repeated_over_P(tmp_path):
    runs = [
        ("c0001_s2", 1700.0, [0.50, 0.60]),
        ("c0001_r2_s2", 1720.0, [0.52, 0.58]),
        ("c0002_s2", 1650.0, [0.40, 0.45]),
    ]
    data = collect(
        case_rows("shear_cell", _case_dir(tmp_path, cid, "ok"), _deck_extract(rho, mu), [0.6, 1.0])
        for cid, rho, mu in runs
    )
    # rho_b is one reading per deck: one row per set and stress, P no longer an input.
    rho = training_rows(data, "shear_cell", "rho_b")
    assert rho["case_id"].tolist() == ["c0001_s2", "c0002_s2"]
    assert "P" not in rho
    assert rho["rho_b"].tolist() == pytest.approx([1710.0, 1650.0], abs=1e-9)
    # mu_sh differs between the P of a deck: a row per P, replicates averaged.
    mu = training_rows(data, "shear_cell", "mu_sh")
    assert mu["P"].tolist() == [0.6, 1.0, 0.6, 1.0]
    assert mu["mu_sh"].tolist() == pytest.approx([0.51, 0.59, 0.40, 0.45], abs=1e-12)
    assert training_rows(data, "angle_of_repose", "rho_b").empty


def test_training_rows_keep_P_of_separate_decks(tmp_path):
    # cycles: separate - one deck per P, each reading its own pre-shear point.
    frames = [
        case_rows(
            "shear_cell",
            _case_dir(tmp_path, f"c0001_s2_p{j}", "ok"),
            _deck_extract(rho, [0.5], P=(p,)),
            [0.6, 1.0],
        )
        for j, (p, rho) in enumerate([(0.6, 1700.0), (1.0, 1690.0)], start=1)
    ]
    rows = training_rows(collect(frames), "shear_cell", "rho_b")
    assert rows["P"].tolist() == [0.6, 1.0]
    assert rows["rho_b"].tolist() == [1700.0, 1690.0]


def test_load_experiment_partial_and_invalid(tmp_path):
    good = tmp_path / "m.yaml"
    good.write_text(
        yaml.safe_dump(
            {
                "material": "m",
                "angle_of_repose": {"value": 35.0},
                "shear_cell": [
                    {"normal_stress": 1068, "P": 0.6, "mu_sh": 0.5},
                    {"normal_stress": 2029, "P": 1.0},
                ],
            }
        )
    )
    exp = load_experiment(good)
    assert exp.angle_of_repose == 35.0
    assert len(exp.shear_conditions) == 1  # a condition without readings matches nothing
    assert exp.shear_conditions[0].values == {"mu_sh": 0.5}
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        yaml.safe_dump({"material": "m", "shear_cell": [{"normal_stress": 1, "P": 2.0}]})
    )
    with pytest.raises(ConfigError, match=r"(?s)bad\.yaml.*shear_cell\.0\.P"):
        load_experiment(bad)


def screening_section(axes: dict) -> dict:
    """A screening config section over ``axes`` (name -> [low, high, count]), 5 % tolerance."""
    return {
        "axes": axes,
        "seed": 1,
        "tolerance": 0.05,
        "measurement_coverage": 2.0,
        "chunk_size": 1024,
        "threads": 1,
    }


class Linear:
    """An exact analytic 'surrogate' y = c + w . x (torch, original units)."""

    def __init__(self, weights, const):
        self.w = torch.tensor(weights, dtype=torch.float32)
        self.c = const

    def predict_torch(self, X):
        return X @ self.w + self.c


def test_calibration_recovers_truth_with_analytic_surrogates():
    features = [
        "coefficientFriction",
        "coefficientRollingFriction",
        "coefficientRestitution",
        "density",
        "dCylDp",
        "normal_stress",
        "P",
    ]
    mu_psh = Linear([0.5, 0.2, 0.0, 0.0, 0.0, 0.0, 0.0], 0.2)
    rho_b = Linear([0.0, 0.0, 0.0, 0.6, 0.0, 0.0, 0.0], 0.0)
    aor = Linear([10.0, 30.0, 0.0, 0.0, 0.0], 10.0)
    truth = {
        "coefficientFriction": 0.6,
        "coefficientRollingFriction": 0.4,
        "coefficientRestitution": 0.7,
        "density": 3000.0,
    }
    exp = Experiment(
        "m",
        "",
        [
            MeasuredCondition(
                values={"mu_psh": 0.2 + 0.5 * 0.6 + 0.2 * 0.4, "rho_b": 0.6 * 3000.0},
                normal_stress=2029.0,
                P=1.0,
            )
        ],
        angle_of_repose=10 + 6 + 12,
    )
    screening = screening_section(
        {
            "coefficientFriction": [0.1, 1.0, 60],
            "coefficientRollingFriction": [0.1, 1.0, 60],
            "coefficientRestitution": [0.5, 0.9, 3],
            "density": [2500, 3500, 25],
        }
    )
    surrogates = {
        "mu_psh": (mu_psh, features),
        "rho_b": (rho_b, features),
        "aor": (aor, features[:5]),
    }
    const = {k: {"dCylDp": 10.0} for k in surrogates}
    result = calibrate(surrogates, exp, screening, const)
    assert result.n_total == 60 * 60 * 3 * 25
    assert set(result.valid) == {"SSC", "AoR", "SSC & AoR"}
    both = result.valid["SSC & AoR"]
    assert 0 < len(both) < len(result.valid["SSC"])
    for name, value in truth.items():
        if name == "coefficientRestitution":
            continue  # no network depends on it: the whole axis stays valid
        assert both[name].min() <= value <= both[name].max()
        # The measurements pin the parameter to a quarter of its box (by hand: mu_s within
        # 0.16, mu_r 0.14, density 200 kg/m^3 of widths 0.9, 0.9, 1000).
        low, high, _ = screening["axes"][name]
        assert both[name].max() - both[name].min() < 0.25 * (high - low), name
    assert set(both["coefficientRestitution"]) == set(result.axes["coefficientRestitution"])
    assert result.identified_group == "SSC & AoR"
    assert result.identified["density"]["mean"] == pytest.approx(3000.0, rel=0.05)
    # The surrogates at the identified mean: the linear models evaluated by hand.
    mean = {k: v["mean"] for k, v in result.identified.items()}
    at = {r["observable"]: r for r in result.at_identified}
    assert list(at) == ["mu_psh", "rho_b", "aor"]
    mu_s, mu_r = mean["coefficientFriction"], mean["coefficientRollingFriction"]
    assert at["mu_psh"]["predicted"] == pytest.approx(0.2 + 0.5 * mu_s + 0.2 * mu_r, rel=1e-5)
    assert at["aor"]["predicted"] == pytest.approx(10.0 + 10.0 * mu_s + 30.0 * mu_r)
    assert (at["rho_b"]["normal_stress"], at["rho_b"]["P"], at["aor"]["P"]) == (2029.0, 1.0, None)
    for row in at.values():
        assert row["deviation"] == pytest.approx(abs(1 - row["predicted"] / row["measured"]))
        assert row["within_tolerance"] == (row["deviation"] < 0.05)


class Bowl:
    """y = c + k ((mu_s - 0.55)^2 + (mu_r - 0.55)^2): the sets matching one y form a ring."""

    def __init__(self, const, k):
        self.c, self.k = const, k

    def predict_torch(self, X):
        return self.c + self.k * ((X[:, 0] - 0.55) ** 2 + (X[:, 1] - 0.55) ** 2)


def test_a_mean_outside_a_curved_valid_region_is_named(tmp_path):
    # A measured angle of 40 deg matched on a ring of radius 0.3 about (0.55, 0.55): the ring's
    # valid sets average to its centre, where the surrogate predicts 30 deg.
    features = ["coefficientFriction", "coefficientRollingFriction"]
    exp = Experiment("m", "", [], angle_of_repose=40.0)
    screening = screening_section(
        {
            "coefficientFriction": [0.1, 1.0, 91],
            "coefficientRollingFriction": [0.1, 1.0, 91],
        }
    )
    result = calibrate({"aor": (Bowl(30.0, 10.0 / 0.09), features)}, exp, screening, {})
    mean = result.identified
    assert mean["coefficientFriction"]["mean"] == pytest.approx(0.55, abs=0.05)
    (row,) = result.at_identified
    assert row["predicted"] == pytest.approx(30.0, abs=1.0) and not row["within_tolerance"]
    line = mean_set_statement(result.at_identified, 0.05)
    assert line.startswith("**The identified mean set is not itself a valid set**")
    assert (
        f"aor {row['predicted']:.4g} against 40 ({row['deviation']:.1%} off)" in line
        and "\n" not in line
    )
    assert mean_set_statement([{**row, "within_tolerance": True}], 0.05).startswith(
        "At the identified mean set the surrogates predict every measured value within the 5%"
    )


def test_measured_sd_widens_the_screening_band():
    # Angle 40 +- 1.5 deg: the 5 % band is +-2 deg; two standard deviations in quadrature make
    # it +-sqrt(2^2 + 3^2) = +-3.61 deg, and only a measurement with an sd is widened.
    features = ["coefficientFriction", "coefficientRollingFriction"]
    axes = {"coefficientFriction": [0.1, 1.0, 91], "coefficientRollingFriction": [0.1, 1.0, 91]}
    bowl = {"aor": (Bowl(30.0, 10.0 / 0.09), features)}
    with_sd = Experiment("m", "", [], angle_of_repose=40.0, angle_of_repose_sd=1.5)
    counts = {}
    for coverage in (0.0, 2.0):
        screening = {**screening_section(axes), "measurement_coverage": coverage}
        result = calibrate(bowl, with_sd, screening, {})
        frame = result.valid["AoR"]
        mu_s = frame["coefficientFriction"].to_numpy()
        mu_r = frame["coefficientRollingFriction"].to_numpy()
        angle = 30.0 + 10.0 / 0.09 * ((mu_s - 0.55) ** 2 + (mu_r - 0.55) ** 2)
        band = 2.0 if coverage == 0.0 else float(np.hypot(2.0, 3.0))
        assert np.all(np.abs(angle - 40.0) < band + 1e-3)
        assert np.abs(angle - 40.0).max() > band - 0.3
        (row,) = result.at_identified
        assert row["band"] == pytest.approx(band / 40.0)
        counts[coverage] = len(frame)
    assert counts[2.0] > 1.5 * counts[0.0] > 0
    without_sd = Experiment("m", "", [], angle_of_repose=40.0)
    result = calibrate(bowl, without_sd, screening_section(axes), {})
    assert len(result.valid["AoR"]) == counts[0.0]


def test_valid_sets_written_read_back_to_six_digits(tmp_path):
    rng = np.random.default_rng(4)
    grid = np.linspace(0.1, 1.0, 37)
    frame = pd.DataFrame(
        {
            "coefficientFriction": rng.choice(grid, 500),
            "density": rng.uniform(2500.0, 3500.0, 500),  # every value distinct
        }
    )
    frame.loc[[3, 70], "density"] = np.nan  # written as empty fields, as pandas does
    empty = frame.iloc[:0]
    result = CalibrationResult(
        {}, {"SSC": frame, "SSC & AoR": empty}, 500, 0.0, pd.DataFrame(), {}, "SSC"
    )
    paths = write_valid_sets(result, tmp_path)
    assert paths["SSC & AoR"].name == "valid_ssc_aor.csv.gz"
    back = pd.read_csv(paths["SSC"])
    assert list(back.columns) == list(frame.columns) and len(back) == 500
    np.testing.assert_allclose(back.to_numpy(), frame.to_numpy(), rtol=5e-6)  # NaN == NaN
    # The same text as pandas writes with the same format.
    with gzip.open(paths["SSC"], "rt") as text:
        assert text.read() == frame.to_csv(index=False, float_format="%.6g")
    assert list(pd.read_csv(paths["SSC & AoR"]).columns) == list(frame.columns)


def test_calibration_names_unscreened_varying_input():
    model = Linear([1.0, 1.0], 0.0)
    exp = Experiment("m", "", [], angle_of_repose=1.0)
    screening = screening_section({"coefficientFriction": [0.1, 1.0, 3]})
    with pytest.raises(ValueError, match="wallFriction"):
        calibrate({"aor": (model, ["coefficientFriction", "wallFriction"])}, exp, screening, {})


def test_constant_inputs_wrapper():
    model = Linear([1.0, 10.0, 100.0], 0.0)
    wrapped = ConstantInputs(model, ["a", "b", "c"], {"b": 2.0})
    assert wrapped.free == ["a", "c"]
    assert wrapped.predict(np.array([[1.0, 3.0]])) == pytest.approx([1.0 + 20.0 + 300.0])


def test_verification_table():
    runs = pd.DataFrame(
        {
            "test": ["shear_cell", "angle_of_repose"],
            "normal_stress": [2029.0, math.nan],
            "P": [1.0, math.nan],
            "rho_b": [1800.0, math.nan],
            "aor": [math.nan, 36.0],
        }
    )
    exp = Experiment(
        "m",
        "",
        [
            MeasuredCondition(
                values={"rho_b": 1760.0}, uncertainties={"rho_b": 42.0}, normal_stress=2029.0, P=1.0
            ),
            # No verification run at this load: no DEM value, never within the tolerance.
            MeasuredCondition(values={"mu_psh": 0.6}, normal_stress=1068.0, P=1.0),
        ],
        angle_of_repose=38.85,
    )
    table = verification_table({"configured": runs}, exp, 0.05)
    assert list(table["observable"]) == ["rho_b", "mu_psh", "aor"]
    assert table["deviation_configured"].iloc[0] == pytest.approx(40 / 1760)
    assert math.isnan(table["dem_configured"].iloc[1])
    assert math.isnan(table["deviation_configured"].iloc[1])
    assert table["deviation_configured"].iloc[2] == pytest.approx(1 - 36.0 / 38.85)
    assert list(table["within_tolerance_configured"]) == [True, False, False]
    assert "engine_difference" not in table  # one engine: nothing to compare


def test_verification_table_averages_replicates():
    """Three seeds at the identified set: the table compares their mean with the measurement
    and gives their scatter; a failed replicate (NaN) is left out and counted."""
    runs = pd.DataFrame(
        {
            "test": ["angle_of_repose"] * 3 + ["shear_cell"] * 3,
            "normal_stress": [math.nan] * 3 + [2029.0] * 3,
            "P": [math.nan] * 3 + [1.0] * 3,
            "aor": [36.0, 38.0, 40.0, math.nan, math.nan, math.nan],
            "rho_b": [math.nan] * 3 + [1700.0, math.nan, 1740.0],
        }
    )
    exp = Experiment(
        "m",
        "",
        [MeasuredCondition(values={"rho_b": 1760.0}, normal_stress=2029.0, P=1.0)],
        angle_of_repose=38.85,
    )
    table = verification_table({"configured": runs}, exp, 0.05).set_index("observable")
    assert table.loc["aor", "dem_configured"] == pytest.approx(38.0)
    assert table.loc["aor", "dem_sd_configured"] == pytest.approx(2.0)
    assert table.loc["aor", "runs_configured"] == 3
    assert table.loc["rho_b", "dem_configured"] == pytest.approx(1720.0)
    assert table.loc["rho_b", "runs_configured"] == 2
    assert bool(table.loc["aor", "within_tolerance_configured"])


def test_verification_table_two_engines_side_by_side(tmp_path):
    """The identified set on the bundled engine and on LIGGGHTS, each against the measurement
    and against each other (values of a tiny-profile run)."""

    def runs(mu_psh: float, rho_b: float, aor: float) -> pd.DataFrame:
        return pd.DataFrame(
            {
                "test": ["shear_cell", "shear_cell", "angle_of_repose"],
                "normal_stress": [2029.0, 2029.0, math.nan],
                "P": [0.5, 1.0, math.nan],
                "mu_psh": [mu_psh, mu_psh, math.nan],
                "rho_b": [rho_b, rho_b, math.nan],
                "aor": [math.nan, math.nan, aor],
            }
        )

    bundled, liggghts = runs(2.20, 1540.0, 27.5), runs(2.42, 1496.0, 30.1)
    exp = Experiment(
        "m",
        "",
        [MeasuredCondition(values={"mu_psh": 2.27, "rho_b": 1526.5}, normal_stress=2029.0, P=1.0)],
        angle_of_repose=28.04,
        angle_of_repose_sd=0.28,
    )
    table = verification_table({"bundled": bundled, "liggghts": liggghts}, exp, 0.05)
    assert list(table.columns) == [
        "observable",
        "normal_stress",
        "P",
        "measured",
        "measured_sd",
        "dem_bundled",
        "dem_sd_bundled",
        "runs_bundled",
        "deviation_bundled",
        "within_tolerance_bundled",
        "dem_liggghts",
        "dem_sd_liggghts",
        "runs_liggghts",
        "deviation_liggghts",
        "within_tolerance_liggghts",
        "engine_difference",
    ]
    rows = table.set_index("observable")
    assert list(rows.index) == ["mu_psh", "rho_b", "aor"]
    assert list(rows["dem_bundled"]) == [2.20, 1540.0, 27.5]
    assert list(rows["dem_liggghts"]) == [2.42, 1496.0, 30.1]
    np.testing.assert_allclose(
        rows["deviation_bundled"], [1 - 2.20 / 2.27, 1540.0 / 1526.5 - 1, 1 - 27.5 / 28.04]
    )
    np.testing.assert_allclose(
        rows["deviation_liggghts"], [2.42 / 2.27 - 1, 1 - 1496.0 / 1526.5, 30.1 / 28.04 - 1]
    )
    # mu_psh: bundled 3.1 % off, LIGGGHTS 6.6 % off (outside 5 %); AoR: LIGGGHTS 7.3 % off.
    assert list(rows["within_tolerance_bundled"]) == [True, True, True]
    assert list(rows["within_tolerance_liggghts"]) == [False, True, False]
    np.testing.assert_allclose(
        rows["engine_difference"], [2.42 / 2.20 - 1, 1 - 1496.0 / 1540.0, 30.1 / 27.5 - 1]
    )
    assert rows.loc["aor", "measured_sd"] == 0.28
    # A run missing on one engine: its value and the engine difference are NaN.
    table = verification_table(
        {"bundled": bundled, "liggghts": liggghts.iloc[:2]}, exp, 0.05
    ).set_index("observable")
    assert math.isnan(table.loc["aor", "dem_liggghts"])
    assert math.isnan(table.loc["aor", "engine_difference"])
    assert not table.loc["aor", "within_tolerance_liggghts"]
    assert table.loc["aor", "within_tolerance_bundled"]


def test_write_verification_table_lists_engines_and_failed_runs(tmp_path):
    """Two engines' bulk files against the tiny synthetic measurement; a failed run is named."""
    experiment = ROOT_DIR / "config" / "experiments" / "synthetic_reference_tiny.yaml"
    base = {"normal_stress": 2029.0, "P": 1.0, "case_id": "identified_s1"}
    files = {}
    for engine, shear, aor, status in (
        ("liggghts", (1.97, 2.31, 1404.4), 30.0, "ok"),
        ("bundled", (math.nan, math.nan, math.nan), 28.06, "failed"),
    ):
        rows = pd.DataFrame(
            [
                {
                    **base,
                    "test": "shear_cell",
                    **dict(zip(("mu_psh", "mu_sh", "rho_b"), shear, strict=True)),
                    "status": status,
                    "error": "ERROR: unstable" if status != "ok" else "",
                },
                {"test": "angle_of_repose", "case_id": "identified", "aor": aor, "status": "ok"},
            ]
        )
        files[engine] = [tmp_path / f"{engine}.csv"]
        rows.to_csv(files[engine][0], index=False)
    table = write_verification_table(
        files,
        experiment,
        0.05,
        tmp_path / "v.csv",
        tmp_path / "v.md",
        commands={"liggghts": "liggghts -in {deck}", "bundled": "dem_engine -in {deck}"},
        threads=2,
    )
    rows = table.set_index("observable")
    assert rows.loc["aor", "dem_liggghts"] == 30.0 and rows.loc["aor", "dem_bundled"] == 28.06
    assert rows.loc["aor", "engine_difference"] == pytest.approx(1 - 28.06 / 30.0)
    measured = load_experiment(experiment).shear_conditions[0].values["rho_b"]
    assert rows.loc["rho_b", "deviation_liggghts"] == pytest.approx(abs(1 - 1404.4 / measured))
    assert math.isnan(rows.loc["mu_psh", "dem_bundled"])
    text = (tmp_path / "v.md").read_text()
    assert "- liggghts: `liggghts -in {deck}`, 2 thread(s)" in text
    assert "FAILED on bundled: shear_cell identified_s1 (ERROR: unstable)" in text
    # Each engine's verdict comes first; a failed run is a miss with no value.
    verdicts = text.splitlines()[:4]
    assert verdicts[0].startswith("**The DEM runs on liggghts miss")
    assert verdicts[2].startswith("**The DEM runs on bundled miss 2 of the 3 measured values")
    assert "mu_psh (2029 Pa, P 1): no finished run" in verdicts[2] and "aor" not in verdicts[2]
    assert pd.read_csv(tmp_path / "v.csv").shape == table.shape
    assert "surrogate" not in table  # no identified-set record given


def _heaps(mean: float, sd: float, n: int) -> np.ndarray:
    """n angles (deg) with exactly this mean and sample standard deviation."""
    z = np.random.default_rng(n).standard_normal(n)
    z = (z - z.mean()) / z.std(ddof=1)
    return mean + sd * z


def test_mean_interval_is_the_student_t_interval():
    # t(0.975, 8) = 2.306, t(0.975, 2) = 4.303: nine heaps of sd 1.47 deg give +-1.13 deg.
    low, high = mean_interval(35.80, 1.47, 9)
    assert (low, high) == pytest.approx((35.80 - 1.130, 35.80 + 1.130), abs=2e-3)
    assert mean_interval(1717.0, 10.0, 3) == pytest.approx((1692.2, 1741.8), abs=0.1)
    assert mean_interval(35.8, math.nan, 1) is None


@pytest.mark.parametrize(
    ("heaps", "start", "undecided"),
    [
        # The default study's nine verification heaps at the sinter fines' set (35.80 +- 1.47
        # deg): 7.9 % low, but the 95 % interval 34.67-36.93 reaches the band's edge 36.91.
        (_heaps(35.80, 1.47, 9), "**The DEM runs on configured miss 1 of the 2", True),
        # Ninety heaps at 37.0 +- 1.8 deg: 4.8 % low, within, interval 36.62-37.38 across 36.91.
        (_heaps(37.0, 1.8, 90), "The DEM runs on configured reproduce every", True),
        # Twelve heaps at 34.0 +- 1.5 deg: 12.5 % low, interval 33.05-34.95, wholly outside.
        (_heaps(34.0, 1.5, 12), "**The DEM runs on configured miss 1 of the 2", False),
        # Nine heaps at 38.5 +- 1.5 deg: 0.9 % low, interval 37.35-39.65, wholly inside.
        (_heaps(38.5, 1.5, 9), "The DEM runs on configured reproduce every", False),
        # One heap: no interval, no undecided.
        (np.array([36.9]), "**The DEM runs on configured miss 1 of the 2", False),
    ],
)
def test_the_verdict_names_values_whose_interval_crosses_the_tolerance(
    heaps, start, undecided, tmp_path
):
    # The sinter fines' values without the bulk density's sd (its effect is tested below).
    experiment = tmp_path / "sinter_fines_no_sd.yaml"
    experiment.write_text(
        (ROOT_DIR / "config" / "experiments" / "sinter_fines.yaml")
        .read_text()
        .replace("    rho_b_sd: 42\n", "")
    )
    assert "rho_b_sd" not in experiment.read_text()
    rows = [
        {"test": "shear_cell", "normal_stress": 10070.0, "P": 1.0, "rho_b": r}
        for r in (1707.0, 1717.0, 1727.0)
    ]
    rows += [{"test": "angle_of_repose", "aor": a} for a in heaps]
    table = verification_table(
        {"configured": pd.DataFrame(rows)}, load_experiment(experiment), 0.05
    )
    verdict = dem_verdict(table, "configured", 0.05)
    assert verdict.startswith(start)
    # rho_b: 1717 +- 10 over three runs, interval 1692-1742 inside the band 1672-1848.
    assert ("Undecided at 95% confidence" in verdict) is undecided
    assert "rho_b (10070 Pa, P 1) 1717 (" not in verdict
    if undecided:
        assert f"aor {heaps.mean():.4g} (95% interval of the mean of {heaps.size} runs" in verdict
        assert "tolerance band 36.91-40.79)" in verdict


def test_the_measured_sd_widens_the_verdict_interval():
    # The synthetic reference's mu_sh at 2 029 Pa, P 0.6 (LIGGGHTS, mean of 4 runs 0.5888 with
    # its standard error and 1 % noise, sd 0.0174) against six engine runs at the identified
    # set, 0.6436 +- 0.0235: 9.3 % high. The runs' interval alone, 0.619-0.668, lies wholly
    # above the band 0.559-0.618 (a decided miss); widened by 1.96 x 0.0174 in quadrature it is
    # 0.603-0.684 and crosses the band's edge: the measurement itself leaves it open.
    row = {
        "observable": "mu_sh",
        "normal_stress": 2029.0,
        "P": 0.6,
        "measured": 0.5888,
        "measured_sd": 0.0174,
        "dem_configured": 0.6436,
        "dem_sd_configured": 0.0235,
        "runs_configured": 6,
    }
    runs_only = mean_interval(0.6436, 0.0235, 6)
    assert runs_only == pytest.approx((0.6189, 0.6683), abs=2e-4)
    assert verdict_interval({**row, "measured_sd": math.nan}, "configured") == runs_only
    low, high = verdict_interval(row, "configured")
    half = math.hypot(0.5 * (runs_only[1] - runs_only[0]), 1.959964 * 0.0174)
    assert (low, high) == pytest.approx((0.6436 - half, 0.6436 + half), abs=1e-6)
    assert undecided({**row, "measured_sd": math.nan}, "configured", 0.05) is None
    text = undecided(row, "configured", 0.05)
    assert text is not None and "with the measured sd 0.0174" in text
    assert f"{low:.4g}-{high:.4g}, tolerance band 0.5594-0.6182)" in text
    # The sinter fines' bulk density (1 760 +- 42 kg/m^3) against three runs at 1 760 +- 10:
    # inside the band even with the measurement's sd (half-width 86 of the band's 88).
    sinter = row | {"measured": 1760.0, "measured_sd": 42.0, "dem_configured": 1760.0}
    sinter |= {"dem_sd_configured": 10.0, "runs_configured": 3}
    assert undecided(sinter, "configured", 0.05) is None
    assert undecided(sinter | {"dem_configured": 1717.0}, "configured", 0.05) is not None


def test_verification_table_shows_the_surrogates_at_the_verified_set(tmp_path):
    experiment = ROOT_DIR / "config" / "experiments" / "sinter_fines.yaml"
    bulk = tmp_path / "bulk.csv"
    pd.DataFrame(
        [
            {"test": "shear_cell", "case_id": "identified_s3", "normal_stress": 10070.0, "P": 1.0}
            | {"rho_b": 1738.0, "status": "ok"},
            {"test": "angle_of_repose", "case_id": "identified", "aor": 35.8, "status": "ok"},
        ]
    ).to_csv(bulk, index=False)
    record = tmp_path / "identified.json"
    predicted = [
        {"observable": "rho_b", "normal_stress": 10070.0, "P": 1.0, "predicted": 1745.2},
        {"observable": "aor", "normal_stress": None, "P": None, "predicted": 34.94},
    ]
    record.write_text(
        json.dumps({"reach": "REACH LINE", "mean_set": "MEAN LINE", "predicted_at_mean": predicted})
    )
    table = write_verification_table(
        {"configured": [bulk]},
        experiment,
        0.05,
        tmp_path / "v.csv",
        tmp_path / "v.md",
        identified=record,
    )
    rows = table.set_index("observable")
    assert (rows.loc["rho_b", "surrogate"], rows.loc["aor", "surrogate"]) == (1745.2, 34.94)
    assert rows.loc["aor", "dem_configured"] == 35.8
    text = (tmp_path / "v.md").read_text().splitlines()
    assert text[:4] == ["REACH LINE", "", "MEAN LINE", ""]
    # One run: the angle's 35.8 deg misses 38.85 by 7.9 %, rho_b's 1738 is within 1.3 %.
    assert text[4] == (
        "**The DEM runs on configured miss 1 of the 2 measured values by more than the 5% "
        "tolerance**: aor 35.8 against 38.85 (7.9%)."
    )
    assert any(line.startswith("surrogate: the surrogates' prediction") for line in text)
