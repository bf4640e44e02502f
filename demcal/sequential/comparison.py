"""Sequential against one-shot calibration: DEM runs spent and error of the identified set.

A comparison row is one identified set: the design that led to it (``sequential`` after one of
its rounds, or ``one-shot`` with a budget), the DEM runs spent on it (every engine execution,
its verification included), the error of its mean set against the truth per parameter (as a
fraction of the design range, since the parameters have different units) and its error against
the measurements per bulk value by DEM verification (``|1 - dem / measured|``, the deviation
the verification table reports). A ``truth`` row runs the true parameters like a verification
on the engine under calibration: the error no calibration can go below.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from demcal.core.experiments import Experiment
from demcal.design.cases import design_id
from demcal.identification.verification import verification_table
from demcal.sequential.rounds import (
    design_ranges,
    runs_per_set,
    verification_label,
    verification_runs,
)


def oneshot_sets(config: Mapping[str, Any], budget: int) -> int:
    """Parameter sets of a one-shot design whose runs and one verification fit ``budget``.

    Parameters
    ----------
    config : mapping
        The validated configuration (shear-cell decks per set, verification seeds).
    budget : int
        DEM runs allowed.

    Raises
    ------
    ValueError
        When the budget leaves fewer than 3 sets (too few to train on).
    """
    n = (int(budget) - verification_runs(config)) // runs_per_set(config)
    if n < 3:
        raise ValueError(
            f"a budget of {budget} DEM runs leaves {n} parameter sets after the verification "
            f"({verification_runs(config)} runs); at least 3 are needed"
        )
    return n


def reuse_cases(source: str | Path, target: str | Path) -> None:
    """Copy the finished DEM cases of the same nested design that the target's design holds.

    Only cases of the target's design table are copied (a case directory is named after its
    ``case_id``, with a ``_s<n>`` suffix per shear-cell deck). The copies are stamped in the
    order of the rules (deck, then run status, then bulk values) so that Snakemake sees them as
    made from the target's design table, not as outdated.

    Parameters
    ----------
    source, target : path
        Study directories of the same configuration; the target's design table exists.
    """
    source, target = Path(source), Path(target)
    cases = source / "results" / "cases"
    if not cases.is_dir():
        return
    wanted = set(pd.read_csv(target / "results" / "design" / "cases.csv")["case_id"])
    now = time.time()
    for case in cases.glob("*/*"):
        if design_id(case.name) not in wanted:
            continue
        dest = target / "results" / "cases" / case.parent.name / case.name
        shutil.copytree(case, dest, dirs_exist_ok=True)
        for path in dest.rglob("*"):
            if path.is_file():
                later = {"status.json": 1.0, "bulk.csv": 2.0}.get(path.name, 0.0)
                os.utime(path, (now + later, now + later))


def parameter_errors(
    identified: Mapping[str, Any],
    truth: Mapping[str, float],
    ranges: Mapping[str, Sequence[float]],
) -> dict[str, float]:
    """Error of the identified mean set per design parameter, as a fraction of its range.

    Parameters
    ----------
    identified : mapping
        An identified-set record (``identified_parameters.json``): ``parameters`` maps each
        name to a mapping with its ``mean``.
    truth : mapping
        True value per parameter (SI units).
    ranges : mapping
        Design range [low, high] per parameter.

    Returns
    -------
    dict
        Parameter -> ``|mean - truth| / (high - low)``; NaN when nothing was identified.
    """
    found = identified.get("parameters") or {}
    out = {}
    for name, (low, high) in ranges.items():
        if name not in truth:
            continue
        mean = (found.get(name) or {}).get("mean")
        out[name] = (
            math.nan if mean is None else abs(float(mean) - float(truth[name])) / (high - low)
        )
    return out


def verification_deviations(table: pd.DataFrame, engine: str = "configured") -> dict[str, float]:
    """Deviation of the DEM verification from each measured value.

    Parameters
    ----------
    table : DataFrame
        The verification table (``verification.csv``): ``observable``, ``normal_stress``, ``P``
        and ``deviation_<engine>``.
    engine : str
        Column suffix of the engine.

    Returns
    -------
    dict
        :func:`~demcal.sequential.rounds.verification_label` -> ``|1 - dem / measured|``, the
        labels of the round records.
    """
    out = {}
    for _, row in table.iterrows():
        out[verification_label(row)] = float(row[f"deviation_{engine}"])
    return out


def truth_row(
    material: str,
    bulk: pd.DataFrame,
    experiment: Experiment,
    truth: Mapping[str, float],
    ranges: Mapping[str, Sequence[float]],
    tolerance: float,
    label: str,
) -> dict[str, Any]:
    """The row of the truth itself run on the engine under calibration: the floor of the error.

    A calibration cannot beat the deviation the true parameters show when they are run like a
    verification (same engine, same number of seeds) against measurements made on the reference
    code: seed scatter on both sides and any difference between the codes. The runs are judged
    by the verification table of an identified set.

    Parameters
    ----------
    material : str
        Name of the synthetic material.
    bulk : DataFrame
        Bulk rows of the runs at the truth (tidy layout of ``demcal.bulk.dataset``, column
        ``case_id``: one engine execution per case).
    experiment : Experiment
        The measurements.
    truth, ranges, tolerance, label
        As in :func:`comparison_row`.
    """
    table = verification_table({"configured": bulk}, experiment, tolerance)
    identified = {"parameters": {k: {"mean": float(v)} for k, v in truth.items()}}
    return comparison_row(
        material,
        "truth",
        int(bulk["case_id"].nunique()),
        identified,
        verification_deviations(table),
        truth,
        ranges,
        tolerance,
        label,
    )


def comparison_row(
    material: str,
    design: str,
    runs: int,
    identified: Mapping[str, Any],
    deviations: Mapping[str, float],
    truth: Mapping[str, float],
    ranges: Mapping[str, Sequence[float]],
    tolerance: float,
    label: str = "",
) -> dict[str, Any]:
    """One row of the comparison table.

    Parameters
    ----------
    material : str
        Name of the synthetic material.
    design : str
        ``sequential``, ``one-shot`` or ``truth``.
    runs : int
        DEM runs spent, the verification included.
    identified, truth, ranges
        As in :func:`parameter_errors`.
    deviations : mapping
        :func:`verification_deviations` (empty when nothing was identified).
    tolerance : float
        The acceptance tolerance (fraction).
    label : str
        Where the set comes from (``round 2``, ``22 sets``).

    Returns
    -------
    dict
        ``material``, ``design``, ``label``, ``runs``, ``error_<parameter>``,
        ``max_parameter_error``, ``worst_bulk_deviation``, ``worst_bulk_value``,
        ``median_bulk_deviation``, ``share_within`` (the fraction of measured values within
        ``tolerance`` by DEM) and ``within`` (every one of them).
    """
    errors = parameter_errors(identified, truth, ranges)
    worst = max(deviations, key=lambda k: deviations[k]) if deviations else ""
    row: dict[str, Any] = {"material": material, "design": design, "label": label, "runs": runs}
    row.update({f"error_{k}": v for k, v in errors.items()})
    finite = [v for v in errors.values() if not math.isnan(v)]
    row["max_parameter_error"] = max(finite) if len(finite) == len(errors) else math.nan
    row["worst_bulk_deviation"] = deviations[worst] if worst else math.nan
    row["worst_bulk_value"] = worst
    values = sorted(deviations.values())
    row["median_bulk_deviation"] = float(np.median(values)) if values else math.nan
    row["share_within"] = sum(v < tolerance for v in values) / len(values) if values else math.nan
    row["within"] = bool(deviations) and all(v < tolerance for v in deviations.values())
    return row


def sequential_rows(
    study: str | Path,
    material: str,
    truth: Mapping[str, float],
    ranges: Mapping[str, Sequence[float]],
    tolerance: float,
) -> list[dict[str, Any]]:
    """One row per finished round of a sequential study directory.

    Each round's identified set is verified by DEM in that round, so every round is a point of
    the error against the DEM runs spent up to it.
    """
    rows = []
    seq = Path(study) / "results" / "sequential"
    r = 0
    while (seq / f"round_{r}" / "state.json").is_file():
        state = json.loads((seq / f"round_{r}" / "state.json").read_text())
        identified = json.loads(
            (seq / f"round_{r}" / "identification" / "identified_parameters.json").read_text()
        )
        deviations = {k: float(v["deviation"]) for k, v in state["verification"].items()}
        rows.append(
            comparison_row(
                material,
                "sequential",
                int(state["runs_total"]),
                identified,
                deviations,
                truth,
                ranges,
                tolerance,
                f"round {r}",
            )
        )
        r += 1
    return rows


def oneshot_row(
    study: str | Path,
    material: str,
    config: Mapping[str, Any],
    truth: Mapping[str, float],
) -> dict[str, Any]:
    """The row of a finished one-shot study directory (identification and verification).

    Its DEM runs are the design's sets times the runs per set, plus the verification's when a
    set was identified (nothing is verified otherwise).
    """
    results = Path(study) / "results"
    identified = json.loads((results / "identification" / "identified_parameters.json").read_text())
    sets = int(config["design"]["n"])
    runs = sets * runs_per_set(config)
    deviations: dict[str, float] = {}
    if identified.get("parameters"):
        runs += verification_runs(config)
        deviations = verification_deviations(
            pd.read_csv(results / "verification" / "verification.csv")
        )
    return comparison_row(
        material,
        "one-shot",
        runs,
        identified,
        deviations,
        truth,
        design_ranges(config),
        float(config["screening"]["tolerance"]),
        f"{sets} sets",
    )


def comparison_markdown(table: pd.DataFrame, tolerance: float, command: str) -> str:
    """The comparison as text: the rows, then per material the fewest runs within tolerance."""
    lines = [
        "# Sequential against one-shot calibration",
        "",
        f"Command: `{command}`",
        "",
        "Parameter errors are |identified mean - truth| / design range; bulk deviations are "
        "|1 - DEM / measured| of the verification runs (the worst measured value is named; "
        f"`share_within`: the fraction within {tolerance:.0%}). `within`: every measured value "
        f"within {tolerance:.0%} by DEM.",
        "",
    ]
    shown = table.copy()
    for column in shown.columns:
        if column.startswith("error_") or column in (
            "max_parameter_error",
            "worst_bulk_deviation",
            "median_bulk_deviation",
            "share_within",
        ):
            shown[column] = shown[column].map(lambda v: "-" if pd.isna(v) else f"{v:.3f}")
    lines.append(shown.to_markdown(index=False, disable_numparse=True))
    lines.append("")
    for material, rows in table.groupby("material", sort=False):
        parts = []
        for design, drows in rows[rows["design"] != "truth"].groupby("design", sort=False):
            ok = drows[drows["within"]]
            parts.append(
                f"{design}: "
                + (f"{int(ok['runs'].min())} DEM runs" if len(ok) else "not within tolerance")
                + f" (of {int(drows['runs'].max())} spent)"
            )
        lines.append(
            f"- {material}, fewest DEM runs to every value within tolerance: "
            + "; ".join(parts)
            + "."
        )
        for _, floor in rows[rows["design"] == "truth"].iterrows():
            lines.append(
                f"- {material}, the truth itself ({floor['label']}): worst deviation "
                f"{floor['worst_bulk_deviation']:.3f} ({floor['worst_bulk_value']}), "
                f"{floor['share_within']:.0%} of the values within tolerance."
            )
    return "\n".join(lines) + "\n"


def comparison_figure(table: pd.DataFrame, tolerance: float, path: str | Path) -> None:
    """Error against DEM runs for both designs, one column per material.

    Top: the worst bulk deviation by DEM verification, with the acceptance tolerance; bottom:
    the largest parameter error against the truth (fraction of the design range).
    """
    materials = list(dict.fromkeys(table["material"]))
    fig, axes = plt.subplots(2, len(materials), figsize=(4.2 * len(materials), 6.4), squeeze=False)
    styles = {"sequential": ("C0", "o-"), "one-shot": ("C3", "s--")}
    for col, material in enumerate(materials):
        rows = table[table["material"] == material]
        for design, (color, style) in styles.items():
            d = rows[rows["design"] == design].sort_values("runs")
            if not len(d):
                continue
            axes[0][col].plot(
                d["runs"], d["worst_bulk_deviation"], style, color=color, label=design
            )
            axes[1][col].plot(d["runs"], d["max_parameter_error"], style, color=color, label=design)
        axes[0][col].axhline(tolerance, color="0.5", lw=0.8, ls=":", label="tolerance")
        for _, floor in rows[rows["design"] == "truth"].iterrows():
            axes[0][col].axhline(
                floor["worst_bulk_deviation"], color="C2", lw=1.5, ls="-.", label="truth itself"
            )
        axes[0][col].set_title(material, fontsize=9)
        axes[0][col].set_ylabel("worst |1 - DEM / measured|")
        axes[1][col].set_ylabel("largest |mean - truth| / range")
        axes[1][col].set_xlabel("DEM runs")
        axes[0][col].legend(fontsize=8)
        for ax in axes[:, col]:
            ax.set_ylim(bottom=0.0)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
