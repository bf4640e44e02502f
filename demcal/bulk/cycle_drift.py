"""How the readings of a multi-cycle shear-cell deck change from one cycle to the next.

A deck without a column P runs every value of ``shear_cell.P`` as a pre-shear / unload / shear
cycle of one sample (``shear_cell.separate_runs: false``). Its pre-shears all run at the same
stress, so their readings repeat one another only if the bed returns to one state after every
cycle. :func:`cycle_table` measures whether it does, from the per-cycle columns that
:func:`demcal.bulk.values.extract` writes (``mu_psh_cycle``, ``rho_b_cycle``, ``mu_sh``);
:func:`collect_cycle_values` reads them back from decks that
:func:`demcal.bulk.engine_comparison.plan_runs` rendered with ``P=None``
(``scripts/cycle_study.py``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from demcal.bulk.engine_comparison import RunJob
from demcal.bulk.values import extract

__all__ = ["collect_cycle_values", "cycle_table"]

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
