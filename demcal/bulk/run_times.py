"""Run time and memory of every DEM case, from the benchmark files Snakemake writes.

The rules that run the engine have a ``benchmark:`` file: a tab-separated table with a header
line and one row per repetition, columns ``s`` (wall-clock seconds), ``h:m:s``, ``max_rss``,
``max_vms``, ``max_uss``, ``max_pss`` (MB), ``io_in``, ``io_out`` (MB), ``mean_load`` (CPU
load sampled over the run) and ``cpu_time`` (CPU seconds). Memory, I/O and CPU are ``NA`` when
the job ended before Snakemake's first sample; I/O is ``-`` where the system does not count it.
This module gathers the files of a study into one table, one row per case and repetition, and
draws the run time of every case.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

#: Columns of the run-time table and the benchmark column each comes from (units in the name).
RUN_TIME_COLUMNS = {
    "seconds": "s",
    "wall_clock": "h:m:s",
    "cpu_seconds": "cpu_time",
    "mean_load": "mean_load",
    "max_rss_mb": "max_rss",
    "max_vms_mb": "max_vms",
    "io_in_mb": "io_in",
    "io_out_mb": "io_out",
}


# How Snakemake writes a value it could not measure.
_MISSING = ("NA", "-")


class BenchmarkFileError(ValueError):
    """A benchmark file is not a Snakemake benchmark table (the message names the file)."""


def read_benchmark(path: str | Path) -> pd.DataFrame:
    """Read one Snakemake benchmark file.

    Parameters
    ----------
    path : str or Path
        Tab-separated benchmark table (``benchmark:`` of a rule).

    Returns
    -------
    pandas.DataFrame
        One row per repetition with the file's columns; ``h:m:s`` as text, the numeric columns
        of :data:`RUN_TIME_COLUMNS` as float64 with NaN for ``NA`` and ``-``.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    BenchmarkFileError
        A column of the run-time table is missing, the file has no row, or a value is not a
        number.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"benchmark file not found: {path}")
    table = pd.read_csv(path, sep="\t", dtype=str, keep_default_na=False)
    missing = [c for c in RUN_TIME_COLUMNS.values() if c not in table.columns]
    if missing:
        raise BenchmarkFileError(
            f"{path}: missing column(s) {', '.join(missing)}; is it a Snakemake benchmark file?"
        )
    if table.empty:
        raise BenchmarkFileError(f"{path}: no benchmark row")
    for column in table.columns:
        if column == "h:m:s" or column not in RUN_TIME_COLUMNS.values():
            continue
        text = table[column].str.strip()
        missing_value = text.isin(_MISSING)
        values = pd.to_numeric(text.where(~missing_value), errors="coerce")
        bad = values.isna() & ~missing_value
        if bad.any():
            row = int(np.flatnonzero(bad.to_numpy())[0])
            raise BenchmarkFileError(
                f"{path}: column '{column}' row {row + 1} holds {table[column].iloc[row]!r}, "
                "not a number"
            )
        table[column] = values.astype(float)
    return table


def collect_run_times(benchmarks: Iterable[tuple[str, str, str | Path]]) -> pd.DataFrame:
    """One table of the benchmark files of many cases.

    Parameters
    ----------
    benchmarks : iterable of (test, case_id, path)
        The virtual test, the case id and the benchmark file of every case.

    Returns
    -------
    pandas.DataFrame
        One row per case and repetition (in the order given): ``test``, ``case_id``,
        ``repeat`` (0-based), then the columns of :data:`RUN_TIME_COLUMNS`.
    """
    frames = []
    for test, case_id, path in benchmarks:
        bench = read_benchmark(path)
        frame = pd.DataFrame(
            {"test": test, "case_id": case_id, "repeat": np.arange(len(bench), dtype=np.int64)}
        )
        for name, column in RUN_TIME_COLUMNS.items():
            frame[name] = bench[column].to_numpy()
        frames.append(frame)
    if not frames:
        return pd.DataFrame(columns=["test", "case_id", "repeat", *RUN_TIME_COLUMNS])
    return pd.concat(frames, ignore_index=True)


def plot_run_times(table: pd.DataFrame, path: str | Path) -> Path:
    """Wall-clock run time of every case, one panel per virtual test, slowest case first.

    Parameters
    ----------
    table : pandas.DataFrame
        Output of :func:`collect_run_times` (columns ``test``, ``case_id``, ``seconds``);
        repetitions of a case are averaged.
    path : str or Path
        PNG file to write (parent folders are created).

    Returns
    -------
    Path
        The written file.
    """
    per_case = table.groupby(["test", "case_id"], sort=False)["seconds"].mean().reset_index()
    tests = list(dict.fromkeys(per_case["test"])) or ["no cases"]
    fig, axes = plt.subplots(len(tests), 1, figsize=(7.0, 2.6 * len(tests)), squeeze=False)
    for ax, test in zip(axes[:, 0], tests, strict=True):
        cases = per_case[per_case["test"] == test].sort_values("seconds", ascending=False)
        seconds = cases["seconds"].to_numpy(dtype=float)
        rank = np.arange(1, seconds.size + 1)
        ax.bar(rank, seconds, width=0.8, color="C0")
        if seconds.size:
            ax.axhline(float(np.median(seconds)), color="C1", linewidth=1.0, label="median")
            ax.legend(loc="upper right", frameon=False)
            ax.set_title(
                f"{test}: {seconds.size} cases, {seconds.sum():.0f} s in all, slowest "
                f"{cases['case_id'].iloc[0]} ({seconds[0]:.1f} s)"
            )
        else:
            ax.set_title(f"{test}: no cases")
        ax.set_xlabel("case, slowest first")
        ax.set_ylabel("run time (s)")
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=150)
    plt.close(fig)
    return out


def write_run_times(
    benchmarks: Iterable[tuple[str, str, str | Path]],
    table: str | Path,
    figure: str | Path,
) -> pd.DataFrame:
    """Collect the benchmark files of a study's cases into a CSV table and a figure.

    Parameters
    ----------
    benchmarks : iterable of (test, case_id, path)
        See :func:`collect_run_times`.
    table : path
        CSV of :func:`collect_run_times`.
    figure : path
        PNG of :func:`plot_run_times`.

    Returns
    -------
    pandas.DataFrame
        The table written.
    """
    run_times = collect_run_times(benchmarks)
    Path(table).parent.mkdir(parents=True, exist_ok=True)
    run_times.to_csv(table, index=False, float_format="%.6g")
    plot_run_times(run_times, figure)
    return run_times
