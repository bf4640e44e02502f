"""Bulk-level comparison of two DEM engines: the same decks, several seeds, Welch's t-test.

The bundled engine and LIGGGHTS 3.8 run the same rendered decks of the virtual bulk tests
(Schulze shear cell at one load condition, lifted-cylinder angle of repose). A run is a
deterministic function of the seed of the particle insertion, so the seed scatter of a bulk
value is its sampling noise; the question asked is whether the *mean over seeds* differs
between the engines.

The statistics are in :mod:`demcal.bulk.engine_statistics`.
"""

from __future__ import annotations

import copy
import json
import math
import os
import time
from collections.abc import Iterable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from demcal.bulk.values import extract
from demcal.engine_io.run import run_deck
from demcal.virtual_tests.deck import DECK_NAMES, render_case

__all__ = [
    "BULK_VALUES",
    "ENGINE_COMMANDS",
    "RunJob",
    "collect_values",
    "load_status",
    "parameter_sets",
    "plan_runs",
    "run_jobs",
    "select_parameter_sets",
]

#: Bulk values compared, with the test they come from.
BULK_VALUES: dict[str, str] = {
    "mu_psh": "shear_cell",
    "mu_sh": "shear_cell",
    "rho_b": "shear_cell",
    "aor": "angle_of_repose",
}

#: Command templates of the engines (one thread / one MPI rank). Both write their log to
#: ``log.liggghts``, where :func:`demcal.engine_io.run.error_lines` looks for errors.
ENGINE_COMMANDS: dict[str, str] = {
    "liggghts": "liggghts -in {deck} -log log.liggghts",
    "engine": "dem_engine -in {deck} -log log.liggghts -noprogress",
}

#: Contact parameters shared by all sets unless a set overrides them.
_BASE_SET: dict[str, float] = {
    "coefficientFriction": 0.3,
    "coefficientRollingFriction": 0.1,
    "coefficientRestitution": 0.6,
    "density": 2500.0,
}

#: Cohesion energy density (J/m^3) of the cohesive set per profile: large enough to change the
#: bulk values of the profile's cells; on tiny's soft particles 50 kJ/m^3 already makes the
#: heap stand as a column.
_COHESION: dict[str, float] = {"tiny": 20000.0, "quick": 100000.0}


def parameter_sets(profile: str = "tiny") -> dict[str, dict[str, float]]:
    """The named parameter sets of the comparison.

    Parameters
    ----------
    profile : str
        Configuration profile (``tiny``, ``quick``, ...); sets the cohesion energy density of the
        cohesive set (20 kJ/m^3 for tiny, 100 kJ/m^3 otherwise).

    Returns
    -------
    dict
        ``low`` (mu_s 0.3, mu_r 0.1), ``middle`` (mu_s 0.6, mu_r 0.3), ``high`` (mu_s 0.9,
        mu_r 0.1, otherwise as ``low``), ``interlocking`` (mu_s 0.9, mu_r 0.7: particles pinch
        at the rim of the split shear cell) and ``cohesion`` (mu_s 0.5, mu_r 0.2 and
        cohesionEnergyDensity > 0); COR 0.6 and rho_p 2500 kg/m^3 throughout.
    """
    cohesion = _COHESION.get(profile, _COHESION["quick"])
    return {
        "low": dict(_BASE_SET),
        "middle": {
            **_BASE_SET,
            "coefficientFriction": 0.6,
            "coefficientRollingFriction": 0.3,
        },
        "high": {**_BASE_SET, "coefficientFriction": 0.9},
        "interlocking": {
            **_BASE_SET,
            "coefficientFriction": 0.9,
            "coefficientRollingFriction": 0.7,
        },
        "cohesion": {
            **_BASE_SET,
            "coefficientFriction": 0.5,
            "coefficientRollingFriction": 0.2,
            "cohesionEnergyDensity": cohesion,
        },
    }


def select_parameter_sets(names: Sequence[str], profile: str) -> dict[str, dict[str, float]]:
    """The named sets of :func:`parameter_sets`, in the order given.

    Parameters
    ----------
    names : sequence of str
        Set names (``low``, ``middle``, ``high``, ``interlocking``, ``cohesion``).
    profile : str
        Configuration profile, as for :func:`parameter_sets`.

    Returns
    -------
    dict
        Set name -> contact parameters.

    Raises
    ------
    ValueError
        A name is not a set; the message lists the unknown names and the choices.
    """
    available = parameter_sets(profile)
    unknown = [name for name in names if name not in available]
    if unknown:
        raise ValueError(f"unknown parameter sets {unknown}; choose from {sorted(available)}")
    return {name: available[name] for name in names}


@dataclass
class RunJob:
    """One rendered case to run: a parameter set, a test, an engine and a seed."""

    set_name: str
    test: str
    engine: str
    seed: int
    case_dir: Path
    command: str
    status: dict[str, Any] = field(default_factory=dict)


def plan_runs(
    settings: Mapping[str, Any],
    sets: Mapping[str, Mapping[str, float]],
    seeds: Sequence[int],
    out_dir: Path,
    engines: Mapping[str, str] | None = None,
    tests: Iterable[str] = ("shear_cell", "angle_of_repose"),
    normal_stress: float | None = None,
    P: float | None = 0.8,
    render: bool = True,
) -> list[RunJob]:
    """Render every case of the comparison (the same deck per set, test and seed for each engine).

    Parameters
    ----------
    settings : mapping
        Validated configuration (``demcal.core.config.load_config``); its ``seed`` is replaced
        by each of ``seeds``.
    sets : mapping
        Parameter set name -> contact parameters (as from :func:`parameter_sets`).
    seeds : sequence of int
        Seeds of the particle insertion; each gives one sample per engine.
    out_dir : Path
        Root directory; cases go to ``out_dir/<set>/<test>/seed<seed>/<engine>``.
    engines : mapping, optional
        Engine name -> command template; default :data:`ENGINE_COMMANDS`.
    tests : iterable of str
        Virtual tests to run.
    normal_stress : float, optional
        Pre-shear normal stress (Pa) of the shear cell; default the first of
        ``settings["shear_cell"]["normal_stresses"]``.
    P : float or None
        Ratio of shear to pre-shear load of the single load condition run; None: every value
        of ``settings["shear_cell"]["P"]`` as a cycle of one deck.
    render : bool
        Write the case directories (False: only list them, e.g. to collect earlier runs with
        :func:`load_status`).

    Returns
    -------
    list of RunJob
        The cases, not yet run.
    """
    engines = dict(ENGINE_COMMANDS if engines is None else engines)
    stress = (
        float(settings["shear_cell"]["normal_stresses"][0])
        if normal_stress is None
        else float(normal_stress)
    )
    jobs: list[RunJob] = []
    for set_name, params in sets.items():
        for test in tests:
            case: dict[str, Any] = {"case_id": f"{set_name}", **params}
            if test == "shear_cell":
                case["normal_stress"] = stress
                if P is not None:
                    case["P"] = float(P)
            for seed in seeds:
                cfg = copy.deepcopy(dict(settings))
                cfg["seed"] = int(seed)
                for engine, command in engines.items():
                    case_dir = Path(out_dir) / set_name / test / f"seed{seed}" / engine
                    if render:
                        render_case(test, case, cfg, case_dir)
                    jobs.append(RunJob(set_name, test, engine, int(seed), case_dir, command))
    return jobs


def run_jobs(jobs: Sequence[RunJob], parallel: int = 2, threads: int = 1) -> float:
    """Run the cases, ``parallel`` at a time, longest expected first; return the wall time (s).

    LIGGGHTS runs as one MPI rank without ``mpirun``; Open MPI is allowed to run as root
    (``OMPI_ALLOW_RUN_AS_ROOT``), as in a container. A failed run is recorded in its
    ``status`` (see :func:`demcal.engine_io.run.run_deck`), not raised.

    Parameters
    ----------
    jobs : sequence of RunJob
        From :func:`plan_runs`; ``status`` is filled in.
    parallel : int
        Runs at a time.
    threads : int
        Threads per run (OpenMP threads of the engine; LIGGGHTS ignores it).

    Returns
    -------
    float
        Wall time of all runs, s.
    """
    os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")

    def cost(job: RunJob) -> tuple[int, int, int]:
        # Seed by seed, so that an interrupted comparison has balanced samples; within a seed
        # the longest runs first.
        return (job.seed, job.test != "angle_of_repose", job.engine != "liggghts")

    def one(job: RunJob) -> None:
        job.status = run_deck(job.case_dir, DECK_NAMES[job.test], job.command, threads)

    start = time.monotonic()
    with ThreadPoolExecutor(max_workers=max(1, int(parallel))) as pool:
        list(pool.map(one, sorted(jobs, key=cost)))
    return time.monotonic() - start


def load_status(jobs: Sequence[RunJob]) -> list[RunJob]:
    """Fill in ``status`` of each job from its ``status.json`` (runs made earlier).

    Jobs whose case directory has no ``status.json`` keep an empty status (``not run``).

    Returns
    -------
    list of RunJob
        The same jobs.
    """
    for job in jobs:
        path = job.case_dir / "status.json"
        if path.is_file():
            job.status = json.loads(path.read_text())
    return list(jobs)


def collect_values(jobs: Sequence[RunJob]) -> pd.DataFrame:
    """Bulk values of finished runs, one row per run and bulk value.

    Returns
    -------
    pandas.DataFrame
        Columns ``set``, ``engine``, ``seed``, ``test``, ``quantity``, ``value``, ``status``
        (``ok``, ``failed`` with the engine's error, or ``unreadable`` with the reason) and
        ``seconds`` (run time). Values of runs that are not ``ok`` are NaN.
    """
    rows: list[dict[str, Any]] = []
    for job in jobs:
        quantities = [q for q, t in BULK_VALUES.items() if t == job.test]
        status = job.status.get("status", "not run")
        values: dict[str, float] = dict.fromkeys(quantities, math.nan)
        if status == "ok":
            try:
                row = extract(job.test, job.case_dir).iloc[0]
                values = {q: float(row[q]) for q in quantities}
                if str(row.get("status", "ok")) != "ok":
                    status = f"readout {row['status']}"
            except (ValueError, KeyError, OSError) as exc:
                status = f"unreadable: {exc}"
        elif job.status.get("error"):
            status = f"failed: {job.status['error']}"
        for quantity, value in values.items():
            rows.append(
                {
                    "set": job.set_name,
                    "engine": job.engine,
                    "seed": job.seed,
                    "test": job.test,
                    "quantity": quantity,
                    "value": value,
                    "status": status,
                    "seconds": job.status.get("seconds", math.nan),
                }
            )
    return pd.DataFrame(rows)
