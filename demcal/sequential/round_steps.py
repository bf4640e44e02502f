"""The file-level steps of one round (what the Snakemake rules of a sequential study call)."""

from __future__ import annotations

import json
import logging
import shutil
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from demcal.bulk.dataset import write_collected
from demcal.core.experiments import load_experiment
from demcal.core.provenance import write_sidecar
from demcal.design.table import design_frame, write_design_table
from demcal.identification.calibration import valid_sets_file
from demcal.identification.verification_run import write_verification_table
from demcal.sequential.figures import rounds_figure
from demcal.sequential.proposal import (
    BulkProcesses,
    draw_candidates,
    misfit_and_uncertainty,
    observables,
    propose,
)
from demcal.sequential.rounds import (
    design_ranges,
    round_bases,
    round_dataset,
    round_record,
    rounds_table,
)

_log = logging.getLogger(__name__)


def take_over(source: str | Path, target: str | Path) -> Path:
    """Copy every file beside ``source`` (a round's network or identification) to the directory
    of ``target``, sidecars and figures included; return the source directory."""
    src, dst = Path(source).parent, Path(target).parent
    dst.mkdir(parents=True, exist_ok=True)
    for item in src.iterdir():
        if item.is_file():
            shutil.copyfile(item, dst / item.name)
    return src


def _valid_sets(identified_file: str | Path) -> pd.DataFrame:
    """The valid sets of the identified group written beside ``identified_file``."""
    record = json.loads(Path(identified_file).read_text())
    group = record.get("group") or ""
    path = valid_sets_file(Path(identified_file).parent, group) if group else None
    return pd.read_csv(path) if path is not None and path.exists() else pd.DataFrame()


def write_round_dataset(
    config: Mapping[str, Any],
    round_no: int,
    new_bulk: Iterable[str | Path],
    previous: str | Path | None,
    verification_bulk: Iterable[str | Path],
    dataset: str | Path,
    failed: str | Path,
) -> pd.DataFrame:
    """Write the dataset after round ``round_no`` and its list of failed runs.

    See :func:`demcal.sequential.rounds.round_dataset` for the parameters.
    """
    data = round_dataset(new_bulk, previous, verification_bulk, round_no - 1)
    write_collected(data, dataset, failed, dict(config), extra={"round": round_no})
    return data


def write_next_design(
    config: Mapping[str, Any],
    round_no: int,
    dataset: str | Path,
    verification_bulk: Sequence[str | Path],
    identified: str | Path,
    experiment: str | Path,
    constants: Mapping[str, Mapping[str, float]],
    design: str | Path,
    choices: str | Path,
) -> pd.DataFrame:
    """Choose and write the parameter sets of round ``round_no`` (>= 1).

    Parameters
    ----------
    config : mapping
        The validated configuration.
    round_no : int
        The round to design.
    dataset : path
        The dataset after round ``round_no - 1``.
    verification_bulk : sequence of path
        ``bulk.csv`` of round ``round_no - 1``'s verification runs (may be empty).
    identified : path
        Round ``round_no - 1``'s identified-set record (valid sets beside it).
    experiment : path
        The measurements.
    constants : mapping
        Bulk value -> inputs held constant (the tests' dCylDp).
    design, choices : path
        Outputs: the round's design table (ids and parameters) and the same sets with the
        reason each was chosen, the predicted misfit and uncertainty.

    Returns
    -------
    pandas.DataFrame
        The design table.
    """
    seq = config["sequential"]
    ranges = design_ranges(config)
    data = round_dataset([], dataset, verification_bulk, round_no - 1)
    measured = observables(load_experiment(experiment))
    tol = float(config["screening"]["tolerance"])
    seed = int(seq["seed"]) + round_no
    processes = BulkProcesses(data, [o.output for o in measured], constants, seed)
    candidates = draw_candidates(ranges, int(seq["candidates"]), seed)
    misfit, uncertainty = misfit_and_uncertainty(candidates, processes, measured, tol)
    existing = data.drop_duplicates("design_id")
    chosen = propose(
        candidates,
        misfit,
        uncertainty,
        _valid_sets(identified),
        existing,
        ranges,
        int(seq["batch"]),
        float(seq["explore_fraction"]),
        float(seq["near_factor"]),
    )
    ids = round_bases(config, round_no)
    fixed = {k: float(v) for k, v in (config["design"].get("fixed") or {}).items()}
    columns = {name: chosen[name].to_numpy(dtype=float) for name in ranges}
    columns.update({k: [v] * len(ids) for k, v in fixed.items()})
    table = design_frame(ids, columns)
    write_design_table(table, design)
    write_sidecar(design, dict(config), seed=seed)
    # The reason and the process' view of each chosen set, for the report.
    chosen_unit = chosen.merge(
        candidates.assign(misfit=misfit, uncertainty=uncertainty), how="left", on=list(ranges)
    )
    chosen_unit.insert(0, "case_id", ids)
    chosen_unit.to_csv(choices, index=False, float_format="%.6g")
    _log.info(
        "round %d: %s; %d of %d candidates near the valid region",
        round_no,
        chosen["reason"].value_counts().to_dict(),
        int((misfit <= float(seq["near_factor"])).sum()),
        len(candidates),
    )
    return table


def surrogate_quality(table4_files: Mapping[str, str | Path]) -> dict[str, dict[str, float]]:
    """Bulk value -> the network's ``test_r2``, ``cv_r2`` and ``cv_rmse`` from Table 4 rows."""
    quality = {}
    for output, path in table4_files.items():
        row = pd.read_csv(path, index_col=0).loc["ANN"]
        quality[output] = {k: float(row[k]) for k in ("test_r2", "cv_r2", "cv_rmse") if k in row}
    return quality


def write_round_record(
    config: Mapping[str, Any],
    round_no: int,
    identified: str | Path,
    verification_bulk: Sequence[str | Path],
    experiment: str | Path,
    table4_files: Mapping[str, str | Path],
    previous: str | Path | None,
    record: str | Path,
    verification_table: str | Path,
) -> dict[str, Any]:
    """Verify the round's identified set, decide whether to stop and write the round record.

    Parameters
    ----------
    config : mapping
        The validated configuration.
    round_no : int
        The round.
    identified : path
        The round's identified-set record.
    verification_bulk : sequence of path
        ``bulk.csv`` of the round's verification runs (empty when nothing was identified).
    experiment : path
        The measurements.
    table4_files : mapping
        Bulk value -> the round's Table 4 CSV of its network.
    previous : path or None
        The record of the previous round.
    record, verification_table : path
        Outputs: the record (JSON) and the verification table as text (a line saying why
        there is none when nothing was identified); the CSV goes beside it.

    Returns
    -------
    dict
        The record (:func:`demcal.sequential.rounds.round_record`).
    """
    ident = json.loads(Path(identified).read_text())
    table = None
    markdown = Path(verification_table)
    if verification_bulk:
        table = write_verification_table(
            {"configured": verification_bulk},
            experiment,
            float(config["screening"]["tolerance"]),
            markdown.with_suffix(".csv"),
            markdown,
            identified=identified,
        )
    else:
        markdown.write_text(f"# Round {round_no}: no parameter set identified, nothing verified\n")
    prev = json.loads(Path(previous).read_text()) if previous else None
    rec = round_record(
        round_no,
        config,
        ident,
        _valid_sets(identified),
        table,
        surrogate_quality(table4_files),
        prev,
    )
    Path(record).write_text(json.dumps(rec, indent=2) + "\n")
    return rec


def write_rounds_report(
    config: Mapping[str, Any],
    records: Sequence[str | Path],
    identified: Sequence[str | Path],
    table_csv: str | Path,
    markdown: str | Path,
    figure: str | Path,
) -> pd.DataFrame:
    """The rounds of the study: table (CSV and text) and figure.

    Parameters
    ----------
    config : mapping
        The validated configuration.
    records : sequence of path
        Every round's record, in round order.
    identified : sequence of path
        Every round's identified-set record, in round order (valid sets beside each).
    table_csv, markdown, figure : path
        Outputs.
    """
    recs = [json.loads(Path(p).read_text()) for p in records]
    table = rounds_table(recs)
    table.to_csv(table_csv, index=False, float_format="%.6g")
    last = recs[-1]
    lines = [
        f"# Sequential calibration: {len(recs)} round(s), {last['runs_total']} DEM runs",
        "",
        f"Stopped after round {last['round']}: {last['reason']}.",
        "",
        table.to_string(index=False),
        "",
    ]
    Path(markdown).write_text("\n".join(lines))
    valid = {rec["round"]: _valid_sets(path) for rec, path in zip(recs, identified, strict=True)}
    rounds_figure(table, valid, design_ranges(config), figure)
    return table
