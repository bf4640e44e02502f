"""The validation matrix of the discrepancy workflow: hidden effects x drawn truths.

Every row of the matrix is one blind study: a truth specification (a hidden catalogue effect,
nothing, or an effect outside the catalogue such as softer particles) and a seed from which the
truth is drawn (:mod:`demcal.discrepancy.truths`); its measurements come from the truth engine
(LIGGGHTS by default) with replicate runs and noise (:mod:`demcal.discrepancy.synthetic`), and
``snakemake discrepancy`` runs on it as a user would. The current model (design runs and
surrogates) does not depend on the truth, so it is made once in a base directory and copied into
every study.

The outcome of a study is what the workflow said: ``nothing missing``, the named candidate, or
``not explained`` (something is missing but no candidate was named). The summary is a confusion
matrix of hidden effect against outcome, with the naming accuracy over the catalogue rows, the
false-alarm rate on the rows with nothing hidden, and for the outside effect whether the gap
after a named proxy stays above the noise. Two measures say whether a miss is the method's or
the data's: the naming power at the truth (from the study's probe runs) and the twin signal
(how far the effect moved the truth engine's measurements against the study with nothing
hidden and the same seed).
"""

from __future__ import annotations

import copy
import json
import math
import shutil
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml

from demcal.core.config import validate_config
from demcal.core.experiments import load_experiment
from demcal.core.snakemake_run import run_snakemake
from demcal.discrepancy.effect_verdict import CONFIRMED, effect_verdict, fitted_dem_values
from demcal.discrepancy.observations import OBSERVABLES, observation_table
from demcal.discrepancy.ranking import UNNAMEABLE
from demcal.discrepancy.report import markdown_table
from demcal.discrepancy.synthetic import (
    study_config,
    write_hidden_effect_experiment,
    write_truth,
)
from demcal.discrepancy.truths import load_truth_spec

__all__ = [
    "AMBIGUOUS",
    "GAP_COLUMNS",
    "NOTHING",
    "NOT_EXPLAINED",
    "REPORT_COLUMNS",
    "VISIBLE_SIGNAL",
    "MatrixCase",
    "confusion_matrix",
    "matrix_cases",
    "matrix_markdown",
    "matrix_scores",
    "pinned_text",
    "placeholder_experiment",
    "power_at",
    "prepare_base",
    "run_case",
    "study_name",
    "study_outcome",
    "twin_signal",
    "with_signal",
]

#: Outcome when Find sees no gap.
NOTHING = "nothing missing"
#: Outcome when something is missing but no candidate is named.
NOT_EXPLAINED = "not explained"
#: Start of the outcome when the two leading candidates cannot be told apart
#: (``"ambiguous: a / b"``, names in alphabetical order).
AMBIGUOUS = "ambiguous"
#: Experiment file of a study, relative to its directory.
EXPERIMENT = "config/experiments/measured.yaml"
#: Gap figures of a study row (NaN where the study did not reach the step).
GAP_COLUMNS = (
    "gap_before",
    "gap_after",
    "dem_gap_before",
    "dem_gap_after",
    "held_out_dem_gap_before",
    "held_out_dem_gap_after",
)
#: Signal of a hidden effect (rms over the measured values of the difference to the
#: nothing-hidden twin, in measurement sd; see :func:`twin_signal`) from which it counts as
#: visible in the measurements. Two samples of one material differ by the replicate scatter of
#: both, at most sqrt(2) sd in expectation, and the rms of 9 or more such differences exceeds 2
#: with less than 5 % probability.
VISIBLE_SIGNAL = 2.0
#: Columns of the per-study table of the matrix report.
REPORT_COLUMNS = (
    "hidden",
    "truth_seed",
    "truth_friction",
    "truth_magnitude",
    "signal",
    "outcome",
    "p_find",
    "p_effect",
    "p_runner_up",
    *GAP_COLUMNS,
    "magnitude_ratio",
    "power_at_truth",
    "dem_verdict",
    "pinned",
)


@dataclass(frozen=True)
class MatrixCase:
    """One study of the matrix.

    Attributes
    ----------
    label : str
        Row label: the spec file's name without ``hidden_`` (``cohesion``, ``none``, ...).
    spec : Path
        Truth specification.
    kind : {"catalogue", "nothing", "outside"}
        A catalogue effect, nothing hidden, or a configuration change outside the catalogue.
    hidden : str
        The candidate name for a catalogue effect, else the label.
    truth_seed : int
        Seed of the truth draw (and of the noise).
    """

    label: str
    spec: Path
    kind: str
    hidden: str
    truth_seed: int

    @property
    def name(self) -> str:
        """Directory name of the study."""
        return study_name(self.label, self.truth_seed)


def study_name(label: str, truth_seed: int) -> str:
    """Directory name of the study of a row label (``hidden`` in the matrix rows) and seed."""
    return f"{label}_{int(truth_seed)}"


def matrix_cases(specs: Sequence[str | Path], truths: int, first_seed: int) -> list[MatrixCase]:
    """The studies of a matrix: every specification with ``truths`` seeds from ``first_seed``,
    ordered seed by seed.

    Raises
    ------
    ValueError
        For fewer than one truth per specification.
    """
    if truths < 1:
        raise ValueError(f"truths per hidden effect must be >= 1, got {truths}")
    kinds = []
    for path in specs:
        path = Path(path)
        spec = load_truth_spec(path)
        label = path.stem.removeprefix("hidden_")
        if spec.get("effect") is not None:
            kinds.append((label, path, "catalogue", str(spec["effect"])))
        elif spec.get("switch"):
            kinds.append((label, path, "outside", label))
        else:
            kinds.append((label, path, "nothing", label))
    # Seed by seed, so that a matrix stopped early still covers every row.
    return [
        MatrixCase(label, path, kind, hidden, first_seed + k)
        for k in range(int(truths))
        for label, path, kind, hidden in kinds
    ]


def placeholder_experiment(config: Mapping[str, Any]) -> dict[str, Any]:
    """An experiment-file mapping with every load of the study and round values.

    The workflow reads the experiment file when it is parsed, so the base directory needs
    one before any truth has run; the design runs and surrogates do not depend on it.
    """
    cell = config["shear_cell"]
    loads = [(float(s), float(p)) for s in cell["normal_stresses"] for p in cell["P"]]
    loads += [(float(h["normal_stress"]), float(h["P"])) for h in config["discrepancy"]["held_out"]]
    return {
        "material": "placeholder (replaced by each study's truth)",
        "source": "none",
        "shear_cell": [
            {"normal_stress": s, "P": p, "mu_psh": 0.6, "mu_sh": 0.5, "rho_b": 1500.0}
            for s, p in loads
        ],
    }


def prepare_base(profile_config: str | Path, base_dir: str | Path, cores: int = 2) -> Path:
    """Make the current model once: the study configuration, its design runs and surrogates.

    Parameters
    ----------
    profile_config : path
        Configuration of the scale (``config/tiny.yaml``, ``config/config.yaml``).
    base_dir : path
        Directory to create (resumable: Snakemake keeps what is done).
    cores : int
        Cores for Snakemake.

    Returns
    -------
    Path
        The base directory.
    """
    base = Path(base_dir)
    (base / "config" / "experiments").mkdir(parents=True, exist_ok=True)
    raw = yaml.safe_load(Path(profile_config).read_text()) or {}
    config = study_config(raw)
    config["experiment"] = EXPERIMENT
    path = base / "config" / "config.yaml"
    path.write_text(yaml.safe_dump(config, sort_keys=False))
    validated = validate_config(copy.deepcopy(config), str(path))
    if not (base / EXPERIMENT).is_file():
        placeholder = placeholder_experiment(validated)
        (base / EXPERIMENT).write_text(yaml.safe_dump(placeholder, sort_keys=False))
    outputs = ("mu_psh", "mu_sh", "rho_b")
    targets = [f"results/surrogates/{o}/model.pt" for o in outputs]
    run_snakemake(base, cores, base / "base.log", *targets)
    return base


def run_case(
    case: MatrixCase,
    base_dir: str | Path,
    out_dir: str | Path,
    truth_engine: str | None,
    noise: Mapping[str, float] | None = None,
    replicates: int = 3,
    cores: int = 2,
) -> dict[str, Any]:
    """Run one blind study (resumable) and return its row of the matrix.

    The base directory is copied into ``out_dir/<case.name>``; the truth is drawn, run on
    ``truth_engine`` and written as the study's experiment (kept when it exists); then
    ``snakemake discrepancy`` runs.
    """
    work = Path(out_dir) / case.name
    if not (work / "config" / "config.yaml").is_file():
        shutil.copytree(base_dir, work, dirs_exist_ok=True, symlinks=True)
    if not (work / "truth.yaml").is_file():
        raw = yaml.safe_load((work / "config" / "config.yaml").read_text())
        validated = validate_config(raw, str(work / "config" / "config.yaml"))
        _, truth = write_hidden_effect_experiment(
            case.spec,
            validated,
            work / EXPERIMENT,
            work / "truth_runs",
            noise,
            case.truth_seed,
            workers=cores,
            replicates=replicates,
            truth_seed=case.truth_seed,
            truth_engine=truth_engine,
        )
        shutil.rmtree(work / "truth_runs")
        write_truth(work, truth)
    run_snakemake(work, cores, work / "discrepancy.log", "discrepancy")
    return study_outcome(case, work)


def study_outcome(case: MatrixCase, work: str | Path) -> dict[str, Any]:
    """The matrix row of a finished study: truth, outcome, gaps and the magnitude found."""
    work = Path(work)
    out = work / "results" / "discrepancy"
    summary = json.loads((out / "summary.json").read_text())
    truth = yaml.safe_load((work / "truth.yaml").read_text())
    ranking = json.loads((out / "ranking.json").read_text())
    # The top candidate and the runner-up when the naming could not tell them apart.
    pair = tuple(sorted(ranking.get("ambiguous") or ()))
    if not summary["missing"]:
        outcome = NOTHING
    elif summary.get("winner"):
        outcome = summary["winner"]
    elif pair:
        outcome = f"{AMBIGUOUS}: {pair[0]} / {pair[1]}"
    else:
        outcome = NOT_EXPLAINED
    verdict = _dem_verdict(summary, out)
    find = json.loads((out / "find.json").read_text())
    magnitude = summary.get("magnitude")
    truth_magnitude = truth.get("magnitude")
    ratio = math.nan
    if outcome == case.hidden and magnitude is not None and truth_magnitude:
        ratio = float(magnitude) / float(truth_magnitude)
    nan = math.nan
    return {
        "hidden": case.label,
        "kind": case.kind,
        "truth_seed": case.truth_seed,
        "truth_friction": truth["parameters"].get("coefficientFriction", nan),
        "truth_magnitude": truth_magnitude if truth_magnitude is not None else nan,
        "outcome": outcome,
        "correct": _correct(case, outcome, verdict),
        "dem_verdict": verdict,
        "shortlisted": case.kind == "catalogue" and (outcome == case.hidden or case.hidden in pair),
        "p_find": summary["p_value"],
        "p_effect": ranking.get("p_effect", nan) if ranking.get("ran", True) else nan,
        "p_runner_up": ranking.get("p_runner_up", nan) if ranking.get("ran", True) else nan,
        "gap_before": summary["gap_before"],
        "gap_after": summary.get("gap_after", nan),
        "dem_gap_before": summary.get("dem_gap_before", nan),
        "dem_gap_after": summary.get("dem_gap_after", nan),
        "held_out_dem_gap_before": summary.get("held_out_dem_gap_before", nan),
        "held_out_dem_gap_after": summary.get("held_out_dem_gap_after", nan),
        "magnitude": magnitude if magnitude is not None else nan,
        "magnitude_ratio": ratio,
        "power_at_truth": (
            power_at(ranking.get("power") or [], case.hidden, float(truth_magnitude))
            if case.kind == "catalogue" and truth_magnitude is not None
            else nan
        ),
        "pinned": pinned_text(find.get("pinned") or {}),
    }


def power_at(power: Sequence[Mapping[str, Any]], candidate: str, magnitude: float) -> float:
    """Naming power of ``candidate`` at ``magnitude`` from a ranking record's ``power`` rows.

    Linear between the probe levels and held at the end ones (as the response is); NaN when the
    record has no power for the candidate (the ranking did not run, or not with it).
    """
    rows = sorted(
        (float(r["magnitude"]), float(r["named"])) for r in power if r["candidate"] == candidate
    )
    if not rows:
        return math.nan
    levels, shares = zip(*rows, strict=True)
    return float(np.interp(magnitude, levels, shares))


def twin_signal(study: str | Path, twin: str | Path) -> float:
    """How far a hidden effect moves the measurements: the difference to its nothing-hidden twin.

    The twin is the study with nothing hidden and the same truth seed: the same drawn
    parameters, the same insertion seeds of its truth runs and the same noise draws, so the
    difference of the two studies' measured values is the effect (on the truth engine, not on
    the model under calibration) plus the replicate scatter of both. It needs no probe run and
    is known whatever the workflow said.

    Parameters
    ----------
    study, twin : path
        Study directories (``config/experiments/measured.yaml`` and ``truth.yaml`` inside).

    Returns
    -------
    float
        sqrt(mean(((y - y_twin) / sd)^2)) over the values both measured, sd the study's
        measurement sd (-); NaN when the studies' drawn parameters differ (not twins) or they
        share no measured value. Below :data:`VISIBLE_SIGNAL` the data do not show the effect
        beyond what two samples of one material differ by; above it the effect is in the data,
        though a change of the refitted parameters may still mimic it.
    """
    study, twin = Path(study), Path(twin)
    mine = yaml.safe_load((study / "truth.yaml").read_text())
    other = yaml.safe_load((twin / "truth.yaml").read_text())
    # The hidden effect's own parameters (drawn in the study only, e.g. a rolling friction the
    # twin holds at 0) differ by design; every other parameter must match.
    effect = set(mine.get("drawn") or {}) - set(other.get("drawn") or {})
    shared = (set(mine["parameters"]) & set(other["parameters"])) - effect
    if any(float(mine["parameters"][k]) != float(other["parameters"][k]) for k in shared):
        return math.nan
    keys = ["observable", "normal_stress", "P"]
    unit_error = dict.fromkeys(OBSERVABLES, 0.0)

    def table(path: Path) -> pd.DataFrame:
        return observation_table(load_experiment(path / EXPERIMENT), unit_error, 1.0)

    both = table(study).merge(table(twin), on=keys, suffixes=("", "_twin"))
    if not len(both):
        return math.nan
    z = (both["measured"] - both["measured_twin"]) / both["measured_sd"]
    return float(np.sqrt(np.mean(np.square(z))))


def with_signal(rows: pd.DataFrame, out_dir: str | Path) -> pd.DataFrame:
    """The matrix rows with a ``signal`` column (:func:`twin_signal`) for every study that has
    a finished nothing-hidden twin in ``out_dir``; NaN for the others and the null studies."""
    out_dir = Path(out_dir)
    # A row's ``hidden`` is its case label, which names the study directory.
    twins = {
        int(r.truth_seed): out_dir / study_name(r.hidden, r.truth_seed)
        for r in rows.itertuples()
        if r.kind == "nothing"
    }
    signal = []
    for r in rows.itertuples():
        twin = twins.get(int(r.truth_seed))
        study = out_dir / study_name(r.hidden, r.truth_seed)
        found = r.kind != "nothing" and twin is not None and study.is_dir()
        signal.append(twin_signal(study, twin) if found else math.nan)
    return rows.assign(signal=signal)


def pinned_text(pinned: Mapping[str, str]) -> str:
    """Find's parameters at a bound of the box, as ``"coefficientFriction lower"`` ("" if none).

    A best fit on the boundary is the current model straining for data it cannot reach; the
    matrix reports it per study because it is the first sign of an effect the model lacks.
    """
    return "; ".join(f"{name} {side}" for name, side in sorted(pinned.items()))


def _correct(case: MatrixCase, outcome: str, verdict: str | None) -> bool:
    if case.kind == "catalogue":
        return outcome == case.hidden
    if case.kind == "nothing":
        return outcome == NOTHING
    # Outside the catalogue: not explained (ambiguous included), nothing visible, or a proxy
    # whose DEM runs do not show it explaining the data (not closer, or a gap left above noise).
    if outcome in (NOT_EXPLAINED, NOTHING) or outcome.startswith(AMBIGUOUS):
        return True
    return verdict is not None and verdict != CONFIRMED


def _dem_verdict(summary: Mapping[str, Any], out: Path) -> str | None:
    """The DEM check's verdict on the added effect (None when none was added).

    Derived from the study's gaps, with the number of fitted values from its
    ``gap_before_after.csv`` where the summary does not give it, so that studies run before
    the verdict had three outcomes are scored alike.
    """
    if "dem_gap_after" not in summary:
        return None
    n = summary.get("dem_values")
    if n is None:
        n = fitted_dem_values(pd.read_csv(out / "gap_before_after.csv"))
    nan = math.nan
    return effect_verdict(
        float(summary.get("dem_gap_before", nan)),
        float(summary.get("dem_gap_after", nan)),
        float(summary.get("held_out_dem_gap_before", nan)),
        float(summary.get("held_out_dem_gap_after", nan)),
        int(n),
        float(summary["alpha"]),
    )


def confusion_matrix(rows: pd.DataFrame) -> pd.DataFrame:
    """Counts of outcome (columns) per hidden effect (rows), in first-seen order."""
    hidden = list(dict.fromkeys(rows["hidden"]))
    seen = list(dict.fromkeys(rows["outcome"]))
    ambiguous = sorted(o for o in seen if o.startswith(AMBIGUOUS))
    named = [o for o in seen if o not in (NOTHING, NOT_EXPLAINED, *ambiguous)]
    order = named + ambiguous + [o for o in (NOTHING, NOT_EXPLAINED) if o in seen]
    table = pd.crosstab(rows["hidden"], rows["outcome"]).reindex(
        index=hidden, columns=order, fill_value=0
    )
    table.index.name = "hidden \\ outcome"
    return table


def matrix_scores(rows: pd.DataFrame) -> dict[str, Any]:
    """Naming accuracy (catalogue rows), false-alarm rate (nothing hidden) and the outside
    effect's share of acceptable outcomes, each with its count."""

    def share(kind: str, values: pd.Series | None = None) -> tuple[float, int]:
        mine = rows[rows["kind"] == kind]
        if not len(mine):
            return math.nan, 0
        hits = mine["correct"] if values is None else values.loc[mine.index]
        return float(hits.mean()), len(mine)

    accuracy, n_catalogue = share("catalogue")
    shortlist = (
        share("catalogue", rows["shortlisted"].astype(bool))[0]
        if "shortlisted" in rows
        else math.nan
    )
    false_alarm, n_nothing = share("nothing", rows["outcome"] != NOTHING)
    outside, n_outside = share("outside")
    # Catalogue studies whose ranking ran, and of those the ones whose data could name the
    # hidden effect at its truth; the accuracy that any method could reach is on the latter.
    ranked, nameable = _catalogue_at_least(rows, "power_at_truth", UNNAMEABLE)
    # Catalogue studies whose hidden effect moved the measurements beyond their error, judged
    # on the truth engine's data against the nothing-hidden twin (no probe, no model).
    measured, visible = _catalogue_at_least(rows, "signal", VISIBLE_SIGNAL)
    return {
        "naming_accuracy": accuracy,
        "catalogue_studies": n_catalogue,
        "ranked_studies": len(ranked),
        "nameable_studies": len(nameable),
        "nameable_accuracy": float(nameable["correct"].mean()) if len(nameable) else math.nan,
        "signal_studies": len(measured),
        "visible_studies": len(visible),
        "visible_accuracy": float(visible["correct"].mean()) if len(visible) else math.nan,
        "shortlist_accuracy": shortlist,
        "false_alarm_rate": false_alarm,
        "null_studies": n_nothing,
        "outside_acceptable": outside,
        "outside_studies": n_outside,
    }


def _catalogue_at_least(
    rows: pd.DataFrame, column: str, threshold: float
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The catalogue rows with a value in ``column``, and those of them at ``threshold`` or
    above (both empty when the column is missing)."""
    values = rows[column] if column in rows else pd.Series(math.nan, rows.index)
    known = rows[(rows["kind"] == "catalogue") & values.notna()]
    return known, known[values.loc[known.index] >= threshold]


def _confirmation_line(rows: pd.DataFrame) -> str:
    """The DEM check's verdicts on right and wrong namings of catalogue effects."""
    if "dem_verdict" not in rows:
        return "-"
    named = rows[(rows["kind"] == "catalogue") & rows["dem_verdict"].notna()]
    right = named[named["correct"].astype(bool)]
    wrong = named[~named["correct"].astype(bool)]

    def count(part: pd.DataFrame) -> str:
        verdicts = part["dem_verdict"].value_counts()
        found = ", ".join(f"{int(verdicts[v])} {v}" for v in verdicts.index)
        return f"{len(part)} ({found})" if len(part) else "0"

    return f"right namings {count(right)}; wrong namings {count(wrong)}"


def _signal_line(rows: pd.DataFrame) -> str:
    """Range of the twin signal per hidden effect (studies with a twin only)."""
    if "signal" not in rows:
        return "-"
    parts = []
    for label, group in rows.groupby("hidden", sort=False):
        values = group["signal"].dropna()
        if len(values):
            parts.append(f"{label} {values.min():.2g}-{values.max():.2g}")
    return "; ".join(parts) or "-"


def _pinned_line(rows: pd.DataFrame) -> str:
    """Studies whose Find best fit sits on the box boundary, per hidden effect."""
    if "pinned" not in rows:
        return "-"
    pinned = rows["pinned"].fillna("").astype(str) != ""
    parts = [
        f"{label} {int(pinned[group.index].sum())} of {len(group)}"
        for label, group in rows.groupby("hidden", sort=False)
    ]
    return "; ".join(parts)


def matrix_markdown(rows: pd.DataFrame, title: str, command: str) -> str:
    """The matrix report: scores, confusion matrix and one line per study."""
    scores = matrix_scores(rows)
    confusion = confusion_matrix(rows).reset_index()

    def pct(value: float) -> str:
        return "-" if not math.isfinite(value) else f"{100 * value:.0f} %"

    lines = [
        f"# {title}",
        "",
        f"Made with `{command}`.",
        "",
        f"- Right effect named: {pct(scores['naming_accuracy'])} of "
        f"{scores['catalogue_studies']} studies with a hidden catalogue effect (goal 90 %); "
        f"named or one of two the data could not tell apart: {pct(scores['shortlist_accuracy'])}.",
        f"- Of the {scores['ranked_studies']} catalogue studies that reached the naming step, "
        f"the data could name the hidden effect at its truth (naming power at least "
        f"{100 * UNNAMEABLE:.0f} % from the study's probe runs) in {scores['nameable_studies']}; "
        f"of those named right: {pct(scores['nameable_accuracy'])}.",
        f"- Of the {scores['signal_studies']} catalogue studies with a nothing-hidden twin, the "
        f"hidden effect moved the measurements by at least {VISIBLE_SIGNAL:g} measurement sd "
        f"(rms of the difference to the twin) in {scores['visible_studies']}; of those named "
        f"right: {pct(scores['visible_accuracy'])}. Signal per hidden effect: "
        f"{_signal_line(rows)}.",
        f"- False alarms with nothing hidden: {pct(scores['false_alarm_rate'])} of "
        f"{scores['null_studies']} (goal at most 5 %).",
        f"- Effect outside the catalogue: {pct(scores['outside_acceptable'])} of "
        f"{scores['outside_studies']} acceptable (nothing missing, not explained, or a proxy "
        "that the DEM runs do not confirm or that leaves a DEM gap above the noise).",
        f"- DEM verdicts on named catalogue effects: {_confirmation_line(rows)}.",
        f"- Find's best fit on the boundary of the box: {_pinned_line(rows)}.",
        "",
        "Confusion matrix (studies per hidden effect and outcome):",
        "",
        markdown_table(confusion, ".3g"),
        "Studies (gaps are sqrt(mean z^2); DEM gaps are the mean of the replicate runs, the "
        "held-out ones at the load no step fitted):",
        "",
        markdown_table(rows.reindex(columns=list(REPORT_COLUMNS)), ".3g"),
    ]
    return "\n".join(lines)
