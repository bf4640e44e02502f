"""Shear-plane cross-check of the shear-cell readout: stresses from the contacts crossing the plane.

The wall-force readout (:mod:`demcal.virtual_tests.shear_cell.readout`) infers the stresses on
the shear plane from the forces on the cell's walls and lid. This module measures them inside
the bulk instead, from a ``pair/gran/local`` contact dump (columns ``pos id force``, see
:func:`demcal.engine_io.local_dump.pair_gran_local_columns`): a contact between particle centres
on either side of the plane ``z = z_shear`` carries force across it. Summing the force on the
upper particle of every such contact whose branch line crosses the plane inside the overlap of
the two cylinder sections, shrunk by ``margin`` from both walls, gives

``tau = |sum F_x| / A_m``, ``sigma = sum F_z / A_m``, ``mu_plane = tau / sigma``,

with ``A_m`` the overlap area of the shrunken circles (the area cancels in ``mu_plane``). Keeping
away from the walls leaves out the particles pinched at the rims of the split, so the two
readouts agree only when the wall effects are small.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from demcal.engine_io.local_dump import read_local_dump
from demcal.virtual_tests.shear_cell.readout import overlap_area

__all__ = ["CONTACT_COLUMNS", "plane_stress", "plane_stress_series"]

#: The twelve columns of the shear deck's contact dump (``pos id force``).
CONTACT_COLUMNS: tuple[str, ...] = (
    "x1", "y1", "z1", "x2", "y2", "z2", "id1", "id2", "periodic", "fx", "fy", "fz",
)  # fmt: skip


def plane_stress(
    contacts: pd.DataFrame, z_shear: float, radius: float, travel: float, margin: float
) -> dict[str, float]:
    """Shear and normal stress carried across the shear plane by one snapshot of contacts.

    Parameters
    ----------
    contacts : pandas.DataFrame
        Shape (n_contacts, 12), columns :data:`CONTACT_COLUMNS` (m, N; ``f`` is the force on
        particle 1 from particle 2).
    z_shear : float
        Height of the shear plane, m.
    radius : float
        Cell radius R, m.
    travel : float
        Offset of the lower part along x at the snapshot, m.
    margin : float
        Distance kept from both cylinder walls, m (``0 <= margin < R``).

    Returns
    -------
    dict
        ``n`` (contacts counted), ``area`` (m^2), ``tau``, ``sigma`` (Pa) and ``mu`` (-); the
        stresses are NaN when no contact crosses the evaluated area.

    Raises
    ------
    ValueError
        ``margin`` outside ``[0, R)``.
    """
    if not 0.0 <= margin < radius:
        raise ValueError(f"margin must lie in [0, R = {radius}), got {margin}")
    z1 = contacts["z1"].to_numpy(dtype=np.float64)
    z2 = contacts["z2"].to_numpy(dtype=np.float64)
    crossing = (z1 - z_shear) * (z2 - z_shear) < 0.0
    z1, z2 = z1[crossing], z2[crossing]
    t = (z_shear - z2) / (z1 - z2)
    x = contacts["x2"].to_numpy()[crossing] + t * (
        contacts["x1"].to_numpy()[crossing] - contacts["x2"].to_numpy()[crossing]
    )
    y = contacts["y2"].to_numpy()[crossing] + t * (
        contacts["y1"].to_numpy()[crossing] - contacts["y2"].to_numpy()[crossing]
    )
    inner = radius - margin
    inside = (x**2 + y**2 <= inner**2) & ((x - travel) ** 2 + y**2 <= inner**2)
    # Force on the upper particle from the lower one.
    sign = np.where(z1 > z_shear, 1.0, -1.0)[inside]
    fx = float(np.sum(sign * contacts["fx"].to_numpy()[crossing][inside]))
    fz = float(np.sum(sign * contacts["fz"].to_numpy()[crossing][inside]))
    area = float(overlap_area(inner, travel))
    n = int(inside.sum())
    if n == 0 or area <= 0.0:
        return {"n": n, "area": area, "tau": np.nan, "sigma": np.nan, "mu": np.nan}
    return {"n": n, "area": area, "tau": abs(fx) / area, "sigma": fz / area, "mu": abs(fx) / fz}


def plane_stress_series(
    dump: str | Path, table: pd.DataFrame, z_shear: float, radius: float, margin: float
) -> pd.DataFrame:
    """:func:`plane_stress` for every snapshot of a contact dump.

    Parameters
    ----------
    dump : str or Path
        The deck's contact dump (``contacts.dump``).
    table : pandas.DataFrame
        The print-file table (columns ``step``, ``time``, ``phase``, ``cycle``, ``travel``),
        which places each snapshot in time, phase and travel (nearest printed step at or
        before it).
    z_shear, radius, margin : float
        As in :func:`plane_stress`, m.

    Returns
    -------
    pandas.DataFrame
        One row per snapshot: ``step``, ``time`` (s), ``phase``, ``cycle``, ``travel`` (m),
        ``n``, ``area`` (m^2), ``tau``, ``sigma`` (Pa), ``mu`` (-).
    """
    steps = table["step"].to_numpy(dtype=np.int64)
    rows = []
    for step, contacts in read_local_dump(dump):
        contacts = contacts.set_axis(list(CONTACT_COLUMNS), axis=1)
        at = int(np.searchsorted(steps, step, side="right")) - 1
        if at < 0:
            continue
        row = table.iloc[at]
        rows.append(
            {
                "step": int(step),
                "time": float(row["time"]),
                "phase": int(row["phase"]),
                "cycle": int(row["cycle"]),
                "travel": float(row["travel"]),
                **plane_stress(contacts, z_shear, radius, float(row["travel"]), margin),
            }
        )
    return pd.DataFrame(rows)
