"""Measured bulk data (``config/experiments/*.yaml``): loading, validation, acceptance targets."""

from dataclasses import dataclass, field
from pathlib import Path

import yaml

from demcal.core.config import ConfigError, validate
from demcal.identification.acceptance import MeasuredCondition

SHEAR_OBSERVABLES = ("mu_psh", "mu_sh", "rho_b")


@dataclass
class Experiment:
    """Measured data of one material; only what was measured is matched."""

    material: str
    source: str
    shear_conditions: list[MeasuredCondition] = field(default_factory=list)
    angle_of_repose: float | None = None
    angle_of_repose_sd: float | None = None


def load_experiment(path: str | Path) -> Experiment:
    """Read and validate an experiment file.

    Raises
    ------
    ConfigError
        Naming the file and the key for invalid content.
    """
    path = Path(path)
    try:
        raw = yaml.safe_load(path.read_text()) or {}
    except (OSError, yaml.YAMLError) as exc:
        raise ConfigError(f"{path}: cannot read experiment file: {exc}") from exc
    if not isinstance(raw, dict):
        raise ConfigError(f"{path}: top level must be a mapping")
    given = {k: v for k, v in raw.items()}
    validate(given, "experiment.schema.yaml", str(path))
    conditions = []
    for entry in raw.get("shear_cell", []) or []:
        values = {k: float(entry[k]) for k in SHEAR_OBSERVABLES if k in entry}
        if not values:
            continue
        sds = {k: float(entry[f"{k}_sd"]) for k in SHEAR_OBSERVABLES if f"{k}_sd" in entry}
        conditions.append(
            MeasuredCondition(
                values=values,
                uncertainties=sds,
                normal_stress=float(entry["normal_stress"]),
                P=float(entry["P"]),
            )
        )
    aor = raw.get("angle_of_repose")
    return Experiment(
        material=str(raw["material"]),
        source=str(raw.get("source", "")),
        shear_conditions=conditions,
        angle_of_repose=float(aor["value"]) if aor else None,
        angle_of_repose_sd=float(aor["sd"]) if aor and "sd" in aor else None,
    )
