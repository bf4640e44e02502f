"""Readout cross-check of a finished shear-cell deck: the wall readout against the contacts.

A deck rendered with ``shear_cell.contact_snapshots`` > 0 writes its particle-particle contacts
(``contacts.dump``) during every pre-shear and shear. :func:`plane_check` turns them into the
stresses across the shear plane (:mod:`demcal.virtual_tests.shear_cell.plane_stress`, split or
ring cell after the deck's ``case.json``) and sets their mean over each steady window beside
the wall-force reading of the same window; for a ring deck it can also split the plane into
bands of equal width, to show how uniform the stresses are that its torque readout takes as
uniform.
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import pandas as pd

from demcal.bulk.values import MissingOutputError, extract, read_case_record
from demcal.engine_io.fix_output import read_print_file
from demcal.virtual_tests.shear_cell.plane_stress import (
    band_profile,
    plane_stress_series,
    plateau_comparison,
)

__all__ = ["PlaneCheck", "plane_check"]


class PlaneCheck(NamedTuple):
    """The readout cross-check of one deck (see :func:`plane_check`)."""

    #: :func:`~demcal.virtual_tests.shear_cell.plane_stress.plateau_comparison`'s rows
    #: (``cycle``, ``phase``, ``snapshots``, ``mu_wall``, ``mu_plane``, ``mu_plane_sd``).
    windows: pd.DataFrame
    #: :func:`~demcal.virtual_tests.shear_cell.plane_stress.band_profile`'s rows (``cycle``,
    #: ``phase``, ``band``, ``r_lo``, ``r_hi`` (m), ``sigma`` (Pa), ``sigma_rel``, ``mu``,
    #: ``mu_annulus``, ``mu_wall``); None without bands.
    bands: pd.DataFrame | None


def plane_check(case_dir: str | Path, margin: float = 0.0, bands: int = 0) -> PlaneCheck:
    """Wall readout and contact stresses over every steady window of one shear deck, and for a
    ring deck optionally band by band across its plane.

    Parameters
    ----------
    case_dir : str or Path
        A finished shear-cell case directory with ``contacts.dump``.
    margin : float
        Distance kept from the cell's walls, m (see
        :func:`demcal.virtual_tests.shear_cell.plane_stress.plane_stress`).
    bands : int
        Ring decks: bands of equal width between the inner and the outer wall (0: none).

    Returns
    -------
    PlaneCheck
        The windows' comparison and, with ``bands``, the band profile; the contact dump is read
        once for both.

    Raises
    ------
    demcal.bulk.values.MissingOutputError
        No shear-cell deck, no contact dump (rendered without ``contact_snapshots``), or bands
        asked of a split-cell deck.
    """
    case_dir = Path(case_dir)
    record = read_case_record(case_dir)
    files = record.get("files", {})
    if record.get("test") != "shear_cell" or not record.get("setup", {}).get("contact_dump_every"):
        raise MissingOutputError(
            f"{case_dir}: not a shear-cell deck with contact snapshots "
            "(render it with shear_cell.contact_snapshots > 0)"
        )
    readout = record["readout"]
    if bands and not readout.get("inner_radius"):
        raise MissingOutputError(f"{case_dir}: bands need the ring cell (shear_cell.geometry)")
    dump = case_dir / files["contacts"]
    if not dump.is_file():
        raise MissingOutputError(f"{dump}: contact dump missing (did the run fail?)")
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
    values = extract("shear_cell", case_dir)
    profile = (
        band_profile(plane, values, readout["inner_radius"], readout["radius"], bands)
        if bands
        else None
    )
    return PlaneCheck(plateau_comparison(plane, values), profile)
