"""The discrepancy workflow on synthetic data with a hidden effect (tiny scale).

"Measured" data come from LIGGGHTS 3.8 at a drawn truth with an effect switched on that the
model under calibration (on the bundled engine) lacks: cohesion, or nothing. The truth's
sliding friction and the effect's magnitude are drawn (seeded) from the truth specifications,
clear of the catalogue's probe levels; each value is the mean of three
runs per load condition from fresh packings, with 3 % noise on friction and 1 % on bulk density
(:data:`demcal.discrepancy.synthetic.NOISE`). The truths are read only here and by the study
set-up, never by the workflow. The studies are a slice of the validation matrix
(:mod:`demcal.discrepancy.validation_matrix`, ``scripts/discrepancy_matrix.py``): the current
model's design, runs and surrogates are made once and copied into one study directory per data
set, which then runs `snakemake discrepancy`."""

import json
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy.stats import chi2

from demcal.core.experiments import load_experiment
from demcal.discrepancy.validation_matrix import (
    AMBIGUOUS,
    NOT_EXPLAINED,
    NOTHING,
    VISIBLE_SIGNAL,
    matrix_cases,
    prepare_base,
    run_case,
    with_signal,
)

from ..liggghts.conftest import require_liggghts

ROOT = Path(__file__).resolve().parents[2]
TRUTH = ROOT / "config" / "experiments" / "truth"
# A hidden effect of a different contact model (SJKR cohesion on LIGGGHTS) and nothing hidden.
# Hidden rolling resistance is in the validation matrix (make discrepancy-matrix, which scores
# every effect over drawn truths); a third study here would add about 2.5 minutes to make test.
SCENARIOS = {
    "cohesion": "hidden_cohesion.yaml",
    "none": "hidden_none.yaml",
}
#: Seed of the truth draws and of the noise.
TRUTH_SEED = 2026
TRUTH_ENGINE = "liggghts -in {deck}"
EXPERIMENT = "config/experiments/measured.yaml"
#: Normal stresses of the measured load conditions (Pa), ascending.
STRESSES = (1068.0, 2029.0, 4000.0)
OUTPUTS = (
    "find.md",
    "ranking.csv",
    "ranking.md",
    "gap_before_after.csv",
    "gap_before_after.png",
    "verification.md",
    "summary.json",
)

pytestmark = [pytest.mark.workflow, pytest.mark.slow]


@pytest.fixture(scope="module")
def studies(tmp_path_factory) -> dict[str, Path]:
    """One finished study directory per data set: a slice of the validation matrix."""
    require_liggghts()
    out = tmp_path_factory.mktemp("discrepancy")
    base = prepare_base(ROOT / "config" / "tiny.yaml", out / "base")
    cases = matrix_cases([TRUTH / spec for spec in SCENARIOS.values()], 1, TRUTH_SEED)
    rows = {case.label: run_case(case, base, out, TRUTH_ENGINE) for case in cases}
    for name, row in rows.items():
        (out / f"{name}_{TRUTH_SEED}" / "row.json").write_text(json.dumps(row, default=float))
    return {case.label: out / case.name for case in cases}


def summary(work: Path) -> dict:
    return json.loads((work / "results" / "discrepancy" / "summary.json").read_text())


def ranking_record(work: Path) -> dict:
    return json.loads((work / "results" / "discrepancy" / "ranking.json").read_text())


def undecided_pair(record: dict) -> list[str]:
    """The two candidates the ranking could not tell apart, alphabetically (empty if none)."""
    return sorted(record.get("ambiguous") or ())


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_all_outputs_written(studies, name):
    out = studies[name] / "results" / "discrepancy"
    for output in OUTPUTS:
        assert (out / output).is_file(), (name, output)
    # One row of the before/after table per measured value. The held-out load is measured
    # and shown, but Find never saw it: no surrogate misfit there.
    experiment = load_experiment(studies[name] / EXPERIMENT)
    measured = sum(len(c.values) for c in experiment.shear_conditions)
    measured += experiment.angle_of_repose is not None
    gap = pd.read_csv(out / "gap_before_after.csv")
    assert len(gap) == measured, (name, len(gap))
    held, fitted = gap[gap["held_out"]], gap[~gap["held_out"]]
    assert sorted(set(held["normal_stress"])) == [1500.0], name
    assert held["z_before"].isna().all() and np.isfinite(held[["measured", "sigma"]]).all().all()
    find = pd.read_csv(out / "find.csv")
    assert 1500.0 not in set(find["normal_stress"]) and len(find) == len(fitted)
    # The fitted misfits before the effect are finite; the summary's gap is their root mean
    # square.
    assert np.isfinite(fitted[["measured", "sigma", "z_before"]].to_numpy()).all(), name
    result = summary(studies[name])
    rms = np.sqrt(np.mean(fitted["z_before"] ** 2))
    assert result["gap_before"] == pytest.approx(rms, rel=1e-4)
    config = (studies[name] / "config" / "config.yaml").read_text()
    assert "truth" not in config
    assert "parameters" not in yaml.safe_load((studies[name] / EXPERIMENT).read_text())
    # The matrix row of the study agrees with its summary and ranking (an undecided naming is
    # the ambiguous pair, names in alphabetical order).
    row = json.loads((studies[name] / "row.json").read_text())
    pair = undecided_pair(ranking_record(studies[name]))
    undecided = f"{AMBIGUOUS}: {pair[0]} / {pair[1]}" if pair else NOT_EXPLAINED
    assert row["outcome"] == ((result["winner"] or undecided) if result["missing"] else NOTHING), (
        name
    )
    assert (
        row["truth_friction"]
        == yaml.safe_load((studies[name] / "truth.yaml").read_text())["parameters"][
            "coefficientFriction"
        ]
    )


# On these honest data (LIGGGHTS truths, drawn with seed 2026: sliding friction 0.339 in both,
# hidden cohesion 32 560 J/m^3; 3 % noise on friction, 1 % on bulk density; a held-out load at
# 1 500 Pa) Find is right in both studies (p = 0.014 with cohesion, 0.73 with nothing hidden).
# What is named moves with the host: the DEM runs are chaotic, floating-point details of the
# host move single runs, and one drawn data set decides the outcome (the validation matrix
# names the right effect in 5 of 15, docs/discrepancy.md). Cohesion was named at 25 400 J/m^3
# (0.78 x the truth; surrogate gap 1.53 -> 0.48, DEM 1.30 -> 1.17, held-out 0.53 -> 0.76) on
# one host (2026-11-24), undecided against rolling resistance on an AMD EPYC (2026-11-25) and
# found but not explained on an Intel Xeon (2026-11-26; p_effect 0.125, runner-up rolling
# resistance 0.163). What holds on all three: the gap is found, and the hidden effect is never
# replaced by another name - it is named, one of the undecided pair, or left unexplained, which
# is a miss and not a wrong answer (the validation matrix counts both against the naming
# accuracy). Where it is named, the extended model closes the gap in the surrogate and in
# replicate DEM runs, the held-out load included, at a magnitude within a factor of 4 of the
# truth.
def test_hidden_effect_is_found_and_never_misnamed(studies):
    name = "cohesion"
    result = summary(studies[name])
    assert result["missing"] and result["p_value"] < result["alpha"], result["verdict"]
    out = studies[name] / "results" / "discrepancy"
    record = ranking_record(studies[name])
    named = [result["winner"]] if result["winner"] else undecided_pair(record)
    assert not named or name in named, (named, result["ranking"])
    # The responses were taken against the mean of the three reference runs at theta*.
    assert "minus the mean of 3 at theta*" in (out / "ranking.md").read_text()
    # The data that revealed the effect could name it had it been present at its strongest
    # probe level; every scored candidate has its naming power per level.
    power = pd.DataFrame(record["power"])
    scored = {r["candidate"] for r in record["ranking"]}
    assert (
        set(power["candidate"]) == scored and power[["found", "named"]].stack().between(0, 1).all()
    )
    assert power.loc[power["candidate"] == name, "named"].max() >= 0.5, record["power"]
    if result["winner"] != name:
        assert not result["extended"], result
        return
    ranking = pd.read_csv(out / "ranking.csv")
    assert list(ranking.loc[ranking["status"] == "named", "candidate"]) == [name]
    assert record["p_effect"] < 0.05 and record["p_runner_up"] < 0.05, record
    # The extended model fits within the noise (rms |z| below 1) where the current one did not.
    assert result["gap_after"] < min(1.0, result["gap_before"]), result
    # The DEM check decides whether the user may use the added effect, and its verdict follows
    # from its own numbers: confirmed only where the extended model at its identified point is
    # closer to the data than the current model, and at the load no step saw within the noise
    # or closer than before. Which way it goes on this one data set depends on the host's
    # floating point (docs/discrepancy.md); the matrix measures the rates.
    # and the gap left within the noise: N G^2 below the 95 % quantile of chi^2 with N degrees
    # of freedom, N the fitted values with a DEM mean (1.371 at N = 9).
    held = result["held_out_dem_gap_after"]
    closer = result["dem_gap_after"] < result["dem_gap_before"]
    held_ok = held <= max(1.0, result["held_out_dem_gap_before"])
    table = pd.read_csv(out / "gap_before_after.csv")
    fitted = table.loc[~table["held_out"].astype(bool), "z_dem_after"].dropna()
    assert result["dem_values"] == len(fitted) == 9, result
    bound = np.sqrt(chi2.ppf(0.95, len(fitted)) / len(fitted))
    assert result["dem_gap_bound"] == pytest.approx(bound)
    expected = (
        "not confirmed"
        if not (closer and held_ok)
        else "gap remains"
        if result["dem_gap_after"] > bound
        else "confirmed"
    )
    assert result["dem_verdict"] == expected, result
    verification = (out / "verification.md").read_text()
    if expected == "not confirmed":
        assert f"**The DEM runs do not confirm {name}**" in verification
        assert "do not use it without a further measurement" in verification
        return
    if expected == "gap remains":
        assert f"**The DEM runs show {name} closing part of the gap, not all of it**" in (
            verification
        )
        return
    assert f"**The DEM runs confirm {name}**" in verification
    truth = yaml.safe_load((studies[name] / "truth.yaml").read_text())["magnitude"]
    assert 0.25 * truth <= result["magnitude"] <= 4.0 * truth, (result, truth)


def test_dem_check_uses_replicates_at_fitted_and_held_out_loads(studies):
    # Wherever Find found a gap, the current model at theta* ran three times from fresh
    # packings at every load, the held-out one included; where an effect was added, so did
    # the extended model at its identified point.
    checked = 0
    for name, work in studies.items():
        result = summary(work)
        if not result["missing"]:
            continue
        gap = pd.read_csv(work / "results" / "discrepancy" / "gap_before_after.csv")
        stages = ["before", "after"] if result["extended"] else ["before"]
        for stage in stages:
            assert (gap[f"dem_{stage}_runs"] == 3).all(), (name, stage)
            assert (gap[f"dem_{stage}_sd"] > 0).all(), (name, stage)
            assert np.isfinite(result[f"held_out_dem_gap_{stage}"]), (name, stage)
        checked += 1
    assert checked, "no study reached the DEM check"


def test_no_hidden_effect_names_none(studies):
    result = summary(studies["none"])
    assert not result["missing"], result["verdict"]
    assert result["winner"] is None and not result["extended"]
    assert result["p_value"] >= result["alpha"]
    assert "Not run" in (studies["none"] / "results" / "discrepancy" / "ranking.md").read_text()
    # Nothing beyond Find was run.
    assert not (studies["none"] / "results" / "discrepancy" / "probes").exists()
    assert not (studies["none"] / "results" / "discrepancy" / "reprobes").exists()
    lead = json.loads((studies["none"] / "results" / "discrepancy" / "lead.json").read_text())
    assert lead["points"] == {}


def test_leaders_are_scored_at_their_own_best_fit(studies):
    # The two leading candidates on the probes at theta* ran again at their own best fit (the
    # reference three times, each level once) and were scored with those runs.
    out = studies["cohesion"] / "results" / "discrepancy"
    lead = json.loads((out / "lead.json").read_text())
    record = ranking_record(studies["cohesion"])
    scored = {r["candidate"] for r in record["ranking"]}
    assert len(lead["points"]) == min(2, len(scored)) and set(lead["points"]) <= scored, lead
    assert record["probed_again_at"] == lead["points"]
    theta_star = json.loads((out / "find.json").read_text())["point"]
    runs = pd.read_csv(out / "reprobes.csv")
    ranking = pd.read_csv(out / "ranking.csv").set_index("candidate")
    notes = (out / "ranking.md").read_text()
    for name, point in lead["points"].items():
        assert point.keys() == theta_star.keys()
        own = runs[runs["run"].str.match(rf"{name}\d")]
        base = own["run"].str.replace(r"_s\d+(_p\d+)?$", "", regex=True)
        assert sorted(set(base)) == sorted(
            {f"{name}0", f"{name}0_r2", f"{name}0_r3"} | {f"{name}{j}" for j in range(1, 4)}
        ), sorted(set(base))
        # Every parameter at the candidate's best fit but the candidate's own, which its levels set.
        parameter = ranking.loc[name, "parameter"]
        for key in point.keys() - {parameter}:
            assert own[key].to_numpy() == pytest.approx(point[key], rel=1e-7), (name, key)
        assert (own.loc[base == f"{name}0", "discrepancy_candidate"] == "none").all()
        assert f"{name}: scored with its probe runs at its own best fit" in notes


def test_hidden_cohesion_moves_the_liggghts_measurements(studies):
    # The twin signal compares the two LIGGGHTS data sets (same drawn friction, insertion seeds
    # and noise draws): the drawn cohesion moves them by more than their error, so naming it
    # is a question of the method, not of the data.
    rows = pd.DataFrame([json.loads((work / "row.json").read_text()) for work in studies.values()])
    table = with_signal(rows, studies["none"].parent).set_index("hidden")
    assert table.loc["cohesion", "signal"] >= VISIBLE_SIGNAL, table["signal"]
    assert math.isnan(table.loc["none", "signal"])


def friction_rise(signature: str, observable: str) -> dict[float, float]:
    """Change of one friction value per normal stress (Pa) read from a probe signature; an
    observable the signature calls "no clear change" rose by nothing at any stress."""
    if f"{observable} no clear change" in signature:
        return dict.fromkeys(STRESSES, 0.0)
    part = re.search(rf"{observable} ([^;(]*)", signature)
    assert part is not None, (observable, signature)
    return {
        float(stress.replace(" ", "")): float(value)
        for value, stress in re.findall(r"([+-][\d.]+) at ([\d ]+) Pa", part.group(1))
    }


def test_cohesion_signature_weakens_with_stress(studies):
    # Every study that reached the naming step probed cohesion at its theta* or at its own best
    # fit: the signature is the engine's response to cohesion there, whichever effect was hidden.
    probed = {}
    for name, work in studies.items():
        path = work / "results" / "discrepancy" / "ranking.csv"
        ranking = pd.read_csv(path) if path.is_file() else pd.DataFrame()
        if "signature" in ranking and "cohesion" in set(ranking["candidate"]):
            probed[name] = ranking.set_index("candidate").loc["cohesion", "signature"]
    assert probed, "no study reached the naming step"
    for name, signature in probed.items():
        # Cohesion loosens a packing (the packing fraction of spheres falls as the cohesive
        # force grows against the weight, Yang, Zou & Yu 2000), raises the friction values,
        # and its extra shear strength is a larger share of the stress at low normal stress.
        assert "rho_b -" in signature, (name, signature)
        rises = [friction_rise(signature, observable) for observable in ("mu_psh", "mu_sh")]
        assert all(sorted(rise) == list(STRESSES) for rise in rises), (name, signature)
        # One probe run per level, and a cohesive bed at low stress fails in lumps: twelve
        # seeds of the top level (65 000 J/m^3) at this theta* and 1 068 Pa read mu_psh
        # 0.63-1.86 and mu_sh 0.69-1.94 (sd 0.36 / 0.34) against 0.64 / 0.61 (sd 0.03 / 0.09)
        # without cohesion; LIGGGHTS scatters alike (docs/benchmarks.md, "Cohesion's top probe
        # at low stress"). The mean of the two friction values rose by 0.15 to 1.28 (mean 0.49)
        # at 1 068 Pa, by -0.08 to 0.18 (mean 0.03) at 4 000 Pa, so the test reads that mean at
        # the ends of the stress range; either value alone can read no rise at 1 068 Pa.
        mean = {s: (rises[0][s] + rises[1][s]) / 2.0 for s in STRESSES}
        assert mean[STRESSES[0]] > 0.1, (name, signature)
        assert mean[STRESSES[0]] > mean[STRESSES[-1]], (name, signature)
