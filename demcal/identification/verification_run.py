"""The verification DEM run at the identified mean set: its decks and the comparison of its bulk
values with the measurements.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import pandas as pd
from scipy.stats import norm
from scipy.stats import t as student_t

from demcal.core.experiments import load_experiment
from demcal.design.cases import verification_case
from demcal.identification.verification import (
    engine_columns,
    scatter_columns,
    verification_table,
)
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


#: Column of the verification table with the surrogates' prediction at the verified set.
SURROGATE_COLUMN = "surrogate"


def _key(observable: str, normal_stress: Any, P: Any) -> str:
    """Row key; a missing load (the angle of repose) reads "-", as NaN never compares equal."""

    def number(v: Any) -> str:
        return "-" if v is None or pd.isna(v) else f"{float(v):.9g}"

    return f"{observable}|{number(normal_stress)}|{number(P)}"


def surrogate_column(table: pd.DataFrame, predicted: list[Mapping[str, Any]]) -> pd.Series:
    """The surrogates' prediction for each row of a verification table (NaN where none).

    Parameters
    ----------
    table : pandas.DataFrame, shape (n_measured, ...)
        Columns ``observable``, ``normal_stress`` (Pa), ``P``.
    predicted : list of mapping
        ``predicted_at_mean`` of the identified-set record: ``observable``, ``normal_stress``,
        ``P``, ``predicted``.

    Returns
    -------
    pandas.Series, shape (n_measured,)
    """
    lookup = {_key(r["observable"], r["normal_stress"], r["P"]): r["predicted"] for r in predicted}
    rows = table[["observable", "normal_stress", "P"]].itertuples(index=False)
    return pd.Series([lookup.get(_key(*row), float("nan")) for row in rows], index=table.index)


def _condition(row: Mapping[str, Any]) -> str:
    if pd.isna(row.get("normal_stress")):
        return str(row["observable"])
    return f"{row['observable']} ({float(row['normal_stress']):.6g} Pa, P {float(row['P']):g})"


#: Confidence of the interval of the replicate runs' mean that tells a decided verdict from one
#: that more runs could turn: one quick heap scatters by about 1.8 deg, so nine heaps leave
#: their mean uncertain by +-1.35 deg (95 %), 3.5 % of a measured 38.85 deg.
CONFIDENCE = 0.95


def mean_interval(values_mean: float, sd: float, runs: int) -> tuple[float, float] | None:
    """Two-sided Student-t interval of a mean over replicate runs.

    Parameters
    ----------
    values_mean : float
        Mean over the runs (unit of the value).
    sd : float
        Sample standard deviation of the runs (same unit).
    runs : int
        Number of runs.

    Returns
    -------
    tuple of float or None
        (low, high) at :data:`CONFIDENCE`; None for fewer than two runs or a missing sd.
    """
    if runs < 2 or not (math.isfinite(sd) and math.isfinite(values_mean)):
        return None
    half = float(student_t.ppf(0.5 + 0.5 * CONFIDENCE, runs - 1)) * sd / math.sqrt(runs)
    return values_mean - half, values_mean + half


def _stated_sd(row: Mapping[str, Any]) -> float | None:
    """The measured value's sd when its experiment file states a positive one."""
    sd = float(row.get("measured_sd", math.nan))
    return sd if math.isfinite(sd) and sd > 0.0 else None


def verdict_interval(row: Mapping[str, Any], engine: str) -> tuple[float, float] | None:
    """The interval a verdict compares with the tolerance band: the runs' mean with its own
    and the measurement's uncertainty.

    The Student-t interval of the runs' mean (:func:`mean_interval`) is widened in quadrature by
    the measured value's own uncertainty, ``z * measured_sd`` with z the normal quantile of
    :data:`CONFIDENCE`: a measurement is a mean of a few tests, known to its stated sd (the
    screening's acceptance band treats it alike), so a DEM mean closer to it than that cannot
    be called a miss, however many runs it averages.

    Parameters
    ----------
    row : mapping
        One row of a verification table (``measured``, ``measured_sd``, ``dem_<engine>``,
        ``dem_sd_<engine>``, ``runs_<engine>``).
    engine : str
        The engine whose columns are read.

    Returns
    -------
    tuple of float or None
        (low, high), unit of the value; the runs' interval alone where the measurement states
        no sd; None for fewer than two runs.
    """
    dem, _, _ = engine_columns(engine)
    sd, runs = scatter_columns(engine)
    mean = float(row[dem])
    interval = mean_interval(mean, float(row[sd]), int(row[runs]))
    measured_sd = _stated_sd(row)
    if interval is None or measured_sd is None:
        return interval
    z = float(norm.ppf(0.5 + 0.5 * CONFIDENCE))
    half = math.hypot(0.5 * (interval[1] - interval[0]), z * measured_sd)
    return mean - half, mean + half


def undecided(row: Mapping[str, Any], engine: str, tolerance: float) -> str | None:
    """The row's interval (:func:`verdict_interval`) when it straddles an edge of the tolerance
    band, as text.

    Parameters
    ----------
    row, engine
        As for :func:`verdict_interval`.
    tolerance : float
        The relative tolerance (e.g. 0.05).

    Returns
    -------
    str or None
        The value, its :data:`CONFIDENCE` interval and the tolerance band; None when the
        interval lies wholly inside or wholly outside the band, or for fewer than two runs.
    """
    dem, _, _ = engine_columns(engine)
    _, runs = scatter_columns(engine)
    interval = verdict_interval(row, engine)
    measured = float(row["measured"])
    band = sorted((measured * (1.0 - tolerance), measured * (1.0 + tolerance)))
    if interval is None or interval[1] < band[0] or interval[0] > band[1]:
        return None  # one run or no value, or the interval wholly outside the band
    if band[0] <= interval[0] and interval[1] <= band[1]:
        return None  # wholly inside
    measured_sd = _stated_sd(row)
    widened = f", with the measured sd {measured_sd:.3g}:" if measured_sd is not None else ""
    return (
        f"{_condition(row)} {float(row[dem]):.4g} ({CONFIDENCE:.0%} interval of the mean of "
        f"{int(row[runs])} runs{widened} {interval[0]:.4g}-{interval[1]:.4g}, tolerance band "
        f"{band[0]:.4g}-{band[1]:.4g})"
    )


def dem_verdict(table: pd.DataFrame, engine: str, tolerance: float) -> str:
    """One line: whether one engine's verification runs reproduce every measured value.

    A value whose replicate runs' mean lies on one side of an edge of the tolerance band while
    the :data:`CONFIDENCE` interval of that mean, widened by the measured value's own sd
    (:func:`verdict_interval`), crosses it is named as undecided: more runs
    (``verification.seeds``, ``verification.repose_seeds``) or a more precise measurement
    would decide it.

    Parameters
    ----------
    table : pandas.DataFrame, shape (n_measured, ...)
        From :func:`demcal.identification.verification.verification_table`.
    engine : str
        The engine whose columns (``dem_<engine>``, ``dem_sd_<engine>``, ``runs_<engine>``,
        ``deviation_<engine>``) are read.
    tolerance : float
        The relative tolerance (e.g. 0.05).

    Returns
    -------
    str
        A single line; a miss names every value outside the tolerance with the runs' mean, its
        standard error over the replicate runs and the measurement; undecided values follow.
    """
    dem, deviation, _ = engine_columns(engine)
    sd, runs = scatter_columns(engine)
    misses = []
    for _, row in table.iterrows():
        if row[deviation] <= tolerance:
            continue
        if not row[runs] or pd.isna(row[dem]):
            misses.append(f"{_condition(row)}: no finished run")
            continue
        spread = ""
        if row[runs] > 1 and not pd.isna(row[sd]):
            error = float(row[sd]) / math.sqrt(float(row[runs]))
            spread = f" +- {error:.3g} (standard error of {int(row[runs])} runs)"
        misses.append(
            f"{_condition(row)} {float(row[dem]):.4g}{spread} against {float(row['measured']):.4g}"
            f" ({float(row[deviation]):.1%})"
        )
    unsure = [u for _, row in table.iterrows() if (u := undecided(row, engine, tolerance))]
    tail = (
        f" Undecided at {CONFIDENCE:.0%} confidence, more replicate runs (or, where the "
        "measured sd dominates, a more precise measurement) would tell: " + "; ".join(unsure) + "."
        if unsure
        else ""
    )
    if not misses:
        worst = table.loc[table[deviation].idxmax()]
        return (
            f"The DEM runs on {engine} reproduce every measured value within the "
            f"{tolerance:.0%} tolerance (largest deviation: {_condition(worst)}, "
            f"{float(worst[deviation]):.1%}).{tail}"
        )
    return (
        f"**The DEM runs on {engine} miss {len(misses)} of the {len(table)} measured values by "
        f"more than the {tolerance:.0%} tolerance**: " + "; ".join(misses) + "." + tail
    )


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
        :func:`demcal.identification.identify.identify`) becomes the first line of the text,
        followed by whether the surrogates accept the mean set itself (``mean_set``); their
        predictions there (``predicted_at_mean``) become the column ``surrogate``. Then, for
        every engine, whether its runs reproduce every measured value (:func:`dem_verdict`).

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
    record = json.loads(Path(identified).read_text()) if identified is not None else {}
    if record.get("predicted_at_mean"):
        table[SURROGATE_COLUMN] = surrogate_column(table, record["predicted_at_mean"])
    table.to_csv(csv, index=False)
    lines = [
        *(f"{record[key]}\n" for key in ("reach", "mean_set") if record.get(key)),
        *(f"{dem_verdict(table, engine, float(tolerance))}\n" for engine in runs),
        "# Verification: DEM at the identified mean set vs measurement",
        "",
    ]
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
    if SURROGATE_COLUMN in table:
        lines.append(
            f"{SURROGATE_COLUMN}: the surrogates' prediction at the identified mean set (the "
            "screening accepted the valid sets on such predictions)."
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
