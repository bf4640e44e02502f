"""Snakemake stops on a bad configuration before any job runs, naming the key."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from demcal.core.snakemake_run import run_snakemake

ROOT = Path(__file__).resolve().parents[2]
SNAKEMAKE = [sys.executable, "-m", "snakemake"]


def _dry_run(tmp_path: Path, config: dict) -> subprocess.CompletedProcess:
    cfg = tmp_path / "cfg.yaml"
    cfg.write_text(yaml.safe_dump(config))
    return subprocess.run(
        [
            *SNAKEMAKE,
            "--cores",
            "1",
            "--dry-run",
            "--configfile",
            str(cfg),
            "--directory",
            str(ROOT),
        ],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=120,
    )


def test_wrong_key_stops_workflow(tmp_path):
    res = _dry_run(tmp_path, {"design": {"kind": "lhs", "samples": 3}})
    assert res.returncode != 0
    assert "'samples'" in res.stderr + res.stdout
    assert "cfg.yaml" in res.stderr + res.stdout


def test_value_out_of_range_stops_workflow(tmp_path):
    res = _dry_run(tmp_path, {"engine": {"threads": -2}})
    assert res.returncode != 0
    assert "engine.threads" in res.stderr + res.stdout


def test_misspelt_contact_parameter_stops_a_real_run_before_any_job(tmp_path):
    """A real (not dry) run of the tiny study with a misspelt design range: Snakemake stops
    while reading the configuration, names the key and suggests the name, and runs no job."""
    work = tmp_path / "study"
    shutil.copytree(ROOT / "config", work / "config")
    config = yaml.safe_load((ROOT / "config" / "tiny.yaml").read_text())
    config["design"]["ranges"] = {
        "coefficientFrction": [0.1, 0.9],
        "coefficientRollingFriction": [0.1, 0.9],
        "coefficientRestitution": [0.5, 0.9],
        "density": [2500.0, 3500.0],
    }
    (work / "config.yaml").write_text(yaml.safe_dump(config))
    res = subprocess.run(
        [
            *SNAKEMAKE,
            "results/design/cases.csv",  # before --configfile, which takes several values
            "--snakefile",
            str(ROOT / "Snakefile"),
            "--directory",
            str(work),
            "--cores",
            "1",
            "--configfile",
            str(work / "config.yaml"),
        ],
        capture_output=True,
        text=True,
        cwd=work,
        timeout=300,
    )
    out = res.stderr + res.stdout
    assert res.returncode != 0
    assert (
        "design.ranges.coefficientFrction: unknown contact parameter "
        "(did you mean coefficientFriction?)" in out
    )
    assert "config.yaml" in out
    assert "Job stats" not in out and "rule design" not in out
    assert not (work / "results").exists()
    assert not (work / "logs").exists()


def test_sequential_study_without_a_box_stops_workflow(tmp_path):
    """A sequential study needs a sampled round 0: a factorial design is refused by name."""
    res = _dry_run(
        tmp_path,
        {
            "design": {"kind": "factorial", "levels": {"coefficientFriction": [0.2, 0.6]}},
            "sequential": {"enabled": True},
        },
    )
    assert res.returncode != 0
    assert "sequential.enabled" in res.stderr + res.stdout
    assert "design.kind" in res.stderr + res.stdout


def test_study_runner_stops_naming_the_study_and_the_key(tmp_path):
    work = tmp_path / "study"
    (work / "config").mkdir(parents=True)
    (work / "config" / "config.yaml").write_text(
        yaml.safe_dump({"design": {"kind": "lhs", "samples": 3}})
    )
    log = tmp_path / "study.log"
    with pytest.raises(RuntimeError) as err:
        run_snakemake(work, 1, log, "--dry-run")
    message = str(err.value)
    assert str(work) in message and str(log) in message
    assert "'samples'" in message
    # a second call appends to the same log
    size = log.stat().st_size
    with pytest.raises(RuntimeError):
        run_snakemake(work, 1, log, "--dry-run")
    assert log.stat().st_size > size
