"""Synthetic measurements with a hidden effect, for validating the discrepancy workflow.

A truth specification (``config/experiments/truth/hidden_*.yaml``) names the hidden effect and
how the true values are drawn (:mod:`demcal.discrepancy.truths`). The virtual tests run at the
drawn truth with the effect switched on, by default on LIGGGHTS 3.8 rather than the bundled
engine, so that the differences between the two codes are part of what the workflow must see
through; the model under calibration stays on the configured engine. Replicate runs from fresh
packings are averaged and noise is added per observable; the experiment file holds only the
noisy values, and the drawn truth is written beside the study, never into its configuration.

The hidden-effect study model is the profile's configuration with the overrides of
:func:`study_overrides`: one particle size, no rolling resistance, no cohesion, and a design
over sliding friction (and particle density at the quick scale). With that model a missing
cohesion, rolling resistance or size spread can each be hidden in the data.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd
import yaml

from demcal.bulk.synthetic import Case, replicate_record, run_replicates
from demcal.core.config import validate_config
from demcal.design.cases import shear_suffixes
from demcal.discrepancy.candidates import deep_merge
from demcal.discrepancy.dem_check import held_out_suffixes, run_load
from demcal.discrepancy.truths import DrawnTruth, draw_truth, load_truth_spec, truth_config
from demcal.engine_io.run import installed_liggghts

__all__ = [
    "NOISE",
    "hidden_effect_bulk",
    "prepare_study",
    "study_config",
    "study_overrides",
    "write_hidden_effect_experiment",
    "write_truth",
]

#: Relative measurement noise added per observable: repeated shear tests scatter by a few per
#: cent in friction, much less in bulk density.
NOISE: dict[str, float] = {"mu_psh": 0.03, "mu_sh": 0.03, "rho_b": 0.01, "aor": 0.03}

_MODEL = {
    "particles": {"distribution": "monodisperse"},
    "material": {"rolling_friction": False},
    # The study does not measure the angle of repose: no heap-only sets. Every set runs every
    # stress: how an effect changes with the stress is its signature.
    "design": {
        "kind": "lhs",
        "repose_extra_sets": 0,
        "shear_extra_sets": 0,
        "shared_stresses": "all",
    },
}

_PROFILES: dict[str, dict[str, Any]] = {
    # Three stresses show how an effect changes with stress (cohesion's share of the strength
    # falls as 1 / sigma, rolling resistance's does not); one shear load (P = 0.5) gives one
    # run per stress with all three shear-cell observables. Not below 1 068 Pa: at 500 Pa the
    # soft particles' own cohesive overlap reaches 9-25 % of the radius at drawn cohesions of
    # 2.8-4.8e4 J/m^3 and the cell reads nonsense (docs/discrepancy.md). The particle density is
    # taken as measured (pycnometer), so that a few cases give trustworthy surrogates; up to
    # 0.9: the soft tiny cell turns unstable near coefficientFriction 1.
    "tiny": {
        "particles": {"radius": 0.0015},
        "design": {
            "n": 8,
            "seed": 3,
            "ranges": {"coefficientFriction": [0.1, 0.9]},
            "fixed": {
                "coefficientRollingFriction": 0.0,
                "coefficientRestitution": 0.7,
                "density": 2800.0,
            },
        },
        "shear_cell": {"normal_stresses": [1068.0, 2029.0, 4000.0], "P": [0.5]},
        # Measured but left out of the fit: the DEM check of the result at a load no step saw.
        "discrepancy": {"held_out": [{"normal_stress": 1500.0, "P": 0.5}]},
        # The angle of repose is not measured in the study; its design runs are kept short.
        "angle_of_repose": {"dCylDp": 6, "lift_time": 0.5, "final_settle_fall_times": 1.0},
        "surrogate": {"hidden_sizes": [3, 6], "max_epochs": 300, "patience": 20},
    },
    "quick": {
        "particles": {"radius": 0.002},
        "design": {
            "n": 16,
            "seed": 1,
            "ranges": {"coefficientFriction": [0.1, 0.9], "density": [2500.0, 3500.0]},
            "fixed": {"coefficientRollingFriction": 0.0, "coefficientRestitution": 0.7},
        },
        "shear_cell": {"normal_stresses": [1068.0, 2029.0, 10070.0], "P": [0.5]},
        "discrepancy": {"held_out": [{"normal_stress": 5000.0, "P": 0.5}]},
    },
}


def study_overrides(profile: str) -> dict[str, Any]:
    """Configuration overrides that turn a profile into the hidden-effect study model.

    Raises
    ------
    KeyError
        For a profile without a study variant.
    """
    if profile not in _PROFILES:
        raise KeyError(f"no hidden-effect study for profile {profile!r} (have {list(_PROFILES)})")
    return deep_merge(_MODEL, _PROFILES[profile])


def study_config(raw: Mapping[str, Any], profile: str | None = None) -> dict[str, Any]:
    """A profile's raw configuration turned into the hidden-effect study model.

    The design's ranges and fixed values are replaced (not merged), so the study varies exactly
    the parameters of :func:`study_overrides` whatever the profile varies.
    """
    overrides = study_overrides(profile or str(raw.get("profile", "quick")))
    out = deep_merge(raw, overrides)
    out["design"]["ranges"] = dict(overrides["design"]["ranges"])
    out["design"]["fixed"] = dict(overrides["design"]["fixed"])
    return out


def prepare_study(
    profile_config: str | Path,
    truth_path: str | Path,
    study_dir: str | Path,
    noise: Mapping[str, float] | None = None,
    seed: int = 1,
    engine_command: str | None = None,
    workers: int = 2,
    replicates: int = 3,
    truth_seed: int = 1,
    truth_engine: str | None = None,
) -> Path:
    """Set up a hidden-effect study directory ready for ``snakemake discrepancy``.

    Writes ``config/config.yaml`` (the study model, with its experiment file),
    ``config/experiments/measured.yaml`` (the mean of ``replicates`` truth runs with their
    scatter and the added noise as sd) and ``truth.yaml`` (the drawn truth, which the workflow
    never reads) under ``study_dir``.

    Parameters
    ----------
    noise : mapping, optional
        Relative noise per observable; default :data:`NOISE`.
    seed : int
        Seed of the noise.
    engine_command : str, optional
        Engine of the model under calibration (default: the profile's).
    truth_seed : int
        Seed of the truth draw.
    truth_engine : str, optional
        Command template of the truth runs; default :func:`demcal.engine_io.run.installed_liggghts`.

    Returns
    -------
    Path
        The study configuration file.
    """
    study_dir = Path(study_dir)
    (study_dir / "config" / "experiments").mkdir(parents=True, exist_ok=True)
    raw = yaml.safe_load(Path(profile_config).read_text()) or {}
    config = study_config(raw)
    config["experiment"] = "config/experiments/measured.yaml"
    if engine_command is not None:
        config.setdefault("engine", {})["command"] = engine_command
    path = study_dir / "config" / "config.yaml"
    path.write_text(yaml.safe_dump(config, sort_keys=False))
    validated = validate_config(copy.deepcopy(config), str(path))
    _, truth = write_hidden_effect_experiment(
        truth_path,
        validated,
        study_dir / config["experiment"],
        study_dir / "truth_runs",
        noise,
        seed,
        workers=workers,
        replicates=replicates,
        truth_seed=truth_seed,
        truth_engine=truth_engine if truth_engine is not None else installed_liggghts(),
    )
    write_truth(study_dir, truth)
    return path


def write_truth(study_dir: str | Path, truth: DrawnTruth) -> Path:
    """Write the drawn truth beside a study (``truth.yaml``), where the workflow never looks."""
    path = Path(study_dir) / "truth.yaml"
    path.write_text(
        "# The drawn truth of this study; the workflow never reads it.\n"
        + yaml.safe_dump(truth.record(), sort_keys=False)
    )
    return path


def hidden_effect_bulk(
    truth: DrawnTruth,
    config: Mapping[str, Any],
    work_dir: str | Path,
    tests: Sequence[str] = ("shear_cell",),
    workers: int = 2,
    replicates: int = 1,
    engine_command: str | None = None,
) -> pd.DataFrame:
    """Bulk values of the virtual tests at the true parameters with the hidden effect on.

    Parameters
    ----------
    truth : DrawnTruth
        The drawn truth (:func:`demcal.discrepancy.truths.draw_truth`).
    config : mapping
        The study configuration (the model under calibration).
    work_dir : path
        Where the runs are made.
    tests : sequence of str
        Virtual tests to run; the shear-cell runs are those of a design row
        (:func:`demcal.design.cases.shear_suffixes`) and the held-out loads
        (``discrepancy.held_out``).
    workers : int
        Runs at the same time.
    replicates : int
        Repetitions of every run with a different configuration seed (a fresh packing), as a
        laboratory repeats a test; column ``replicate`` numbers them.
    engine_command : str, optional
        Command template of the truth runs (e.g. ``liggghts -in {deck}``); default the
        study's ``engine.command``.

    Raises
    ------
    RuntimeError
        When a run fails (names the case directory and the engine's error).
    """
    cfg = truth_config(truth, config)
    if engine_command is not None:
        cfg = deep_merge(cfg, {"engine": {"command": engine_command}})
    params = dict(truth.parameters)

    def cases_of(r: int) -> list[Case]:
        cases: list[Case] = []
        if "angle_of_repose" in tests:
            cases.append(("angle_of_repose", {"case_id": f"truth{r}", **params}))
        if "shear_cell" in tests:
            for suffix in shear_suffixes(cfg) + held_out_suffixes(cfg):
                key = f"truth{r}{suffix}"
                cases.append(("shear_cell", {"case_id": key, **params, **run_load(cfg, key)}))
        return cases

    return run_replicates(cases_of, cfg, work_dir, "truth run", replicates, workers)


def write_hidden_effect_experiment(
    truth_path: str | Path,
    config: Mapping[str, Any],
    out: str | Path,
    work_dir: str | Path,
    noise: Mapping[str, float] | None,
    seed: int,
    tests: Sequence[str] = ("shear_cell",),
    workers: int = 2,
    replicates: int = 3,
    truth_seed: int = 1,
    truth_engine: str | None = None,
) -> tuple[dict[str, Any], DrawnTruth]:
    """Draw the truth, run it ``replicates`` times, add noise and write the experiment ``out``.

    Parameters
    ----------
    truth_path : path
        Truth specification.
    config : mapping
        Validated study configuration.
    noise : mapping or None
        Relative noise per observable; None for :data:`NOISE`.
    seed : int
        Seed of the noise.
    truth_seed : int
        Seed of the truth draw.
    truth_engine : str, optional
        Command template of the truth runs; None runs them on the study's engine.

    Returns
    -------
    tuple
        The experiment record written (material, source, measured values with sd) and the
        drawn truth.
    """
    truth = draw_truth(load_truth_spec(truth_path), config, truth_seed, str(truth_path))
    noise = dict(NOISE if noise is None else noise)
    bulk = hidden_effect_bulk(
        truth, config, work_dir, tests, workers, replicates, engine_command=truth_engine
    )
    engine = truth_engine or str(config["engine"]["command"])
    levels = ", ".join(f"{k} {v:.1%}" for k, v in noise.items())
    record = replicate_record(
        bulk,
        truth.material,
        noise,
        seed,
        f"`{engine}` with a hidden effect ({config['profile']} profile, truth drawn with seed "
        f"{truth_seed}), mean of {replicates} runs, noise {levels}",
    )
    Path(out).write_text(
        "# Synthetic measurements with a hidden effect; the truth is kept apart and never read\n"
        "# by the workflow.\n" + yaml.safe_dump(record, sort_keys=False)
    )
    return record, truth
