"""Static angle of repose of a particle heap by the slice / convex-hull method.

The heap (particle centres above the base plate, optionally only particles with at least
``min_contacts`` contacts, which drops loose particles rolling on the plate) is cut into
``n_slices`` horizontal slices of equal thickness between the plate and the heap top
(``max(z + radius)``). Per slice:

* the convex hull of the particle centres projected on the xy plane gives an area ``A`` and an
  equivalent radius ``r* = sqrt(A / pi)``;
* per azimuthal sector around ``centre_xy`` (``n_sectors`` sectors, sector 0 centred on +x,
  counter-clockwise), the outer envelope radius is the largest horizontal distance of a centre
  in that sector from ``centre_xy``.

Radii are attributed to the slice mid-heights. The angle follows from the radii a quarter of the
heap height below and above the middle (linearly interpolated between slice mid-heights):
``angle = atan(dz / (r_low - r_high))``. Two variants are returned as well: the mean of the
slice-to-slice angles ``atan(h / (r_k - r_{k+1}))`` over the slices between those two heights,
and the angle of a least-squares line ``r*(z)`` over the same range. Because the outermost
centres of a slice sit a roughly constant distance inside the free surface, that offset cancels
in the differences.

A heap's flank narrows upwards all round: the hull angle and every sector's angle lie strictly
between 0 and 90 degrees. Particles spread over the plate a layer or two deep (spheres without
rolling resistance, for example) give hull and sector "angles" anywhere up to 180 degrees; a
pile lower than :data:`LAYER_DIAMETERS` mean particle diameters whose flank does not narrow
all round is such a layer and raises :class:`NotAHeapError` rather than returning an angle. A
cohesive bulk that stands as a column after the lift keeps its height; its vertical or
bulging flank reads 90 degrees or a little more, the test's upper limit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull, QhullError

__all__ = ["LAYER_DIAMETERS", "NotAHeapError", "ReposeResult", "angle_of_repose"]


#: A pile lower than this many mean particle diameters whose flank does not narrow upwards all
#: round is particles spread over the plate, not a heap (quick spread layers: 2.1-2.5).
LAYER_DIAMETERS = 4.0


class NotAHeapError(ValueError):
    """The particles on the plate form no heap whose angle could be read."""


@dataclass(frozen=True)
class ReposeResult:
    """Angle of repose and the slice data it was computed from.

    Attributes
    ----------
    angle_deg : float
        Angle from the convex-hull radii at a quarter of the heap height below and above the
        middle (degrees).
    angle_mean_slices_deg : float
        Mean of the slice-to-slice hull angles between those heights (degrees).
    angle_fit_deg : float
        Angle of a least-squares line through the hull radii between those heights (degrees).
    sector_angles_deg : numpy.ndarray
        Shape (n_sectors,), per-sector angle from the outer-envelope radii (degrees).
    sector_centres_deg : numpy.ndarray
        Shape (n_sectors,), azimuth of each sector's centre line, from +x (degrees).
    heap_height : float
        Height of the heap top above the base plate (m).
    z_low, z_high : float
        Heights (absolute, m) a quarter of the heap height below and above its middle.
    slice_z : numpy.ndarray
        Shape (n_slices,), slice mid-heights (absolute, m).
    slice_radii : numpy.ndarray
        Shape (n_slices,), equivalent hull radius r* per slice (m); NaN where a slice holds
        fewer than three non-collinear particles.
    slice_counts : numpy.ndarray
        Shape (n_slices,), number of particles per slice.
    sector_radii : numpy.ndarray
        Shape (n_sectors, n_slices), outer-envelope radius per sector and slice (m); NaN for
        an empty cell.
    n_particles : int
        Number of particles used (after the contact and height filters).
    """

    angle_deg: float
    angle_mean_slices_deg: float
    angle_fit_deg: float
    sector_angles_deg: np.ndarray
    sector_centres_deg: np.ndarray
    heap_height: float
    z_low: float
    z_high: float
    slice_z: np.ndarray
    slice_radii: np.ndarray
    slice_counts: np.ndarray
    sector_radii: np.ndarray
    n_particles: int

    @property
    def sector_spread_deg(self) -> float:
        """Sample standard deviation of the finite sector angles (degrees)."""
        finite = self.sector_angles_deg[np.isfinite(self.sector_angles_deg)]
        return float(np.std(finite, ddof=1)) if finite.size > 1 else float("nan")


def _hull_area(xy: np.ndarray) -> float:
    """Area (m^2) of the convex hull of points ``xy`` of shape (k, 2); NaN if degenerate."""
    if xy.shape[0] < 3:
        return float("nan")
    try:
        return float(ConvexHull(xy).volume)  # in 2-D, "volume" is the enclosed area
    except QhullError:
        return float("nan")


def _interp_finite(z: float, zs: np.ndarray, rs: np.ndarray) -> float:
    """Linear interpolation of r(z) through the finite entries of ``rs``."""
    ok = np.isfinite(rs)
    if ok.sum() < 2:
        return float("nan")
    return float(np.interp(z, zs[ok], rs[ok]))


def _angle_deg(dz: float, dr: float) -> float:
    """Slope angle (degrees) of a surface that narrows by ``dr`` over a rise of ``dz``."""
    if not (np.isfinite(dz) and np.isfinite(dr)):
        return float("nan")
    return float(np.degrees(np.arctan2(dz, dr)))


def _as_array(value: object, name: str, shape: tuple[int | None, ...]) -> np.ndarray:
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim != len(shape) or any(
        want is not None and got != want for got, want in zip(arr.shape, shape, strict=True)
    ):
        want_text = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"
        raise ValueError(f"{name} must have shape {want_text}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite")
    return arr


def angle_of_repose(
    positions: np.ndarray,
    radii: np.ndarray,
    centre_xy: tuple[float, float] | np.ndarray,
    base_z: float,
    contacts: np.ndarray | None = None,
    n_slices: int = 20,
    n_sectors: int = 8,
    min_contacts: int = 2,
) -> ReposeResult:
    """Angle of repose of a heap by the slice / convex-hull method (see the module docstring).

    Parameters
    ----------
    positions : numpy.ndarray
        Shape (n, 3), particle centres (m).
    radii : numpy.ndarray
        Shape (n,), particle radii (m).
    centre_xy : array_like
        Shape (2,), heap axis (the lifted cylinder's axis) in the xy plane (m); used for the
        sectors only, the hull angle does not depend on it.
    base_z : float
        Height of the base plate (m); centres below it are ignored.
    contacts : numpy.ndarray, optional
        Shape (n,), contact count per particle; if given, only particles with at least
        ``min_contacts`` contacts are used.
    n_slices : int
        Number of horizontal slices between the plate and the heap top, at least 4.
    n_sectors : int
        Number of azimuthal sectors, at least 1.
    min_contacts : int
        Contact threshold applied when ``contacts`` is given.

    Returns
    -------
    ReposeResult
        Angles (degrees), heap height (m), slice and sector radii (m).

    Raises
    ------
    ValueError
        Arrays of the wrong shape or with non-finite values, non-positive radii, too few
        slices or sectors.
    NotAHeapError
        (a ValueError) Fewer than ``3 * n_slices`` particles left on the plate after
        filtering, or particles spread over the plate: a pile lower than
        :data:`LAYER_DIAMETERS` mean particle diameters whose flank does not narrow upwards
        all round.
    """
    pos = _as_array(positions, "positions", (None, 3))
    n = pos.shape[0]
    rad = _as_array(radii, "radii", (n,))
    centre = _as_array(centre_xy, "centre_xy", (2,))
    if np.any(rad <= 0.0):
        raise ValueError("radii must be positive")
    if n_slices < 4:
        raise ValueError(f"n_slices must be at least 4, got {n_slices}")
    if n_sectors < 1:
        raise ValueError(f"n_sectors must be at least 1, got {n_sectors}")

    keep = pos[:, 2] >= base_z
    on_plate = int(keep.sum())
    if contacts is not None:
        cnt = np.asarray(contacts)
        if cnt.shape != (n,):
            raise ValueError(f"contacts must have shape ({n},), got {cnt.shape}")
        keep &= cnt >= min_contacts
    pos, rad = pos[keep], rad[keep]
    if pos.shape[0] < 3 * n_slices:
        which = "" if contacts is None else f" with {min_contacts}+ contacts"
        raise NotAHeapError(
            f"no heap: {pos.shape[0]} of the {on_plate} particles on the plate{which}, fewer "
            f"than the {3 * n_slices} that {n_slices} slices need"
        )

    top = float(np.max(pos[:, 2] + rad))
    height = top - base_z
    thickness = height / n_slices
    slice_z = base_z + (np.arange(n_slices) + 0.5) * thickness
    which = np.clip(((pos[:, 2] - base_z) / thickness).astype(np.int64), 0, n_slices - 1)

    rel = pos[:, :2] - centre
    rho = np.hypot(rel[:, 0], rel[:, 1])
    width = 2.0 * np.pi / n_sectors
    phi = np.mod(np.arctan2(rel[:, 1], rel[:, 0]) + 0.5 * width, 2.0 * np.pi)
    sector = np.minimum((phi / width).astype(np.int64), n_sectors - 1)

    slice_radii = np.full(n_slices, np.nan)
    slice_counts = np.bincount(which, minlength=n_slices)
    sector_radii = np.full((n_sectors, n_slices), np.nan)
    for k in range(n_slices):
        in_slice = which == k
        slice_radii[k] = np.sqrt(_hull_area(pos[in_slice, :2]) / np.pi)
        if in_slice.any():
            env = np.full(n_sectors, -np.inf)
            np.maximum.at(env, sector[in_slice], rho[in_slice])
            sector_radii[env > -np.inf, k] = env[env > -np.inf]

    z_low = base_z + 0.25 * height
    z_high = base_z + 0.75 * height
    dz = z_high - z_low
    angle = _angle_deg(
        dz,
        _interp_finite(z_low, slice_z, slice_radii) - _interp_finite(z_high, slice_z, slice_radii),
    )
    sector_angles = np.array(
        [
            _angle_deg(
                dz,
                _interp_finite(z_low, slice_z, sector_radii[s])
                - _interp_finite(z_high, slice_z, sector_radii[s]),
            )
            for s in range(n_sectors)
        ]
    )

    flanks = np.append(sector_angles, angle)
    narrows = np.all((flanks > 0.0) & (flanks < 90.0))  # NaN (no flank there) is False
    diameter = 2.0 * float(np.mean(rad))
    if not narrows and height < LAYER_DIAMETERS * diameter:
        shown = ", ".join(f"{a:.1f}" for a in sector_angles)
        raise NotAHeapError(
            f"no heap: particles spread over the plate, {height * 1e3:.1f} mm "
            f"({height / diameter:.1f} mean diameters) high, and the pile does not narrow "
            f"upwards all round (hull angle {angle:.1f} deg, sector angles {shown} deg; "
            f"{pos.shape[0]} particles with {min_contacts}+ contacts)"
        )

    mid = (slice_z >= z_low) & (slice_z <= z_high) & np.isfinite(slice_radii)
    pair = mid[:-1] & mid[1:]
    step_angles = np.degrees(np.arctan2(thickness, slice_radii[:-1] - slice_radii[1:]))[pair]
    angle_mean = float(np.mean(step_angles)) if step_angles.size else float("nan")
    if mid.sum() >= 2:
        slope = float(np.polyfit(slice_z[mid], slice_radii[mid], 1)[0])  # dr*/dz, negative
        angle_fit = float(np.degrees(np.arctan2(1.0, -slope)))
    else:
        angle_fit = float("nan")

    return ReposeResult(
        angle_deg=angle,
        angle_mean_slices_deg=angle_mean,
        angle_fit_deg=angle_fit,
        sector_angles_deg=sector_angles,
        sector_centres_deg=np.degrees(np.arange(n_sectors) * width),
        heap_height=height,
        z_low=z_low,
        z_high=z_high,
        slice_z=slice_z,
        slice_radii=slice_radii,
        slice_counts=slice_counts,
        sector_radii=sector_radii,
        n_particles=int(pos.shape[0]),
    )
