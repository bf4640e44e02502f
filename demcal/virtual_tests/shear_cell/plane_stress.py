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

The ring cell turns about the z axis, so its shear force is azimuthal: :func:`ring_plane_stress`
sums the torque ``T = sum (x F_y - y F_x)`` of the same forces about the axis, with the lever arm
at the crossing point, over the contacts crossing inside the annulus ``R_i + margin <= r <=
R - margin``, and takes the shear stress uniform over it as the wall readout does:
``tau = 3 |T| / (2 pi (R_o^3 - R_in^3))`` and ``sigma = sum F_z / (pi (R_o^2 - R_in^2))`` with
the shrunken radii ``R_in = R_i + margin`` and ``R_o = R - margin``.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd

from demcal.engine_io.local_dump import read_local_dump
from demcal.virtual_tests.shear_cell.readout import overlap_area

__all__ = [
    "CONTACT_COLUMNS",
    "band_profile",
    "plane_stress",
    "plane_stress_series",
    "plateau_comparison",
    "ring_band_forces",
    "ring_plane_stress",
]

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
    x, y, force = _crossings(contacts, z_shear)
    inner = radius - margin
    inside = (x**2 + y**2 <= inner**2) & ((x - travel) ** 2 + y**2 <= inner**2)
    fx = float(np.sum(force[inside, 0]))
    fz = float(np.sum(force[inside, 2]))
    area = float(overlap_area(inner, travel))
    return _stresses(int(inside.sum()), area, abs(fx) / area if area > 0.0 else np.nan, fz)


def ring_plane_stress(
    contacts: pd.DataFrame, z_shear: float, inner_radius: float, radius: float, margin: float
) -> dict[str, float]:
    """Shear and normal stress across the ring cell's shear plane from one snapshot of contacts.

    Parameters
    ----------
    contacts : pandas.DataFrame
        Shape (n_contacts, 12), columns :data:`CONTACT_COLUMNS` (m, N; ``f`` is the force on
        particle 1 from particle 2).
    z_shear : float
        Height of the shear plane, m.
    inner_radius, radius : float
        Inner and outer radius of the annulus, R_i and R, m.
    margin : float
        Distance kept from both walls, m (``0 <= 2 margin < R - R_i``).

    Returns
    -------
    dict
        ``n`` (contacts counted), ``area`` (m^2, of the shrunken annulus), ``torque`` (N m,
        about the cell axis, on the bulk above the plane), ``tau``, ``sigma`` (Pa) and ``mu``
        (-); the stresses are NaN when no contact crosses the evaluated annulus.

    Raises
    ------
    ValueError
        ``margin`` negative or leaving no annulus.
    """
    if not (margin >= 0.0 and 2.0 * margin < radius - inner_radius):
        raise ValueError(
            f"margin must lie in [0, (R - R_i) / 2 = {(radius - inner_radius) / 2}), got {margin}"
        )
    x, y, force = _crossings(contacts, z_shear)
    r_in, r_out = inner_radius + margin, radius - margin
    reach2 = x**2 + y**2
    inside = (reach2 >= r_in**2) & (reach2 <= r_out**2)
    torque = float(np.sum(x[inside] * force[inside, 1] - y[inside] * force[inside, 0]))
    fz = float(np.sum(force[inside, 2]))
    area = float(np.pi * (r_out**2 - r_in**2))
    tau = 3.0 * abs(torque) / (2.0 * np.pi * (r_out**3 - r_in**3))
    return {**_stresses(int(inside.sum()), area, tau, fz), "torque": torque}


def ring_band_forces(
    contacts: pd.DataFrame, z_shear: float, inner_radius: float, radius: float, bands: int
) -> dict[str, float]:
    """Azimuthal and normal force across the ring's shear plane in bands of equal width.

    Parameters
    ----------
    contacts : pandas.DataFrame
        Shape (n_contacts, 12), columns :data:`CONTACT_COLUMNS` (m, N).
    z_shear : float
        Height of the shear plane, m.
    inner_radius, radius : float
        Inner and outer radius of the annulus, R_i and R, m.
    bands : int
        Number of bands between R_i and R (>= 1).

    Returns
    -------
    dict
        ``azimuthal_force_<k>`` and ``normal_force_<k>`` for k = 0 (innermost) ... bands - 1, N:
        the sums over the contacts crossing the plane in band k of the force on the upper
        particle along the azimuth (at the crossing point) and along z.
    """
    if bands < 1:
        raise ValueError(f"bands must be >= 1, got {bands}")
    x, y, force = _crossings(contacts, z_shear)
    reach = np.hypot(x, y)
    with np.errstate(divide="ignore", invalid="ignore"):
        azimuthal = np.where(reach > 0.0, (x * force[:, 1] - y * force[:, 0]) / reach, 0.0)
    edges = np.linspace(inner_radius, radius, bands + 1)
    band = np.searchsorted(edges, reach, side="right") - 1
    out: dict[str, float] = {}
    for k in range(bands):
        # The outer edge belongs to the last band.
        inside = (band == k) | ((k == bands - 1) & (reach == radius))
        out[f"azimuthal_force_{k}"] = float(np.sum(azimuthal[inside]))
        out[f"normal_force_{k}"] = float(np.sum(force[inside, 2]))
    return out


def _crossings(contacts: pd.DataFrame, z_shear: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where the branch lines crossing ``z = z_shear`` pierce it, and the force on the upper one.

    Returns
    -------
    x, y : numpy.ndarray
        Shape (n_crossing,), the crossing points, m.
    force : numpy.ndarray
        Shape (n_crossing, 3), the force on the particle above the plane from the one below, N.
    """
    z1 = contacts["z1"].to_numpy(dtype=np.float64)
    z2 = contacts["z2"].to_numpy(dtype=np.float64)
    crossing = (z1 - z_shear) * (z2 - z_shear) < 0.0
    z1, z2 = z1[crossing], z2[crossing]
    t = (z_shear - z2) / (z1 - z2)
    at = {k: contacts[k].to_numpy(dtype=np.float64)[crossing] for k in ("x1", "y1", "x2", "y2")}
    x = at["x2"] + t * (at["x1"] - at["x2"])
    y = at["y2"] + t * (at["y1"] - at["y2"])
    # The dump gives the force on particle 1; on the upper particle it is that or its opposite.
    sign = np.where(z1 > z_shear, 1.0, -1.0)
    force = sign[:, None] * contacts[["fx", "fy", "fz"]].to_numpy(dtype=np.float64)[crossing]
    return x, y, force


def _stresses(n: int, area: float, tau: float, normal: float) -> dict[str, float]:
    """The result row of a plane: NaN stresses when no contact crosses the evaluated area."""
    if n == 0 or area <= 0.0:
        return {"n": n, "area": area, "tau": np.nan, "sigma": np.nan, "mu": np.nan}
    sigma = normal / area
    return {"n": n, "area": area, "tau": tau, "sigma": sigma, "mu": tau / sigma}


def plane_stress_series(
    dump: str | Path,
    table: pd.DataFrame,
    z_shear: float,
    radius: float,
    margin: float,
    inner_radius: float | None = None,
    bands: int = 0,
) -> pd.DataFrame:
    """:func:`plane_stress` (or :func:`ring_plane_stress`) for every snapshot of a contact dump.

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
    inner_radius : float, optional
        Inner radius R_i of the ring cell, m; None or 0 for the split cell.
    bands : int
        For the ring, also :func:`ring_band_forces` in this many bands (0: none).

    Returns
    -------
    pandas.DataFrame
        One row per snapshot: ``step``, ``time`` (s), ``phase``, ``cycle``, ``travel`` (m),
        ``n``, ``area`` (m^2), ``tau``, ``sigma`` (Pa), ``mu`` (-); for the ring also
        ``torque`` (N m) and, with ``bands``, the band forces (N).
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
                **(
                    ring_plane_stress(contacts, z_shear, inner_radius, radius, margin)
                    if inner_radius
                    else plane_stress(contacts, z_shear, radius, float(row["travel"]), margin)
                ),
                **(
                    ring_band_forces(contacts, z_shear, inner_radius, radius, bands)
                    if inner_radius and bands
                    else {}
                ),
            }
        )
    return pd.DataFrame(rows)


def _windows(
    plane: pd.DataFrame, values: pd.DataFrame
) -> Iterator[tuple[pd.Series, str, str, pd.DataFrame]]:
    """The snapshots inside every steady window: (row of ``values``, ``psh`` or ``sh``, the
    wall reading's column, snapshots)."""
    for _, row in values.iterrows():
        in_cycle = plane[plane["cycle"] == row["cycle"]]
        for phase, key, wall in ((1, "psh", "mu_psh_cycle"), (3, "sh", "mu_sh")):
            window = in_cycle[
                (in_cycle["phase"] == phase)
                & (in_cycle["time"] >= row[f"{key}_t_start"])
                & (in_cycle["time"] <= row[f"{key}_t_end"])
            ]
            yield row, key, wall, window


def plateau_comparison(plane: pd.DataFrame, values: pd.DataFrame) -> pd.DataFrame:
    """The contacts' mu over each steady window of a deck beside the wall readout's.

    Parameters
    ----------
    plane : pandas.DataFrame
        The snapshots of :func:`plane_stress_series`.
    values : pandas.DataFrame
        The deck's shear-cell rows (:func:`demcal.bulk.values.extract`): ``cycle``, the windows
        ``psh_t_start`` ... ``sh_t_end`` (s), ``mu_sh`` and the cycle's own pre-shear reading
        ``mu_psh_cycle`` (``mu_psh`` is the deck's mean over its cycles).

    Returns
    -------
    pandas.DataFrame
        One row per cycle and phase: ``cycle``, ``phase`` (``psh`` or ``sh``), ``snapshots``
        (in the window), ``mu_wall``, ``mu_plane`` (their mean) and ``mu_plane_sd`` (their
        standard deviation), all mu dimensionless; NaN without a snapshot in the window.
    """
    rows = []
    for row, key, wall, window in _windows(plane, values):
        mu = window["mu"]
        rows.append(
            {
                "cycle": int(row["cycle"]),
                "phase": key,
                "snapshots": len(mu),
                "mu_wall": float(row[wall]),
                "mu_plane": float(mu.mean()) if len(mu) else np.nan,
                "mu_plane_sd": float(mu.std()) if len(mu) > 1 else np.nan,
            }
        )
    return pd.DataFrame(rows)


def band_profile(
    plane: pd.DataFrame, values: pd.DataFrame, inner_radius: float, radius: float, bands: int
) -> pd.DataFrame:
    """Normal stress and friction across the ring's shear plane band by band, per steady window.

    The ring's readout takes the shear stress uniform over the annulus; this profile shows how
    far it is.

    Parameters
    ----------
    plane : pandas.DataFrame
        The snapshots of :func:`plane_stress_series` with ``bands`` band forces.
    values : pandas.DataFrame
        The deck's shear-cell rows, as for :func:`plateau_comparison`.
    inner_radius, radius : float
        R_i and R, m.
    bands : int
        Number of bands in ``plane``.

    Returns
    -------
    pandas.DataFrame
        One row per cycle, phase and band: ``cycle``, ``phase``, ``band`` (0 innermost),
        ``r_lo``, ``r_hi`` (m), ``sigma`` (Pa, the band's mean normal stress over the window),
        ``sigma_rel`` (over the whole annulus's), ``mu`` (sum of azimuthal over sum of normal
        force in the band), ``mu_annulus`` (the same over the whole annulus: the contacts'
        friction without the uniform-stress assumption) and ``mu_wall`` (the torque readout).
    """
    edges = np.linspace(inner_radius, radius, bands + 1)
    area = np.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    rows = []
    for row, key, wall, window in _windows(plane, values):
        if window.empty:
            continue
        azimuthal = np.array([window[f"azimuthal_force_{k}"].sum() for k in range(bands)])
        normal = np.array([window[f"normal_force_{k}"].sum() for k in range(bands)])
        sigma = normal / len(window) / area
        mean_sigma = normal.sum() / len(window) / area.sum()
        for k in range(bands):
            rows.append(
                {
                    "cycle": int(row["cycle"]),
                    "phase": key,
                    "band": k,
                    "r_lo": float(edges[k]),
                    "r_hi": float(edges[k + 1]),
                    "sigma": float(sigma[k]),
                    "sigma_rel": float(sigma[k] / mean_sigma),
                    "mu": float(abs(azimuthal[k]) / normal[k]),
                    "mu_annulus": float(abs(azimuthal.sum()) / normal.sum()),
                    "mu_wall": float(row[wall]),
                }
            )
    return pd.DataFrame(rows)
