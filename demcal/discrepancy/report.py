"""Tables, texts and the figure of the discrepancy workflow (Find, Name, Show)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from demcal.discrepancy.effect_verdict import CONFIRMED, GAP_REMAINS
from demcal.discrepancy.find import FindResult
from demcal.discrepancy.observations import format_stress
from demcal.discrepancy.ranking import UNNAMEABLE

#: DEM replicate statistics per observation: mean, sd and number of runs, shape (K,) each.
Replicates = tuple[np.ndarray, np.ndarray, np.ndarray]

__all__ = [
    "KEY_COLUMNS",
    "Replicates",
    "condition_label",
    "find_markdown",
    "gap_figure",
    "gap_of",
    "gap_table",
    "markdown_table",
    "ranking_markdown",
    "verification_markdown",
]

#: Columns that identify an observation.
KEY_COLUMNS = ("observable", "normal_stress", "P")


def markdown_table(frame: pd.DataFrame, floatfmt: str = ".4g") -> str:
    """A GitHub-flavoured markdown table (NaN shown as empty)."""

    def cell(value: Any) -> str:
        if isinstance(value, float | np.floating):
            return "" if not math.isfinite(value) else format(float(value), floatfmt)
        return str(value).replace("|", "/")

    header = "| " + " | ".join(str(c) for c in frame.columns) + " |"
    rule = "|" + "|".join("---" for _ in frame.columns) + "|"
    body = ["| " + " | ".join(cell(v) for v in row) + " |" for row in frame.itertuples(False)]
    return "\n".join([header, rule, *body]) + "\n"


def condition_label(row: Any) -> str:
    """A load condition as text, e.g. ``1 068 Pa, P = 0.5`` (``-`` for the angle of repose)."""
    if not math.isfinite(row.normal_stress):
        return "-"
    return f"{format_stress(row.normal_stress)}, P = {row.P:g}"


def find_markdown(result: FindResult, material: str, box_bounds: Mapping[str, Any]) -> str:
    """The Find report: verdict, gap, theta*, sentences and the per-observation table."""
    obs = result.observations
    lines = [
        f"# Discrepancy - Find: {material}",
        "",
        f"**Verdict: {result.verdict}.**",
        "",
        f"Gap figure G = sqrt(min chi^2 / N) = sqrt({result.best.deviance:.3g} / {len(obs)}) "
        f"= {result.gap:.3f}; z = (model - measured) / sigma with sigma = sqrt(measurement "
        'sd^2 + surrogate held-out RMSE^2). Verdict: p-value of "nothing missing" from '
        f"{result.draws} data sets drawn at theta* with these sigma and fitted over the same "
        f"grid, p = {result.p_value:.3g} against alpha = {result.alpha:g}.",
        "",
        "Where the disagreement sits:",
        "",
        *[f"- {s}" for s in result.sentences],
        "",
        "Best joint point theta* of the current model (parameter box in brackets):",
        "",
    ]
    for name, value in result.best.theta.items():
        lo, hi = box_bounds[name]
        lines.append(f"- {name} = {value:.4g} [{lo:g}, {hi:g}]")
    table = pd.DataFrame(
        {
            "observable": obs["observable"],
            "condition": [condition_label(r) for r in obs.itertuples()],
            "measured": obs["measured"],
            "sigma": obs["sigma"],
            "model range": [
                f"{a:.4g} .. {b:.4g}"
                for a, b in zip(obs["reach_min"], obs["reach_max"], strict=True)
            ],
            "best |z| alone": obs["best_abs_z"],
            "at theta*": obs["at_best"],
            "z at theta*": obs["z_at_best"],
        }
    )
    lines += ["", markdown_table(table, ".3g")]
    return "\n".join(lines)


def ranking_markdown(
    table: pd.DataFrame,
    winner: str | None,
    n_observations: int,
    alpha: float,
    min_explained: float = 0.0,
    notes: Sequence[str] = (),
    verdict: str | None = None,
    probe_runs: int = 1,
    reference_runs: int = 1,
) -> str:
    """The Name report: the ranking with scores, fitted magnitudes and signatures.

    ``probe_runs`` and ``reference_runs`` are the DEM runs averaged per probe level and at
    theta*; they set the response's share of the weights.
    """
    lines = ["# Discrepancy - Name: which effect explains the gap", ""]
    if verdict is not None:
        lines += [f"Not run: {verdict}.", ""]
        return "\n".join(lines)
    penalty = math.log(n_observations) if n_observations > 0 else math.nan
    lines += [
        "Score: dBIC = D_0 - D_c - ln N against 'nothing missing' (one extra parameter; "
        f"N = {n_observations}, ln N = {penalty:.2f}), D = sum ((model - measured) / s)^2 with "
        f"s^2 = sigma^2 + (1/{probe_runs} + 1/{reference_runs}) RMSE^2 (a probe response is "
        f"the mean of {probe_runs} DEM run(s) minus the mean of {reference_runs} at theta*); "
        "explained = share of D_0 removed; gap = sqrt(D_c / N). dBIC orders the candidates; "
        "the top one is named when a parametric bootstrap rejects both 'nothing missing' and "
        f"'the runner-up is the effect' at alpha = {alpha:g}, and explained >= "
        f"{min_explained:g}.",
        "",
        f"**Named: {winner}.**" if winner else "**No candidate named** (why: the notes below).",
        "",
    ]
    shown = table.copy()
    columns = [
        c
        for c in (
            "rank",
            "candidate",
            "parameter",
            "magnitude",
            "delta_bic",
            "explained",
            "gap",
            "status",
            "power",
            "signature",
        )
        if c in shown
    ]
    lines.append(markdown_table(shown[columns], ".3g"))
    if "power" in shown:
        lines += [
            "power: per probe level, the share of data sets drawn with the candidate present at "
            "that level (the current model's best fit plus its response plus noise) in which "
            "the effect test rejects 'nothing missing' and the candidate leads - an upper bound "
            f"on how often these measurements would name it. Below {100 * UNNAMEABLE:.0f} % at "
            "every level they "
            "cannot name it, and not naming it says nothing about its presence.",
        ]
    descriptions = table[["candidate", "description"]].drop_duplicates()
    lines += ["", "Candidates:", ""]
    lines += [f"- {r.candidate}: {r.description}" for r in descriptions.itertuples()]
    if notes:
        lines += ["", "Notes:", "", *[f"- {n}" for n in notes]]
    return "\n".join(lines) + "\n"


def gap_of(z: pd.Series | np.ndarray) -> float:
    """sqrt(mean z^2) over the finite entries (NaN when there are none)."""
    arr = np.asarray(z, dtype=float)
    arr = arr[np.isfinite(arr)]
    return float(np.sqrt(np.mean(arr**2))) if arr.size else math.nan


def gap_table(
    before: pd.DataFrame,
    after: pd.DataFrame | None,
    dem_before: Replicates | None,
    dem_after: Replicates | None,
) -> pd.DataFrame:
    """Per observation: misfit before and after the effect was added, surrogates and DEM.

    Parameters
    ----------
    before : DataFrame, shape (K, ...)
        Find observations of the current model (measured, sigma, at_best, z_at_best), and the
        held-out observations (``held_out`` True, at_best NaN) after them.
    after : DataFrame or None
        Find observations of the extended model on the same observations.
    dem_before, dem_after : (mean, sd, n) of ndarray, shape (K,), or None
        DEM replicate statistics at theta* (current model) and at the extended model's best
        point (:func:`demcal.discrepancy.run_results.replicate_statistics`). Their z uses the
        current model's sigma for both, so the two are directly comparable.

    Returns
    -------
    DataFrame, shape (K, 22)
        Also ``sigma_common`` (the larger sigma of the two models), the misfits of both
        models on it (``z_before_common``, ``z_after_common``), the DEM means, their sd and
        number of runs, and ``held_out``.
    """
    out = before[[*KEY_COLUMNS, "measured", "sigma"]].copy().reset_index(drop=True)
    held = before["held_out"] if "held_out" in before else pd.Series(False, index=before.index)
    out["held_out"] = held.fillna(False).astype(bool).to_numpy()
    out["model_before"] = before["at_best"].to_numpy(float)
    out["z_before"] = before["z_at_best"].to_numpy(float)
    if after is not None:
        merged = out[list(KEY_COLUMNS)].merge(
            after[[*KEY_COLUMNS, "sigma", "at_best", "z_at_best"]], on=list(KEY_COLUMNS), how="left"
        )
        out["sigma_after"] = merged["sigma"].to_numpy(float)
        out["model_after"] = merged["at_best"].to_numpy(float)
        out["z_after"] = merged["z_at_best"].to_numpy(float)
    else:
        out["sigma_after"] = out["model_after"] = out["z_after"] = math.nan
    # One yardstick for both models: the larger of their sigmas, so that a less certain
    # extended surrogate cannot shrink the gap by its uncertainty alone.
    common = np.fmax(out["sigma"].to_numpy(float), out["sigma_after"].to_numpy(float))
    out["sigma_common"] = common
    out["z_before_common"] = (out["model_before"] - out["measured"]) / common
    out["z_after_common"] = (out["model_after"] - out["measured"]) / common
    for label, values in (("before", dem_before), ("after", dem_after)):
        if values is None:
            nan = np.full(len(out), math.nan)
            values = (nan, nan, np.zeros(len(out), dtype=int))
        mean, sd, count = (np.asarray(v) for v in values)
        out[f"dem_{label}"] = mean.astype(float)
        out[f"dem_{label}_sd"] = sd.astype(float)
        out[f"dem_{label}_runs"] = count.astype(int)
        out[f"z_dem_{label}"] = (out[f"dem_{label}"] - out["measured"]) / out["sigma"]
    return out


def _labels(table: pd.DataFrame) -> list[str]:
    labels = []
    for row in table.itertuples():
        if math.isfinite(row.normal_stress):
            label = f"{row.observable}\n{row.normal_stress:.0f} Pa, P={row.P:g}"
        else:
            label = str(row.observable)
        labels.append(f"{label}\n(held out)" if row.held_out else label)
    return labels


def _gap_label(table: pd.DataFrame, column: str) -> str:
    fitted = gap_of(table.loc[~table["held_out"], column])
    text = f"gap {fitted:.2f}"
    if table["held_out"].any():
        text += f", held out {gap_of(table.loc[table['held_out'], column]):.2f}"
    return text


def gap_figure(table: pd.DataFrame, title: str, path: str | Path) -> None:
    """|z| per observation before and after: DEM replicate means with their scatter as error
    bars (main panel) and the surrogate best fits (secondary panel).

    Error bars are one replicate standard deviation of the DEM runs in units of sigma; the
    held-out observations are labelled and shaded.
    """
    x = np.arange(len(table))
    fig, axes = plt.subplots(
        2,
        1,
        figsize=(max(6.0, 0.55 * len(table) + 2.0), 7.0),
        sharex=True,
        constrained_layout=True,
        gridspec_kw={"height_ratios": [3, 2]},
    )
    panels = (
        ("DEM runs (mean of replicates, error bar 1 sd)", "z_dem_before", "z_dem_after", "dem"),
        ("surrogate best fit (common sigma), secondary", "z_before_common", "z_after_common", None),
    )
    sigma = table["sigma"].to_numpy(float)
    for ax, (name, zb, za, dem) in zip(axes, panels, strict=True):
        for j in np.flatnonzero(table["held_out"].to_numpy(bool)):
            ax.axvspan(j - 0.5, j + 0.5, color="0.92", zorder=0)
        for offset, column, label, color in ((-0.2, zb, "before", "C3"), (0.2, za, "after", "C0")):
            values = np.abs(table[column].to_numpy(float))
            if not np.isfinite(values).any():
                continue
            errors = None
            if dem is not None:
                errors = table[f"dem_{label}_sd"].to_numpy(float) / sigma
                errors = np.where(np.isfinite(errors), errors, 0.0)
            ax.bar(
                x + offset,
                values,
                0.4,
                yerr=errors,
                capsize=2,
                label=f"{label} ({_gap_label(table, column)})",
                color=color,
            )
        ax.axhline(1.0, color="0.5", lw=0.8, ls="--")
        ax.set_ylabel("|z| = |model - measured| / sigma")
        ax.set_title(name, fontsize=10)
        ax.legend(fontsize=8, loc="upper right")
    axes[-1].set_xticks(x, _labels(table), rotation=60, ha="right", fontsize=7)
    fig.suptitle(title, fontsize=11)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _dem_cell(mean: float, sd: float, runs: int) -> str:
    if not math.isfinite(mean):
        return ""
    spread = f" +- {sd:.3g}" if math.isfinite(sd) else ""
    return f"{mean:.4g}{spread} ({runs})"


def _dem_columns(table: pd.DataFrame, labels: Sequence[str]) -> pd.DataFrame:
    shown = pd.DataFrame(
        {
            "observable": table["observable"],
            "condition": [condition_label(r) for r in table.itertuples()],
            "held out": np.where(table["held_out"], "yes", ""),
            "measured": table["measured"],
            "sigma": table["sigma"],
        }
    )
    for label in labels:
        shown[f"DEM {label} (runs)"] = [
            _dem_cell(m, s, int(n))
            for m, s, n in zip(
                table[f"dem_{label}"],
                table[f"dem_{label}_sd"],
                table[f"dem_{label}_runs"],
                strict=True,
            )
        ]
        shown[f"z {label}"] = table[f"z_dem_{label}"]
    return shown


def verification_markdown(table: pd.DataFrame, summary: Mapping[str, Any]) -> str:
    """DEM replicates at the extended model's identified point against the measurements and
    the current model at theta*, fitted and held-out loads apart."""
    lines = ["# Discrepancy - Show: verification DEM runs", ""]
    if not summary.get("extended"):
        lines += [f"No extended model: {summary.get('reason', '')}.", ""]
        if np.isfinite(table["dem_before"].to_numpy(float)).any():
            lines += ["DEM at theta* of the current model (mean +- sd of the replicates):", ""]
            lines.append(markdown_table(_dem_columns(table, ["before"]), ".4g"))
        return "\n".join(lines) + "\n"
    params = ", ".join(f"{k} = {v:.4g}" for k, v in summary["identified"].items())
    verdict = summary.get("dem_verdict")
    if verdict == CONFIRMED:
        lines += [
            f"**The DEM runs confirm {summary['winner']}**: closer to the measurements "
            "than the current model, held-out loads within the noise or closer, and the gap "
            "left within the noise.",
            "",
        ]
    elif verdict == GAP_REMAINS:
        lines += [
            f"**The DEM runs show {summary['winner']} closing part of the gap, not all of "
            f"it**: closer to the measurements than the current model and held-out loads "
            f"within the noise or closer, but the DEM gap left, "
            f"{summary['dem_gap_after']:.3f}, is more than noise explains (at most "
            f"{summary['dem_gap_bound']:.3f} over {summary['dem_values']} values, alpha = "
            f"{summary['alpha']:g}). {summary['winner']} explains part of the discrepancy or "
            "stands in for an effect the catalogue lacks; something is still missing.",
            "",
        ]
    else:
        lines += [
            f"**The DEM runs do not confirm {summary['winner']}**: the extended model is not "
            "closer to the measurements in DEM than the current model, or it misses the "
            "held-out loads by more than before. It may stand in for another effect; do not "
            "use it without a further measurement.",
            "",
        ]
    lines += [
        f"Effect added: {summary['winner']} ({summary['parameter']}); identified point of the "
        f"extended model: {params}.",
        "",
        f"DEM gap on the fitted loads, mean of {summary['replicates']} runs from fresh packings: "
        f"{summary['dem_gap_before']:.3f} before (current model at theta*), "
        f"{summary['dem_gap_after']:.3f} after (extended model at its identified point); z "
        "uses the current model's sigma in both.",
        "",
    ]
    if summary.get("held_out"):
        lines += [
            f"Held-out loads ({', '.join(summary['held_out'])}; never seen by Find, naming or "
            f"the recalibration): DEM gap {summary['held_out_dem_gap_before']:.3f} before, "
            f"{summary['held_out_dem_gap_after']:.3f} after.",
            "",
        ]
    lines += [
        f"Surrogate gap on a common sigma (the larger of both models'): "
        f"{summary['gap_before_common']:.3f} before, {summary['gap_after']:.3f} after "
        f"({summary['gap_ratio']:.1f} x smaller).",
        "",
        markdown_table(_dem_columns(table, ["before", "after"]), ".4g"),
    ]
    return "\n".join(lines) + "\n"
