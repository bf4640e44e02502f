"""Triangle meshes of the chute cooler: the row of boxes with perforated floors and the chute.

The perforated floor is a triangulated plate with a square grid of square holes; it is cut
along the hole edges into rectangular cells, so the triangles keep an aspect ratio near one
(no slivers). Meshes are built at the initial position of the row (the deck moves it).
Lengths in m.
"""

from __future__ import annotations

import math

import numpy as np

from demcal.application.chute_cooler.layout import ChuteCoolerSetup
from demcal.decks.mesh_primitives import quad
from demcal.decks.triangle_surface import merge

__all__ = ["box_row_triangles", "chute_triangles", "hole_grid", "perforated_plate"]


def hole_grid(length: float, pitch: float, hole: float) -> np.ndarray:
    """Breakpoints of one axis of a centred hole grid.

    Parameters
    ----------
    length : float
        Length of the plate along the axis, m.
    pitch : float
        Hole pitch, m.
    hole : float
        Hole side, m (0: no holes).

    Returns
    -------
    numpy.ndarray, shape (2 n + 2,)
        ``0, a_0, b_0, ..., a_{n-1}, b_{n-1}, length`` relative to the plate start, with
        ``[a_i, b_i]`` the hole intervals (n = floor(length / pitch) holes, centred).
    """
    n = math.floor(length / pitch + 1e-9) if hole > 0.0 else 0
    if n == 0:
        return np.array([0.0, length])
    margin = 0.5 * (length - n * pitch)
    centres = margin + pitch * (np.arange(n) + 0.5)
    inner = np.column_stack((centres - 0.5 * hole, centres + 0.5 * hole)).reshape(-1)
    return np.concatenate(([0.0], inner, [length]))


def perforated_plate(
    x0: float, x1: float, y0: float, y1: float, z: float, pitch: float, hole: float
) -> np.ndarray:
    """Horizontal plate [x0, x1] x [y0, y1] at height z with a centred grid of square holes.

    The plate is cut along the hole edges into rectangular cells; every cell that is not a hole
    becomes two triangles (normals +z).

    Parameters
    ----------
    x0, x1, y0, y1, z : float
        Plate bounds and height, m.
    pitch : float
        Hole pitch, m (> hole).
    hole : float
        Hole side, m; 0 gives a closed plate of two triangles.

    Returns
    -------
    numpy.ndarray, shape (n, 3, 3)
        Triangles, m; total area ``(x1 - x0)(y1 - y0) - n_x n_y hole^2``.
    """
    if not (x1 > x0 and y1 > y0):
        raise ValueError(f"plate needs x0 < x1 and y0 < y1, got {x0}, {x1}, {y0}, {y1}")
    if hole < 0.0 or (hole > 0.0 and not pitch > hole):
        raise ValueError(f"plate holes need 0 <= hole < pitch, got hole={hole}, pitch={pitch}")
    bx = x0 + hole_grid(x1 - x0, pitch, hole)
    by = y0 + hole_grid(y1 - y0, pitch, hole)
    ix, iy = np.meshgrid(np.arange(bx.size - 1), np.arange(by.size - 1), indexing="ij")
    # odd intervals are hole intervals; a cell is a hole when it is one along both axes
    solid = ~((ix % 2 == 1) & (iy % 2 == 1))
    ix, iy = ix[solid], iy[solid]
    xa, xb, ya, yb = bx[ix], bx[ix + 1], by[iy], by[iy + 1]
    zz = np.full(xa.shape, float(z))
    p0 = np.stack((xa, ya, zz), axis=-1)
    p1 = np.stack((xb, ya, zz), axis=-1)
    p2 = np.stack((xb, yb, zz), axis=-1)
    p3 = np.stack((xa, yb, zz), axis=-1)
    tri = np.concatenate((np.stack((p0, p1, p2), axis=1), np.stack((p0, p2, p3), axis=1)))
    return tri


def _vertical_wall_x(x: float, y0: float, y1: float, z0: float, z1: float) -> np.ndarray:
    """Wall in the plane x = const, normal +x."""
    return quad(
        np.array((x, y0, z0)), np.array((x, y1, z0)), np.array((x, y1, z1)), np.array((x, y0, z1))
    )


def _vertical_wall_y(y: float, x0: float, x1: float, z0: float, z1: float) -> np.ndarray:
    """Wall in the plane y = const, normal -y."""
    return quad(
        np.array((x0, y, z0)), np.array((x1, y, z0)), np.array((x1, y, z1)), np.array((x0, y, z1))
    )


def box_row_triangles(s: ChuteCoolerSetup) -> np.ndarray:
    """The row of boxes at its initial position (one mesh, moved as a whole).

    Perforated floors, the leading wall (``lead_wall_height``), the partitions and the back
    wall (height H) and the two side walls of the row (rim height).

    Returns
    -------
    numpy.ndarray, shape (n, 3, 3)
        Triangles, m.
    """
    L, W, H = s.box_length, s.box_width, s.box_height
    front = s.box_front_x0
    back = front - s.n_boxes * L
    parts = [
        perforated_plate(front - (k + 1) * L, front - k * L, 0.0, W, 0.0, s.hole_pitch, s.hole_size)
        for k in range(s.n_boxes)
    ]
    parts.append(_vertical_wall_x(front, 0.0, W, 0.0, s.lead_wall_height))
    parts += [_vertical_wall_x(front - k * L, 0.0, W, 0.0, H) for k in range(1, s.n_boxes + 1)]
    parts.append(_vertical_wall_y(0.0, back, front, 0.0, s.rim_height))
    parts.append(_vertical_wall_y(W, back, front, 0.0, s.rim_height))
    return merge(*parts)


def chute_triangles(s: ChuteCoolerSetup) -> np.ndarray:
    """The fixed chute: inclined floor, two side walls and a back wall at its upper end.

    Returns
    -------
    numpy.ndarray, shape (8, 3, 3)
        Triangles, m.
    """
    (xe, ze), (xu, zu) = s.chute_edge, s.chute_top
    (y0, y1), h = s.chute_y, s.chute_wall_height
    floor = quad(
        np.array((xe, y0, ze)),
        np.array((xu, y0, zu)),
        np.array((xu, y1, zu)),
        np.array((xe, y1, ze)),
    )
    sides = [
        quad(
            np.array((xe, y, ze)),
            np.array((xu, y, zu)),
            np.array((xu, y, zu + h)),
            np.array((xe, y, ze + h)),
        )
        for y in (y0, y1)
    ]
    back = _vertical_wall_x(xu, y0, y1, zu, zu + h)
    return merge(floor, *sides, back)
