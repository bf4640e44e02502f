"""JSON sidecars that record where an artifact came from: config hash, seed, versions, commit."""

import hashlib
import json
import platform
import subprocess
from collections.abc import Mapping
from importlib import metadata
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]


def config_hash(config: Mapping[str, Any]) -> str:
    """SHA-256 of the configuration serialised with sorted keys."""
    text = json.dumps(config, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def git_commit() -> str | None:
    """The commit of the working tree, or None outside a git checkout."""
    try:
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True, timeout=10
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    return out.stdout.strip() or None


def versions() -> dict[str, str]:
    """Versions of Python and of the packages the results depend on."""
    found = {"python": platform.python_version()}
    for name in ("demcal", "numpy", "pandas", "scipy", "torch", "scikit-learn", "snakemake"):
        try:
            found[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            continue
    return found


def write_sidecar(
    artifact: str | Path,
    config: Mapping[str, Any],
    seed: int | None = None,
    extra: Mapping[str, Any] | None = None,
) -> Path:
    """Write ``<artifact>.json`` describing how ``artifact`` was made.

    Parameters
    ----------
    artifact : str or Path
        The file the sidecar describes.
    config : mapping
        The validated workflow configuration.
    seed : int, optional
        The seed of the stochastic step that made the artifact.
    extra : mapping, optional
        Further facts (counts, timings, settings).
    """
    path = Path(f"{artifact}.json")
    record = {
        "artifact": Path(artifact).name,
        "config_sha256": config_hash(config),
        "seed": seed,
        "git_commit": git_commit(),
        "versions": versions(),
        **(dict(extra) if extra else {}),
    }
    path.write_text(json.dumps(record, indent=2, sort_keys=True, default=str) + "\n")
    return path
