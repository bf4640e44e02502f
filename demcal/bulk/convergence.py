"""Convergence study of the virtual bulk tests: each bulk value against one numerical setting.

One setting (a *factor*: cell size, shear speed, stiffness, coarse-graining, time step, lift
speed) is varied at a time around a base configuration, for a few reference parameter sets and
several insertion seeds. The seed scatter is the yardstick: a level whose seed mean differs from
the most refined level by more than the tolerance (5 % for mu_psh, mu_sh and rho_b, 2 deg for the
angle of repose) has not converged. The runs themselves are rendered and run with
:mod:`demcal.bulk.engine_comparison` (same case layout, same status files); this module plans
them and condenses their values.

A factor level is a mapping of configuration overrides ``"section.key" -> value``; the most
refined level of each factor (largest cell, slowest motion, stiffest particles, smallest time
step, finest particles) is its reference.
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from demcal.bulk.engine_comparison import BULK_VALUES, RunJob
from demcal.core.parameters import TESTS
from demcal.virtual_tests.deck import render_case

__all__ = [
    "FACTORS",
    "TOLERANCES",
    "Factor",
    "plan_study",
    "quantities_of",
    "summarise",
]

#: Convergence tolerance per bulk value: relative for the shear values, degrees for the AoR.
TOLERANCES: dict[str, tuple[str, float]] = {
    "mu_psh": ("relative", 0.05),
    "mu_sh": ("relative", 0.05),
    "rho_b": ("relative", 0.05),
    "aor": ("absolute", 2.0),
}


@dataclass(frozen=True)
class Factor:
    """One numerical setting of a virtual test and the levels it is tried at.

    Attributes
    ----------
    name : str
        Short name (``dCylDp``, ``shear_speed``, ...).
    test : str
        ``shear_cell`` or ``angle_of_repose``.
    label : str
        Axis label of the plot.
    levels : tuple of mapping
        Configuration overrides ``"section.key" -> value`` per level, ordered from the
        cheapest to the most refined; the last is the reference.
    axis : str
        The override key whose value is plotted on the x axis.
    """

    name: str
    test: str
    label: str
    levels: tuple[Mapping[str, Any], ...]
    axis: str

    def level_value(self, level: Mapping[str, Any]) -> float:
        """The plotted value of one level."""
        return float(level[self.axis])


#: Smallest cell the study renders (the configuration's min_dCylDp guards production runs).
MIN_STUDY_DCYLDP = 4.0

#: The heap-size levels' lift: height in tube diameters and speed in largest-particle
#: diameters per second (the quick heap's: 1.2 D of dCylDp 9 in 4 s).
LIFT_HEIGHT = 1.2
LIFT_SPEED = LIFT_HEIGHT * 9.0 / 4.0


def _levels(key: str, values: Sequence[float], **fixed: Any) -> tuple[dict[str, Any], ...]:
    return tuple({key: v, **{k.replace("__", "."): f for k, f in fixed.items()}} for v in values)


#: The factors of the study, each ordered cheapest first. The stiffness levels lift the cap on
#: the shear cell's modulus so that Y / sigma is what varies. Coarse-graining keeps the cell's
#: physical size (dCylDp x scale = 48 for the shear cell, the quick ring; 18 for the heap) and
#: changes only how many particles fill it.
FACTORS: dict[str, Factor] = {
    f.name: f
    for f in (
        Factor(
            "shear_dCylDp",
            "shear_cell",
            "split cell: diameter / particle diameter dCylDp",
            # The split cell as the quick profile ran it before the ring.
            _levels(
                "shear_cell.dCylDp",
                (8, 12, 18, 24),
                shear_cell__geometry="split",
                shear_cell__bulk_density="cell",
                shear_cell__cycles="return",
                shear_cell__fill_height=1.5,
                shear_cell__overfill=0.3,
                shear_cell__preshear_travel=0.375,
            ),
            "shear_cell.dCylDp",
        ),
        Factor(
            "shear_speed",
            "shear_cell",
            "shear speed (particle radii per second)",
            _levels("shear_cell.shear_speed", (80.0, 40.0, 20.0, 10.0)),
            "shear_cell.shear_speed",
        ),
        Factor(
            "shear_inertial",
            "shear_cell",
            "stress whose inertial number every stress keeps (Pa; 0: one speed at every stress)",
            # A deck above the reference stress shears sqrt(sigma / reference) times faster;
            # the reference level (0) shears at shear_speed whatever the stress.
            _levels("shear_cell.shear_speed_reference_stress", (1068.0, 2029.0, 0.0)),
            "shear_cell.shear_speed_reference_stress",
        ),
        Factor(
            "shear_travel",
            "shear_cell",
            "pre-shear travel (outer radii R; the shear travels 19/20 of it)",
            # From a freshly compressed bed: does one pre-shear reach the steady state? In the
            # quick ring 0.75 R is 9 particle diameters along the mean circle.
            _levels("shear_cell.preshear_travel", (0.375, 0.75, 1.5)),
            "shear_cell.preshear_travel",
        ),
        Factor(
            "shear_stiffness",
            "shear_cell",
            "Young's modulus / pre-shear stress",
            _levels(
                "shear_cell.youngs_modulus_per_stress",
                (1000.0, 3000.0, 10000.0, 30000.0),
                shear_cell__youngs_modulus_max=1.0e9,
            ),
            "shear_cell.youngs_modulus_per_stress",
        ),
        Factor(
            "shear_timestep",
            "shear_cell",
            "time step / Rayleigh time",
            _levels("material.rayleigh_fraction", (0.25, 0.15, 0.08, 0.04)),
            "material.rayleigh_fraction",
        ),
        Factor(
            "shear_coarse_graining",
            "shear_cell",
            "coarse-graining factor (particle radii x)",
            # At x 3 the ring (4 diameters high) leaves no room between its bars and the
            # shear plane; x 2.5 is the coarsest that renders, and its bed (4.8 diameters)
            # holds an interior region only half a diameter clear of the bar tips.
            tuple(
                {
                    "particles.scale": s,
                    "shear_cell.dCylDp": 48.0 / s,
                    "shear_cell.interior_margin": 0.5,
                }
                for s in (2.5, 2.0, 1.5)
            ),
            "particles.scale",
        ),
        Factor(
            "ring_dCylDp",
            "shear_cell",
            "ring cell: outer diameter / particle diameter dCylDp (R / R_i = 2)",
            tuple(
                {
                    "shear_cell.geometry": "ring",
                    "shear_cell.dCylDp": float(d),
                    # Bed height (6 diameters) and pre-shear travel (9 diameters) fixed in
                    # particle sizes, so that only the width (dCylDp / 4 diameters) varies.
                    "shear_cell.fill_height": 12.0 / d,
                    "shear_cell.overfill": 2.0 / d,
                    "shear_cell.preshear_travel": 18.0 / d,
                }
                for d in (16, 24, 32, 40)
            ),
            "shear_cell.dCylDp",
        ),
        Factor(
            "ring_height",
            "shear_cell",
            "ring cell: bed height (outer radii R; at dCylDp 24, 0.5 R = 6 particle diameters)",
            # The quick ring's shear zone spans the 4 diameters between the floor's and the
            # lid's bars; a taller bed gives it room (the plane stays at half the height).
            _levels("shear_cell.fill_height", (0.5, 0.75, 1.0), shear_cell__geometry="ring"),
            "shear_cell.fill_height",
        ),
        Factor(
            "aor_dCylDp",
            "angle_of_repose",
            "cylinder diameter / largest particle diameter dCylDp",
            tuple(
                {
                    "angle_of_repose.dCylDp": float(d),
                    # The lift rises 1.2 D at the quick heap's speed (1.2 D in 4 s at dCylDp 9:
                    # 2.7 largest diameters per second) at every size; with a fixed lift time
                    # the tube would rise faster in wider cells, and a faster lift flattens the
                    # heap (aor_lift_time), which a size study must not mix in.
                    "angle_of_repose.lift_height": LIFT_HEIGHT,
                    "angle_of_repose.lift_time": LIFT_HEIGHT * d / LIFT_SPEED,
                }
                for d in (6, 9, 14, 20)
            ),
            "angle_of_repose.dCylDp",
        ),
        Factor(
            "aor_lift_time",
            "angle_of_repose",
            "lift time (s)",
            _levels("angle_of_repose.lift_time", (1.0, 2.0, 4.0, 8.0)),
            "angle_of_repose.lift_time",
        ),
        Factor(
            "aor_stiffness",
            "angle_of_repose",
            "Young's modulus (Pa)",
            _levels("material.youngsModulus", (2.0e6, 1.0e7, 5.0e7)),
            "material.youngsModulus",
        ),
        Factor(
            "aor_timestep",
            "angle_of_repose",
            "time step / Rayleigh time",
            _levels("material.rayleigh_fraction", (0.25, 0.15, 0.08)),
            "material.rayleigh_fraction",
        ),
    )
}


def restrict_levels(factor: Factor, values: Sequence[float]) -> Factor:
    """The factor with only the levels whose plotted value is one of ``values``.

    The most refined level left is the reference. Useful to repeat a cheap comparison (e.g.
    the quick heap against the next larger one) with many seeds without the costliest level.

    Raises
    ------
    ValueError
        When a value is not a level of the factor; the message lists its levels.
    """
    known = [factor.level_value(level) for level in factor.levels]
    unknown = [v for v in values if not any(math.isclose(v, k, rel_tol=1e-9) for k in known)]
    if unknown:
        raise ValueError(
            f"factor {factor.name}: {unknown} are not among its levels {[f'{k:g}' for k in known]}"
        )
    kept = tuple(
        level
        for level, k in zip(factor.levels, known, strict=True)
        if any(math.isclose(v, k, rel_tol=1e-9) for v in values)
    )
    return replace(factor, levels=kept)


def _apply(settings: Mapping[str, Any], overrides: Mapping[str, Any]) -> dict[str, Any]:
    cfg = copy.deepcopy(dict(settings))
    for key, value in overrides.items():
        section, name = key.split(".", 1)
        cfg[section] = {**cfg[section], name: value}
    return cfg


def _text(value: Any) -> str:
    """A level value in a directory name: numbers in the shortest form, words as they are."""
    return f"{value:g}" if isinstance(value, int | float) else str(value)


def _base_value(settings: Mapping[str, Any], key: str) -> Any:
    section, name = key.split(".", 1)
    return settings.get(section, {}).get(name)


def plan_study(
    settings: Mapping[str, Any],
    sets: Mapping[str, Mapping[str, float]],
    factors: Sequence[Factor],
    seeds: Sequence[int],
    out_dir: Path,
    command: str,
    normal_stress: float,
    P: float = 1.0,
    render: bool = True,
) -> list[tuple[RunJob, str, Mapping[str, Any]]]:
    """Render every run of the study.

    Levels shared by several factors (the same overrides for the same test) are rendered once.

    Parameters
    ----------
    settings : mapping
        Validated base configuration; each level's overrides are applied to a copy.
    sets : mapping
        Reference parameter set name -> contact parameters.
    factors : sequence of Factor
        Factors to vary.
    seeds : sequence of int
        Insertion seeds.
    out_dir : Path
        Root; a run goes to ``out_dir/<test>/<level>/<set>/seed<seed>``.
    command : str
        Engine command template (``{deck}`` is the deck file name).
    normal_stress : float
        Pre-shear normal stress of the shear cell, Pa.
    P : float
        Shear to pre-shear load ratio, -.
    render : bool
        Write the case directories of runs that have not finished (no ``status.json``);
        False: only list them.

    Returns
    -------
    list of (RunJob, str, mapping)
        Each run with the factor name and the level's overrides; a run shared by two factors
        appears once per factor (same RunJob object).
    """
    # The study explores cells below the production minimum on purpose.
    settings = _apply(settings, {f"{t}.min_dCylDp": MIN_STUDY_DCYLDP for t in TESTS})
    planned: dict[Path, RunJob] = {}
    out: list[tuple[RunJob, str, Mapping[str, Any]]] = []
    for factor in factors:
        for level in factor.levels:
            overrides = dict(level)
            # Overrides equal to the base configuration change nothing: the base run is
            # shared by every factor that passes through it.
            changed = {k: v for k, v in overrides.items() if _base_value(settings, k) != v}
            key = "__".join(f"{k}={_text(v)}" for k, v in sorted(changed.items())) or "base"
            cfg = _apply(settings, overrides)
            for set_name, params in sets.items():
                case: dict[str, Any] = {"case_id": set_name, **params}
                if factor.test == "shear_cell":
                    case.update(normal_stress=float(normal_stress), P=float(P))
                for seed in seeds:
                    case_dir = Path(out_dir) / factor.test / key / set_name / f"seed{seed}"
                    job = planned.get(case_dir)
                    if job is None:
                        _check_earlier_run(case_dir, params)
                        if render and not (case_dir / "status.json").is_file():
                            run_cfg = dict(cfg)
                            run_cfg["seed"] = int(seed)
                            render_case(factor.test, case, run_cfg, case_dir)
                        job = RunJob(set_name, factor.test, "engine", int(seed), case_dir, command)
                        planned[case_dir] = job
                    out.append((job, factor.name, overrides))
    return out


def _check_earlier_run(case_dir: Path, params: Mapping[str, float]) -> None:
    """Refuse to reuse a run made earlier for a set of the same name but other values."""
    record = case_dir / "case.json"
    if not record.is_file():
        return
    earlier = json.loads(record.read_text()).get("case", {})
    differ = [
        f"{key} {earlier.get(key)} (now {value:g})"
        for key, value in params.items()
        if earlier.get(key) is None or not math.isclose(float(earlier[key]), value, rel_tol=1e-9)
    ]
    if differ:
        raise ValueError(
            f"{case_dir}: made earlier for set {case_dir.parent.name} with "
            + ", ".join(differ)
            + "; give the set another name or use another output directory"
        )


def _deviation(quantity: str, value: float, reference: float) -> float:
    kind, _ = TOLERANCES[quantity]
    if kind == "relative":
        return (value - reference) / abs(reference) if reference else math.nan
    return value - reference


def summarise(values: pd.DataFrame, factors: Mapping[str, Factor]) -> pd.DataFrame:
    """Seed means, scatter and distance to the reference level of every factor level.

    Parameters
    ----------
    values : pandas.DataFrame
        One row per run and bulk value with columns ``factor``, ``level`` (the plotted value),
        ``set``, ``seed``, ``quantity``, ``value`` (NaN for a run without value).
    factors : mapping
        Factor name -> Factor (for the reference level and the test).

    Returns
    -------
    pandas.DataFrame
        One row per factor, level, set and quantity: ``n`` (runs with a value), ``mean``,
        ``sd`` (seed standard deviation, NaN below two runs), ``reference`` (mean at the most
        refined level), ``deviation`` (relative, or degrees for the AoR), ``tolerance`` and
        ``converged`` (the deviation lies within the tolerance; the reference level is
        converged by definition when it has values), ``deviation_se`` (standard error of the
        deviation from the seed scatter, in the deviation's unit; the scatter is pooled over
        the factor's levels, so a level with one run still gets one) and ``resolved`` (the
        deviation lies outside two standard errors, i.e. is more than seed noise).
    """
    rows: list[dict[str, Any]] = []
    for (name, set_name, quantity), group in values.groupby(["factor", "set", "quantity"]):
        factor = factors[str(name)]
        reference_level = factor.level_value(factor.levels[-1])
        stats = group.groupby("level")["value"].agg(["count", "mean", "std"])
        reference = (
            float(stats.loc[reference_level, "mean"]) if reference_level in stats.index else np.nan
        )
        kind, tolerance = TOLERANCES[str(quantity)]
        # Seed scatter pooled over the levels with at least two runs.
        several = stats[stats["count"] >= 2]
        pooled = float(np.sqrt(np.mean(several["std"] ** 2))) if len(several) else np.nan
        n_ref = int(stats.loc[reference_level, "count"]) if reference_level in stats.index else 0
        scale = abs(reference) if kind == "relative" and reference else 1.0
        for level, row in stats.iterrows():
            deviation = _deviation(str(quantity), float(row["mean"]), reference)
            n = int(row["count"])
            se = (
                pooled * np.sqrt(1.0 / n + 1.0 / n_ref) / scale
                if n and n_ref and float(level) != reference_level
                else 0.0
            )
            rows.append(
                {
                    "factor": name,
                    "test": factor.test,
                    "level": float(level),
                    "set": set_name,
                    "quantity": quantity,
                    "n": int(row["count"]),
                    "mean": float(row["mean"]),
                    "sd": float(row["std"]),
                    "reference": reference,
                    "deviation": deviation,
                    "tolerance": tolerance,
                    "converged": bool(np.isfinite(deviation) and abs(deviation) <= tolerance),
                    "deviation_se": se,
                    "resolved": bool(np.isfinite(se) and abs(deviation) > 2.0 * se),
                }
            )
    return pd.DataFrame(rows)


def quantities_of(test: str) -> list[str]:
    """Bulk values a test yields."""
    return [q for q, t in BULK_VALUES.items() if t == test]
