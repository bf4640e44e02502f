"""Measured bulk data (``config/experiments/*.yaml``): loading, validation, acceptance targets."""

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from demcal.core.config import ConfigError, validate

SHEAR_OBSERVABLES = ("mu_psh", "mu_sh", "rho_b")


def _format_load(value: float | None) -> str:
    return "None" if value is None else f"{value:g}"


@dataclass(frozen=True)
class MeasuredCondition:
    """Measured bulk values of one experiment at one load condition.

    Parameters
    ----------
    values : Mapping[str, float]
        Measured bulk values by output name (``mu_psh``, ``mu_sh`` [-], ``rho_b`` [kg/m^3],
        ``aor`` [deg], ...). Must be non-empty, finite and non-zero (they are divisors).
    uncertainties : Mapping[str, float], optional
        Standard deviations of the measured values, same units; keys must be in ``values``.
    normal_stress : float or None
        Pre-shear normal stress [Pa] of a shear-cell condition; None for tests without load.
    P : float or None
        Shear load as a fraction of the pre-shear load [-]; given together with
        ``normal_stress``.
    name : str or None
        Label of the condition; generated from the load when omitted.
    """

    values: Mapping[str, float]
    uncertainties: Mapping[str, float] = field(default_factory=dict)
    normal_stress: float | None = None
    P: float | None = None
    name: str | None = None

    def __post_init__(self) -> None:
        if not self.values:
            raise ValueError(f"measured condition {self.label!r}: no measured values given")
        for key, value in self.values.items():
            if not math.isfinite(value) or value == 0.0:
                raise ValueError(
                    f"measured condition {self.label!r}: value of {key!r} must be finite and "
                    f"non-zero, got {value!r}"
                )
        for key, value in self.uncertainties.items():
            if key not in self.values:
                raise KeyError(
                    f"measured condition {self.label!r}: uncertainty given for {key!r} "
                    f"which has no measured value"
                )
            if not math.isfinite(value) or value < 0.0:
                raise ValueError(
                    f"measured condition {self.label!r}: uncertainty of {key!r} must be finite "
                    f"and >= 0, got {value!r}"
                )
        if (self.normal_stress is None) != (self.P is None):
            raise ValueError(
                f"measured condition {self.label!r}: normal_stress and P must be given together"
            )
        if self.normal_stress is not None and not self.normal_stress > 0.0:
            raise ValueError(
                f"measured condition {self.label!r}: normal_stress must be > 0 Pa, "
                f"got {self.normal_stress!r}"
            )

    @property
    def label(self) -> str:
        """Name of the condition, e.g. ``"normal_stress=10070,P=1"``."""
        if self.name is not None:
            return self.name
        if self.normal_stress is None and self.P is None:
            return "+".join(self.values)
        return f"normal_stress={_format_load(self.normal_stress)},P={_format_load(self.P)}"

    @property
    def load(self) -> dict[str, float]:
        """Load features of the condition (``normal_stress`` [Pa], ``P`` [-]); empty if none."""
        if self.normal_stress is None or self.P is None:
            return {}
        return {"normal_stress": float(self.normal_stress), "P": float(self.P)}


@dataclass
class Experiment:
    """Measured data of one material; only what was measured is matched."""

    material: str
    source: str
    shear_conditions: list[MeasuredCondition] = field(default_factory=list)
    angle_of_repose: float | None = None
    angle_of_repose_sd: float | None = None

    @property
    def outputs(self) -> list[str]:
        """The bulk values measured at least once, shear-cell values first, no repeats."""
        names = [name for cond in self.shear_conditions for name in cond.values]
        if self.angle_of_repose is not None:
            names.append("aor")
        return list(dict.fromkeys(names))


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
