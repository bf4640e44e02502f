"""Bulk values of one rendered and run case of a virtual bulk test.

:func:`extract` reads ``case.json`` (written by :func:`demcal.virtual_tests.deck.render_case`)
and the engine outputs in the case directory and returns the bulk values as a table:

* shear cell: one row per load condition (cycle) with ``case_id``, ``test`` ("shear_cell"),
  ``normal_stress`` (Pa), ``P`` (-), ``mu_psh``, ``mu_sh`` (-), ``rho_b`` (kg/m^3),
  ``steady_psh``, ``steady_sh`` (bool), ``status`` and diagnostics (``cycle``, standard
  errors, plateau windows, the detector's reasons);
* angle of repose: one row with ``case_id``, ``test`` ("repose"), ``aor`` (degrees, slice /
  convex-hull method), ``aor_mean_slices``, ``aor_fit``, the per-sector angles ``aor_sector_k``
  and their spread ``aor_sector_spread`` (sample standard deviation) and range, the heap height
  (m), the particle counts and ``settled`` (the kinetic energy at the end is negligible).

A missing or truncated output raises :class:`MissingOutputError` (a ``ValueError``) naming the
file.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from demcal.core.parameters import GRAVITY
from demcal.decks.render import CASE_FILE
from demcal.engine_io.dump_file import read_dump_last
from demcal.engine_io.fix_output import read_print_file
from demcal.virtual_tests.angle_of_repose.readout import angle_of_repose
from demcal.virtual_tests.shear_cell.readout import required_columns, shear_cell_bulk_values

__all__ = [
    "REPOSE_COLUMNS",
    "SETTLED_ENERGY_RATIO",
    "SHEAR_COLUMNS",
    "MissingOutputError",
    "extract",
    "read_case_record",
]


#: Leading columns of the shear-cell table (diagnostics follow).
SHEAR_COLUMNS = (
    "case_id",
    "test",
    "normal_stress",
    "P",
    "mu_psh",
    "mu_sh",
    "rho_b",
    "steady_psh",
    "steady_sh",
    "status",
)
#: Leading columns of the angle-of-repose table (per-sector angles follow).
REPOSE_COLUMNS = (
    "case_id",
    "test",
    "aor",
    "aor_mean_slices",
    "aor_fit",
    "aor_sector_spread",
    "aor_sector_min",
    "aor_sector_max",
    "heap_height",
    "n_particles_heap",
    "n_particles_final",
    "ke_final",
    "settled",
    "status",
)

#: A heap counts as settled when its kinetic energy at the end is below this fraction of
#: ``N m g d`` (N particles of the mean mass m lifted by one mean diameter d).
SETTLED_ENERGY_RATIO = 1e-5


class MissingOutputError(ValueError):
    """An engine output or ``case.json`` is missing, incomplete or inconsistent."""


def read_case_record(case_dir: Path) -> dict[str, Any]:
    """Content of ``case_dir/case.json``.

    Raises
    ------
    MissingOutputError
        If the file is missing or not valid JSON (the message names the file).
    """
    path = Path(case_dir) / CASE_FILE
    if not path.is_file():
        raise MissingOutputError(f"{path}: no case description (render the case first)")
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise MissingOutputError(f"{path}: not valid JSON ({exc})") from exc
    for key in ("test", "case_id", "case", "files", "setup", "readout"):
        if key not in record:
            raise MissingOutputError(f"{path}: missing key '{key}'")
    return record


def _output(case_dir: Path, record: Mapping[str, Any], key: str) -> Path:
    path = Path(case_dir) / record["files"][key]
    if not path.is_file():
        raise MissingOutputError(f"{path}: engine output missing (did the run fail?)")
    return path


def _check_complete(table: pd.DataFrame, path: Path, total_steps: int, every: int) -> None:
    last = int(table["step"].max()) if len(table) else -1
    expected = (total_steps // every) * every
    if last < expected:
        raise MissingOutputError(
            f"{path}: truncated, the last row is step {last} but the run ends at step {total_steps}"
        )


def _shear_cell(case_dir: Path, record: Mapping[str, Any]) -> pd.DataFrame:
    setup = record["setup"]
    readout = record["readout"]
    path = _output(case_dir, record, "table")
    # Case records written before the ring cell have no inner radius.
    inner = float(readout.get("inner_radius", 0.0))
    # Case records written before the interior region measure the whole cell.
    interior = readout.get("bulk_density", "cell") == "interior"
    table = read_print_file(path, columns=[*required_columns(inner, interior), "step"])
    _check_complete(table, path, int(setup["total_steps"]), int(setup["print_every"]))
    values = shear_cell_bulk_values(
        table,
        float(readout["radius"]),
        float(readout["z_floor"]),
        float(readout["z_shear"]),
        float(readout["gravity"]),
        inner_radius=inner,
        interior_volume=float(readout["interior_volume"]) if interior else None,
        min_fraction=float(readout["min_fraction"]),
    )
    cycles = setup["cycles"]
    found = sorted(int(c) for c in values["cycle"])
    if found != list(range(len(cycles))):
        raise MissingOutputError(
            f"{path}: expected cycles 0..{len(cycles) - 1}, found {found or 'none'}"
        )
    values = values.sort_values("cycle").reset_index(drop=True)
    values = _preshear_point(values)
    # The load condition as specified, not as re-derived from printed forces.
    values["P"] = [float(c["P"]) for c in cycles]
    values["normal_stress"] = float(setup["normal_stress"])
    values.insert(0, "case_id", str(record["case_id"]))
    values.insert(1, "test", "shear_cell")
    values["status"] = "ok"
    rest = [c for c in values.columns if c not in SHEAR_COLUMNS]
    return values[[*SHEAR_COLUMNS, *rest]]


def _preshear_point(values: pd.DataFrame) -> pd.DataFrame:
    """The pre-shear point of a deck's yield locus: mu_psh and rho_b as the means over the
    pre-shears of all its cycles.

    Every cycle pre-shears at the same normal stress, so its readings measure the yield locus's
    single pre-shear point again, and their mean scatters half as much over four cycles. (A
    polydisperse bed segregates as it is sheared and its readings drift by a few per cent from
    the first cycle to the last, see docs/virtual-tests.md.) Each cycle's own reading stays in
    ``mu_psh_cycle`` and ``rho_b_cycle``; a cycle without a steady pre-shear plateau (NaN)
    does not count.
    """
    out = values.copy()
    for key in ("mu_psh", "rho_b"):
        readings = out[key].to_numpy(dtype=np.float64)
        out[f"{key}_cycle"] = readings
        finite = readings[np.isfinite(readings)]
        if len(out) > 1 and finite.size:
            out[key] = float(finite.mean())
    return out


def _repose(case_dir: Path, record: Mapping[str, Any]) -> pd.DataFrame:
    setup = record["setup"]
    readout = record["readout"]
    table_path = _output(case_dir, record, "table")
    table = read_print_file(table_path, columns=["step", "atoms", "ke"])
    _check_complete(table, table_path, int(setup["total_steps"]), int(setup["print_every"]))
    dump_path = _output(case_dir, record, "dump")
    snap = read_dump_last(dump_path, columns=["x", "y", "z", "radius", "c_cn"])
    atoms = snap.atoms
    result = angle_of_repose(
        atoms[["x", "y", "z"]].to_numpy(dtype=np.float64),
        atoms["radius"].to_numpy(dtype=np.float64),
        tuple(readout["centre_xy"]),
        float(readout["base_z"]),
        contacts=atoms["c_cn"].to_numpy(dtype=np.float64),
        n_slices=int(readout["n_slices"]),
        n_sectors=int(readout["n_sectors"]),
        min_contacts=int(readout["min_contacts"]),
    )
    particles = record["particles"]
    density = float(record["material"]["density"])
    mean_mass = density * float(particles["mean_particle_volume"])
    diameter = 2.0 * float(particles["mass_mean_radius"])
    n_final = len(atoms)
    ke_final = float(table["ke"].iloc[-1])
    scale = max(n_final, 1) * mean_mass * GRAVITY * diameter
    sectors = result.sector_angles_deg
    finite = sectors[np.isfinite(sectors)]
    row: dict[str, Any] = {
        "case_id": str(record["case_id"]),
        "test": "repose",
        "aor": result.angle_deg,
        "aor_mean_slices": result.angle_mean_slices_deg,
        "aor_fit": result.angle_fit_deg,
        "aor_sector_spread": result.sector_spread_deg,
        "aor_sector_min": float(finite.min()) if finite.size else float("nan"),
        "aor_sector_max": float(finite.max()) if finite.size else float("nan"),
        "heap_height": result.heap_height,
        "n_particles_heap": result.n_particles,
        "n_particles_final": n_final,
        "ke_final": ke_final,
        "settled": bool(ke_final < SETTLED_ENERGY_RATIO * scale),
        "status": "ok",
    }
    for k, angle in enumerate(sectors):
        row[f"aor_sector_{k}"] = float(angle)
    return pd.DataFrame([row])


def extract(test: str, case_dir: Path) -> pd.DataFrame:
    """Bulk values of one case from its directory.

    Parameters
    ----------
    test : {"shear_cell", "angle_of_repose"}
        Which test the case directory holds.
    case_dir : Path
        Directory written by :func:`demcal.virtual_tests.deck.render_case` in which the engine
        has run.

    Returns
    -------
    pandas.DataFrame
        Shear cell: one row per load condition (mu_psh and rho_b are the deck's pre-shear
        point, the mean over its cycles), columns :data:`SHEAR_COLUMNS` then
        diagnostics. Angle of repose: one row, columns :data:`REPOSE_COLUMNS` then
        ``aor_sector_0 ...`` (degrees).

    Raises
    ------
    ValueError
        For an unknown test, or a case directory of another test.
    MissingOutputError
        For a missing or truncated output file or ``case.json`` (names the file).
    demcal.engine_io.output_errors.EngineOutputError
        For a malformed output file (names the file and line).
    """
    if test not in ("shear_cell", "angle_of_repose"):
        raise ValueError(f"unknown test {test!r}; expected 'shear_cell' or 'angle_of_repose'")
    case_dir = Path(case_dir)
    record = read_case_record(case_dir)
    if record["test"] != test:
        raise ValueError(
            f"{case_dir / CASE_FILE}: the case is a {record['test']!r} case, not {test!r}"
        )
    if test == "shear_cell":
        return _shear_cell(case_dir, record)
    return _repose(case_dir, record)
