"""How the readings of a multi-cycle shear-cell deck change from one cycle to the next.

A deck without a column P runs every value of ``shear_cell.P`` as a pre-shear / unload / shear
cycle of one sample (``shear_cell.separate_runs: false``). Its pre-shears all run at the same
stress, so their readings repeat one another only if the bed returns to one state after every
cycle. :func:`cycle_table` measures whether it does, from the per-cycle columns that
:func:`demcal.bulk.values.extract` writes (``mu_psh_cycle``, ``rho_b_cycle``, ``mu_sh``);
:func:`plan_cycle_decks` and :func:`collect_cycle_values` render, and read back, such decks for
reference parameter sets (``scripts/cycle_study.py``).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from demcal.bulk.engine_comparison import RunJob
from demcal.bulk.values import extract
from demcal.virtual_tests.deck import render_case

__all__ = ["collect_cycle_values", "cycle_table", "plan_cycle_decks"]

_COLUMNS = ("cycle", "P", "mu_psh_cycle", "rho_b_cycle", "mu_sh", "steady_psh")


def cycle_table(values: pd.DataFrame, deck: str = "case_id") -> pd.DataFrame:
    """Mean and standard error over decks of each cycle's readings, relative to its deck.

    Parameters
    ----------
    values : pandas.DataFrame
        One row per deck and cycle (e.g. the shear-cell rows of ``results/bulk/dataset.csv``
        of a study with ``separate_runs: false``), with columns ``deck``, ``cycle``, ``P``,
        ``mu_psh_cycle``, ``rho_b_cycle`` (kg/m^3), ``mu_sh`` and ``steady_psh``.
    deck : str
        Column naming the deck of a row.

    Returns
    -------
    pandas.DataFrame
        Indexed by cycle: ``P``; ``decks`` (decks with a reading); ``psh`` and ``psh_se``
        (the cycle's pre-shear mu over the mean of its deck's pre-shears, -); ``rho`` and
        ``rho_se`` (the same for the bulk density, -); ``sh`` and ``sh_se`` (mu_sh over the
        pre-shear mu of the same cycle, -); ``steady`` (fraction of pre-shears with a steady
        window). Ratios of 1 in every cycle mean the cycles repeat one another.

    Raises
    ------
    ValueError
        When a column is missing or no deck has two cycles.
    """
    missing = [c for c in (deck, *_COLUMNS) if c not in values.columns]
    if missing:
        raise ValueError(f"cycle_table: missing columns {missing}")
    rows = values.dropna(subset=["cycle"]).copy()
    if rows.empty or rows.groupby(deck)["cycle"].nunique().max() < 2:
        raise ValueError("cycle_table: no deck with two or more cycles (separate runs?)")
    by_deck = rows.groupby(deck)
    rows["psh"] = rows["mu_psh_cycle"] / by_deck["mu_psh_cycle"].transform("mean")
    rows["rho"] = rows["rho_b_cycle"] / by_deck["rho_b_cycle"].transform("mean")
    rows["sh"] = rows["mu_sh"] / rows["mu_psh_cycle"]
    grouped = rows.groupby("cycle")
    table = pd.DataFrame(
        {
            "P": grouped["P"].first(),
            "decks": grouped["psh"].count(),
            "steady": grouped["steady_psh"].mean(),
        }
    )
    for name in ("psh", "rho", "sh"):
        table[name] = grouped[name].mean()
        table[f"{name}_se"] = grouped[name].std() / np.sqrt(grouped[name].count())
    return table


def plan_cycle_decks(
    settings: Mapping[str, Any],
    sets: Mapping[str, Mapping[str, float]],
    seeds: Sequence[int],
    out_dir: Path,
    command: str,
    normal_stress: float,
    render: bool = True,
    engine: str = "engine",
) -> list[RunJob]:
    """Render one multi-cycle shear-cell deck per parameter set and seed.

    Parameters
    ----------
    settings : mapping
        Validated configuration; every value of ``shear_cell.P`` becomes a cycle.
    sets : mapping
        Parameter set name -> contact parameters.
    seeds : sequence of int
        Insertion seeds, one deck each.
    out_dir : Path
        A deck goes to ``out_dir/<set>/seed<seed>``.
    command : str
        Engine command template (``{deck}`` is the deck file name).
    normal_stress : float
        Pre-shear normal stress, Pa.
    render : bool
        Write the case directories of decks without a ``status.json``; False: only list them.
    engine : str
        Name of the code that runs ``command`` (``engine`` or ``liggghts``), kept with the job.

    Returns
    -------
    list of RunJob

    Raises
    ------
    ValueError
        When ``shear_cell.P`` has fewer than two values.
    """
    if len(settings["shear_cell"]["P"]) < 2:
        raise ValueError("shear_cell.P: a deck with cycles needs at least two values of P")
    jobs = []
    for set_name, params in sets.items():
        # No P in the case row: the deck runs all values of P as cycles.
        case = {"case_id": set_name, **params, "normal_stress": float(normal_stress)}
        for seed in seeds:
            case_dir = Path(out_dir) / set_name / f"seed{seed}"
            if render and not (case_dir / "status.json").is_file():
                cfg = copy.deepcopy(dict(settings))
                cfg["seed"] = int(seed)
                render_case("shear_cell", case, cfg, case_dir)
            jobs.append(RunJob(set_name, "shear_cell", engine, int(seed), case_dir, command))
    return jobs


def collect_cycle_values(jobs: Sequence[RunJob]) -> pd.DataFrame:
    """Per-cycle readings of the finished decks.

    Returns
    -------
    pandas.DataFrame
        :func:`demcal.bulk.values.extract` rows of every deck whose status is ``ok``, with
        ``set``, ``seed`` and ``deck`` (the case directory) added; empty when none finished.
    """
    frames = []
    for job in jobs:
        if job.status.get("status") != "ok":
            continue
        rows = extract("shear_cell", job.case_dir)
        frames.append(rows.assign(set=job.set_name, seed=job.seed, deck=str(job.case_dir)))
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
