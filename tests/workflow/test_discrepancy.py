"""The discrepancy workflow on synthetic data with a hidden effect (tiny scale).

"Measured" data come from LIGGGHTS 3.8 at a drawn truth with an effect switched on that the
model under calibration (on the bundled engine) lacks: cohesion, rolling resistance, or
nothing. The truth's sliding friction and the effect's magnitude are drawn (seeded) from the
truth specifications, clear of the catalogue's probe levels; each value is the mean of three
runs per load condition from fresh packings, with 3 % noise on friction and 1 % on bulk density
(:data:`demcal.discrepancy.synthetic.NOISE`). The truths are read only here and by the study
set-up, never by the workflow. The current model's design, runs and surrogates are made once
and copied into one study directory per data set, which then runs `snakemake discrepancy`."""

import json
import re
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

from ..liggghts.conftest import require_liggghts

ROOT = Path(__file__).resolve().parents[2]
TRUTH = ROOT / "config" / "experiments" / "truth"
SCENARIOS = {
    "cohesion": "hidden_cohesion.yaml",
    "rolling": "hidden_rolling.yaml",
    "none": "hidden_none.yaml",
}
#: Seed of the truth draws and of the noise.
TRUTH_SEED = 2026
TRUTH_ENGINE = "liggghts -in {deck}"
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
    require_liggghts()
    measured, truths = {}, {}
    for name, truth in SCENARIOS.items():
        measured[name] = base / f"measured_{name}.yaml"
        _, truths[name] = write_hidden_effect_experiment(
            TRUTH / truth,
            validated,
            measured[name],
            base / "truth_runs" / name,
            None,
            TRUTH_SEED,
            truth_seed=TRUTH_SEED,
            truth_engine=TRUTH_ENGINE,
        )
        (base / f"truth_{name}.yaml").write_text(yaml.safe_dump(truths[name].record()))
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


# Known failures. On these honest data (LIGGGHTS truths, drawn with seed 2026: sliding friction
# 0.339 in all three, hidden cohesion 32 560 J/m^3, hidden rolling resistance 0.163; 3 % noise
# on friction, 1 % on bulk density) Find is right in all three studies (p = 0.017 with
# cohesion, 0.001 with rolling resistance, 0.72 with nothing hidden). Hidden rolling resistance
# is named (p_effect 0.010, against cohesion p 0.002) and the DEM gap shrinks from 2.11 to
# 0.71, but the surrogate gap only from 2.12 to 0.61 (ratio 2.2 < 3) and the fitted magnitude is
# 0.062, 0.38 of the truth. Hidden cohesion is not named (p_effect 0.31). These are the
# weaknesses the discrepancy validation (replicate probe runs, a validation matrix) has to
# remove; strict, so that a change that makes them pass is noticed.
_KNOWN = pytest.mark.xfail(
    strict=True, reason="honest tiny data: cohesion not named, rolling named with 0.38x magnitude"
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
    truth = yaml.safe_load((studies[name] / f"truth_{name}.yaml").read_text())["magnitude"]
    assert 0.4 * truth <= result["magnitude"] <= 2.0 * truth, (result, truth)
    ranking = pd.read_csv(studies[name] / "results" / "discrepancy" / "ranking.csv")
    named = ranking[ranking["status"] == "named"]
    assert list(named["candidate"]) == [name]
    record = json.loads((studies[name] / "results" / "discrepancy" / "ranking.json").read_text())
    assert record["p_effect"] < 0.05 and record["p_runner_up"] < 0.05, record


def test_no_hidden_effect_names_none(studies):
    result = summary(studies["none"])
    assert not result["missing"], result["verdict"]
    assert result["winner"] is None and not result["extended"]
    assert result["p_value"] >= result["alpha"]
    assert "Not run" in (studies["none"] / "results" / "discrepancy" / "ranking.md").read_text()
    # Nothing beyond Find was run.
    assert not (studies["none"] / "results" / "discrepancy" / "probes").exists()


def test_cohesion_signature_weakens_with_stress(studies):
    # Every study that reached the naming step probed cohesion at its theta*: the signature is
    # the engine's response to cohesion there, whichever effect was hidden.
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
        # Single probe runs scatter (mu_sh by about 0.1), so mu_sh is not asserted.
        assert "rho_b -" in signature, (name, signature)
        rise = re.search(r"mu_psh \+([\d.]+) at 1 068 Pa, \+([\d.]+) at 2 029 Pa", signature)
        assert rise is not None, (name, signature)
        assert float(rise.group(1)) > float(rise.group(2)) > 0.0, (name, signature)
