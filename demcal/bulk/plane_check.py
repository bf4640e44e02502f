"""Readout cross-check of a finished shear-cell deck: the wall readout against the contacts.

A deck rendered with ``shear_cell.contact_snapshots`` > 0 writes its particle-particle contacts
(``contacts.dump``) during every pre-shear and shear. :func:`plane_check` turns them into the
stresses across the shear plane (:mod:`demcal.virtual_tests.shear_cell.plane_stress`, split or
ring cell after the deck's ``case.json``) and sets their mean over each steady window beside
the wall-force reading of the same window.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from demcal.bulk.values import MissingOutputError, extract, read_case_record
from demcal.engine_io.fix_output import read_print_file
from demcal.virtual_tests.shear_cell.plane_stress import plane_stress_series, plateau_comparison

__all__ = ["plane_check"]


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
    case_dir = Path(case_dir)
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
    )
    return plateau_comparison(plane, extract("shear_cell", case_dir))
