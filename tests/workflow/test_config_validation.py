"""Snakemake stops on a bad configuration before any job runs, naming the key."""

import subprocess
import sys
from pathlib import Path

import yaml

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
