"""Synthetic "measured" data: the virtual tests run at known parameters, optionally with noise.

The true parameters live in a file that the workflow never reads, so that tests can check that
the identification recovers them. As a laboratory repeats a test, the stated value is the mean
of replicate runs from fresh packings, and its sd covers their scatter: one quick shear-cell run
scatters by 3-4 % in the friction values, as much as the acceptance tolerance.
"""

import json
import math
import tempfile
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml

from demcal.bulk.values import extract
from demcal.core.config import load_config
from demcal.design.cases import load_condition, shear_suffixes
from demcal.engine_io.run import engine_command, run_deck
from demcal.virtual_tests.deck import render_case

Case = tuple[str, dict[str, Any]]
"""A virtual test's name and its case row (``case_id``, parameters, load)."""


def run_replicates(
    cases_of: Callable[[int], Sequence[Case]],
    config: Mapping[str, Any],
    work_dir: str | Path,
    label: str,
    replicates: int = 1,
    workers: int = 1,
) -> pd.DataFrame:
    """Run the cases of every replicate, the r-th (from 0) with the configuration seed + r.

    Parameters
    ----------
    cases_of : callable
        Replicate number -> its cases; their ``case_id`` must differ between replicates.
    config : mapping
        Validated configuration the tests run with.
    work_dir : path
        Where the runs are made (``<work_dir>/<test>/<case_id>``); runs that finished there
        earlier are read back.
    label : str
        What a failed run is called in the error, e.g. ``"reference run"``.
    replicates : int
        Repetitions of every case, each from a fresh packing; column ``replicate`` numbers
        them.
    workers : int
        Runs at the same time.

    Returns
    -------
    DataFrame
        Tidy bulk-value rows with ``test`` and ``replicate`` columns.

    Raises
    ------
    RuntimeError
        When a run fails (names its directory).
    """
    items = [(test, case, r) for r in range(int(replicates)) for test, case in cases_of(r)]

    def run(item: tuple[str, dict[str, Any], int]) -> pd.DataFrame:
        test, case, r = item
        run_config = {**config, "seed": int(config["seed"]) + r}
        rows = run_case_bulk(test, case, run_config, Path(work_dir) / test / case["case_id"], label)
        rows["replicate"] = r
        return rows

    with ThreadPoolExecutor(max_workers=max(1, int(workers))) as pool:
        frames = list(pool.map(run, items))
    return pd.concat(frames, ignore_index=True)


def simulate_reference(
    parameters: Mapping[str, float],
    config: Mapping[str, Any],
    work_dir: str | Path,
    replicates: int = 1,
    workers: int = 1,
) -> pd.DataFrame:
    """Bulk values of both virtual tests at ``parameters`` (:func:`run_replicates`).

    Parameters
    ----------
    parameters : mapping
        Contact parameters (SI units) by name.
    config, work_dir, replicates, workers
        As for :func:`run_replicates`; the cases are named ``reference<r><suffix>``.
    """

    def cases_of(r: int) -> list[Case]:
        cases: list[Case] = [("angle_of_repose", {"case_id": f"reference{r}", **parameters})]
        for suffix in shear_suffixes(config):
            load = load_condition(config, f"reference{suffix}")
            cases.append(("shear_cell", {"case_id": f"reference{r}{suffix}", **parameters, **load}))
        return cases

    return run_replicates(cases_of, config, work_dir, "reference run", replicates, workers)


def finished_run(case_dir: Path) -> tuple[list[str], str, str] | None:
    """What a run that finished in ``case_dir`` ran: its command, ``case.json`` and deck text.

    None when there is none: no ``status.json``, a failed run, or files that do not parse.
    """
    try:
        status = json.loads((case_dir / "status.json").read_text())
        case_text = (case_dir / "case.json").read_text()
        deck = case_dir / Path(json.loads(case_text)["deck"]).name
        if status["status"] != "ok":
            return None
        return list(status["command"]), case_text, deck.read_text()
    except (OSError, ValueError, KeyError, TypeError):
        return None


def run_case_bulk(
    test: str,
    case: Mapping[str, Any],
    config: Mapping[str, Any],
    case_dir: Path,
    label: str,
) -> pd.DataFrame:
    """Render, run and read one case: its bulk-value rows with a ``test`` column.

    A run that finished earlier in ``case_dir`` with the same command, ``case.json`` and deck
    text is read back, not run again, so that an interrupted set of runs resumes where it
    stopped.

    Raises
    ------
    RuntimeError
        When the engine run fails (the message starts with ``label`` and names ``case_dir``).
    """
    earlier = finished_run(case_dir)
    info = render_case(test, case, config, case_dir)
    deck = Path(info["deck"]).name
    command = engine_command(config["engine"]["command"], deck, int(config["engine"]["threads"]))
    now = (command, (case_dir / "case.json").read_text(), (case_dir / deck).read_text())
    if earlier == now:
        status = json.loads((case_dir / "status.json").read_text())
    else:
        status = run_deck(
            case_dir, deck, config["engine"]["command"], int(config["engine"]["threads"])
        )
    if status["status"] != "ok":
        raise RuntimeError(f"{label} {case_dir} failed: {status['error']}")
    rows = extract(test, case_dir)
    rows["test"] = test
    return rows


def replicate_record(
    bulk: pd.DataFrame,
    material: str,
    noise: Mapping[str, float],
    seed: int,
    source: str,
    observables: Sequence[str] = ("mu_psh", "mu_sh", "rho_b"),
    p_values: Sequence[float] | None = None,
) -> dict[str, Any]:
    """An experiment-file mapping: the mean of the replicates with its standard deviation.

    Every value is the mean over the n replicate runs times (1 + noise_k * N(0, 1)); its sd is
    sqrt(s^2 / n + (noise_k * mean)^2) with s the sample standard deviation of the replicates (0
    for a single run): the standard error of the mean combined with the added noise, the
    uncertainty of the value that is stated.

    Parameters
    ----------
    bulk : DataFrame
        Output of :func:`simulate_reference` (or
        :func:`demcal.discrepancy.synthetic.hidden_effect_bulk`): bulk rows with ``test`` and
        ``replicate`` columns.
    noise : mapping
        Relative standard deviation of the added noise per observable (``mu_psh``, ``mu_sh``,
        ``rho_b``, ``aor``; a missing one gets none).
    observables : sequence of str
        Shear-cell readings to keep (partial data, as a real test may give).
    p_values : sequence of float, optional
        Shear load fractions to keep; all when None.
    """
    rng = np.random.default_rng(seed)

    def measured(values: pd.Series, name: str) -> tuple[float, float]:
        vals = values.dropna().to_numpy(float)
        mean = float(vals.mean())
        scatter = float(vals.std(ddof=1) / math.sqrt(vals.size)) if vals.size > 1 else 0.0
        level = float(noise.get(name, 0.0))
        value = mean * (1.0 + level * rng.standard_normal()) if level > 0 else mean
        return value, math.hypot(scatter, level * mean)

    record: dict[str, Any] = {"material": material, "source": source}
    aor = bulk[bulk["test"] == "angle_of_repose"]
    if len(aor) and aor["aor"].notna().any():
        value, sd = measured(aor["aor"], "aor")
        record["angle_of_repose"] = {"value": round(value, 4), "sd": round(sd, 4)}
    shear = bulk[bulk["test"] == "shear_cell"]
    if p_values is not None:
        shear = shear[shear["P"].round(6).isin([round(float(p), 6) for p in p_values])]
    conditions = []
    # Runs without a value (a phase that lost its load, no plateau) are left out of the mean,
    # as a laboratory discards a failed test, and the source says where.
    short = []
    for (stress, p), rows in shear.groupby(["normal_stress", "P"], sort=True):
        entry: dict[str, float] = {"normal_stress": float(stress), "P": float(p)}
        for name in observables:
            valid = int(rows[name].notna().sum())
            if valid < len(rows):
                short.append(f"{name} at {stress:g} Pa, P {p:g}: {valid} of {len(rows)}")
            if valid:
                value, sd = measured(rows[name], name)
                entry[name] = round(value, 6)
                entry[f"{name}_sd"] = round(sd, 6)
        conditions.append(entry)
    if conditions:
        record["shear_cell"] = conditions
    if short:
        record["source"] = f"{source}; runs with a value: {'; '.join(short)}"
    return record


def truth_run_config(
    config: Mapping[str, Any],
    truth_engine: str | None = None,
    normal_stresses: Sequence[float] | None = None,
) -> dict[str, Any]:
    """The configuration of the truth runs: ``config`` with another engine command and other
    shear-cell normal stresses where given (the input is not changed).

    Raises
    ------
    ValueError
        When a normal stress is not a positive finite number (Pa), or none is given.
    """
    out = dict(config)
    if truth_engine is not None:
        out["engine"] = {**config["engine"], "command": truth_engine}
    if normal_stresses is not None:
        values = [float(value) for value in normal_stresses]
        if not values or not all(np.isfinite(v) and v > 0 for v in values):
            raise ValueError(
                f"--normal-stresses {normal_stresses!r}: give one or more positive stresses in Pa"
            )
        out["shear_cell"] = {**config["shear_cell"], "normal_stresses": values}
    return out


def write_synthetic_experiment(
    config_path: str | Path,
    truth_path: str | Path,
    out_path: str | Path,
    noise: float = 0.0,
    seed: int = 1,
    observables: Sequence[str] = ("mu_psh", "mu_sh", "rho_b"),
    p_values: Sequence[float] | None = None,
    truth_engine: str | None = None,
    normal_stresses: Sequence[float] | None = None,
    replicates: int = 1,
    work_dir: str | Path | None = None,
    workers: int = 1,
) -> Path:
    """Run the virtual tests at the true parameters of a truth file and write an experiment
    file: the mean of ``replicates`` runs per value, with relative Gaussian ``noise`` added.

    Parameters
    ----------
    config_path : path
        Workflow configuration (profile) the virtual tests run with.
    truth_path : path
        File with ``material`` and the true ``parameters``; it is not copied into the output.
    out_path : path
        Experiment file to write.
    noise : float
        Relative standard deviation of the noise added to every value (e.g. 0.01).
    seed : int
        Seed of the noise.
    observables, p_values
        As in :func:`replicate_record`.
    truth_engine : str, optional
        Command template of the truth runs (e.g. ``liggghts -in {deck}``), so that the
        measurements come from another code than the model under calibration; default the
        configuration's ``engine.command``.
    normal_stresses : sequence of float, optional
        Normal stresses (Pa) of the shear-cell truth runs, instead of the configuration's
        ``shear_cell.normal_stresses`` (one run per stress, so fewer stresses cost fewer runs).
    replicates : int
        Truth runs per test, each from a fresh packing (:func:`simulate_reference`).
    work_dir : path, optional
        Where the truth runs are kept, so that an interrupted set resumes; a temporary
        directory when None.
    workers : int
        Truth runs at the same time.

    Returns
    -------
    Path
        ``out_path``.
    """
    config = truth_run_config(load_config(config_path), truth_engine, normal_stresses)
    stresses = ""
    if normal_stresses is not None:
        stresses = " at " + ", ".join(f"{value:g}" for value in normal_stresses) + " Pa"
    engine = str(config["engine"]["command"])
    truth = yaml.safe_load(Path(truth_path).read_text())
    with tempfile.TemporaryDirectory() as tmp:
        bulk = simulate_reference(
            truth["parameters"], config, work_dir or tmp, replicates=replicates, workers=workers
        )
    runs = f"mean of {replicates} runs" if replicates > 1 else "one run"
    record = replicate_record(
        bulk,
        f"{truth['material']} ({config['profile']} profile)",
        {name: noise for name in (*observables, "aor")},
        seed,
        f"`{engine}` at the parameters of {Path(truth_path).name}, {config_path}{stresses}, "
        f"{runs}, noise {noise:.1%}",
        observables=tuple(observables),
        p_values=tuple(float(p) for p in p_values) if p_values else None,
    )
    out = Path(out_path)
    out.write_text(
        "# Synthetic measurements made by scripts/make_synthetic_experiment.py; the true\n"
        "# parameters are kept apart and never read by the workflow.\n"
        + yaml.safe_dump(record, sort_keys=False)
    )
    return out
