"""The catalogue of candidate effects and the DEM cases of the discrepancy workflow.

A candidate effect (config ``discrepancy.candidates``) names a piece of physics the current
model may lack, the deck switch that turns it on (configuration overrides, e.g.
``material.rolling_friction: true``), and the one parameter that sets its magnitude: a case
column (``cohesionEnergyDensity``, ``coefficientRollingFriction``, ``wallFriction``) or a
configuration key (``particles.classes`` for size polydispersity), with its range, probe levels
and the value at which the effect is absent (a number, or the name of a parameter whose value
means "absent", e.g. wall friction equal to coefficientFriction).

This module only builds configurations and case rows; rendering and running stay in
:mod:`demcal.decks.render` and :mod:`demcal.engine_io.run`.
"""

from __future__ import annotations

import copy
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import pandas as pd

from demcal.core.experiments import Experiment
from demcal.core.parameters import CONTACT_PARAMETERS
from demcal.design.build import build_design
from demcal.design.cases import design_spec, load_condition, shear_suffixes
from demcal.discrepancy.dem_check import run_load, run_seed

__all__ = [
    "REFERENCE_CASE",
    "Candidate",
    "applicability",
    "base_point",
    "candidate_config",
    "case_setup",
    "deep_merge",
    "extended_design",
    "measured_tests",
    "parse_candidates",
    "probe_runs",
    "reprobe_runs",
    "run_suffixes",
]

#: Case id of the probe run at theta* with no effect added.
REFERENCE_CASE = "ref"
_NAME = re.compile(r"^[a-z][a-z0-9]*$")
_CONTACT = CONTACT_PARAMETERS


@dataclass(frozen=True)
class Candidate:
    """One candidate effect of the catalogue.

    Attributes
    ----------
    name : str
        Lower-case letters and digits (it becomes part of case ids).
    description : str
        One line of physics.
    switch : dict
        Configuration overrides that turn the effect on (deep-merged into the config).
    parameter : str
        Name of the magnitude (a case column; also the surrogate input name).
    config_key : str or None
        Dotted configuration key that receives the magnitude (e.g. ``particles.classes``);
        None when the parameter is a case column the decks read.
    off_value : float or str
        Magnitude at which the effect is absent, or the parameter whose value means absent.
    range : tuple of float
        [low, high] of the magnitude in the extended design.
    probe_levels : tuple of float
        Magnitudes of the probe runs around theta*.
    integer : bool
        The magnitude takes whole values only.
    """

    name: str
    description: str
    switch: dict
    parameter: str
    config_key: str | None
    off_value: float | str
    range: tuple[float, float]
    probe_levels: tuple[float, ...]
    integer: bool = False

    def off_magnitude(self, point: Mapping[str, float]) -> float:
        """Magnitude meaning "effect absent" at the parameter set ``point``."""
        if isinstance(self.off_value, str):
            if self.off_value not in point:
                raise KeyError(
                    f"candidate {self.name}: off_value {self.off_value!r} is not a parameter "
                    f"of the point ({', '.join(point)})"
                )
            return float(point[self.off_value])
        return float(self.off_value)

    def case_id(self, level_index: int) -> str:
        """Case id of the probe run at ``probe_levels[level_index]`` (e.g. ``cohesion1``)."""
        return f"{self.name}{level_index + 1}"

    @property
    def reference_case(self) -> str:
        """Case id of the run with the effect absent at the candidate's own best fit, where it
        is probed again (``cohesion0``; :func:`reprobe_runs`)."""
        return f"{self.name}0"


def parse_candidates(entries: Sequence[Mapping[str, Any]]) -> list[Candidate]:
    """Candidates from the ``discrepancy.candidates`` config list.

    Raises
    ------
    KeyError
        For a missing key (named with its position in the list).
    ValueError
        For a bad name, duplicate names, an empty or reversed range, or no probe level.
    """
    out: list[Candidate] = []
    for i, entry in enumerate(entries):
        where = f"discrepancy.candidates[{i}]"
        for key in ("name", "description", "parameter", "off_value", "range", "probe_levels"):
            if key not in entry:
                raise KeyError(f"{where}: missing key '{key}'")
        name = str(entry["name"])
        if not _NAME.match(name):
            raise ValueError(f"{where}.name: {name!r} must be lower-case letters and digits")
        lo, hi = (float(v) for v in entry["range"])
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise ValueError(f"{where}.range: need finite low < high, got {entry['range']!r}")
        levels = tuple(float(v) for v in entry["probe_levels"])
        if not levels:
            raise ValueError(f"{where}.probe_levels: give at least one level")
        for level in levels:
            if not lo <= level <= hi:
                raise ValueError(f"{where}.probe_levels: {level} is outside the range [{lo}, {hi}]")
        off = entry["off_value"]
        off_value: float | str = off if isinstance(off, str) else float(off)
        integer = bool(entry.get("integer", False))
        if integer and any(v != round(v) for v in (lo, hi, *levels)):
            raise ValueError(f"{where}: an integer parameter needs whole range and levels")
        out.append(
            Candidate(
                name=name,
                description=str(entry["description"]),
                switch=copy.deepcopy(dict(entry.get("switch") or {})),
                parameter=str(entry["parameter"]),
                config_key=entry.get("config_key"),
                off_value=off_value,
                range=(lo, hi),
                probe_levels=levels,
                integer=integer,
            )
        )
    names = [c.name for c in out]
    if len(set(names)) != len(names):
        raise ValueError(f"discrepancy.candidates: duplicate names in {names}")
    return out


def deep_merge(base: Mapping[str, Any], overrides: Mapping[str, Any]) -> dict[str, Any]:
    """A copy of ``base`` with ``overrides`` merged in (nested mappings merged key by key)."""
    out = copy.deepcopy(dict(base))
    for key, value in overrides.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = deep_merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def _get_key(config: Mapping[str, Any], dotted: str) -> Any:
    node: Any = config
    for part in dotted.split("."):
        if not isinstance(node, Mapping) or part not in node:
            raise KeyError(f"configuration: no key '{dotted}'")
        node = node[part]
    return node


def _nested(dotted: str, value: Any) -> dict[str, Any]:
    parts = dotted.split(".")
    node: dict[str, Any] = {parts[-1]: value}
    for part in reversed(parts[:-1]):
        node = {part: node}
    return node


def candidate_config(
    config: Mapping[str, Any], candidate: Candidate, magnitude: float
) -> dict[str, Any]:
    """The configuration of a run with the effect on at ``magnitude``."""
    out = deep_merge(config, candidate.switch)
    if candidate.config_key:
        _get_key(out, candidate.config_key)  # the key must exist (validated config)
        value: Any = round(magnitude) if candidate.integer else float(magnitude)
        out = deep_merge(out, _nested(candidate.config_key, value))
    return out


def _varied(spec: Mapping[str, Any]) -> set[str]:
    varied = set(spec.get("ranges", {})) | set(spec.get("choices", {}))
    varied |= {k for k, v in spec.get("levels", {}).items() if len(v) > 1}
    return varied


def applicability(candidate: Candidate, config: Mapping[str, Any]) -> tuple[bool, str]:
    """Whether the current model lacks the effect, with the reason in words.

    The model lacks it when the switch changes the configuration, or when the magnitude is
    neither varied in the design nor set to a value other than the "absent" one.
    """
    switched = deep_merge(config, candidate.switch)
    if switched != config:
        return True, "its deck switch is off in the current model"
    spec = design_spec(config["design"])
    if candidate.parameter in _varied(spec):
        return False, f"{candidate.parameter} already varies in the design"
    if candidate.config_key:
        current: Any = _get_key(config, candidate.config_key)
    else:
        current = spec.get("fixed", {}).get(candidate.parameter)
        if current is None and "levels" in spec:
            levels = spec["levels"].get(candidate.parameter)
            current = levels[0] if levels else None
    if current is None:
        return True, f"the model has no {candidate.parameter}"
    if isinstance(candidate.off_value, str):
        return False, f"{candidate.parameter} is fixed at {current} in the current model"
    if float(current) == float(candidate.off_value):
        return True, f"{candidate.parameter} is at its 'absent' value {candidate.off_value:g}"
    return False, f"the current model already has {candidate.parameter} = {current}"


def measured_tests(experiment: Experiment) -> list[str]:
    """The virtual tests whose observables were measured."""
    tests = []
    if experiment.shear_conditions:
        tests.append("shear_cell")
    if experiment.angle_of_repose is not None:
        tests.append("angle_of_repose")
    return tests


def base_point(theta: Mapping[str, float], config: Mapping[str, Any]) -> dict[str, float]:
    """A complete parameter set: ``theta`` plus the design's fixed values.

    Design parameters that are neither in ``theta`` nor fixed take the middle of their range
    (they did not vary enough to be surrogate inputs, or only through choices).

    Raises
    ------
    KeyError
        When a contact parameter the decks need is nowhere to be found.
    """
    spec = design_spec(config["design"])
    point: dict[str, float] = {}
    for name, (lo, hi) in spec.get("ranges", {}).items():
        point[name] = 0.5 * (float(lo) + float(hi))
    for name, values in spec.get("choices", {}).items():
        point[name] = float(sorted(values)[len(values) // 2])
    for name, values in spec.get("levels", {}).items():
        point[name] = float(sorted(values)[len(values) // 2])
    point.update({k: float(v) for k, v in spec.get("fixed", {}).items()})
    point.update({k: float(v) for k, v in theta.items()})
    missing = [name for name in _CONTACT if name not in point]
    if missing:
        raise KeyError(f"design: no value for {missing} (add them to design.fixed or ranges)")
    return point


@dataclass(frozen=True)
class ProbeRun:
    """One probe point: the reference (candidate None) or a candidate at one level."""

    case: str
    candidate: str | None
    level: float | None


def _level_runs(cand: Candidate) -> list[ProbeRun]:
    return [ProbeRun(cand.case_id(j), cand.name, v) for j, v in enumerate(cand.probe_levels)]


def probe_runs(candidates: Sequence[Candidate]) -> list[ProbeRun]:
    """The probe points: the reference run, then every candidate at each of its levels."""
    runs = [ProbeRun(REFERENCE_CASE, None, None)]
    for cand in candidates:
        runs += _level_runs(cand)
    return runs


def reprobe_runs(candidates: Sequence[Candidate]) -> list[ProbeRun]:
    """The runs of candidates probed again at their own best fit: for each, the reference with
    the effect absent (its :attr:`Candidate.reference_case`), then every level."""
    runs = []
    for cand in candidates:
        runs += [ProbeRun(cand.reference_case, None, None), *_level_runs(cand)]
    return runs


def case_setup(
    test: str,
    case_id: str,
    point: Mapping[str, float],
    config: Mapping[str, Any],
    candidate: Candidate | None = None,
    magnitude: float | None = None,
) -> tuple[dict[str, Any], dict[str, Any]]:
    """The case row and configuration of one discrepancy run.

    Parameters
    ----------
    test : {"shear_cell", "angle_of_repose"}
    case_id : str
        Case id (:func:`demcal.discrepancy.dem_check.parse_run_id`): ``_r<k>`` marks
        replicate k (its own insertion seed); a shear-cell id carries its load condition as in
        the design's cases (``_s<k>`` and, for separate runs, ``_p<j>``) or ``_h<m>``, the m-th
        held-out condition.
    point : mapping
        Complete parameter set (see :func:`base_point`).
    config : mapping
        The validated workflow configuration (the current model).
    candidate, magnitude
        The effect to switch on and its magnitude; None for the current model.

    Returns
    -------
    row : dict
        Case row for :func:`demcal.decks.render.render_case` (with ``discrepancy_candidate`` and the
        magnitude column for bookkeeping).
    config : dict
        The configuration to render it with.

    Raises
    ------
    KeyError
        For a shear-cell id without a valid load suffix.
    """
    row: dict[str, Any] = {"case_id": case_id, **{k: float(v) for k, v in point.items()}}
    cfg = copy.deepcopy(dict(config))
    row["discrepancy_candidate"] = candidate.name if candidate else "none"
    if candidate is not None:
        if magnitude is None:
            raise ValueError(f"case {case_id}: candidate {candidate.name} needs a magnitude")
        value = float(round(magnitude)) if candidate.integer else float(magnitude)
        row[candidate.parameter] = value
        cfg = candidate_config(config, candidate, value)
    row["seed"] = run_seed(config, case_id)
    if test == "shear_cell":
        row.update(run_load(config, case_id))
    return row, cfg


def run_suffixes(config: Mapping[str, Any], experiment: Experiment) -> list[str]:
    """Shear-cell case-id suffixes of one parameter set, restricted to measured conditions.

    The suffixes are those of the design's cases (:func:`demcal.design.cases.shear_suffixes`); a run
    is kept when its normal stress (and its P, for separate runs) was measured.
    """
    measured = {(float(c.normal_stress), float(c.P)) for c in experiment.shear_conditions}
    stresses = {stress for stress, _ in measured}
    kept = []
    for suffix in shear_suffixes(config):
        load = load_condition(config, f"x{suffix}")
        if load["normal_stress"] not in stresses:
            continue
        if "P" in load and (load["normal_stress"], load["P"]) not in measured:
            continue
        kept.append(suffix)
    return kept


def extended_design(
    config: Mapping[str, Any], candidate: Candidate, n: int, seed: int
) -> pd.DataFrame:
    """A Latin hypercube over the current design's box plus the candidate's magnitude.

    The box is the current design's ranges (or the span of its factorial levels), its choices
    and fixed values; the candidate's parameter gets its range (whole values if integer).
    Case ids are ``e0001``, ``e0002``, ...

    Returns
    -------
    DataFrame, shape (n, ...)
        One row per case: case_id and the parameter columns.
    """
    spec = design_spec(config["design"])
    ranges = {k: [float(v[0]), float(v[1])] for k, v in spec.get("ranges", {}).items()}
    for name, values in spec.get("levels", {}).items():
        if len(values) > 1:
            ranges[name] = [float(min(values)), float(max(values))]
    fixed = {k: float(v) for k, v in spec.get("fixed", {}).items()}
    for name, values in spec.get("levels", {}).items():
        if len(values) == 1:
            fixed[name] = float(values[0])
    fixed.pop(candidate.parameter, None)
    ranges[candidate.parameter] = [candidate.range[0], candidate.range[1]]
    new_spec: dict[str, Any] = {
        "kind": "lhs",
        "n": int(n),
        "seed": int(seed),
        "ranges": ranges,
        "fixed": fixed,
    }
    if spec.get("choices"):
        new_spec["choices"] = spec["choices"]
    if candidate.integer:
        new_spec["integer"] = [candidate.parameter]
    table = build_design(new_spec)
    table["case_id"] = [f"e{int(c[1:]):04d}" for c in table["case_id"]]
    return table
