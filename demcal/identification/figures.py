"""Figures of the valid parameter sets: normalised box plots (paper Figs. 6, 8, 9) and the
COR density plot over (mu_s, mu_r) (paper Fig. 7)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.colors import ListedColormap
from matplotlib.patches import Patch

from demcal.core.parameters import PARAMETER_LABELS
from demcal.identification.statistics import dominant_bin_map

_BIN_COLOURS = ("#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02")


def box_plot_normalised(
    valid: pd.DataFrame,
    path: str | Path,
    title: str,
    parameters: Sequence[str] | None = None,
) -> Path:
    """Box plot of the valid sets, each parameter divided by its maximum over the valid sets.

    Parameters
    ----------
    valid : pandas.DataFrame, shape (n_valid, ...)
        Valid sets, one column per parameter.
    path : str or Path
        PNG file to write.
    title : str
        Figure title (e.g. ``"SSC, normal_stress = 10070 Pa, P = 1"``).
    parameters : Sequence[str], optional
        Columns to show; defaults to the known contact parameters present in ``valid``.

    Returns
    -------
    Path
        The written file.
    """
    if parameters is None:
        parameters = [p for p in PARAMETER_LABELS if p in valid.columns]
    missing = [p for p in parameters if p not in valid.columns]
    if missing:
        raise KeyError(f"box_plot_normalised: valid-set table has no column(s) {missing}")
    if not parameters:
        raise ValueError("box_plot_normalised: no parameters to plot")
    if len(valid) == 0:
        raise ValueError(f"box_plot_normalised: no valid sets to plot for {title!r}")
    data = []
    for name in parameters:
        column = valid[name].to_numpy(dtype=np.float64)
        top = column.max()
        if not top > 0.0:
            raise ValueError(f"box_plot_normalised: maximum of {name!r} is {top}, cannot normalise")
        data.append(column / top)

    fig, ax = plt.subplots(figsize=(5.5, 4.0))
    ax.boxplot(data, tick_labels=[PARAMETER_LABELS.get(p, p) for p in parameters])
    ax.set_ylabel("value / maximum over valid sets (-)")
    ax.set_title(f"{title} ({len(valid)} valid sets)", fontsize=10)
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def cor_density_plot(
    valid: pd.DataFrame,
    axes: Mapping[str, np.ndarray | Sequence[float]],
    path: str | Path,
    n_cells: int | tuple[int, int] = 20,
    n_cor_bins: int = 4,
    title: str | None = None,
) -> Path:
    """Paper Fig. 7: each (mu_s, mu_r) cell coloured by the COR range with most valid sets.

    Parameters
    ----------
    valid : pandas.DataFrame
        Valid sets with columns coefficientFriction, coefficientRollingFriction and
        coefficientRestitution.
    axes : Mapping[str, array_like]
        Screening axes (or (low, high) per parameter); they fix the cell and COR-bin edges.
    path : str or Path
        PNG file to write.
    n_cells : int or (int, int)
        Cells along mu_s and mu_r.
    n_cor_bins : int
        Equal COR ranges over the COR axis range.
    title : str, optional
        Figure title.

    Returns
    -------
    Path
        The written file. Cells without valid sets stay white.
    """
    if n_cor_bins > len(_BIN_COLOURS):
        raise ValueError(f"cor_density_plot: at most {len(_BIN_COLOURS)} COR bins supported")
    m = dominant_bin_map(valid, axes, n_cells=n_cells, n_bins=n_cor_bins)
    shown = np.ma.masked_less(m.dominant, 0)
    cmap = ListedColormap(list(_BIN_COLOURS[:n_cor_bins])).with_extremes(bad="white")

    fig, ax = plt.subplots(figsize=(5.5, 4.8))
    ax.pcolormesh(m.x_edges, m.y_edges, shown, cmap=cmap, vmin=-0.5, vmax=n_cor_bins - 0.5)
    ax.set_xlabel(PARAMETER_LABELS["coefficientFriction"])
    ax.set_ylabel(PARAMETER_LABELS["coefficientRollingFriction"])
    ax.set_xlim(m.x_edges[0], m.x_edges[-1])
    ax.set_ylim(m.y_edges[0], m.y_edges[-1])
    handles = [
        Patch(color=_BIN_COLOURS[k], label=f"COR {m.bin_edges[k]:.2f}-{m.bin_edges[k + 1]:.2f}")
        for k in range(n_cor_bins)
    ]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    ax.set_title(title or f"COR range with most valid sets ({len(valid)} sets)", fontsize=10)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def note_figure(path: str | Path, text: str) -> Path:
    """A figure that states why there is nothing to plot (keeps the report's layout)."""
    fig, ax = plt.subplots(figsize=(6, 2))
    ax.axis("off")
    ax.text(0.5, 0.5, text, ha="center", va="center", wrap=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return Path(path)
