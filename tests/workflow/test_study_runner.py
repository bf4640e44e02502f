"""The study runner of the validation drivers keeps finished jobs across a code upgrade."""

import base64
import json
import shutil
import subprocess
import sys
from pathlib import Path

import yaml

from demcal.core.snakemake_run import SNAKEFILE, run_snakemake

ROOT = Path(__file__).resolve().parents[2]
TARGET = "results/design/cases.csv"


def _study(tmp_path: Path) -> Path:
    work = tmp_path / "study"
    shutil.copytree(ROOT / "config", work / "config")
    shutil.copy(ROOT / "config" / "tiny.yaml", work / "config" / "config.yaml")
    return work


def _plain_dry_run(work: Path) -> str:
    """Snakemake with its default rerun triggers, as a user would call it."""
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "snakemake",
            TARGET,
            "--dry-run",
            "--snakefile",
            str(SNAKEFILE),
            "--directory",
            str(work),
            "--cores",
            "1",
            "--configfile",
            str(work / "config" / "config.yaml"),
        ],
        capture_output=True,
        text=True,
        cwd=work,
        timeout=300,
    )
    assert res.returncode == 0, res.stderr
    return res.stdout + res.stderr


def test_a_code_change_keeps_the_finished_job_a_parameter_change_does_not(tmp_path):
    work = _study(tmp_path)
    log = tmp_path / "study.log"
    run_snakemake(work, 1, log, TARGET)
    table = (work / TARGET).read_text()

    # What Snakemake recorded of the job's code is now different, as after an upgrade.
    record = work / ".snakemake" / "metadata" / base64.b64encode(TARGET.encode()).decode()
    meta = json.loads(record.read_text())
    meta["code"] = "an older version of the rule"
    record.write_text(json.dumps(meta))
    assert "Code has changed since last execution" in _plain_dry_run(work)

    start = log.stat().st_size
    run_snakemake(work, 1, log, TARGET)
    assert "Nothing to be done" in log.read_text()[start:]
    assert (work / TARGET).read_text() == table

    # A changed parameter of the job still reruns it.
    config = yaml.safe_load((work / "config" / "config.yaml").read_text())
    config["design"]["seed"] = int(config["design"]["seed"]) + 1
    (work / "config" / "config.yaml").write_text(yaml.safe_dump(config))
    start = log.stat().st_size
    run_snakemake(work, 1, log, TARGET)
    assert "Params have changed since last execution" in log.read_text()[start:]
    assert (work / TARGET).read_text() != table
