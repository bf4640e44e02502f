"""The DEM check of the discrepancy workflow: replicate runs at fitted and held-out loads.

The Show step compares DEM runs, not surrogates, with the measurements: the current model at
theta* ("before") and the extended model at its identified point ("after"), each run
``discrepancy.replicates`` times from fresh packings, at every fitted load condition and at the
held-out ones (``discrepancy.held_out``), which Find, naming and the recalibration never see.

Run ids: ``<run>`` is replicate 1 (the configuration's seed), ``<run>_r<k>`` replicate k (seed
+ (k - 1) x :data:`demcal.design.cases.REPLICATE_SEED_STEP`); a shear-cell id ends in the
design's load suffix ``_s<i>[_p<j>]`` or in ``_h<m>``, the m-th held-out condition.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Mapping
from typing import Any

from demcal.core.config import ConfigError
from demcal.core.experiments import Experiment
from demcal.design.cases import load_condition, replicate_bases, seed_of_replicate

__all__ = [
    "RunId",
    "fitted_experiment",
    "held_out_conditions",
    "held_out_experiment",
    "held_out_suffixes",
    "parse_run_id",
    "replicate_bases",
    "run_load",
    "run_seed",
]

_RUN_ID = re.compile(
    r"(?P<run>[a-z][a-z0-9]*)(?:_r(?P<rep>\d+))?(?P<load>_s\d+(?:_p\d+)?|_h(?P<held>\d+))?"
)


@dataclasses.dataclass(frozen=True)
class RunId:
    """The parts of a discrepancy run id.

    Attributes
    ----------
    run : str
        Run name (``ref``, a probe level such as ``cohesion2``, ``verify``, an extended case).
    replicate : int
        1 for the first run, k for ``_r<k>``.
    load : str
        The load suffix (``_s1_p1``, ``_h1``) or ``""`` for a test without load.
    held_out : int or None
        Number (1-based) of the held-out condition, None for a fitted load.
    """

    run: str
    replicate: int
    load: str
    held_out: int | None

    @property
    def base(self) -> str:
        """The id without its load suffix (``ref_r2`` of ``ref_r2_s1_p1``)."""
        return self.run if self.replicate == 1 else f"{self.run}_r{self.replicate}"


def parse_run_id(case_id: str) -> RunId:
    """Split a discrepancy run id into run, replicate and load.

    Raises
    ------
    KeyError
        For an id that does not have the form ``<run>[_r<k>][_s<i>[_p<j>]|_h<m>]``.
    """
    match = _RUN_ID.fullmatch(case_id)
    if match is None:
        raise KeyError(f"{case_id!r} is not a discrepancy run id")
    replicate = int(match.group("rep") or 1)
    if replicate < 1:
        raise KeyError(f"{case_id!r}: replicate numbers start at 1")
    held = match.group("held")
    return RunId(
        match.group("run"), replicate, match.group("load") or "", int(held) if held else None
    )


def run_seed(config: Mapping[str, Any], case_id: str) -> int:
    """Insertion seed of a run (:func:`demcal.design.cases.seed_of_replicate`)."""
    return seed_of_replicate(config, parse_run_id(case_id).replicate)


def held_out_conditions(config: Mapping[str, Any]) -> list[tuple[float, float]]:
    """(normal stress [Pa], P [-]) of every held-out condition, in configured order."""
    entries = (config.get("discrepancy") or {}).get("held_out") or []
    return [(float(e["normal_stress"]), float(e["P"])) for e in entries]


def held_out_suffixes(config: Mapping[str, Any]) -> list[str]:
    """Load suffixes ``_h1``, ``_h2``, ... of the held-out conditions."""
    return [f"_h{m}" for m in range(1, len(held_out_conditions(config)) + 1)]


def run_load(config: Mapping[str, Any], case_id: str) -> dict[str, float]:
    """normal_stress and P of a shear-cell run id (a design load or a held-out one).

    Raises
    ------
    KeyError
        For an id without a load suffix or with one the configuration does not have.
    """
    parsed = parse_run_id(case_id)
    if parsed.held_out is None:
        return load_condition(config, f"x{parsed.load}")
    held = held_out_conditions(config)
    if not 1 <= parsed.held_out <= len(held):
        raise KeyError(f"case {case_id!r}: discrepancy.held_out has {len(held)} entries")
    stress, p = held[parsed.held_out - 1]
    return {"normal_stress": stress, "P": p}


def _is_held_out(stress: float | None, p: float | None, held: list[tuple[float, float]]) -> bool:
    if stress is None or p is None:
        return False
    return any(math.isclose(stress, s, rel_tol=1e-9) and math.isclose(p, q) for s, q in held)


def _split(experiment: Experiment, config: Mapping[str, Any], where: str) -> tuple[list, list]:
    held = held_out_conditions(config)
    kept, out = [], []
    for cond in experiment.shear_conditions:
        (out if _is_held_out(cond.normal_stress, cond.P, held) else kept).append(cond)
    for m, (stress, p) in enumerate(held, start=1):
        if not any(_is_held_out(c.normal_stress, c.P, [(stress, p)]) for c in out):
            raise ConfigError(
                f"{where}: discrepancy.held_out[{m - 1}] (normal_stress {stress:g} Pa, P {p:g}) "
                "is not a shear-cell condition of the experiment file"
            )
    return kept, out


def fitted_experiment(experiment: Experiment, config: Mapping[str, Any]) -> Experiment:
    """The measurements Find, naming and the recalibration see: all but the held-out loads.

    Raises
    ------
    ConfigError
        When a held-out condition is not in the experiment, or nothing is left to fit.
    """
    kept, _ = _split(experiment, config, str(config.get("experiment", "experiment")))
    if not kept and experiment.angle_of_repose is None:
        raise ConfigError(
            f"{config.get('experiment', 'experiment')}: discrepancy.held_out leaves no "
            "measured value to fit"
        )
    return dataclasses.replace(experiment, shear_conditions=kept)


def held_out_experiment(experiment: Experiment, config: Mapping[str, Any]) -> Experiment:
    """Only the held-out shear-cell conditions of ``experiment`` (no angle of repose)."""
    _, out = _split(experiment, config, str(config.get("experiment", "experiment")))
    return dataclasses.replace(
        experiment, shear_conditions=out, angle_of_repose=None, angle_of_repose_sd=None
    )
