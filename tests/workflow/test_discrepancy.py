"""The discrepancy workflow on synthetic data with a hidden effect (tiny scale, real engine).

"Measured" data come from the engine at known parameters with an effect switched on that the
model under calibration lacks (cohesion; rolling resistance): the mean of three runs per load
condition from fresh packings, with 0.5 % noise; a third data set has no hidden effect. The
truth files are read only here and by the study set-up, never by the workflow. The current
model's design, runs and surrogates are made once and copied into one study directory per data
set, which then runs `snakemake discrepancy`."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from demcal.core.config import validate_config
from demcal.core.experiments import load_experiment
from demcal.discrepancy.synthetic import study_config, write_hidden_effect_experiment

ROOT = Path(__file__).resolve().parents[2]
TRUTH = ROOT / "config" / "experiments" / "truth"
SCENARIOS = {
    "cohesion": "hidden_cohesion.yaml",
    "rolling": "hidden_rolling.yaml",
    "none": "hidden_none.yaml",
}
EXPERIMENT = "config/experiments/measured.yaml"
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


def snakefile(work: Path) -> Path:
    """The repository's Snakefile, with the discrepancy rules included if it lacks them."""
    main = ROOT / "Snakefile"
    if "discrepancy.smk" in main.read_text():
        return main
    wrapper = work / "Snakefile.discrepancy"
    wrapper.write_text(
        f'include: "{main}"\ninclude: "{ROOT / "workflow" / "rules" / "discrepancy.smk"}"\n'
    )
    return wrapper


def snakemake(work: Path, *targets: str) -> subprocess.CompletedProcess:
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "snakemake",
            *targets,
            "--snakefile",
            str(snakefile(work)),
            "--directory",
            str(work),
            "--cores",
            "2",
            # `run:` jobs in threads: otherwise Snakemake parses the whole workflow anew in a
            # subprocess for every rendering and bulk-value job (several times slower here).
            "--force-use-threads",
            "--configfile",
            str(work / "config" / "config.yaml"),
        ],
        cwd=work,
        capture_output=True,
        text=True,
        timeout=1200,
    )
    assert res.returncode == 0, res.stderr[-6000:]
    return res


@pytest.fixture(scope="module")
def studies(tmp_path_factory) -> dict[str, Path]:
    """One finished study directory per data set."""
    base = tmp_path_factory.mktemp("discrepancy_base")
    (base / "config" / "experiments").mkdir(parents=True)
    raw = yaml.safe_load((ROOT / "config" / "tiny.yaml").read_text())
    config = study_config(raw)
    config["experiment"] = EXPERIMENT
    (base / "config" / "config.yaml").write_text(yaml.safe_dump(config, sort_keys=False))
    validated = validate_config(json.loads(json.dumps(config)), "study config")
    measured = {}
    for name, truth in SCENARIOS.items():
        measured[name] = base / f"measured_{name}.yaml"
        write_hidden_effect_experiment(
            TRUTH / truth, validated, measured[name], base / "truth_runs" / name, 0.005, 1
        )
    shutil.copy(measured["none"], base / EXPERIMENT)
    # The current model: design runs and surrogates, shared by all studies.
    snakemake(base, *[f"results/surrogates/{o}/model.pt" for o in ("mu_psh", "mu_sh", "rho_b")])
    shutil.rmtree(base / "truth_runs")
    out = {}
    for name in SCENARIOS:
        work = tmp_path_factory.mktemp(f"discrepancy_{name}")
        shutil.copytree(base, work, dirs_exist_ok=True, symlinks=True)
        shutil.copy(measured[name], work / EXPERIMENT)
        snakemake(work, "discrepancy")
        out[name] = work
    return out


def summary(work: Path) -> dict:
    return json.loads((work / "results" / "discrepancy" / "summary.json").read_text())


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_all_outputs_written(studies, name):
    out = studies[name] / "results" / "discrepancy"
    for output in OUTPUTS:
        assert (out / output).is_file(), (name, output)
    # One row of the before/after table per measured value, its misfit before the effect
    # finite; the summary's gap is the root mean square of those misfits.
    experiment = load_experiment(studies[name] / EXPERIMENT)
    measured = sum(len(c.values) for c in experiment.shear_conditions)
    measured += experiment.angle_of_repose is not None
    gap = pd.read_csv(out / "gap_before_after.csv")
    assert len(gap) == measured, (name, len(gap))
    assert np.isfinite(gap[["measured", "sigma", "z_before"]].to_numpy()).all(), name
    result = summary(studies[name])
    assert result["gap_before"] == pytest.approx(np.sqrt(np.mean(gap["z_before"] ** 2)), rel=1e-4)
    config = (studies[name] / "config" / "config.yaml").read_text()
    assert "truth" not in config
    assert "parameters" not in yaml.safe_load((studies[name] / EXPERIMENT).read_text())


# Known failures since the shear-cell readout measures the bulk (docs/virtual-tests.md): with
# mu no longer inflated by the upper tube's wall friction, hidden cohesion 5e4 J/m^3 is named as
# rolling resistance (dBIC 31.1 against 27.9 for cohesion, tiny scale). Hidden rolling
# resistance is named (dBIC 11.3, magnitude 0.16 for a truth of 0.2, surrogate gap 2.62 -> 0.56),
# but the DEM run of the extended model misses the data by more than the model without it
# (gap 3.22 against 2.61). Both are the weaknesses the discrepancy validation (independent
# LIGGGHTS data, drawn truths, replicate DEM checks, calibrated decisions) has to remove;
# strict, so that a change that makes them pass is noticed.
_KNOWN = pytest.mark.xfail(
    strict=True, reason="hidden cohesion named as rolling; rolling's DEM check misses"
)


@pytest.mark.parametrize(
    "name", [pytest.param("cohesion", marks=_KNOWN), pytest.param("rolling", marks=_KNOWN)]
)
def test_hidden_effect_is_named_and_gap_shrinks(studies, name):
    result = summary(studies[name])
    assert result["missing"], result["verdict"]
    assert result["winner"] == name, result["ranking"]
    assert result["gap_ratio"] >= 3.0, (result["gap_before"], result["gap_after"])
    # The DEM runs agree: the extended model at its identified point is closer to the data.
    assert result["dem_gap_after"] < result["dem_gap_before"], result
    truth = yaml.safe_load((TRUTH / SCENARIOS[name]).read_text())["parameters"]
    parameter = result["parameter"]
    assert 0.4 * truth[parameter] <= result["magnitude"] <= 2.0 * truth[parameter], result
    ranking = pd.read_csv(studies[name] / "results" / "discrepancy" / "ranking.csv")
    named = ranking[ranking["status"] == "named"]
    assert list(named["candidate"]) == [name]
    assert named["delta_bic"].iloc[0] >= 6.0


def test_no_hidden_effect_names_none(studies):
    result = summary(studies["none"])
    assert not result["missing"], result["verdict"]
    assert result["winner"] is None and not result["extended"]
    assert result["gap_before"] <= result["threshold"]
    assert "Not run" in (studies["none"] / "results" / "discrepancy" / "ranking.md").read_text()
    # Nothing beyond Find was run.
    assert not (studies["none"] / "results" / "discrepancy" / "probes").exists()


def test_cohesion_signature_weakens_with_stress(studies):
    ranking = pd.read_csv(studies["cohesion"] / "results" / "discrepancy" / "ranking.csv")
    signature = ranking.set_index("candidate").loc["cohesion", "signature"]
    # Cohesion loosens a packing (the packing fraction of spheres falls as the cohesive force
    # grows against the weight, Yang, Zou & Yu 2000) and its extra shear strength is a larger
    # share of the stress at low normal stress.
    assert "rho_b -" in signature and "weakens with normal stress" in signature, signature
