"""Solid fraction of the ring cell's interior annulus from a particle snapshot.

The deck prints the mass of the particles whose centres lie in the annulus
``r_lo < r < r_hi``, ``z_lo < z < z_hi`` (LIGGGHTS ``mass(all,region)``). That count is unbiased
where the packing is the same everywhere on average, but spheres stacked in layers parallel to
a boundary of the region make it depend on where the boundary cuts the layers. This module
gives the other estimate: the part of every sphere's volume that lies inside the annulus. Each
boundary cuts a sphere as a plane (a spherical cap; the curved walls are taken flat across one
particle, their radii being several particle radii), and the radial and vertical fractions
multiply, which is exact away from the annulus' four edges. The ratio of the two estimates is
the centre count's bias for that packing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["InteriorFractions", "interior_fractions", "sphere_fraction_inside"]


@dataclass(frozen=True)
class InteriorFractions:
    """Solid fractions of the interior annulus, -.

    Attributes
    ----------
    by_centre : float
        Volume of the spheres whose centres lie inside, over the annulus' volume.
    by_volume : float
        Volume of the spheres' parts that lie inside, over the annulus' volume.
    n_centres : int
        Spheres whose centres lie inside.
    """

    by_centre: float
    by_volume: float
    n_centres: int


def sphere_fraction_inside(depth: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Fraction of a sphere's volume on the inner side of a plane.

    Parameters
    ----------
    depth : numpy.ndarray
        Shape (n,), signed distance of the centre from the plane, positive on the inner side, m.
    radius : numpy.ndarray
        Shape (n,), sphere radii, m.

    Returns
    -------
    numpy.ndarray
        Shape (n,), in [0, 1]: the cap of height ``radius + depth`` over the sphere's volume.
    """
    h = np.clip(np.asarray(depth) + radius, 0.0, 2.0 * radius)
    return h * h * (3.0 * radius - h) / (4.0 * radius**3)


def interior_fractions(
    points: np.ndarray,
    radii: np.ndarray,
    r_lo: float,
    r_hi: float,
    z_lo: float,
    z_hi: float,
) -> InteriorFractions:
    """Solid fraction of the annulus about the z axis, by centres and by volume.

    Parameters
    ----------
    points : numpy.ndarray
        Shape (n, 3), sphere centres, m.
    radii : numpy.ndarray
        Shape (n,), sphere radii, m.
    r_lo, r_hi : float
        Inner and outer radius of the annulus, m.
    z_lo, z_hi : float
        Its bottom and top, m.

    Returns
    -------
    InteriorFractions

    Raises
    ------
    ValueError
        For an empty annulus or arrays of mismatched shapes.
    """
    points = np.asarray(points, dtype=np.float64)
    radii = np.asarray(radii, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3 or radii.shape != (len(points),):
        raise ValueError(f"points must be (n, 3) and radii (n,), got {points.shape}, {radii.shape}")
    if not (0.0 <= r_lo < r_hi and z_lo < z_hi):
        raise ValueError(f"empty annulus: r {r_lo}..{r_hi}, z {z_lo}..{z_hi}")
    r = np.hypot(points[:, 0], points[:, 1])
    z = points[:, 2]
    volume = 4.0 / 3.0 * np.pi * radii**3
    inside = (r > r_lo) & (r < r_hi) & (z > z_lo) & (z < z_hi)
    # Inside both planes of a pair: the two caps minus the whole sphere.
    radial = sphere_fraction_inside(r - r_lo, radii) + sphere_fraction_inside(r_hi - r, radii)
    vertical = sphere_fraction_inside(z - z_lo, radii) + sphere_fraction_inside(z_hi - z, radii)
    share = np.clip(radial - 1.0, 0.0, 1.0) * np.clip(vertical - 1.0, 0.0, 1.0)
    annulus = np.pi * (r_hi**2 - r_lo**2) * (z_hi - z_lo)
    return InteriorFractions(
        by_centre=float(volume[inside].sum() / annulus),
        by_volume=float((volume * share).sum() / annulus),
        n_centres=int(inside.sum()),
    )
