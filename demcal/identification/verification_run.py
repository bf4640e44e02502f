"""The verification DEM run at the identified mean set: its decks and the comparison of its bulk
values with the measurements.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import pandas as pd

from demcal.core.experiments import load_experiment
from demcal.design.cases import verification_case
from demcal.identification.verification import verification_table
from demcal.virtual_tests.deck import render_case


def render_verification_case(
    identified_file: str | Path,
    test: str,
    case_id: str,
    config: Mapping[str, Any],
    out_dir: str | Path,
) -> dict[str, Any]:
    """Render one verification case (deck, meshes, ``case.json``) at the identified mean set.

    Parameters
    ----------
    identified_file : path
        The identified set (``identified_parameters.json``).
    test : {"shear_cell", "angle_of_repose"}
        Which virtual test.
    case_id : str
        ``identified`` or ``identified_s<k>[_p<j>]`` (selects the load condition).
    config : mapping
        The validated configuration.
    out_dir : path
        Case directory; created if missing.

    Returns
    -------
    dict
        The case row: ``case_id``, the mean parameters and, for the shear cell, the load.

    Raises
    ------
    ValueError
        When no parameter set was identified.
    """
    identified = json.loads(Path(identified_file).read_text())
    case = verification_case(config, identified, test, case_id)
    render_case(test, case, config, Path(out_dir))
    return case


def write_verification_table(
    bulk_files: Mapping[str, Iterable[str | Path]],
    experiment_file: str | Path,
    tolerance: float,
    csv: str | Path,
    markdown: str | Path,
    commands: Mapping[str, str] | None = None,
    threads: int | None = None,
    identified: str | Path | None = None,
) -> pd.DataFrame:
    """Compare the verification runs of every engine with the measurements and each other;
    write the table as CSV and as text.

    Parameters
    ----------
    bulk_files : mapping of str to iterable of path
        Per engine name (in column order), ``bulk.csv`` of every verification case it ran.
    experiment_file : path
        The measured bulk values.
    tolerance : float
        Acceptance tolerance |1 - num/exp| (eqs. 3-4).
    csv, markdown : path
        Output files: the table as CSV, and under a heading as fixed-width text.
    commands : mapping of str to str, optional
        Command template of each engine, listed above the text table.
    threads : int, optional
        Threads or MPI ranks of each run, listed with the commands.
    identified : path, optional
        The identified-set record; its reachability verdict (``reach``, written by
        :func:`demcal.identification.identify.identify`) becomes the first line of the text.

    Returns
    -------
    pandas.DataFrame
        One row per measured observable (see
        :func:`demcal.identification.verification.verification_table`).
    """
    runs = {
        engine: pd.concat([pd.read_csv(p) for p in files], ignore_index=True)
        for engine, files in bulk_files.items()
    }
    table = verification_table(runs, load_experiment(experiment_file), float(tolerance))
    table.to_csv(csv, index=False)
    lines = ["# Verification: DEM at the identified mean set vs measurement", ""]
    if identified is not None:
        verdict = json.loads(Path(identified).read_text()).get("reach")
        if verdict:
            lines = [verdict, "", *lines]
    lines.append(
        "Engines (columns dem_<engine>: mean over replicate runs, dem_sd_<engine>: their standard "
        "deviation, runs_<engine>: runs that finished, deviation_<engine> = |1 - dem/measured|):"
    )
    for engine in runs:
        command = (commands or {}).get(engine)
        ranks = f", {threads} thread(s) or MPI rank(s)" if threads is not None else ""
        lines.append(f"- {engine}: `{command}`{ranks}" if command else f"- {engine}")
    if len(runs) > 1:
        first = next(iter(runs))
        lines.append(
            f"engine_difference: largest |1 - dem_<engine>/dem_{first}| over the other engines."
        )
    lines.append(f"Tolerance: {float(tolerance):g}")
    for engine, frame in runs.items():
        if "status" not in frame:
            continue
        failed = frame[frame["status"] != "ok"].drop_duplicates(["test", "case_id"])
        for _, run in failed.iterrows():
            lines.append(
                f"FAILED on {engine}: {run['test']} {run['case_id']} ({run.get('error', '')}); "
                "its values are NaN."
            )
    with open(markdown, "w") as fh:
        fh.write("\n".join(lines) + "\n\n")
        fh.write(table.to_string(index=False) + "\n")
    return table
