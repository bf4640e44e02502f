"""The DEM cases of a study: design rows expanded to one case per virtual test run.

A shear-cell case is a design row at one pre-shear normal stress and, by default, one shear
load P (``c0003_s2_p1``); with ``shear_cell.separate_runs: false`` all P values run as cycles
in one deck (``c0003_s2``). An angle-of-repose case is a design row (``c0003``). With
``design.replicates`` = k > 1 every case also runs as replicates ``c0003_r2_s2_p1`` ...
``c0003_r<k>_s2_p1`` (``c0003_r2`` ... for the angle of repose), each from its own packing;
``design.repose_replicates`` sets the heaps' count apart. Wildcards carry these ids, never
floats.
"""

import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pandas as pd

from demcal.core.config import DESIGN_KEYS_BY_KIND
from demcal.core.provenance import write_sidecar
from demcal.design.build import build_design
from demcal.design.table import CASE_ID_COLUMN, write_design_table
from demcal.design.table import case_ids as numbered_ids

_SHEAR_KEY = re.compile(r"[A-Za-z0-9]+_s(?P<s>\d+)(_p(?P<p>\d+))?")
# A replicate's number follows the design row's id, before any load suffix.
_REPLICATE_PART = re.compile(r"_r(?P<r>[1-9]\d*)(?=_s\d|$)")


def design_replicates(config: Mapping[str, Any], test: str = "shear_cell") -> int:
    """DEM runs of every design case of ``test``.

    ``design.replicates`` (1 when absent); for the angle of repose ``design.repose_replicates``
    where given, since a heap costs a small fraction of a shear-cell set.
    """
    section = config["design"]
    shared = int(section.get("replicates", 1))
    heaps = section.get("repose_replicates")
    if test == "angle_of_repose" and heaps is not None:
        return int(heaps)
    return shared


def replicate_bases(run: str, count: int) -> list[str]:
    """Ids of ``count`` replicates of ``run``: ``run``, ``run_r2``, ..."""
    return [run] + [f"{run}_r{k}" for k in range(2, int(count) + 1)]


def with_replicates(
    config: Mapping[str, Any], bases: list[str], suffixes: list[str] | None = None
) -> list[str]:
    """Case ids of design rows ``bases`` with load ``suffixes`` (none: the angle of repose),
    each case followed by its replicate runs (``c0003_r2_s1_p1`` ...)."""
    k = design_replicates(config, "shear_cell" if suffixes else "angle_of_repose")
    return [
        f"{replicate}{suffix}"
        for base in bases
        for suffix in (suffixes or [""])
        for replicate in replicate_bases(base, k)
    ]


def replicate_of(case_id: str) -> tuple[str, int]:
    """The case a run id replicates and the replicate's number (1 for the case itself).

    Examples
    --------
    >>> replicate_of("c0003_r3_s2_p1")
    ('c0003_s2_p1', 3)
    >>> replicate_of("c0003")
    ('c0003', 1)
    """
    match = _REPLICATE_PART.search(case_id)
    if match is None:
        return case_id, 1
    return case_id[: match.start()] + case_id[match.end() :], int(match.group("r"))


def design_id(case_id: str) -> str:
    """The design row (parameter set) of a run id: ``c0003`` for ``c0003_r2_s2_p1``."""
    return replicate_of(case_id)[0].split("_s")[0]


def design_spec(section: Mapping[str, Any]) -> dict[str, Any]:
    """Reduce the validated ``design`` config section to the keys its kind uses."""
    keys = DESIGN_KEYS_BY_KIND[section["kind"]]
    return {k: section[k] for k in keys if k in section and section[k] != {}}


def design_from_config(config: Mapping[str, Any]) -> pd.DataFrame:
    """The design table (one row per parameter set) of a validated configuration.

    With ``design.repose_extra_sets`` = m > 0, the ``n`` shared sets are followed by m sets of
    a second design of the same kind and ranges drawn with ``design.seed + 1``, on which only
    the angle of repose runs; with ``design.shear_extra_sets`` = q > 0 by q sets of a third
    design drawn with ``design.seed + 2``, on which only the shear cell runs, at one normal
    stress each (:func:`case_ids`). The ids run on (``c0017 ...`` after 16).
    """
    section = config["design"]
    spec = design_spec(section)
    parts = [build_design(spec)]
    for offset, extra in enumerate((repose_extra_sets(config), shear_extra_sets(config)), 1):
        if extra:
            parts.append(build_design({**spec, "n": extra, "seed": int(section["seed"]) + offset}))
    if len(parts) == 1:
        return parts[0]
    table = pd.concat(parts, ignore_index=True)
    table[CASE_ID_COLUMN] = numbered_ids(len(table))
    return table


def every_set_runs_everything(config: Mapping[str, Any]) -> bool:
    """Whether every set of the design runs both tests at every stress: a factorial design,
    and a sequential study, whose rounds choose each set for both tests. The keys that thin a
    design (``repose_extra_sets``, ``shear_extra_sets``, ``shared_stresses``) are ignored
    there, as they are when a profile merged over the quick one inherits them."""
    kind = config["design"].get("kind")
    return kind == "factorial" or bool(config.get("sequential", {}).get("enabled"))


def repose_extra_sets(config: Mapping[str, Any]) -> int:
    """Sets of the design on which only the angle of repose runs (0 where
    :func:`every_set_runs_everything`)."""
    if every_set_runs_everything(config):
        return 0
    return int(config["design"].get("repose_extra_sets", 0))


def shear_extra_sets(config: Mapping[str, Any]) -> int:
    """Sets of the design on which only the shear cell runs, at one normal stress each (0 where
    :func:`every_set_runs_everything`)."""
    if every_set_runs_everything(config):
        return 0
    return int(config["design"].get("shear_extra_sets", 0))


def write_design(config: Mapping[str, Any], path: str | Path) -> pd.DataFrame:
    """Write the design table of a validated configuration as CSV with a provenance sidecar.

    Parameters
    ----------
    config : mapping
        The validated configuration (its ``design`` section and seed).
    path : str or Path
        Output CSV; parent directories are created. The sidecar is ``<path>.json``.

    Returns
    -------
    pandas.DataFrame
        The design table, one row per parameter set.
    """
    table = design_from_config(config)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    write_design_table(table, path)
    write_sidecar(path, config, seed=int(config["design"]["seed"]))
    return table


def case_ids(config: Mapping[str, Any], design: pd.DataFrame, test: str) -> list[str]:
    """Ids of the DEM cases of one test.

    Shear-cell cases run one pre-shear stress (``_s<k>``) and, with
    ``shear_cell.separate_runs``, one shear load P per deck (``_p<j>``); otherwise all P
    values run as cycles in one deck. The design's rows are the ``n`` shared sets (both tests,
    every stress unless ``design.shared_stresses`` is ``one``), then
    ``design.repose_extra_sets`` rows that run only the angle of repose, then
    ``design.shear_extra_sets`` rows that run only the shear cell at one stress each
    (:func:`one_stress_each`). Every case is followed by its replicate runs
    (:func:`with_replicates`).
    """
    ids = list(design[CASE_ID_COLUMN])
    heaps, shears = repose_extra_sets(config), shear_extra_sets(config)
    if test == "angle_of_repose":  # every row but the shear-only ones, which come last
        return with_replicates(config, ids[: len(ids) - shears])
    shared = ids[: len(ids) - heaps - shears]
    extra = one_stress_each(config, ids[len(ids) - shears :])
    if shared_stresses(config) == "one":
        return one_stress_each(config, shared) + extra
    return with_replicates(config, shared, shear_suffixes(config)) + extra


def one_stress_each(config: Mapping[str, Any], bases: list[str]) -> list[str]:
    """Shear-cell case ids of design rows ``bases`` at one pre-shear stress each: the j-th
    (from 0) at stress number ``j mod len(shear_cell.normal_stresses)`` + 1, with all its P
    values, each case followed by its replicate runs."""
    suffixes = shear_suffixes(config)
    n_stresses = len(config["shear_cell"]["normal_stresses"])
    cases: list[str] = []
    for j, base in enumerate(bases):
        stress = f"_s{j % n_stresses + 1}"
        one = [s for s in suffixes if s == stress or s.startswith(stress + "_")]
        cases += with_replicates(config, [base], one)
    return cases


def shared_stresses(config: Mapping[str, Any]) -> str:
    """``all`` or ``one``: the pre-shear stresses of the shared sets' shear-cell runs
    (``design.shared_stresses``; ``all`` where :func:`every_set_runs_everything`)."""
    if every_set_runs_everything(config):
        return "all"
    return str(config["design"].get("shared_stresses", "all"))


def shear_suffixes(config: Mapping[str, Any]) -> list[str]:
    """Case-id suffixes of the shear-cell runs of one parameter set."""
    cell = config["shear_cell"]
    stresses = range(1, len(cell["normal_stresses"]) + 1)
    if cell.get("separate_runs", False):
        return [f"_s{k}_p{j}" for k in stresses for j in range(1, len(cell["P"]) + 1)]
    return [f"_s{k}" for k in stresses]


def load_condition(config: Mapping[str, Any], key: str) -> dict[str, float]:
    """normal_stress (and P for a separate-run case) encoded in a shear-cell case id."""
    match = _SHEAR_KEY.fullmatch(replicate_of(key)[0])
    if match is None:
        raise KeyError(f"shear-cell case {key!r} has no _s<k> suffix")
    cell = config["shear_cell"]
    k = int(match.group("s")) - 1
    if not 0 <= k < len(cell["normal_stresses"]):
        raise KeyError(f"case {key!r}: no normal stress number {k + 1}")
    load = {"normal_stress": float(cell["normal_stresses"][k])}
    if match.group("p"):
        j = int(match.group("p")) - 1
        if not 0 <= j < len(cell["P"]):
            raise KeyError(f"case {key!r}: no P number {j + 1}")
        load["P"] = float(cell["P"][j])
    return load


def case_row(config: Mapping[str, Any], design: pd.DataFrame, test: str, key: str) -> dict:
    """The parameters of one case: its design row, plus the load condition for the shear cell
    and, for a replicate run (``c0003_r2_s1_p1``), its insertion seed (:func:`seed_of_replicate`).

    Raises
    ------
    KeyError
        When ``key`` is not a case of the design.
    """
    base = design_id(key)
    rows = design[design["case_id"] == base]
    if rows.empty:
        raise KeyError(f"case {key!r} is not in the design")
    row = {k: (v.item() if hasattr(v, "item") else v) for k, v in rows.iloc[0].items()}
    row["case_id"] = key
    replicate = replicate_of(key)[1]
    if replicate > 1:
        row["seed"] = seed_of_replicate(config, replicate)
    if test == "shear_cell":
        row.update(load_condition(config, key))
    return row


def verification_case(
    config: Mapping[str, Any], identified: Mapping[str, Any], test: str, key: str
) -> dict:
    """A case at the identified mean parameters (``identified`` or ``identified_s<k>``).

    Raises
    ------
    ValueError
        When no parameter set was identified.
    """
    params = identified.get("parameters") or {}
    if not params:
        raise ValueError("no parameter set was identified; nothing to verify")
    row: dict[str, Any] = {"case_id": key, **{k: float(v["mean"]) for k, v in params.items()}}
    row["seed"] = replicate_seed(config, key)
    if test == "shear_cell":
        row.update(load_condition(config, key))
    return row


#: Name of the engine of ``engine.command`` when ``verification.engines`` is empty.
CONFIGURED_ENGINE = "configured"


def verification_engines(config: Mapping[str, Any]) -> dict[str, str]:
    """The engines of the verification runs: name -> command template, in configured order.

    Parameters
    ----------
    config : mapping
        The validated configuration.

    Returns
    -------
    dict
        ``verification.engines``, or ``{"configured": engine.command}`` when that is empty.
    """
    engines = dict((config.get("verification") or {}).get("engines") or {})
    return engines or {CONFIGURED_ENGINE: config["engine"]["command"]}


def verification_threads(config: Mapping[str, Any]) -> int:
    """Threads or MPI ranks of one verification run (``verification.threads`` or
    ``engine.threads``)."""
    threads = (config.get("verification") or {}).get("threads")
    return int(threads if threads is not None else config["engine"]["threads"])


#: Seed offset between replicate verification runs (replicate k uses seed + k x this).
REPLICATE_SEED_STEP = 1000
_REPLICATE_KEY = re.compile(r"identified(?P<k>\d*)(_s\d+(_p\d+)?)?")


def verification_bases(config: Mapping[str, Any], test: str = "shear_cell") -> list[str]:
    """Base ids of the replicate verification runs of ``test``: ``identified``,
    ``identified2``, ... (``verification.seeds``; for the angle of repose
    ``verification.repose_seeds`` where given)."""
    section = config.get("verification") or {}
    seeds = section.get("seeds", 1)
    if test == "angle_of_repose" and section.get("repose_seeds") is not None:
        seeds = section["repose_seeds"]
    return ["identified"] + [f"identified{k}" for k in range(2, int(seeds) + 1)]


def verification_case_ids(config: Mapping[str, Any], test: str) -> list[str]:
    """Ids of the verification runs at the identified set (every replicate, every load)."""
    bases = verification_bases(config, test)
    if test == "angle_of_repose":
        return bases
    return [f"{base}{suffix}" for base in bases for suffix in shear_suffixes(config)]


def seed_of_replicate(config: Mapping[str, Any], k: int) -> int:
    """Insertion seed of replicate ``k`` (1-based) of a run: the configuration's seed for the
    first, then steps of :data:`REPLICATE_SEED_STEP`."""
    return int(config["seed"]) + (int(k) - 1) * REPLICATE_SEED_STEP


def replicate_seed(config: Mapping[str, Any], key: str) -> int:
    """Insertion seed of the verification run ``key``: the master seed for replicate 1, then
    ``seed + (k - 1) * REPLICATE_SEED_STEP`` for ``identified<k>``.

    Raises
    ------
    KeyError
        When ``key`` is not a verification case id.
    """
    match = _REPLICATE_KEY.fullmatch(key)
    if match is None:
        raise KeyError(f"{key!r} is not a verification case id")
    return seed_of_replicate(config, int(match.group("k") or 1))
