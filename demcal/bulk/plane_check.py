"""Readout cross-check of a finished shear-cell deck: the wall readout against the contacts.

A deck rendered with ``shear_cell.contact_snapshots`` > 0 writes its particle-particle contacts
(``contacts.dump``) during every pre-shear and shear. :func:`plane_check` turns them into the
stresses across the shear plane (:mod:`demcal.virtual_tests.shear_cell.plane_stress`, split or
ring cell after the deck's ``case.json``) and sets their mean over each steady window beside
the wall-force reading of the same window; :func:`band_check` splits the ring's plane into
bands of equal width to show how uniform the stresses are that its torque readout takes as
uniform.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from demcal.bulk.values import MissingOutputError, extract, read_case_record
from demcal.engine_io.fix_output import read_print_file
from demcal.virtual_tests.shear_cell.plane_stress import (
    band_profile,
    plane_stress_series,
    plateau_comparison,
)

__all__ = ["band_check", "plane_check"]


def _snapshots(
    case_dir: Path, margin: float, bands: int
) -> tuple[pd.DataFrame, pd.DataFrame, dict]:
    """The deck's contact snapshots across the plane, its bulk values and its readout record."""
    record = read_case_record(case_dir)
    files = record.get("files", {})
    if record.get("test") != "shear_cell" or not record.get("setup", {}).get("contact_dump_every"):
        raise MissingOutputError(
            f"{case_dir}: not a shear-cell deck with contact snapshots "
            "(render it with shear_cell.contact_snapshots > 0)"
        )
    dump = case_dir / files["contacts"]
    if not dump.is_file():
        raise MissingOutputError(f"{dump}: contact dump missing (did the run fail?)")
    readout = record["readout"]
    table = read_print_file(case_dir / files["table"])
    plane = plane_stress_series(
        dump,
        table,
        readout["z_shear"],
        readout["radius"],
        margin,
        inner_radius=readout.get("inner_radius"),
        bands=bands,
    )
    return plane, extract("shear_cell", case_dir), readout


def plane_check(case_dir: str | Path, margin: float = 0.0) -> pd.DataFrame:
    """Wall readout and contact stresses over every steady window of one shear deck.

    Parameters
    ----------
    case_dir : str or Path
        A finished shear-cell case directory with ``contacts.dump``.
    margin : float
        Distance kept from the cell's walls, m (see
        :func:`demcal.virtual_tests.shear_cell.plane_stress.plane_stress`).

    Returns
    -------
    pandas.DataFrame
        :func:`~demcal.virtual_tests.shear_cell.plane_stress.plateau_comparison`'s rows
        (``cycle``, ``phase``, ``snapshots``, ``mu_wall``, ``mu_plane``, ``mu_plane_sd``).

    Raises
    ------
    demcal.bulk.values.MissingOutputError
        No shear-cell deck, or no contact dump (rendered without ``contact_snapshots``).
    """
    plane, values, _ = _snapshots(Path(case_dir), margin, 0)
    return plateau_comparison(plane, values)


def band_check(case_dir: str | Path, bands: int = 3) -> pd.DataFrame:
    """Normal stress and friction band by band across a ring deck's shear plane.

    Parameters
    ----------
    case_dir : str or Path
        A finished ring shear-cell case directory with ``contacts.dump``.
    bands : int
        Bands of equal width between the inner and the outer wall (>= 1).

    Returns
    -------
    pandas.DataFrame
        :func:`~demcal.virtual_tests.shear_cell.plane_stress.band_profile`'s rows (``cycle``,
        ``phase``, ``band``, ``r_lo``, ``r_hi`` (m), ``sigma`` (Pa), ``sigma_rel``, ``mu``,
        ``mu_annulus``, ``mu_wall``).

    Raises
    ------
    demcal.bulk.values.MissingOutputError
        As :func:`plane_check`, or a split-cell deck.
    """
    plane, values, readout = _snapshots(Path(case_dir), 0.0, bands)
    if not readout.get("inner_radius"):
        raise MissingOutputError(f"{case_dir}: bands need the ring cell (shear_cell.geometry)")
    return band_profile(plane, values, readout["inner_radius"], readout["radius"], bands)
