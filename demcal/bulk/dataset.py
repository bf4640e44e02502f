"""The tidy bulk dataset: one row per DEM case and load condition, inputs, outputs and flags."""

import json
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from demcal.bulk.values import extract
from demcal.core.parameters import (
    CONTACT_PARAMETERS,
    GEOMETRY_PARAMETERS,
    OPTIONAL_CONTACT_PARAMETERS,
)
from demcal.core.provenance import write_sidecar
from demcal.core.rule_log import rule_log
from demcal.design.cases import design_id, replicate_of

#: Contact and geometry parameters a case may carry (LIGGGHTS names).
PARAMETERS = (*CONTACT_PARAMETERS, *OPTIONAL_CONTACT_PARAMETERS, *GEOMETRY_PARAMETERS)
#: Bulk values per test.
OUTPUTS = {"shear_cell": ("mu_psh", "mu_sh", "rho_b"), "angle_of_repose": ("aor",)}


def case_rows(
    test: str,
    case_dir: str | Path,
    extract: Callable[[str, Path], pd.DataFrame],
    p_values: Sequence[float],
) -> pd.DataFrame:
    """Bulk rows of one case, with its inputs, status and flags.

    A case whose engine run failed gives rows with ``status == "failed"``, empty outputs and the
    engine's error, one per load condition, so that it is counted and excluded, never lost.

    Parameters
    ----------
    test : {"shear_cell", "angle_of_repose"}
    case_dir : path
        Directory with ``case.json`` and ``status.json``.
    extract : callable
        ``extract(test, case_dir) -> DataFrame`` of bulk values (see ``demcal.bulk.values``).
    p_values : sequence of float
        Shear load fractions, for the rows of a failed shear-cell case that ran all P values
        as cycles (a separate-run case carries its own P).
    """
    case_dir = Path(case_dir)
    info = json.loads((case_dir / "case.json").read_text())
    status = json.loads((case_dir / "status.json").read_text())
    case = info["case"]
    if status["status"] == "ok":
        try:
            rows = extract(test, case_dir).copy()
            status_text, error = "ok", ""
        except (OSError, ValueError, KeyError) as exc:
            rows, status_text, error = None, "failed", f"bulk extraction: {exc}"
    else:
        rows, status_text, error = None, "failed", status.get("error", "")
    if rows is None:
        # One row per load condition the case was meant to produce.
        loads = [case["P"]] if "P" in case else list(p_values)
        n = len(loads) if test == "shear_cell" else 1
        rows = pd.DataFrame({"case_id": [case["case_id"]] * n})
        if test == "shear_cell":
            rows["normal_stress"] = case["normal_stress"]
            rows["P"] = loads
        for out in OUTPUTS[test]:
            rows[out] = math.nan
    rows["test"] = test
    rows["case_id"] = case["case_id"]
    rows["design_id"] = design_id(case["case_id"])
    for name in PARAMETERS:
        if name in case:
            rows[name] = float(case[name])
        elif name == "dCylDp":
            rows[name] = float(info.get("setup", {}).get("dCylDp", math.nan))
    rows["status"] = status_text
    rows["error"] = error
    rows["engine_seconds"] = status.get("seconds", math.nan)
    return rows


def collect(frames: Iterable[pd.DataFrame]) -> pd.DataFrame:
    """Concatenate per-case rows into the tidy dataset with a stable column order."""
    data = pd.concat(list(frames), ignore_index=True, sort=False)
    first = ["test", "case_id", "design_id", *[p for p in PARAMETERS if p in data]]
    load = [c for c in ("normal_stress", "P") if c in data]
    outputs = [o for outs in OUTPUTS.values() for o in outs if o in data]
    rest = [c for c in data.columns if c not in {*first, *load, *outputs}]
    return data[first + load + outputs + rest]


def usable(data: pd.DataFrame, output: str) -> pd.DataFrame:
    """Rows fit for training on ``output``: the run succeeded and the value is finite."""
    ok = (data["status"] == "ok") & data[output].notna()
    return data[ok]


def replicate_means(rows: pd.DataFrame, output: str) -> pd.DataFrame:
    """One row per case and load condition: the mean of ``output`` over the case's replicate
    runs (``design.replicates``; ids ``c0003_r2_s1_p1`` ...).

    Parameters
    ----------
    rows : DataFrame
        Usable rows (:func:`usable`) of one test, with ``case_id``.
    output : str
        The bulk value averaged.

    Returns
    -------
    DataFrame
        ``rows`` where no case has replicates (or no ``case_id``); otherwise the first row of
        every case and load condition (``case_id`` without the replicate number) with the mean
        ``output`` and the number of runs averaged in ``replicates``.
    """
    if "case_id" not in rows:
        return rows
    case = rows["case_id"].astype(str).map(lambda cid: replicate_of(cid)[0])
    if case.equals(rows["case_id"].astype(str)):
        return rows
    keys = [case.rename("_case")] + [rows[c] for c in ("normal_stress", "P") if c in rows]
    grouped = rows[output].groupby(keys, sort=False, dropna=False)
    first = ~pd.concat(keys, axis=1).duplicated()
    out = rows[first].copy()
    out[output] = grouped.transform("mean")[first].to_numpy()
    out["replicates"] = grouped.transform("size")[first].to_numpy()
    out["case_id"] = case[first].to_numpy()
    return out


def collapse_shared_loads(rows: pd.DataFrame, output: str) -> pd.DataFrame:
    """One row per deck (case and normal stress) where ``output`` does not depend on P.

    With ``shear_cell.cycles: continue`` a deck's mu_psh and rho_b are its pre-shear point, read
    once over all its cycles and repeated on the row of every P. Those copies are not
    independent samples: fed to a surrogate as rows they weight every deck by the number of P
    values and offer P as an input that carries nothing, which misleads a Gaussian process
    (its noise level and length scales) and inflates the row counts of Table 4.

    Parameters
    ----------
    rows : DataFrame
        Usable rows of one test (:func:`usable`, :func:`replicate_means`).
    output : str
        The bulk value.

    Returns
    -------
    DataFrame
        ``rows`` unchanged when ``output`` differs between the P of any deck, or no deck holds
        more than one P (one deck per P, or no ``P``); otherwise the first row of every deck,
        without the ``P`` column.
    """
    if "P" not in rows or "case_id" not in rows or rows.empty:
        return rows
    keys = [rows[c] for c in ("case_id", "normal_stress") if c in rows]
    per_deck = rows.groupby(keys, sort=False, dropna=False)
    spread = per_deck[output].agg(["min", "max"])
    # With one deck per P (``cycles: separate``) every case holds a single P: nothing repeats.
    several_p = (per_deck["P"].nunique() > 1).any()
    if not several_p or not (spread["min"] == spread["max"]).all():
        return rows
    return rows[~pd.concat(keys, axis=1).duplicated()].drop(columns="P")


def training_rows(data: pd.DataFrame, test: str, output: str) -> pd.DataFrame:
    """The rows a surrogate of ``output`` learns from: one per independent DEM reading.

    Runs that succeeded with a finite value (:func:`usable`), replicates averaged
    (:func:`replicate_means`), copies of one per-deck value over P merged
    (:func:`collapse_shared_loads`).

    Parameters
    ----------
    data : DataFrame
        The tidy bulk dataset.
    test : {"shear_cell", "angle_of_repose"}
        The virtual test that measures ``output``.
    output : str
        The bulk value.

    Returns
    -------
    DataFrame
    """
    rows = replicate_means(usable(data[data["test"] == test], output), output)
    return collapse_shared_loads(rows, output)


def ringing_notes(rows: pd.DataFrame) -> list[str]:
    """What a case's shear-cell rows say about a ringing servo lid, one note per phase kind.

    Parameters
    ----------
    rows : DataFrame
        The rows of one case (:func:`case_rows`); ``psh_lid_rings`` and ``sh_lid_rings``
        (bool, see :func:`demcal.virtual_tests.shear_cell.readout.lid_rings`) and ``cycle``
        where present.

    Returns
    -------
    list of str
        Empty when no phase rang (or the rows have no such flags).
    """
    notes = []
    for flag, phase in (("psh_lid_rings", "pre-shear"), ("sh_lid_rings", "shear")):
        if flag not in rows:
            continue
        rang = rows[flag].astype("boolean").fillna(False).to_numpy(dtype=bool)
        if rang.any():
            cycles = ", ".join(str(int(c)) for c in rows.loc[rang, "cycle"])
            notes.append(
                f"the servo lid rings in the {phase} of cycle(s) {cycles} (its force "
                "alternates between print steps, shaking the bed): lower shear_cell.servo_kp"
            )
    return notes


def write_case_rows(
    test: str,
    info: str | Path,
    p_values: Sequence[float],
    path: str,
    config: Mapping[str, Any],
    log: str,
) -> None:
    """Extract the bulk rows of one case (directory of ``info``, see :func:`case_rows`) and
    write them as CSV with a provenance sidecar (``<path>.json``); logs to ``log``."""
    with rule_log(log) as logger:
        rows = case_rows(test, Path(info).parent, extract, p_values)
        for note in ringing_notes(rows):
            logger.warning("%s: %s", Path(info).parent, note)
        rows.to_csv(path, index=False, float_format="%.10g")
        write_sidecar(path, config, seed=int(config["seed"]), extra={"rows": len(rows)})


def write_dataset(
    bulk_files: Sequence[str | Path],
    dataset: str | Path,
    failed: str | Path,
    config: Mapping[str, Any],
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Collect the bulk rows of every case into the tidy dataset and list the failed cases.

    Parameters
    ----------
    bulk_files : sequence of path
        ``bulk.csv`` of every case (:func:`write_case_rows`).
    dataset : path
        The tidy dataset (CSV), with a provenance sidecar ``<dataset>.json``.
    failed : path
        CSV of the failed cases: test, case_id, error.
    config : mapping
        The validated configuration (for the sidecar).

    Returns
    -------
    data : pandas.DataFrame
        The dataset, one row per case and load condition.
    failed_cases : pandas.DataFrame
        One row per failed case (kept in the dataset, excluded from training).
    """
    data = collect(pd.read_csv(path) for path in bulk_files)
    return data, write_collected(data, dataset, failed, config)


def write_collected(
    data: pd.DataFrame,
    dataset: str | Path,
    failed: str | Path,
    config: Mapping[str, Any],
    extra: Mapping[str, Any] | None = None,
) -> pd.DataFrame:
    """Write a collected dataset, its list of failed cases and its provenance sidecar.

    Parameters
    ----------
    data : DataFrame
        The tidy dataset (:func:`collect`).
    dataset, failed : path
        Outputs, as in :func:`write_dataset`.
    config : mapping
        The validated configuration (for the sidecar).
    extra : mapping, optional
        More sidecar fields (e.g. the round of a sequential study).

    Returns
    -------
    pandas.DataFrame
        One row per failed case.
    """
    data.to_csv(dataset, index=False, float_format="%.10g")
    bad = data[data["status"] != "ok"].drop_duplicates("case_id")
    bad[["test", "case_id", "error"]].to_csv(failed, index=False)
    write_sidecar(
        dataset,
        config,
        extra={
            "rows": len(data),
            "cases": int(data["case_id"].nunique()),
            "failed_cases": len(bad),
            **(extra or {}),
        },
    )
    return bad
