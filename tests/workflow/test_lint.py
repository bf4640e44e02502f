"""Code style gates: ruff (lint and format) on the Python code and Snakemake's own linter on
the workflow."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(sys.executable).parent


def _ruff(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(BIN / "ruff"), *args, "demcal", "scripts", "tests"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_ruff_clean():
    res = _ruff("check")
    assert res.returncode == 0, res.stdout + res.stderr


def test_ruff_format_clean():
    res = _ruff("format", "--check")
    assert res.returncode == 0, res.stdout + res.stderr


def test_snakemake_lint_clean():
    res = subprocess.run(
        [sys.executable, "-m", "snakemake", "--lint"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert res.returncode == 0, res.stdout + res.stderr
    assert "Congratulations" in res.stdout + res.stderr
