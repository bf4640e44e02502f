"""The figure of the rounds: valid region per round, DEM runs per round, surrogate quality."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd


def rounds_figure(
    table: pd.DataFrame,
    valid: Mapping[int, pd.DataFrame],
    ranges: Mapping[str, Sequence[float]],
    path: str | Path,
) -> None:
    """Box plots of the valid sets per round and parameter (scaled to the design box), DEM runs
    per round (bars) with their running total, and the networks' test R^2 per round.

    Parameters
    ----------
    table : DataFrame
        :func:`demcal.sequential.rounds.rounds_table`.
    valid : mapping of int to DataFrame
        Round -> valid sets of its identified group (missing or empty: no box that round).
    ranges : mapping
        Parameter -> [low, high] of the design box.
    path : path
        PNG to write.
    """
    names = list(ranges)
    rounds = list(table["round"])
    fig, axes = plt.subplots(2, max(len(names), 2), figsize=(3.2 * max(len(names), 2), 6.4))
    for ax, name in zip(axes[0], names, strict=False):
        lo, hi = (float(v) for v in ranges[name])
        data, where = [], []
        for r in rounds:
            frame = valid.get(r)
            if frame is not None and len(frame):
                data.append((frame[name].to_numpy(dtype=float) - lo) / (hi - lo))
                where.append(r)
        if data:
            ax.boxplot(data, positions=where, widths=0.6, showfliers=False)
        ax.set_xticks(rounds)
        ax.set_ylim(0.0, 1.0)
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("round")
    axes[0][0].set_ylabel("valid sets (scaled to the box)")
    runs_ax, r2_ax = axes[1][0], axes[1][1]
    runs_ax.bar(rounds, table["runs"], color="0.7", label="runs in the round")
    runs_ax.plot(rounds, table["runs_total"], "k.-", label="total")
    runs_ax.set_xlabel("round")
    runs_ax.set_ylabel("DEM runs")
    runs_ax.legend(fontsize=8)
    for column in [c for c in table.columns if c.endswith("_test_r2")]:
        r2_ax.plot(rounds, table[column], ".-", label=column.removesuffix("_test_r2"))
    r2_ax.set_xlabel("round")
    r2_ax.set_ylabel("network test R$^2$")
    r2_ax.set_ylim(float(np.nanmin(table.filter(like="_test_r2").to_numpy(), initial=0.0)), 1.05)
    r2_ax.legend(fontsize=8)
    for ax in axes[1][2:]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
