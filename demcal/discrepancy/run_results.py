"""Results of the discrepancy runs: bulk rows with their case parameters, the DEM values of
the observations in one run and their statistics over replicate runs."""

from __future__ import annotations

import json
import math
import numbers
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["read_runs", "replicate_statistics", "run_values"]

_TEST_NAMES = {"repose": "angle_of_repose"}


def read_runs(bulk_files: Iterable[str | Path]) -> pd.DataFrame:
    """Bulk rows of discrepancy runs with every numeric and text field of their case row.

    Each ``bulk.csv`` (written by the ``bulk_case`` rule) is joined with the ``case`` entry of
    the ``case.json`` beside it, so parameters the tidy dataset does not know (a magnitude set
    through the configuration, the candidate's name) are kept.

    Raises
    ------
    FileNotFoundError
        When a ``case.json`` is missing (names the file).
    """
    frames = []
    for path in bulk_files:
        path = Path(path)
        info_path = path.parent / "case.json"
        if not info_path.is_file():
            raise FileNotFoundError(f"{info_path}: case description of {path} is missing")
        case = json.loads(info_path.read_text())["case"]
        rows = pd.read_csv(path)
        for key, value in case.items():
            if key == "case_id" or (key in ("normal_stress", "P") and key in rows):
                continue
            if isinstance(value, bool) or not isinstance(value, numbers.Real | str):
                continue
            rows[key] = value
        rows["run"] = path.parent.name
        rows["test"] = rows["test"].replace(_TEST_NAMES)
        frames.append(rows)
    if not frames:
        return pd.DataFrame()
    return pd.concat(frames, ignore_index=True, sort=False)


def _run_base(runs: pd.DataFrame) -> pd.Series:
    """Run id of every row without its load suffix (``_s<i>[_p<j>]`` or ``_h<m>``)."""
    return runs["run"].astype(str).str.replace(r"(_s\d+(_p\d+)?|_h\d+)$", "", regex=True)


def run_values(runs: pd.DataFrame, run: str, observations: pd.DataFrame) -> np.ndarray:
    """DEM values of the observations in one run (all its tests), NaN where missing or failed.

    Parameters
    ----------
    runs : DataFrame
        Rows of :func:`read_runs` (column ``run`` = case dir).
    run : str
        Run id without the load suffix (e.g. ``ref`` for ``ref_s1``, ``ref_s2``, ``ref_h1``
        and the angle-of-repose case ``ref``).
    observations : DataFrame, shape (K, ...)

    Returns
    -------
    ndarray, shape (K,)
    """
    if len(runs) == 0:
        return np.full(len(observations), math.nan)
    mine = runs[(_run_base(runs) == run) & (runs["status"] == "ok")]
    out = np.full(len(observations), math.nan)
    for k, (_, row) in enumerate(observations.iterrows()):
        name = row["observable"]
        if name == "aor":
            match = mine[mine["test"] == "angle_of_repose"]
        else:
            shear = mine[mine["test"] == "shear_cell"]
            match = shear[
                np.isclose(shear["normal_stress"].astype(float), row["normal_stress"], rtol=1e-9)
                & np.isclose(shear["P"].astype(float), row["P"], rtol=1e-9)
            ]
        if len(match) and name in match and np.isfinite(float(match[name].iloc[0])):
            out[k] = float(match[name].iloc[0])
    return out


def replicate_statistics(
    runs: pd.DataFrame, bases: Sequence[str], observations: pd.DataFrame
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean, sample standard deviation and count of the observations over replicate runs.

    Parameters
    ----------
    runs : DataFrame
        Rows of :func:`read_runs`.
    bases : sequence of str
        Run ids of the replicates without load suffix (``ref``, ``ref_r2``, ...).
    observations : DataFrame, shape (K, ...)

    Returns
    -------
    mean, sd, n : ndarray, shape (K,)
        Over the replicates that finished; sd is NaN below two, mean NaN for none.
    """
    values = np.array([run_values(runs, base, observations) for base in bases]).reshape(
        len(bases), len(observations)
    )
    finite = np.isfinite(values)
    n = finite.sum(axis=0)
    total = np.where(finite, values, 0.0).sum(axis=0)
    mean = np.divide(total, n, out=np.full(len(observations), math.nan), where=n > 0)
    squares = np.where(finite, (values - mean) ** 2, 0.0).sum(axis=0)
    sd = np.sqrt(np.divide(squares, n - 1, out=np.full(len(observations), math.nan), where=n > 1))
    return mean, sd, n
