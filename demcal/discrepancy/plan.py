"""Which files the discrepancy workflow needs: the run lists behind its Snakemake rules.

Everything here is known from the configuration and the measured data when the workflow is
parsed, except what the two checkpoints decide: whether anything is missing (Find) and which
effect is added (Name). The functions that depend on a checkpoint take its output file.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from demcal.core.experiments import Experiment, load_experiment
from demcal.discrepancy.candidates import (
    REFERENCE_CASE,
    Candidate,
    ProbeRun,
    applicability,
    measured_tests,
    parse_candidates,
    probe_runs,
    reprobe_runs,
    run_suffixes,
)
from demcal.discrepancy.dem_check import fitted_experiment, held_out_suffixes, replicate_bases
from demcal.discrepancy.observations import OBSERVABLES

__all__ = ["VERIFICATION_CASE", "DiscrepancyPlan", "measured_observables"]

#: Run id of the verification of the extended model.
VERIFICATION_CASE = "verify"


def measured_observables(experiment: Experiment) -> list[str]:
    """Bulk values that were measured, in the order of ``OBSERVABLES``."""
    seen = {name for cond in experiment.shear_conditions for name in cond.values}
    if experiment.angle_of_repose is not None:
        seen.add("aor")
    return [o for o in OBSERVABLES if o in seen]


@dataclass(frozen=True)
class DiscrepancyPlan:
    """Run lists and file names of one discrepancy study.

    Attributes
    ----------
    root : str
        Output directory of the workflow (``results/discrepancy``).
    tests : list[str]
        Virtual tests with measured observables.
    suffixes : list[str]
        Shear-cell case-id suffixes of one run (``_s<k>`` or ``_s<k>_p<j>``), the measured
        and fitted load conditions among those of the design.
    outputs : list[str]
        Measured observables (their surrogates are needed).
    candidates : list[Candidate]
        Applicable candidates (the current model lacks them).
    held_out : list[str]
        Suffixes ``_h<m>`` of the held-out conditions (DEM check only).
    replicates : int
        DEM runs per point and load in the DEM check; the reference at theta* runs this many
        times before the naming too.
    probe_replicates : int
        DEM runs of every candidate probe level.
    """

    root: str
    tests: list[str]
    suffixes: list[str]
    outputs: list[str]
    candidates: list[Candidate]
    held_out: list[str]
    replicates: int
    probe_replicates: int = 1

    @classmethod
    def from_config(cls, config: Mapping[str, Any], results: str = "results") -> DiscrepancyPlan:
        """The plan of a validated configuration (reads its experiment file)."""
        experiment = fitted_experiment(load_experiment(config["experiment"]), config)
        candidates = [
            c
            for c in parse_candidates(config["discrepancy"]["candidates"])
            if applicability(c, config)[0]
        ]
        return cls(
            root=f"{results}/discrepancy",
            tests=measured_tests(experiment),
            suffixes=run_suffixes(config, experiment),
            outputs=measured_observables(experiment),
            candidates=candidates,
            held_out=held_out_suffixes(config),
            replicates=int(config["discrepancy"]["replicates"]),
            probe_replicates=int(config["discrepancy"]["probe_replicates"]),
        )

    def case_ids(self, bases: Sequence[str], held_out: bool = False) -> list[tuple[str, str]]:
        """(test, case id) of runs ``bases`` in every measured test; with ``held_out`` the
        shear cell also at the held-out loads (always measured there)."""
        tests = self.tests
        if held_out and self.held_out and "shear_cell" not in tests:
            tests = ["shear_cell", *tests]
        suffixes = self.suffixes + (self.held_out if held_out else [])
        ids = []
        for test in tests:
            for base in bases:
                if test == "shear_cell":
                    ids += [(test, f"{base}{suffix}") for suffix in suffixes]
                else:
                    ids.append((test, base))
        return ids

    def bulk_files(self, stage: str, bases: Sequence[str], held_out: bool = False) -> list[str]:
        """``bulk.csv`` of runs ``bases`` under ``<root>/<stage>``."""
        return [f"{self.root}/{stage}/{t}/{c}/bulk.csv" for t, c in self.case_ids(bases, held_out)]

    @property
    def probe_cases(self) -> list[str]:
        """Run ids of the probe stage: every replicate of the reference at theta*, then
        ``probe_replicates`` runs of every candidate level."""
        return self._replicated(probe_runs(self.candidates))

    def reprobe_cases(self, lead_record: str | Path) -> list[str]:
        """Run ids of the candidates probed again at their own best fit (``points`` of the
        lead record, :func:`demcal.discrepancy.probe_ranking.write_lead`): per candidate the
        reference ``replicates`` times, then ``probe_replicates`` runs of every level."""
        names = reprobed(lead_record)
        return self._replicated(reprobe_runs([c for c in self.candidates if c.name in names]))

    def reprobe_bulk(self, lead_record: str | Path) -> list[str]:
        """Bulk files of the runs of :meth:`reprobe_cases` (none when no candidate leads)."""
        return self.bulk_files("reprobes", self.reprobe_cases(lead_record))

    def _replicated(self, runs: Sequence[ProbeRun]) -> list[str]:
        """Run ids of every replicate of ``runs``: a reference (no candidate) ``replicates``
        times, a candidate level ``probe_replicates`` times."""
        cases = []
        for run in runs:
            count = self.replicates if run.candidate is None else self.probe_replicates
            cases += replicate_bases(run.case, count)
        return cases

    def probe_bulk(self, find_record: str | Path) -> list[str]:
        """Bulk files of all probe runs, or none when Find found nothing missing."""
        return self.bulk_files("probes", self.probe_cases) if missing(find_record) else []

    def reference_bulk(self, find_record: str | Path) -> list[str]:
        """Bulk files of the replicates of the reference run at theta* (fitted and held-out
        loads), or none when nothing is missing."""
        if not missing(find_record):
            return []
        bases = replicate_bases(REFERENCE_CASE, self.replicates)
        return self.bulk_files("probes", bases, held_out=True)

    def extended_bulk(self, design: str | Path) -> list[str]:
        """Bulk files of the extended design's runs (none when no effect was named)."""
        table = pd.read_csv(design, dtype={"case_id": str})
        return self.bulk_files("extended", list(table["case_id"])) if len(table) else []

    def verification_bulk(self, ranking_record: str | Path) -> list[str]:
        """Bulk files of the replicate verification runs (fitted and held-out loads), or none
        when no effect was named."""
        if not winner(ranking_record):
            return []
        bases = replicate_bases(VERIFICATION_CASE, self.replicates)
        return self.bulk_files("verification", bases, held_out=True)

    def show_inputs(
        self, find_record: str | Path, ranking_record: str | Path
    ) -> dict[str, str | list[str]]:
        """Inputs of the Show step that depend on the checkpoints."""
        out: dict[str, str | list[str]] = {"reference": self.reference_bulk(find_record)}
        if winner(ranking_record):
            out["recalibration"] = f"{self.root}/recalibration.json"
            out["after_table"] = f"{self.root}/find_after.csv"
            out["verification"] = self.verification_bulk(ranking_record)
        return out

    def model_files(self, stage: str) -> list[str]:
        """Surrogate files of the measured observables (``surrogates`` or the extended ones)."""
        if stage == "current":
            return [f"{Path(self.root).parent}/surrogates/{o}/model.pt" for o in self.outputs]
        return [f"{self.root}/surrogates/{o}/model.pt" for o in self.outputs]


def missing(find_record: str | Path) -> bool:
    """Whether Find rejected "nothing missing"."""
    return bool(json.loads(Path(find_record).read_text())["missing"])


def reprobed(lead_record: str | Path) -> list[str]:
    """Names of the candidates the lead record sends to be probed again at their best fit."""
    return list(json.loads(Path(lead_record).read_text())["points"])


def winner(ranking_record: str | Path) -> str | None:
    """Name of the effect the ranking named, or None."""
    return json.loads(Path(ranking_record).read_text()).get("winner")
