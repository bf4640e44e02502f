"""Synthetic "measured" data: the engine run at known parameters, optionally with noise.

The true parameters live in a file that the workflow never reads, so that tests can check that
the identification recovers them.
"""

import json
import tempfile
from collections.abc import Mapping, Sequence
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


def simulate_reference(
    parameters: Mapping[str, float], config: Mapping[str, Any], work_dir: str | Path
) -> pd.DataFrame:
    """Bulk values of both virtual tests at ``parameters`` (tidy rows; raises if a run fails)."""
    work_dir = Path(work_dir)
    frames = []
    cases: list[tuple[str, dict]] = [("angle_of_repose", {"case_id": "reference", **parameters})]
    for suffix in shear_suffixes(config):
        key = f"reference{suffix}"
        cases.append(("shear_cell", {"case_id": key, **parameters, **load_condition(config, key)}))
    for test, case in cases:
        frames.append(
            run_case_bulk(test, case, config, work_dir / test / case["case_id"], "reference run")
        )
    return pd.concat(frames, ignore_index=True)


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


def experiment_record(
    bulk: pd.DataFrame,
    material: str,
    noise: float,
    seed: int,
    source: str,
    observables: tuple[str, ...] = ("mu_psh", "mu_sh", "rho_b"),
    p_values: tuple[float, ...] | None = None,
) -> dict[str, Any]:
    """An experiment-file mapping from reference bulk values, with relative Gaussian noise.

    Parameters
    ----------
    bulk : DataFrame
        Output of :func:`simulate_reference`.
    noise : float
        Relative standard deviation of the measurement noise (e.g. 0.01), also written as sd.
    observables : tuple of str
        Shear-cell readings to keep (partial data, as a real test may give).
    p_values : tuple of float, optional
        Shear load fractions to keep; all when None.
    """
    rng = np.random.default_rng(seed)

    def noisy(value: float) -> float:
        return float(value * (1.0 + noise * rng.standard_normal())) if noise > 0 else float(value)

    record: dict[str, Any] = {"material": material, "source": source}
    aor = bulk[bulk["test"] == "angle_of_repose"]
    if len(aor) and np.isfinite(aor["aor"].iloc[0]):
        value = float(aor["aor"].iloc[0])
        record["angle_of_repose"] = {"value": round(noisy(value), 4), "sd": round(noise * value, 4)}
    conditions = []
    shear = bulk[bulk["test"] == "shear_cell"]
    if p_values is not None:
        shear = shear[shear["P"].round(6).isin([round(p, 6) for p in p_values])]
    for _, row in shear.sort_values(["normal_stress", "P"]).iterrows():
        entry: dict[str, float] = {
            "normal_stress": float(row["normal_stress"]),
            "P": float(row["P"]),
        }
        for name in observables:
            if np.isfinite(row[name]):
                entry[name] = round(noisy(float(row[name])), 6)
                entry[f"{name}_sd"] = round(noise * float(row[name]), 6)
        conditions.append(entry)
    if conditions:
        record["shear_cell"] = conditions
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
) -> Path:
    """Run the virtual tests at the true parameters of a truth file and write an experiment
    file.

    Parameters
    ----------
    config_path : path
        Workflow configuration (profile) the virtual tests run with.
    truth_path : path
        File with ``material`` and the true ``parameters``; it is not copied into the output.
    out_path : path
        Experiment file to write.
    noise, seed, observables, p_values
        As in :func:`experiment_record`.
    truth_engine : str, optional
        Command template of the truth runs (e.g. ``liggghts -in {deck}``), so that the
        measurements come from another code than the model under calibration; default the
        configuration's ``engine.command``.
    normal_stresses : sequence of float, optional
        Normal stresses (Pa) of the shear-cell truth runs, instead of the configuration's
        ``shear_cell.normal_stresses`` (one run per stress, so fewer stresses cost fewer runs).

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
        bulk = simulate_reference(truth["parameters"], config, tmp)
    record = experiment_record(
        bulk,
        f"{truth['material']} ({config['profile']} profile)",
        noise,
        seed,
        f"`{engine}` at the parameters of {Path(truth_path).name}, {config_path}{stresses}, "
        f"noise {noise:.1%}",
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
