"""A one-node Slurm cluster on localhost, started once per test module, and a Snakemake runner."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[2]
PROFILES = ROOT / "workflow" / "profiles"


def _load_local_cluster() -> ModuleType:
    """Import ``scripts/slurm/local_cluster.py`` (scripts are not a package)."""
    path = ROOT / "scripts" / "slurm" / "local_cluster.py"
    spec = importlib.util.spec_from_file_location("demcal_local_cluster", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    # Registered before execution: dataclasses look their module up by name.
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


local_cluster = _load_local_cluster()


@pytest.fixture(scope="module")
def slurm_cluster() -> Iterator:
    """Install Slurm/MUNGE if missing, start the daemons, and stop exactly those afterwards.

    Only a run without root skips these tests: munged, slurmctld and slurmd need root. As root
    (CI runs `make test` as root) anything else that stops the cluster fails the tests.
    """
    if os.geteuid() != 0:
        pytest.skip(
            f"needs root to install Slurm/MUNGE and start munged, slurmctld and slurmd "
            f"(running as uid {os.geteuid()})"
        )
    reason = local_cluster.unavailable_reason(install=True)
    if reason:
        pytest.fail(f"no local Slurm cluster although running as root: {reason}", pytrace=False)
    cluster = local_cluster.start()
    try:
        yield cluster
    finally:
        local_cluster.stop(cluster)


def snakemake(
    workdir: Path, *args: str, snakefile: Path = ROOT / "Snakefile", timeout: float = 1200
) -> subprocess.CompletedProcess:
    """Run Snakemake on ``snakefile`` in ``workdir`` with the venv's programs on PATH.

    Jobs submitted to Slurm inherit this environment (sbatch --export=ALL), so they find the
    same Python and ``dem_engine`` (installed in the venv, or else the build tree's).
    """
    env = {k: v for k, v in os.environ.items() if k not in ("SLURM_CONF", "SNAKEMAKE_PROFILE")}
    programs = [str(Path(sys.executable).parent), str(ROOT / "build" / "engine")]
    env["PATH"] = os.pathsep.join([*programs, env.get("PATH", "")])
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "snakemake",
            "--snakefile",
            str(snakefile),
            "--directory",
            str(workdir),
            *args,
        ],
        cwd=workdir,
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
    )
