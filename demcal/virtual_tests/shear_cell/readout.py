"""Bulk values of the virtual Schulze shear test: mu_psh, mu_sh and rho_b per pre-shear cycle.

Input is the table of the deck's ``fix print`` file (read by
:func:`demcal.engine_io.fix_output.read_print_file`), one row per print step, with the columns

====================  ======================================================================
time                  s
phase                 0 settle, 1 pre-shear, 2 unload, 3 shear
cycle                 0, 1, 2, ... one per pre-shear/shear cycle
lid_z                 m, lid height
lid_force             N, normal force of the particles on the lid (positive)
shear_force           N, horizontal force along the shear direction on the moving lower part
                      (floor and tube) plus that on the fixed upper flange: the force the bulk
                      carries across the shear plane (see below)
travel                m, offset of the moving part against the upper ring (the ring cell:
                      distance turned along the mean circle, which in the continue mode grows
                      over all cycles; not used by the ring's readout)
mass                  kg, particle mass in the cell
target_force          N, the servo's target lid force in that phase
upper_force_z         N, vertical force of the particles on the fixed upper tube (positive up)
lower_flange_force_z  N, vertical force of the particles on the moving lower flange (positive
                      up)
====================  ======================================================================

The split-cylinder cell of radius ``R`` has its floor at ``z_floor`` and its shear plane at
``z_shear``. With ``A(s)`` the overlap area of the two cylinder sections shifted by the travel
``s``, the bulk above the shear plane is in equilibrium under the lid force, its weight, the
upper tube and the lower flange (on the crescent that the moving part uncovers) and the bulk
below, so the normal force the bulk carries across the overlap area is

``N = lid_force + rho_b g pi R^2 (lid_z - z_shear) + upper_force_z + lower_flange_force_z``.

The upper-tube term is the wall friction: while the sheared bed dilates the tube holds it down
(positive), while it compacts the tube carries part of the load (negative). Ignoring it, as a
readout from lid force and weight alone does, overstates mu by the ratio of the two normal
forces (a factor near 2 in a narrow cell of tall fill). Likewise the moving flange's friction on
the bulk above it is not shear across the plane, which is why ``shear_force`` adds the upper
flange (friction of the fixed flange on the bulk below it) to the lower part but not the lower
flange. Then

* ``rho_b = mass / (pi R^2 (lid_z - z_floor))``,
* ``sigma = N / A`` and ``tau = |shear_force| / A``, ``mu = tau / sigma``.

The ring cell (``shear_cell.geometry: ring``, radii ``R_i`` and ``R``) prints ``torque``, the
torque about the cell axis of the particles on the held parts (lid and upper bands), instead
of ``shear_force``, and ``upper_force_z`` covers both upper bands; it has no flanges. Its shear
plane is the annulus ``A = pi (R^2 - R_i^2)`` at every travel, the normal force is
``N = lid_force + rho_b g A (lid_z - z_shear) + upper_force_z`` as above, and the torque, with
the shear stress taken uniform over the plane, gives ``tau = 3 |torque| / (2 pi (R^3 - R_i^3))``.

The steady plateaus are detected in ``mu`` (by :func:`demcal.core.steady_state.detect_plateau`)
in the pre-shear and the shear phase of a cycle; ``mu_psh`` and ``mu_sh`` are the mean shear
stress over the plateau divided by its mean normal stress, as a tester's averaged forces give
it, not the mean of ``mu`` itself: a servo lid that rings (its force swinging by half its
value and more between print steps while the bed below carries a steady stress) makes the mean
of the ratio read high (up to 2.3 times the ratio of the means in the quick ring at 1 068 Pa,
mu_s 0.1), while the ratio of the means keeps to the contacts across the plane. ``rho_b`` is
averaged over the pre-shear plateau. ``P`` is the ratio of the servo target forces of shear
and pre-shear, and ``normal_stress`` the pre-shear target force over ``pi R^2``.

The lid's servo is a proportional controller acting once per time step, and the contacts'
damping feeds the lid's own speed straight back into the force it reads; with too high a gain
(``shear_cell.servo_kp``) for a heavy, strongly damped bed at low stress the lid's speed flips
sign every step and its force alternates between two values (in the quick ring at 1 068 Pa
with mu_s 0.1, rho_p 3 500 kg/m^3 and COR 0.5: a coefficient of variation of 67-88 % at kp 1,
not at 0.5 or 0.25, in both codes). The ratio of means reads such a phase within a few per
cent, but the bed is being shaken, so ``psh_lid_rings`` and ``sh_lid_rings`` flag it
(:func:`lid_rings`: the lid force over the plateau alternating from one print step to the
next, lag-one autocorrelation below :data:`RINGING_AUTOCORRELATION`, by more than
:data:`RINGING_CV` of its mean); the remedy is a lower ``servo_kp``.

A phase whose servo did not hold the load gives no value: when the lid force averaged over the
plateau lies outside :data:`LOAD_HELD` times the target force, ``mu`` (and for a pre-shear
``rho_b``) is NaN, the phase is not steady and its reason says so. With a strongly cohesive bed
at low stress the lid's force jumps to zero, below it or to several times the target, and the
lid stops following, in the bundled engine and in LIGGGHTS alike; the readings of such a phase
(a mu_psh of -2 or of 3) describe the controller, not the material.

A ring deck run with ``shear_cell.bulk_density: interior`` also prints ``interior_mass`` (kg),
the mass of the particles whose centres lie in an annulus clear of the walls and bars; then
``rho_b`` is that mass over the annulus' volume, averaged over the same plateau, and the whole
cell's value is kept as ``rho_b_cell``. Counting whole particles by their centres is unbiased
for a region away from walls, where the packing is the same everywhere on average.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import pandas as pd

from demcal.core.parameters import GRAVITY
from demcal.core.steady_state import Plateau, batch_means_sem, detect_plateau
from demcal.engine_io.output_errors import require_columns

__all__ = [
    "INTERIOR_MASS_COLUMN",
    "LOAD_HELD",
    "PHASE_PRE_SHEAR",
    "PHASE_SETTLE",
    "PHASE_SHEAR",
    "PHASE_UNLOAD",
    "REQUIRED_COLUMNS",
    "RINGING_AUTOCORRELATION",
    "RINGING_CV",
    "RING_COLUMNS",
    "lid_rings",
    "overlap_area",
    "required_columns",
    "shear_cell_bulk_values",
    "shear_stress_series",
]

PHASE_SETTLE = 0
PHASE_PRE_SHEAR = 1
PHASE_UNLOAD = 2
PHASE_SHEAR = 3

REQUIRED_COLUMNS: tuple[str, ...] = (
    "time",
    "phase",
    "cycle",
    "lid_z",
    "lid_force",
    "shear_force",
    "travel",
    "mass",
    "target_force",
    "upper_force_z",
    "lower_flange_force_z",
)

RING_COLUMNS: tuple[str, ...] = (
    "time",
    "phase",
    "cycle",
    "lid_z",
    "lid_force",
    "torque",
    "travel",
    "mass",
    "target_force",
    "upper_force_z",
)

#: Print-file column of the particle mass in the ring's interior region (kg).
INTERIOR_MASS_COLUMN = "interior_mass"

_SOURCE = "shear-cell table"

#: Band of the plateau-mean lid force over the target force within which a phase held its
#: normal load. Sound runs stay within 0.87-1.35 (tiny cell, strong rolling resistance) and
#: 0.93-1.08 (quick cell); runs whose servo lost the load read -1.7 to 0.25 or 2.0 to 3.3.
LOAD_HELD = (0.5, 1.5)

#: A lid force whose lag-one autocorrelation over a plateau is below this alternates between
#: print steps (a servo oscillating at every time step, read at an odd print interval): ringing
#: lids read -0.98 to -1.0, quiet ones +0.7 to +0.95 (quick ring, 2026-12-07).
RINGING_AUTOCORRELATION = -0.5
#: ... and swings by more than this fraction of its mean (ringing 0.67-0.88, quiet <= 0.04).
RINGING_CV = 0.2


def _cross_section(radius: float, inner_radius: float | None) -> float:
    """Cell cross-section pi (R^2 - R_i^2), m^2 (R_i None or 0: the split cell's disc)."""
    return float(np.pi * (radius**2 - (inner_radius or 0.0) ** 2))


def required_columns(inner_radius: float | None = None, interior: bool = False) -> tuple[str, ...]:
    """Print-file columns the readout needs: the split cell's, or the ring's when
    ``inner_radius`` (m) is given and positive, plus :data:`INTERIOR_MASS_COLUMN` when
    ``interior``."""
    columns = RING_COLUMNS if inner_radius else REQUIRED_COLUMNS
    return (*columns, INTERIOR_MASS_COLUMN) if interior else columns


def overlap_area(radius: float, travel: float | np.ndarray) -> float | np.ndarray:
    """Area shared by two circles of equal radius whose centres are ``travel`` apart.

    ``A = 2 R^2 acos(d / 2R) - (d / 2) sqrt(4 R^2 - d^2)`` with ``d = |travel|``, and zero for
    ``d >= 2R``.

    Parameters
    ----------
    radius : float
        Circle (cell) radius R (m), positive.
    travel : float or numpy.ndarray
        Centre distance, any shape (m); the sign is ignored.

    Returns
    -------
    float or numpy.ndarray
        Overlap area (m^2), same shape as ``travel``.

    Raises
    ------
    ValueError
        ``radius`` is not positive or ``travel`` is not finite.
    """
    if not radius > 0.0:
        raise ValueError(f"radius must be positive, got {radius}")
    d = np.abs(np.asarray(travel, dtype=np.float64))
    if not np.all(np.isfinite(d)):
        raise ValueError("travel must be finite")
    ratio = np.minimum(d / (2.0 * radius), 1.0)
    half_chord = np.sqrt(np.maximum(radius**2 - (d / 2.0) ** 2, 0.0))
    area = 2.0 * radius**2 * np.arccos(ratio) - d * half_chord
    area = np.where(d >= 2.0 * radius, 0.0, area)
    return float(area) if area.ndim == 0 else area


def _validated(
    table: pd.DataFrame, radius: float, z_floor: float, z_shear: float, inner_radius: float | None
) -> None:
    columns = required_columns(inner_radius)
    require_columns(list(table.columns), columns, _SOURCE)
    if not radius > 0.0:
        raise ValueError(f"radius must be positive, got {radius}")
    if inner_radius is not None and not 0.0 <= inner_radius < radius:
        raise ValueError(f"inner_radius must lie in [0, radius), got {inner_radius}")
    if not z_shear > z_floor:
        raise ValueError(f"z_shear ({z_shear}) must lie above z_floor ({z_floor})")
    for name in columns:
        values = pd.to_numeric(table[name], errors="coerce").to_numpy(dtype=np.float64)
        bad = ~np.isfinite(values)
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise ValueError(
                f"{_SOURCE}: column {name!r} has a missing or non-numeric value in row {row}"
            )
    sheared = table["phase"].isin([PHASE_PRE_SHEAR, PHASE_SHEAR]).to_numpy()
    lid_z = table["lid_z"].to_numpy(dtype=np.float64)
    low = sheared & (lid_z <= z_shear)
    if low.any():
        row = int(np.flatnonzero(low)[0])
        raise ValueError(
            f"{_SOURCE}: column 'lid_z' = {lid_z[row]} is not above the shear plane "
            f"z_shear = {z_shear} in row {row}"
        )
    if inner_radius:
        return
    travel = np.abs(table["travel"].to_numpy(dtype=np.float64))
    far = sheared & (travel >= 2.0 * radius)
    if far.any():
        row = int(np.flatnonzero(far)[0])
        raise ValueError(
            f"{_SOURCE}: column 'travel' = {travel[row]} leaves no overlap of the cell halves "
            f"(2R = {2.0 * radius}) in row {row}"
        )


def shear_stress_series(
    table: pd.DataFrame,
    radius: float,
    z_floor: float,
    z_shear: float,
    g: float = GRAVITY,
    inner_radius: float | None = None,
) -> pd.DataFrame:
    """Add the time series of area, bulk density, stresses and mu to a shear-cell table.

    Parameters
    ----------
    table : pandas.DataFrame
        Shape (n_rows, ...), the print-file table with the columns in :data:`REQUIRED_COLUMNS`.
    radius : float
        Cell radius R (m).
    z_floor : float
        Height of the cell floor (m).
    z_shear : float
        Height of the shear plane (m).
    g : float
        Gravitational acceleration (m/s^2).
    inner_radius : float, optional
        Inner radius R_i of the ring cell (m); None or 0 for the split cell.

    Returns
    -------
    pandas.DataFrame
        A copy of ``table`` with the added columns ``area`` (m^2), ``rho_b`` (kg/m^3),
        ``sigma`` (Pa), ``tau`` (Pa) and ``mu`` (-).

    Raises
    ------
    demcal.engine_io.output_errors.MissingColumnError
        A required column is absent.
    ValueError
        Non-finite values, a lid at or below the shear plane, or a travel of 2R or more
        during pre-shear or shear.
    """
    _validated(table, radius, z_floor, z_shear, inner_radius)
    out = table.copy()
    ring = bool(inner_radius)
    column = {name: out[name].to_numpy(dtype=np.float64) for name in required_columns(inner_radius)}
    r_in = float(inner_radius) if ring else 0.0
    cross_section = _cross_section(radius, inner_radius)
    lid_z = column["lid_z"]
    if ring:
        area = np.full(len(out), cross_section)
    else:
        area = np.asarray(overlap_area(radius, column["travel"]))
    with np.errstate(divide="ignore", invalid="ignore"):
        # Settling and unloading rows may have a lid near the floor; only phases 1 and 3 count.
        rho_b = column["mass"] / (cross_section * (lid_z - z_floor))
        weight_above = rho_b * g * cross_section * (lid_z - z_shear)
        normal = column["lid_force"] + weight_above + column["upper_force_z"]
        if ring:
            tau = 3.0 * np.abs(column["torque"]) / (2.0 * np.pi * (radius**3 - r_in**3))
        else:
            normal = normal + column["lower_flange_force_z"]
            tau = np.abs(column["shear_force"]) / area
        sigma = normal / area
        mu = tau / sigma
    out["area"] = area
    out["rho_b"] = rho_b
    out["sigma"] = sigma
    out["tau"] = tau
    out["mu"] = mu
    return out


def _unique_steps(rows: pd.DataFrame) -> pd.DataFrame:
    """The rows of one phase without repeats: a step printed twice at a run boundary carries
    no new information. Plateau indices count these rows."""
    return rows.drop_duplicates(subset="time", keep="last")


def _phase_plateau(rows: pd.DataFrame, plateau_kwargs: dict[str, Any]) -> Plateau | None:
    """Plateau of mu over the rows of one phase (:func:`_unique_steps`), or None if the phase
    is absent."""
    if rows.empty:
        return None
    t = rows["time"].to_numpy(dtype=np.float64)
    if np.any(np.diff(t) <= 0.0):
        row = int(rows.index[int(np.flatnonzero(np.diff(t) <= 0.0)[0]) + 1])
        raise ValueError(f"{_SOURCE}: column 'time' decreases within a phase at row {row}")
    return detect_plateau(t, rows["mu"].to_numpy(dtype=np.float64), **plateau_kwargs)


def _window(rows: pd.DataFrame, plateau: Plateau) -> pd.DataFrame:
    """The rows of ``plateau``'s window (``rows`` as given to :func:`_phase_plateau`)."""
    return rows.iloc[plateau.start_index : plateau.end_index]


def _stress_ratio(rows: pd.DataFrame, plateau: Plateau | None) -> Plateau | None:
    """The plateau with its mean and standard error those of mean tau / mean sigma over its
    window (``rows`` as given to :func:`_phase_plateau`, with ``tau`` and ``sigma``).

    The standard error is the ratio estimator's: the batch-means error of ``tau - r sigma``
    over the mean of ``sigma``.
    """
    if plateau is None or not np.isfinite(plateau.mean):
        return plateau
    window = _window(rows, plateau)
    tau = window["tau"].to_numpy(dtype=np.float64)
    sigma = window["sigma"].to_numpy(dtype=np.float64)
    mean_sigma = float(sigma.mean())
    if mean_sigma == 0.0:
        return dataclasses.replace(plateau, mean=math.nan, sem=math.nan)
    ratio = float(tau.mean()) / mean_sigma
    return dataclasses.replace(
        plateau, mean=ratio, sem=batch_means_sem(tau - ratio * sigma) / abs(mean_sigma)
    )


def lid_rings(lid_force: np.ndarray) -> bool:
    """Whether a lid force series alternates from one print step to the next.

    Parameters
    ----------
    lid_force : numpy.ndarray
        Shape (n,), the lid force at consecutive print steps of one plateau, N.

    Returns
    -------
    bool
        True when its lag-one autocorrelation is below :data:`RINGING_AUTOCORRELATION` and its
        standard deviation above :data:`RINGING_CV` times its mean; False for fewer than four
        values or a non-positive mean.
    """
    force = np.asarray(lid_force, dtype=np.float64)
    if force.size < 4:
        return False
    mean = float(force.mean())
    if not mean > 0.0:
        return False
    deviation = force - mean
    variance = float(deviation @ deviation)
    if variance == 0.0:
        return False
    lag_one = float(deviation[:-1] @ deviation[1:]) / variance
    return lag_one < RINGING_AUTOCORRELATION and float(force.std()) > RINGING_CV * mean


def _rings(rows: pd.DataFrame, plateau: Plateau | None) -> bool:
    """:func:`lid_rings` over the plateau's window of ``rows`` (False without a plateau)."""
    if plateau is None or plateau.n_samples <= 0:
        return False
    return lid_rings(_window(rows, plateau)["lid_force"].to_numpy(dtype=np.float64))


def _load_checked(rows: pd.DataFrame, plateau: Plateau | None) -> Plateau | None:
    """The plateau, or a NaN one when the lid force over it left :data:`LOAD_HELD` x target
    (``rows`` as given to :func:`_phase_plateau`)."""
    if plateau is None or not np.isfinite(plateau.mean):
        return plateau
    window = _window(rows, plateau)
    target = float(window["target_force"].median())
    ratio = float(window["lid_force"].mean()) / target if target > 0.0 else math.nan
    low, high = LOAD_HELD
    if low <= ratio <= high:
        return plateau
    return dataclasses.replace(
        plateau,
        mean=math.nan,
        sem=math.nan,
        steady=False,
        reason=f"normal load not held: lid force {ratio:.2f} x the target over the plateau",
    )


def shear_cell_bulk_values(
    table: pd.DataFrame,
    radius: float,
    z_floor: float,
    z_shear: float,
    g: float = GRAVITY,
    inner_radius: float | None = None,
    interior_volume: float | None = None,
    **plateau_kwargs: Any,
) -> pd.DataFrame:
    """Bulk values of every pre-shear/shear cycle of a shear-cell run.

    Parameters
    ----------
    table : pandas.DataFrame
        Shape (n_rows, ...), the print-file table with the columns in :data:`REQUIRED_COLUMNS`.
    radius : float
        Cell radius R (m).
    z_floor : float
        Height of the cell floor (m).
    z_shear : float
        Height of the shear plane (m).
    g : float
        Gravitational acceleration (m/s^2).
    inner_radius : float, optional
        Inner radius R_i of the ring cell (m); None or 0 for the split cell.
    interior_volume : float, optional
        Volume of the interior region whose particle mass the column ``interior_mass``
        holds (m^3); when given, ``rho_b`` is the interior's and ``rho_b_cell`` the cell's.
    **plateau_kwargs
        Passed on to :func:`demcal.core.steady_state.detect_plateau` (e.g.
        ``min_fraction``).

    Returns
    -------
    pandas.DataFrame
        One row per cycle that has a pre-shear or shear phase, with columns ``cycle``, ``P``
        (-), ``normal_stress`` (Pa), ``mu_psh``, ``mu_sh`` (-), ``rho_b`` (kg/m^3),
        ``rho_b_cell`` (kg/m^3, the whole cell's; equal to ``rho_b`` without an interior
        region), ``steady_psh``, ``steady_sh`` (bool), the plateau windows ``psh_t_start``,
        ``psh_t_end``, ``sh_t_start``, ``sh_t_end`` (s), the standard errors ``mu_psh_sem``,
        ``mu_sh_sem`` (-), the detector's ``psh_reason``, ``sh_reason`` and the flags
        ``psh_lid_rings``, ``sh_lid_rings`` (bool, :func:`lid_rings` over the plateau). Values
        of a missing phase are NaN and its steady and ringing flags are False.

    Raises
    ------
    demcal.engine_io.output_errors.MissingColumnError
        A required column is absent.
    ValueError
        Invalid geometry or table values (see :func:`shear_stress_series`), a non-positive
        pre-shear target force, or time running backwards within a phase.
    """
    series = shear_stress_series(table, radius, z_floor, z_shear, g, inner_radius)
    if interior_volume is not None:
        if not (np.isfinite(interior_volume) and interior_volume > 0.0):
            raise ValueError(f"interior_volume must be positive, got {interior_volume}")
        require_columns(list(table.columns), (INTERIOR_MASS_COLUMN,), _SOURCE)
        mass = pd.to_numeric(series[INTERIOR_MASS_COLUMN], errors="coerce").to_numpy(np.float64)
        bad = ~(np.isfinite(mass) & (mass >= 0.0))
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise ValueError(
                f"{_SOURCE}: column {INTERIOR_MASS_COLUMN!r} has a missing, non-numeric or "
                f"negative value in row {row}"
            )
        series["rho_b_interior"] = mass / interior_volume
    cross_section = _cross_section(radius, inner_radius)
    records = []
    phase = series["phase"].to_numpy()
    cycles = np.unique(series["cycle"].to_numpy()[np.isin(phase, [PHASE_PRE_SHEAR, PHASE_SHEAR])])
    for cycle in cycles:
        in_cycle = series["cycle"] == cycle
        pre = series[in_cycle & (series["phase"] == PHASE_PRE_SHEAR)]
        shear = series[in_cycle & (series["phase"] == PHASE_SHEAR)]
        pre_steps, shear_steps = _unique_steps(pre), _unique_steps(shear)
        found_psh = _phase_plateau(pre_steps, plateau_kwargs)
        found_sh = _phase_plateau(shear_steps, plateau_kwargs)
        p_psh = _load_checked(pre_steps, _stress_ratio(pre_steps, found_psh))
        p_sh = _load_checked(shear_steps, _stress_ratio(shear_steps, found_sh))

        target_pre = float(pre["target_force"].median()) if not pre.empty else np.nan
        target_sh = float(shear["target_force"].median()) if not shear.empty else np.nan
        if not pre.empty and not target_pre > 0.0:
            raise ValueError(
                f"{_SOURCE}: column 'target_force' must be positive during pre-shear "
                f"(cycle {int(cycle)}, median {target_pre})"
            )
        rho_b = rho_b_cell = np.nan
        if p_psh is not None and np.isfinite(p_psh.mean):
            plateau = _window(pre_steps, p_psh)
            rho_b = rho_b_cell = float(plateau["rho_b"].mean())
            if interior_volume is not None:
                rho_b = float(plateau["rho_b_interior"].mean())
        records.append(
            {
                "cycle": int(cycle),
                "P": target_sh / target_pre,
                "normal_stress": target_pre / cross_section,
                "mu_psh": p_psh.mean if p_psh else np.nan,
                "mu_sh": p_sh.mean if p_sh else np.nan,
                "rho_b": rho_b,
                "rho_b_cell": rho_b_cell,
                "steady_psh": bool(p_psh.steady) if p_psh else False,
                "steady_sh": bool(p_sh.steady) if p_sh else False,
                "psh_t_start": p_psh.start_time if p_psh else np.nan,
                "psh_t_end": p_psh.end_time if p_psh else np.nan,
                "sh_t_start": p_sh.start_time if p_sh else np.nan,
                "sh_t_end": p_sh.end_time if p_sh else np.nan,
                "mu_psh_sem": p_psh.sem if p_psh else np.nan,
                "mu_sh_sem": p_sh.sem if p_sh else np.nan,
                "psh_reason": p_psh.reason if p_psh else "no pre-shear phase",
                "sh_reason": p_sh.reason if p_sh else "no shear phase",
                "psh_lid_rings": _rings(pre_steps, found_psh),
                "sh_lid_rings": _rings(shear_steps, found_sh),
            }
        )
    columns = [
        "cycle",
        "P",
        "normal_stress",
        "mu_psh",
        "mu_sh",
        "rho_b",
        "rho_b_cell",
        "steady_psh",
        "steady_sh",
        "psh_t_start",
        "psh_t_end",
        "sh_t_start",
        "sh_t_end",
        "mu_psh_sem",
        "mu_sh_sem",
        "psh_reason",
        "sh_reason",
        "psh_lid_rings",
        "sh_lid_rings",
    ]
    return pd.DataFrame.from_records(records, columns=columns)
