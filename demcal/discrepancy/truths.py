"""Hidden truths of a discrepancy validation study, drawn instead of chosen.

A truth *specification* (``config/experiments/truth/hidden_*.yaml``) says which effect is hidden
(the name of a candidate of the study's catalogue, or null for none) and how the true values
are found:

- ``parameters``: values fixed at the truth (case columns);
- ``draw``: case columns drawn uniformly from ``[low, high]`` (e.g. the sliding friction);
- ``effect_span``: the part of the candidate's range its magnitude is drawn from, as fractions
  ``[a, b]`` of the range (default :data:`EFFECT_SPAN`). With ``b`` at most
  :data:`MAX_EFFECT_FRACTION` the range extends well past any truth, so that a fitted magnitude
  can overshoot it and the magnitude check can fail;
- ``probe_clearance``: a drawn magnitude closer than this fraction of the range to a probe level
  is drawn again (default :data:`PROBE_CLEARANCE`), so no truth sits at a level the workflow
  measures directly;
- ``off_clearance``: likewise for the candidate's "absent" value (default
  :data:`OFF_CLEARANCE`), which for wall friction is the truth's own sliding friction: a hidden
  effect has to be there to be found;
- ``switch``: configuration overrides of the truth runs beyond the hidden candidate (an
  effect outside the catalogue, e.g. softer particles);
- ``profiles``: per profile, replacements of ``parameters``, ``draw`` and ``switch``.

The effect is switched on with the candidate's own switch and configuration key, so the truth
runs use exactly the deck switch the workflow would add. The drawn truth is written next to the
study (``truth.yaml``), never into its configuration: the workflow does not read it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from demcal.discrepancy.candidates import (
    Candidate,
    candidate_config,
    deep_merge,
    parse_candidates,
)

__all__ = [
    "EFFECT_SPAN",
    "MAX_EFFECT_FRACTION",
    "OFF_CLEARANCE",
    "PROBE_CLEARANCE",
    "DrawnTruth",
    "draw_truth",
    "load_truth_spec",
    "truth_config",
]

#: Default part of a candidate's range that a hidden magnitude is drawn from (fractions).
EFFECT_SPAN = (0.15, 0.7)
#: Largest upper fraction allowed: the range must extend past every truth by 20 % of itself.
MAX_EFFECT_FRACTION = 0.8
#: Default smallest distance of a drawn magnitude from any probe level (fraction of the range).
PROBE_CLEARANCE = 0.05
#: Default smallest distance of a drawn magnitude from the candidate's "absent" value (fraction
#: of the range). Equal to the lower end of EFFECT_SPAN, so that it only acts where the absent
#: value lies inside the range (wall friction: the sliding friction).
OFF_CLEARANCE = 0.15
_MAX_DRAWS = 1000


@dataclass(frozen=True)
class DrawnTruth:
    """The true material of one hidden-effect study.

    Attributes
    ----------
    material : str
        Name of the synthetic material.
    effect : str or None
        Candidate name of the hidden effect; None when nothing is hidden.
    parameters : dict
        Case columns of the truth runs (model parameters, and the effect's magnitude when it
        is a case column).
    switch : dict
        Configuration overrides of the specification (``switch``), applied before the
        effect's own switch (see :func:`truth_config`).
    magnitude : float or None
        The hidden effect's magnitude.
    seed : int
        Seed of the draw.
    drawn : dict
        The values that were drawn (name -> value), for the record.
    """

    material: str
    effect: str | None
    parameters: dict[str, float]
    switch: dict[str, Any]
    magnitude: float | None
    seed: int
    drawn: dict[str, float] = field(default_factory=dict)

    def record(self) -> dict[str, Any]:
        """A YAML-ready mapping of the truth (``truth.yaml`` of a study)."""
        return {
            "material": self.material,
            "effect": self.effect,
            "magnitude": self.magnitude,
            "seed": self.seed,
            "parameters": dict(self.parameters),
            "drawn": dict(self.drawn),
            "switch": dict(self.switch),
        }


def load_truth_spec(path: str | Path) -> dict[str, Any]:
    """A truth specification file as a mapping; raises ``ValueError`` naming the file."""
    path = Path(path)
    spec = yaml.safe_load(path.read_text())
    if not isinstance(spec, Mapping) or "material" not in spec or "effect" not in spec:
        raise ValueError(f"{path}: a truth specification needs 'material' and 'effect'")
    return dict(spec)


def _profile_spec(spec: Mapping[str, Any], profile: str) -> dict[str, Any]:
    overrides = (spec.get("profiles") or {}).get(profile) or {}
    out = dict(spec)
    for key in ("parameters", "draw", "switch", "effect_span", "probe_clearance", "off_clearance"):
        if key in overrides:
            out[key] = (
                {**(spec.get(key) or {}), **overrides[key]}
                if isinstance(overrides[key], Mapping)
                else overrides[key]
            )
    return out


def _candidate(config: Mapping[str, Any], name: str, where: str) -> Candidate:
    candidates = parse_candidates(config.get("discrepancy", {}).get("candidates", []))
    for c in candidates:
        if c.name == name:
            return c
    raise ValueError(
        f"{where}: effect {name!r} is not a candidate of the study's catalogue "
        f"({', '.join(c.name for c in candidates)})"
    )


def _draw_magnitude(
    candidate: Candidate,
    span: tuple[float, float],
    clearance: float,
    rng: np.random.Generator,
    where: str,
    off: tuple[float, float] = (math.nan, 0.0),
) -> float:
    """A magnitude from ``span`` of the candidate's range, clear of its probe levels and of
    ``off`` = (absent value, clearance as a fraction of the range)."""
    lo, hi = candidate.range
    width = hi - lo
    a, b = span
    if not 0.0 <= a < b <= MAX_EFFECT_FRACTION:
        raise ValueError(
            f"{where}: effect_span {list(span)} must satisfy 0 <= a < b <= "
            f"{MAX_EFFECT_FRACTION} (the candidate's range must extend past the truth)"
        )
    low, high = lo + a * width, lo + b * width
    levels = np.asarray(candidate.probe_levels, float)
    off_value, off_clearance = off

    def clear(value: float) -> bool:
        # NaN (no absent value inside the range) compares False: nothing to keep clear of.
        near_off = abs(value - off_value) <= off_clearance * width
        return bool(np.all(np.abs(levels - value) > clearance * width)) and not near_off

    if candidate.integer:
        options = [v for v in range(math.ceil(low), math.floor(high) + 1) if clear(v)]
        if not options:
            raise ValueError(
                f"{where}: no whole magnitude of {candidate.name} in [{low:g}, {high:g}] keeps "
                f"clear of the probe levels {list(candidate.probe_levels)}"
            )
        return float(options[int(rng.integers(len(options)))])
    for _ in range(_MAX_DRAWS):
        value = float(rng.uniform(low, high))
        if clear(value):
            return value
    raise ValueError(
        f"{where}: the probe levels {list(candidate.probe_levels)} and the absent value "
        f"{off_value:g} leave no room in [{low:g}, {high:g}] at clearances of {clearance:g} "
        f"and {off_clearance:g} of the range"
    )


def draw_truth(
    spec: Mapping[str, Any], config: Mapping[str, Any], seed: int, where: str = "truth"
) -> DrawnTruth:
    """Draw the true material of a study from a truth specification.

    Parameters
    ----------
    spec : mapping
        The truth specification (see the module documentation).
    config : mapping
        The validated study configuration: its profile selects ``profiles`` entries, its
        ``discrepancy.candidates`` give the hidden effect's range, probe levels and switch, and
        its design ranges must contain every drawn model parameter.
    seed : int
        Seed of the draw; the same seed gives the same truth.
    where : str
        Name of the specification in error messages (e.g. its file).

    Raises
    ------
    ValueError
        For an effect that is not a candidate, a draw range outside the design's, an
        ``effect_span`` that leaves no room past the truth, or probe levels that leave no room
        for a magnitude.
    """
    spec = _profile_spec(spec, str(config.get("profile", "")))
    rng = np.random.default_rng(seed)
    parameters = {k: float(v) for k, v in (spec.get("parameters") or {}).items()}
    ranges = config.get("design", {}).get("ranges", {})
    drawn: dict[str, float] = {}
    for name, bounds in sorted((spec.get("draw") or {}).items()):
        low, high = (float(v) for v in bounds)
        if not low < high:
            raise ValueError(f"{where}: draw.{name} needs low < high, got {list(bounds)}")
        if name in ranges and not (ranges[name][0] <= low and high <= ranges[name][1]):
            raise ValueError(
                f"{where}: draw.{name} {list(bounds)} leaves the design range "
                f"{list(ranges[name])}: the model could not reach the truth for that reason alone"
            )
        drawn[name] = parameters[name] = float(rng.uniform(low, high))
    switch = dict(spec.get("switch") or {})
    effect = spec.get("effect")
    magnitude = None
    if effect is not None:
        candidate = _candidate(config, str(effect), where)
        span = tuple(float(v) for v in spec.get("effect_span", EFFECT_SPAN))
        clearance = float(spec.get("probe_clearance", PROBE_CLEARANCE))
        off = (
            candidate.off_magnitude(parameters),
            float(spec.get("off_clearance", OFF_CLEARANCE)),
        )
        magnitude = _draw_magnitude(candidate, (span[0], span[1]), clearance, rng, where, off)
        drawn[candidate.parameter] = magnitude
        if not candidate.config_key:
            parameters[candidate.parameter] = magnitude
    return DrawnTruth(
        material=str(spec["material"]),
        effect=None if effect is None else str(effect),
        parameters=parameters,
        switch=switch,
        magnitude=magnitude,
        seed=int(seed),
        drawn=drawn,
    )


def truth_config(truth: DrawnTruth, config: Mapping[str, Any]) -> dict[str, Any]:
    """The configuration of the truth runs: the study's with the hidden effect switched on.

    The effect is switched on as the workflow would add it (the candidate's switch and, for a
    configuration-key magnitude such as ``particles.classes``, that key), so the truth differs
    from the model by exactly the effect and the drawn values.
    """
    out = deep_merge(config, truth.switch)
    if truth.effect is None or truth.magnitude is None:
        return out
    return candidate_config(out, _candidate(config, truth.effect, "truth"), truth.magnitude)
