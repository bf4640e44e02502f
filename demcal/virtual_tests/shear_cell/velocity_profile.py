"""Where the ring cell shears: the azimuthal velocity profile across its height.

The ring's floor turns with angular velocity omega and its lid is held, both with bars. A
particle at radius r and azimuthal velocity v_theta moves with the fraction
``u = v_theta / (omega r)`` of the floor's speed: 1 where it is carried by the floor, 0 where it
is held by the lid. Averaged over the particles of a thin horizontal slice of an annulus, u(z)
shows the shear zone: its limits (where u falls through 0.9 and 0.1), its width, and the local
shear rate ``gamma_dot = omega r |du/dz|``, hence the zone's own inertial number
``I = gamma_dot d / sqrt(p / rho_p)`` (GDR MiDi 2004), which a nominal band width can only
guess. One snapshot carries the particles' velocity fluctuations; a slice of a few hundred
particles averages them to a few per cent of the floor's speed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

__all__ = ["ShearZone", "azimuthal_profile", "mean_gradient", "shear_zone"]


def azimuthal_profile(
    points: np.ndarray,
    velocity: np.ndarray,
    omega: float,
    r_lo: float,
    r_hi: float,
    bin_height: float,
    z_floor: float = 0.0,
) -> pd.DataFrame:
    """Mean fraction of the floor's azimuthal speed per horizontal slice of an annulus.

    Parameters
    ----------
    points : numpy.ndarray
        Shape (n, 3), particle centres, m (cell axis along z through the origin).
    velocity : numpy.ndarray
        Shape (n, 3), particle velocities, m/s.
    omega : float
        Angular velocity of the floor about +z, rad/s (signed, not 0).
    r_lo, r_hi : float
        The annulus' inner and outer radius, m.
    bin_height : float
        Slice height, m.
    z_floor : float
        Bottom of the first slice, m.

    Returns
    -------
    pandas.DataFrame
        One row per slice holding particles, from the floor up: ``z`` (slice centre, m), ``n``
        (particles), ``u`` (mean v_theta / (omega r), -) and ``u_se`` (its standard error, NaN
        for one particle).

    Raises
    ------
    ValueError
        Arrays of mismatched shapes, omega 0, an empty annulus or slice height, or no particle
        in the annulus.
    """
    points = np.asarray(points, dtype=np.float64)
    velocity = np.asarray(velocity, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3 or velocity.shape != points.shape:
        raise ValueError(
            f"points and velocity must both be (n, 3), got {points.shape}, {velocity.shape}"
        )
    if omega == 0.0 or not math.isfinite(omega):
        raise ValueError(f"the floor's angular velocity must be finite and not 0, got {omega}")
    if not (0.0 <= r_lo < r_hi) or not bin_height > 0.0:
        raise ValueError(f"empty annulus or slice: r {r_lo}..{r_hi}, slice height {bin_height}")
    x, y, z = points.T
    r2 = x * x + y * y
    keep = (r2 > r_lo * r_lo) & (r2 < r_hi * r_hi) & (z >= z_floor)
    if not keep.any():
        raise ValueError(f"no particle between r = {r_lo} and {r_hi} m above z = {z_floor} m")
    # v_theta / (omega r) = (x v_y - y v_x) / (omega r^2)
    u = (x * velocity[:, 1] - y * velocity[:, 0])[keep] / (omega * r2[keep])
    slot = np.floor((z[keep] - z_floor) / bin_height).astype(np.int64)
    frame = pd.DataFrame({"slot": slot, "u": u})
    grouped = frame.groupby("slot")["u"]
    out = pd.DataFrame({"n": grouped.size(), "u": grouped.mean(), "u_sd": grouped.std(ddof=1)})
    out["u_se"] = out["u_sd"] / np.sqrt(out["n"])
    out["z"] = z_floor + (out.index.to_numpy() + 0.5) * bin_height
    return out.reset_index(drop=True)[["z", "n", "u", "u_se"]]


def _first_fall(z: np.ndarray, u: np.ndarray, level: float) -> float:
    """Height where u first falls through ``level`` going up (linear between slices)."""
    below = np.flatnonzero(u < level)
    if below.size == 0:
        raise ValueError(f"the velocity profile does not fall below {level:g} of the floor's")
    k = int(below[0])
    if k == 0:
        return float(z[0])
    z0, z1, u0, u1 = z[k - 1], z[k], u[k - 1], u[k]
    return float(z0 + (u0 - level) / (u0 - u1) * (z1 - z0))


@dataclass(frozen=True)
class ShearZone:
    """The shear zone of a velocity profile (see :func:`shear_zone`).

    Attributes
    ----------
    z_floor_side : float
        Height where the mean speed falls below ``upper`` of the floor's, m.
    z_lid_side : float
        Height where it falls below ``lower``, m.
    width : float
        ``z_lid_side - z_floor_side``, m.
    peak_gradient : float
        Largest fall of u per height between neighbouring slices, 1/m.
    """

    z_floor_side: float
    z_lid_side: float
    width: float
    peak_gradient: float


def shear_zone(
    profile: pd.DataFrame, upper: float = 0.9, lower: float = 0.1, min_particles: int = 10
) -> ShearZone:
    """Limits, width and steepest gradient of the zone where u falls from ``upper`` to ``lower``.

    Parameters
    ----------
    profile : pandas.DataFrame
        :func:`azimuthal_profile`'s slices.
    upper, lower : float
        Fractions of the floor's speed that bound the zone, -.
    min_particles : int
        Slices with fewer particles (the loose top and bottom layers) are left out.

    Returns
    -------
    ShearZone

    Raises
    ------
    ValueError
        ``lower`` not below ``upper``, fewer than two slices, or a profile that does not fall
        through both levels.
    """
    if not 0.0 <= lower < upper <= 1.0:
        raise ValueError(f"need 0 <= lower < upper <= 1, got {lower}, {upper}")
    used = profile[profile["n"] >= min_particles]
    if len(used) < 2:
        raise ValueError(f"fewer than two slices with {min_particles} particles or more")
    z = used["z"].to_numpy()
    u = used["u"].to_numpy()
    top = _first_fall(z, u, lower)
    bottom = _first_fall(z, u, upper)
    fall = -np.diff(u) / np.diff(z)
    return ShearZone(
        z_floor_side=bottom,
        z_lid_side=top,
        width=top - bottom,
        peak_gradient=float(fall.max()),
    )


def mean_gradient(profile: pd.DataFrame, z_lo: float, z_hi: float) -> float:
    """Mean fall of u per height between ``z_lo`` and ``z_hi`` (linear between slices), 1/m.

    Parameters
    ----------
    profile : pandas.DataFrame
        :func:`azimuthal_profile`'s slices.
    z_lo, z_hi : float
        The range, m, inside the slices' centres.

    Raises
    ------
    ValueError
        An empty range or one outside the slices.
    """
    z = profile["z"].to_numpy()
    if not (z[0] <= z_lo < z_hi <= z[-1]):
        raise ValueError(f"range {z_lo}..{z_hi} m is not inside the slices {z[0]}..{z[-1]} m")
    u = profile["u"].to_numpy()
    return float((np.interp(z_lo, z, u) - np.interp(z_hi, z, u)) / (z_hi - z_lo))
