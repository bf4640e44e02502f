"""Rounds of a sequential calibration: which cases each round runs, its dataset, its record and
the stopping rule.

Round 0 runs the design section's ``n`` sets (ids ``c0001 ... c<n>``); round r >= 1 runs
``sequential.batch`` new sets whose ids continue the numbering, so every case id of the study is
known before any round has run and only the values of a round's sets wait for the round before.
After each round the surrogates are retrained on all runs so far and the candidate grid is
screened; the identified mean set is verified by DEM (``verification.seeds`` replicates), and
those runs join the data of the next round.

Stopping rule: stop after round r when

- the verification matches every measured value within ``screening.tolerance`` and the volume of
  the valid box (5-95 % quantiles per parameter, relative to the design box) changed by less
  than ``sequential.shrink_tolerance`` since round r - 1 ("verified"), or
- round r + 1 would exceed ``sequential.max_rounds`` ("max_rounds"), or
- the DEM runs so far plus those of one more round (its sets and a verification) would exceed
  ``sequential.budget`` ("budget").

A verified round names the values whose replicate runs' mean is within the tolerance while the
interval of that mean (``CONFIDENCE`` of :mod:`demcal.identification.verification_run`) crosses
an edge of the band (``undecided``): the stop may rest on a lucky draw. They do not hold the
study back: the next round would verify another set, so only more verification runs at this set
decide them.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from demcal.bulk.dataset import collect
from demcal.design.cases import (
    design_replicates,
    shear_suffixes,
    verification_case_ids,
    with_replicates,
)
from demcal.identification.verification_run import CONFIDENCE, undecided

#: Quantiles of the valid sets that bound the valid box per parameter.
BOX_QUANTILES = (0.05, 0.95)
#: Suffix that marks a verification run of round r in the dataset.
VERIFICATION_MARK = "@round"


def check_sequential(config: Mapping[str, Any]) -> None:
    """Reject a sequential study the rounds cannot run, naming the configuration key.

    Raises
    ------
    ValueError
        When ``design.kind`` is not a sampled design or the design draws ``choices``.
    """
    design = config["design"]
    if design["kind"] == "factorial":
        raise ValueError(
            "sequential.enabled: round 0 needs a sampled design (design.kind lhs, sobol or "
            "random with design.ranges); a factorial design has no box to draw the rounds in"
        )
    if design.get("choices"):
        raise ValueError(
            "sequential.enabled: design.choices cannot be drawn by the rounds; move those "
            "parameters to design.ranges or design.fixed"
        )


def design_ranges(config: Mapping[str, Any]) -> dict[str, list[float]]:
    """The design box: parameter -> [low, high] (``design.ranges``)."""
    return {k: [float(v[0]), float(v[1])] for k, v in config["design"]["ranges"].items()}


def round_of_case(config: Mapping[str, Any], base: str) -> int:
    """The round that runs design set ``base`` (``c0001`` ...)."""
    number = int(base.lstrip("c"))
    first = int(config["design"]["n"])
    if number <= first:
        return 0
    return 1 + (number - first - 1) // int(config["sequential"]["batch"])


def round_bases(config: Mapping[str, Any], round_no: int) -> list[str]:
    """Ids of the parameter sets of round ``round_no``."""
    first, batch = int(config["design"]["n"]), int(config["sequential"]["batch"])
    last = first + (int(config["sequential"]["max_rounds"]) - 1) * batch
    width = max(4, len(str(last)))
    start, count = (0, first) if round_no == 0 else (first + (round_no - 1) * batch, batch)
    return [f"c{i:0{width}d}" for i in range(start + 1, start + count + 1)]


def round_case_ids(config: Mapping[str, Any], round_no: int, test: str) -> list[str]:
    """Case ids (``c0009`` or ``c0009_s1_p2``, and their replicates) of one test in round
    ``round_no``."""
    bases = round_bases(config, round_no)
    if test == "angle_of_repose":
        return with_replicates(config, bases)
    return with_replicates(config, bases, shear_suffixes(config))


def runs_per_set(config: Mapping[str, Any]) -> int:
    """DEM runs of one parameter set: each shear-cell deck ``design.replicates`` times, the
    heap ``design.repose_replicates`` times."""
    shear = len(shear_suffixes(config)) * design_replicates(config)
    return shear + design_replicates(config, "angle_of_repose")


def verification_runs(config: Mapping[str, Any]) -> int:
    """DEM runs of one verification (every replicate of every deck, the heaps counted apart)."""
    return sum(len(verification_case_ids(config, t)) for t in ("shear_cell", "angle_of_repose"))


def round_dataset(
    new_bulk: Iterable[str | Path],
    previous: str | Path | None,
    verification_bulk: Iterable[str | Path],
    previous_round: int,
) -> pd.DataFrame:
    """The DEM data after one round: earlier data, the earlier round's verification runs and the
    round's own cases.

    Parameters
    ----------
    new_bulk : iterable of path
        ``bulk.csv`` of every case of the round.
    previous : path or None
        The dataset after the previous round (None for round 0).
    verification_bulk : iterable of path
        ``bulk.csv`` of the previous round's verification runs (empty when it identified
        nothing). Their case ids get ``@round<r>`` and their parameter set one ``design_id``.
    previous_round : int
        Number of the previous round (names the verification runs).

    Returns
    -------
    pandas.DataFrame
        The tidy dataset (:func:`demcal.bulk.dataset.collect`).
    """
    frames = [pd.read_csv(path) for path in new_bulk]
    if previous is not None:
        frames.insert(0, pd.read_csv(previous))
    mark = f"{VERIFICATION_MARK}{previous_round}"
    for path in verification_bulk:
        rows = pd.read_csv(path)
        rows["case_id"] = rows["case_id"].astype(str) + mark
        rows["design_id"] = f"identified{mark}"
        frames.append(rows)
    return collect(frames)


def valid_box(valid: pd.DataFrame, ranges: Mapping[str, Sequence[float]]) -> dict[str, list]:
    """Per parameter the 5-95 % quantile range of the valid sets, scaled to the design box.

    Returns
    -------
    dict of str to [float, float]
        Parameter -> [low, high] in [0, 1]; empty when there is no valid set.
    """
    if valid is None or not len(valid):
        return {}
    box = {}
    for name, (lo, hi) in ranges.items():
        q = np.quantile(valid[name].to_numpy(dtype=float), BOX_QUANTILES)
        box[name] = [float((q[0] - lo) / (hi - lo)), float((q[1] - lo) / (hi - lo))]
    return box


def box_volume(box: Mapping[str, Sequence[float]]) -> float:
    """Volume of a valid box in the unit design cube (0 when empty)."""
    if not box:
        return 0.0
    return float(np.prod([max(hi - lo, 0.0) for lo, hi in box.values()]))


def verification_label(row: Mapping[str, Any]) -> str:
    """Name of one measured value in the round records: ``mu_psh@2029Pa,P=1`` or ``aor``."""
    label = str(row["observable"])
    if not pd.isna(row["normal_stress"]):
        label += f"@{row['normal_stress']:g}Pa,P={row['P']:g}"
    return label


def round_record(
    round_no: int,
    config: Mapping[str, Any],
    identified: Mapping[str, Any],
    valid: pd.DataFrame | None,
    verification: pd.DataFrame | None,
    surrogates: Mapping[str, Mapping[str, float]],
    previous: Mapping[str, Any] | None,
) -> dict[str, Any]:
    """The record of one round with the stopping decision (rule in the module docstring).

    Parameters
    ----------
    round_no : int
        The round.
    config : mapping
        The validated configuration.
    identified : mapping
        The round's identified-set record (``identified_parameters.json``).
    valid : DataFrame or None
        The valid sets of the identified group.
    verification : DataFrame or None
        The round's verification table (one engine, column suffix ``configured``), None when
        nothing was identified.
    surrogates : mapping
        Bulk value -> quality of the round's network (``test_r2``, ``cv_r2``, ...).
    previous : mapping or None
        The record of round ``round_no - 1``.

    Returns
    -------
    dict
        ``round``, ``sets``, ``runs``, ``runs_total``, ``group``, ``n_valid``, ``box``,
        ``volume``, ``volume_change``, ``settled``, ``verification`` (per observable: dem,
        measured, deviation), ``verified``, ``undecided`` (labels of the values whose
        verification is undecided, module docstring), ``surrogates``, ``stop`` and ``reason``.
    """
    seq = config["sequential"]
    tol = float(config["screening"]["tolerance"])
    ranges = design_ranges(config)
    sets = len(round_bases(config, round_no))
    runs = sets * runs_per_set(config)
    checked: dict[str, dict[str, float]] = {}
    verified = False
    unsure: list[str] = []
    if verification is not None and len(verification):
        runs += verification_runs(config)
        for _, row in verification.iterrows():
            checked[verification_label(row)] = {
                "dem": float(row["dem_configured"]),
                "measured": float(row["measured"]),
                "deviation": float(row["deviation_configured"]),
            }
        verified = bool(verification["within_tolerance_configured"].all())
        unsure = [
            verification_label(row)
            for _, row in verification.iterrows()
            if undecided(row, "configured", tol)
        ]
    total = runs + (int(previous["runs_total"]) if previous else 0)
    box = valid_box(valid, ranges) if valid is not None else {}
    volume = box_volume(box)
    before = float(previous["volume"]) if previous else 0.0
    change = abs(volume - before) / before if before > 0 else math.inf
    settled = bool(box) and change < float(seq["shrink_tolerance"])
    next_cost = int(seq["batch"]) * runs_per_set(config) + verification_runs(config)
    caveat = (
        f"; undecided at {CONFIDENCE:.0%} confidence: {', '.join(unsure)} (more "
        "verification runs at this set would tell)"
        if verified and unsure
        else ""
    )
    if verified and settled:
        stop, reason = (
            True,
            (
                f"verified: every measured value within {tol:.0%} by DEM and the valid box changed "
                f"by {change:.0%} (< {float(seq['shrink_tolerance']):.0%}){caveat}"
            ),
        )
    elif round_no + 1 >= int(seq["max_rounds"]):
        stop, reason = True, f"max_rounds: {seq['max_rounds']} rounds run"
    elif total + next_cost > int(seq["budget"]):
        stop, reason = (
            True,
            (
                f"budget: {total} DEM runs used, one more round needs {next_cost}, budget "
                f"{seq['budget']}"
            ),
        )
    else:
        stop, reason = (
            False,
            (f"verified, valid box still changing{caveat}" if verified else "continue"),
        )
    return {
        "round": round_no,
        "sets": sets,
        "runs": runs,
        "runs_total": total,
        "group": identified.get("group", ""),
        "n_valid": int((identified.get("n_valid") or {}).get(identified.get("group", ""), 0)),
        "box": box,
        "volume": volume,
        "volume_change": None if math.isinf(change) else change,
        "settled": settled,
        "verification": checked,
        "verified": verified,
        "undecided": unsure,
        "surrogates": {k: dict(v) for k, v in surrogates.items()},
        "stop": stop,
        "reason": reason,
    }


def rounds_table(records: Sequence[Mapping[str, Any]]) -> pd.DataFrame:
    """One row per round: sets, runs, valid sets, box volume, verification and surrogates."""
    rows = []
    for rec in records:
        row = {
            "round": rec["round"],
            "sets": rec["sets"],
            "runs": rec["runs"],
            "runs_total": rec["runs_total"],
            "group": rec["group"],
            "n_valid": rec["n_valid"],
            "box_volume": rec["volume"],
            "volume_change": rec["volume_change"],
            "verified": rec["verified"],
            "undecided": ", ".join(rec.get("undecided", [])),
            "worst_deviation": max(
                (v["deviation"] for v in rec["verification"].values()), default=math.nan
            ),
            "stop": rec["stop"],
            "reason": rec["reason"],
        }
        for output, quality in rec["surrogates"].items():
            for key, value in quality.items():
                row[f"{output}_{key}"] = value
        rows.append(row)
    return pd.DataFrame(rows)
