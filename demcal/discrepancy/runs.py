"""The runs of the discrepancy workflow: which deck to render for a probe, extended-design or
verification case (light to import, so that the rendering rules run in-process)."""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pandas as pd

from demcal.core.rule_log import rule_log
from demcal.discrepancy.candidates import (
    Candidate,
    ProbeRun,
    base_point,
    case_setup,
    parse_candidates,
    probe_runs,
    reprobe_runs,
)
from demcal.discrepancy.dem_check import parse_run_id
from demcal.virtual_tests.deck import render_case

__all__ = ["candidate_by_name", "discrepancy_case", "named_candidate", "render_discrepancy_run"]


def candidate_by_name(config: Mapping[str, Any], name: str) -> Candidate:
    """The catalogue entry called ``name``.

    Raises
    ------
    KeyError
        When the catalogue has no such candidate.
    """
    for cand in parse_candidates(config["discrepancy"]["candidates"]):
        if cand.name == name:
            return cand
    raise KeyError(f"discrepancy.candidates: no candidate named {name!r}")


def named_candidate(config: Mapping[str, Any], ranking_record: str | Path) -> Candidate:
    """The catalogue entry of the effect the ranking named (``winner`` of its JSON record)."""
    record = json.loads(Path(ranking_record).read_text())
    return candidate_by_name(config, record["winner"])


def discrepancy_case(
    mode: str,
    test: str,
    case: str,
    config: Mapping[str, Any],
    record: Mapping[str, Any],
    design: pd.DataFrame | None = None,
) -> tuple[dict[str, Any], dict[str, Any]]:
    """Case row and configuration of one run of the discrepancy workflow.

    Parameters
    ----------
    mode : {"probe", "reprobe", "extended", "verification"}
        probe: the reference or a candidate level at theta* (``record`` = Find record);
        reprobe: a candidate's reference or level at its own best fit (``record`` = lead
        record, its ``points``);
        extended: a row of the extended design (``record`` = ranking record, ``design``);
        verification: the extended model's best point (``record`` = recalibration record).
    test, case : str
        Test and case id (``<run>[_r<k>]``, with ``_s<i>[_p<j>]`` or ``_h<m>`` for the shear
        cell; :func:`demcal.discrepancy.dem_check.parse_run_id`).
    config : mapping
        The validated configuration of the current model.

    Raises
    ------
    KeyError
        For a case id that belongs to no run of the mode.
    """
    run = parse_run_id(case).run
    if mode == "probe":
        cands = parse_candidates(config["discrepancy"]["candidates"])
        found = _run_of(probe_runs(cands), run)
        if found is None:
            raise KeyError(f"probe case {case!r}: no candidate level of that name")
        return _probe_setup(test, case, dict(record["point"]), config, cands, found)
    if mode == "reprobe":
        for cand in parse_candidates(config["discrepancy"]["candidates"]):
            if cand.name not in record["points"]:
                continue
            found = _run_of(reprobe_runs([cand]), run)
            if found is not None:
                point = dict(record["points"][cand.name])
                return _probe_setup(test, case, point, config, [cand], found)
        raise KeyError(f"reprobe case {case!r}: no run of a candidate probed again")
    if mode == "extended":
        if design is None:
            raise ValueError("extended case: the extended design table is needed")
        cand = candidate_by_name(config, str(record["winner"]))
        rows = design[design["case_id"] == run]
        if rows.empty:
            raise KeyError(f"extended case {case!r} is not in the extended design")
        values = {k: float(v) for k, v in rows.iloc[0].items() if k != "case_id"}
        point = base_point(values, config)
        return case_setup(test, case, point, config, cand, values[cand.parameter])
    if mode == "verification":
        cand = candidate_by_name(config, str(record["winner"]))
        point = dict(record["point"])
        return case_setup(test, case, point, config, cand, float(record["magnitude"]))
    raise ValueError(f"unknown mode {mode!r}; expected probe, reprobe, extended or verification")


def _run_of(runs: list[ProbeRun], run: str) -> ProbeRun | None:
    """The probe run called ``run`` (a case id without replicate and load), or None."""
    return next((r for r in runs if r.case == run), None)


def _probe_setup(
    test: str,
    case: str,
    point: dict[str, Any],
    config: Mapping[str, Any],
    candidates: list[Candidate],
    found: ProbeRun,
) -> tuple[dict[str, Any], dict[str, Any]]:
    """Case row and configuration of a probe run: its candidate at its level, or the model as
    it is for a reference run."""
    cand = next((c for c in candidates if c.name == found.candidate), None)
    return case_setup(test, case, point, config, cand, found.level)


def render_discrepancy_run(
    mode: str,
    test: str,
    case: str,
    config: Mapping[str, Any],
    record_path: str | Path,
    deck: str | Path,
    log: str,
    design_path: str | Path | None = None,
) -> dict[str, Any]:
    """Render one probe, extended-design or verification run (deck file ``deck``), logging to
    ``log``.

    ``record_path`` is the Find record (probe), the lead record (reprobe), the ranking record
    (extended, with ``design_path``) or the recalibration record (verification); see
    :func:`discrepancy_case`.

    Returns
    -------
    dict
        The ``case.json`` content written by :func:`demcal.decks.render.render_case`.
    """
    with rule_log(log):
        record = json.loads(Path(record_path).read_text())
        design = pd.read_csv(design_path, dtype={"case_id": str}) if design_path else None
        row, cfg = discrepancy_case(mode, test, case, config, record, design)
        return render_case(test, row, cfg, Path(deck).parent)
