"""Triangulated surfaces in metres: checks, measures (normals, areas, volume, closedness) and
rigid transforms.

A surface is a float64 array of shape (n, 3, 3): n triangles, three vertices each, x/y/z in m.
The facet normal follows the right-hand rule of the vertex order (v0 -> v1 -> v2).
"""

from __future__ import annotations

from collections import Counter

import numpy as np


def as_triangles(triangles: np.ndarray) -> np.ndarray:
    """``triangles`` as a float array of shape (n, 3, 3); a ValueError for another shape or
    non-finite coordinates."""
    tri = np.asarray(triangles, dtype=float)
    if tri.ndim != 3 or tri.shape[1:] != (3, 3):
        raise ValueError(f"triangles must have shape (n, 3, 3), got {tri.shape}")
    if not np.all(np.isfinite(tri)):
        raise ValueError("triangles contain non-finite coordinates")
    return tri


def triangle_normals(triangles: np.ndarray) -> np.ndarray:
    """Unit facet normals by the right-hand rule.

    Parameters
    ----------
    triangles : numpy.ndarray, shape (n, 3, 3)
        Vertices, m.

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        Unit normals; zero vectors for degenerate (zero-area) triangles.
    """
    tri = as_triangles(triangles)
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(cross, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = np.where(length > 0, cross / np.where(length > 0, length, 1.0), 0.0)
    return unit


def triangle_areas(triangles: np.ndarray) -> np.ndarray:
    """Triangle areas.

    Parameters
    ----------
    triangles : numpy.ndarray, shape (n, 3, 3)
        Vertices, m.

    Returns
    -------
    numpy.ndarray, shape (n,)
        Areas, m^2.
    """
    tri = as_triangles(triangles)
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    return 0.5 * np.linalg.norm(cross, axis=1)


def surface_area(triangles: np.ndarray) -> float:
    """Total area of a surface, m^2 (input shape (n, 3, 3), m)."""
    return float(triangle_areas(triangles).sum())


def enclosed_volume(triangles: np.ndarray) -> float:
    """Signed volume enclosed by a closed surface (divergence theorem).

    Parameters
    ----------
    triangles : numpy.ndarray, shape (n, 3, 3)
        A closed surface, m.

    Returns
    -------
    float
        Volume, m^3; positive when the normals point outward, negative when inward.
    """
    tri = as_triangles(triangles)
    return float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0)


def is_closed(triangles: np.ndarray, tol: float = 1e-9) -> bool:
    """Whether a surface is closed and consistently oriented.

    True when every directed edge (a -> b) is matched by exactly one opposite edge (b -> a) of
    another triangle, i.e. each edge is shared by exactly two triangles traversing it in
    opposite directions. Vertices closer than ``tol`` (m) are treated as the same point.

    Parameters
    ----------
    triangles : numpy.ndarray, shape (n, 3, 3)
        Vertices, m.
    tol : float
        Vertex merge distance, m.
    """
    tri = as_triangles(triangles)
    if len(tri) == 0:
        return False
    keys = np.round(tri / tol).astype(np.int64)
    edges: Counter[tuple[tuple[int, ...], tuple[int, ...]]] = Counter()
    for t in keys:
        verts = [tuple(int(c) for c in v) for v in t]
        for a, b in ((0, 1), (1, 2), (2, 0)):
            edges[(verts[a], verts[b])] += 1
    return all(count == 1 and edges.get((b, a), 0) == 1 for (a, b), count in edges.items())


def translate(triangles: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """Shift a surface by ``offset`` (shape (3,), m); returns a new (n, 3, 3) array."""
    off = np.asarray(offset, dtype=float)
    if off.shape != (3,):
        raise ValueError(f"offset must be a 3-vector, got shape {off.shape}")
    return as_triangles(triangles) + off


def rotate_z(
    triangles: np.ndarray, angle: float, centre: tuple[float, float] = (0.0, 0.0)
) -> np.ndarray:
    """Rotate a surface about a vertical axis.

    Parameters
    ----------
    triangles : numpy.ndarray, shape (n, 3, 3)
        Vertices, m.
    angle : float
        Counter-clockwise angle seen from +z, rad.
    centre : (float, float)
        Axis position (x, y), m.

    Returns
    -------
    numpy.ndarray, shape (n, 3, 3)
        Rotated copy.
    """
    tri = as_triangles(triangles)
    c, s = np.cos(angle), np.sin(angle)
    x = tri[..., 0] - centre[0]
    y = tri[..., 1] - centre[1]
    out = tri.copy()
    out[..., 0] = centre[0] + c * x - s * y
    out[..., 1] = centre[1] + s * x + c * y
    return out


def merge(*parts: np.ndarray) -> np.ndarray:
    """Concatenate surfaces (each shape (n_i, 3, 3), m) into one (sum n_i, 3, 3) array."""
    if not parts:
        return np.empty((0, 3, 3))
    return np.concatenate([as_triangles(p) for p in parts])
