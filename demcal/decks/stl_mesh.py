"""Triangulated wall geometry in metres and its STL files.

A surface is a float64 array of shape (n, 3, 3): n triangles, three vertices each, x/y/z in m.
The facet normal follows the right-hand rule of the vertex order (v0 -> v1 -> v2).

Curved surfaces are approximated by polygons whose vertices lie on the circle (inscribed
polygons with ``n_segments`` sides, first vertex at angle 0). The area of an inscribed polygon
is smaller than the circle's by the factor ``sin(2 pi/n) / (2 pi/n)`` (discs, annuli) or
``sin(pi/n) / (pi/n)`` (tube walls); the relative error is about ``(2 pi/n)^2 / 6`` and
``(pi/n)^2 / 6``: 1.6e-3 and 4.0e-4 for n = 64. Flat faces of the polygonal tube lie at
``radius * cos(pi/n)`` from the axis.

Files: ASCII STL with ``%.10e`` numbers and ``\\n`` line endings, binary STL with little-endian
float32 (the binary format cannot hold more; about 1e-7 relative precision). Both writers are
deterministic, so the same triangles give byte-identical files.
"""

from __future__ import annotations

import re
import struct
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

__all__ = [
    "StlFormatError",
    "StlMesh",
    "annulus",
    "box_open_top",
    "cylinder_shell",
    "disc",
    "enclosed_volume",
    "is_closed",
    "merge",
    "quad",
    "read_stl",
    "rectangle",
    "rotate_z",
    "surface_area",
    "translate",
    "triangle_areas",
    "triangle_normals",
    "write_stl_ascii",
    "write_stl_binary",
]

_NAME_PATTERN = re.compile(r"^[A-Za-z0-9_.\-]+$")
_NUM = "%.10e"
_BINARY_HEADER_BYTES = 80
_BINARY_FACET = struct.Struct("<12fH")


class StlFormatError(ValueError):
    """An STL file is malformed; the message names the file (and the line for ASCII)."""


@dataclass(frozen=True)
class StlMesh:
    """Contents of an STL file.

    Attributes
    ----------
    name : str
        Solid name (ASCII) or the header text (binary), stripped.
    triangles : numpy.ndarray, shape (n, 3, 3)
        Vertices, m.
    normals : numpy.ndarray, shape (n, 3)
        Facet normals as stored in the file.
    """

    name: str
    triangles: np.ndarray
    normals: np.ndarray


# ----------------------------------------------------------------------------------------------
# checks and measures


def _as_triangles(triangles: np.ndarray) -> np.ndarray:
    tri = np.asarray(triangles, dtype=float)
    if tri.ndim != 3 or tri.shape[1:] != (3, 3):
        raise ValueError(f"triangles must have shape (n, 3, 3), got {tri.shape}")
    if not np.all(np.isfinite(tri)):
        raise ValueError("triangles contain non-finite coordinates")
    return tri


def _check_segments(n_segments: int) -> None:
    if isinstance(n_segments, bool) or not isinstance(n_segments, int | np.integer):
        raise ValueError(f"n_segments must be an integer, got {n_segments!r}")
    if n_segments < 3:
        raise ValueError(f"n_segments must be >= 3, got {n_segments}")


def _check_positive(name: str, value: float) -> None:
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a positive finite length (m), got {value!r}")


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
    tri = _as_triangles(triangles)
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
    tri = _as_triangles(triangles)
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
    tri = _as_triangles(triangles)
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
    tri = _as_triangles(triangles)
    if len(tri) == 0:
        return False
    keys = np.round(tri / tol).astype(np.int64)
    edges: Counter[tuple[tuple[int, ...], tuple[int, ...]]] = Counter()
    for t in keys:
        verts = [tuple(int(c) for c in v) for v in t]
        for a, b in ((0, 1), (1, 2), (2, 0)):
            edges[(verts[a], verts[b])] += 1
    return all(count == 1 and edges.get((b, a), 0) == 1 for (a, b), count in edges.items())


# ----------------------------------------------------------------------------------------------
# primitives


def _ring(radius: float, n_segments: int, centre: tuple[float, float]) -> np.ndarray:
    """(n_segments + 1, 2) points on a circle, the last equal to the first (bit-identical)."""
    angles = 2.0 * np.pi * np.arange(n_segments) / n_segments
    pts = np.column_stack(
        (centre[0] + radius * np.cos(angles), centre[1] + radius * np.sin(angles))
    )
    return np.vstack((pts, pts[:1]))


def cylinder_shell(
    radius: float,
    z0: float,
    z1: float,
    n_segments: int,
    centre: tuple[float, float] = (0.0, 0.0),
    normals: Literal["inward", "outward"] = "inward",
) -> np.ndarray:
    """Open vertical tube (no end caps).

    Parameters
    ----------
    radius : float
        Radius of the circle the polygon vertices lie on, m.
    z0, z1 : float
        Bottom and top heights, m (z0 < z1).
    n_segments : int
        Number of polygon sides (>= 3).
    centre : (float, float)
        Axis position (x, y), m.
    normals : {"inward", "outward"}
        Normals towards the axis (a container wall seen from the particles inside) or away.

    Returns
    -------
    numpy.ndarray, shape (2 * n_segments, 3, 3)
        Triangles, m. Area ``2 n r sin(pi/n) (z1 - z0)``.
    """
    _check_positive("radius", radius)
    _check_segments(n_segments)
    if not z1 > z0:
        raise ValueError(f"cylinder_shell needs z0 < z1, got z0={z0}, z1={z1}")
    if normals not in ("inward", "outward"):
        raise ValueError(f"normals must be 'inward' or 'outward', got {normals!r}")
    ring = _ring(radius, n_segments, centre)
    a, b = ring[:-1], ring[1:]
    n = n_segments
    lo_a = np.column_stack((a, np.full(n, z0)))
    lo_b = np.column_stack((b, np.full(n, z0)))
    hi_a = np.column_stack((a, np.full(n, z1)))
    hi_b = np.column_stack((b, np.full(n, z1)))
    # counter-clockwise ring seen from +z: (lo_a, lo_b, hi_b) has an outward normal
    outward = np.concatenate(
        (np.stack((lo_a, lo_b, hi_b), axis=1), np.stack((lo_a, hi_b, hi_a), axis=1))
    )
    return outward if normals == "outward" else outward[:, ::-1].copy()


def disc(
    radius: float,
    z: float,
    n_segments: int,
    centre: tuple[float, float] = (0.0, 0.0),
    normal_up: bool = True,
) -> np.ndarray:
    """Horizontal polygonal disc (triangle fan around the centre).

    Parameters
    ----------
    radius : float
        Radius of the circle the polygon vertices lie on, m.
    z : float
        Height, m.
    n_segments : int
        Number of polygon sides (>= 3).
    centre : (float, float)
        Centre (x, y), m.
    normal_up : bool
        Normals along +z (True) or -z.

    Returns
    -------
    numpy.ndarray, shape (n_segments, 3, 3)
        Triangles, m. Area ``n/2 r^2 sin(2 pi/n)``.
    """
    _check_positive("radius", radius)
    _check_segments(n_segments)
    ring = _ring(radius, n_segments, centre)
    n = n_segments
    c = np.tile([centre[0], centre[1], z], (n, 1)).astype(float)
    a = np.column_stack((ring[:-1], np.full(n, z)))
    b = np.column_stack((ring[1:], np.full(n, z)))
    up = np.stack((c, a, b), axis=1)
    return up if normal_up else up[:, ::-1].copy()


def annulus(
    r_in: float,
    r_out: float,
    z: float,
    n_segments: int,
    centre: tuple[float, float] = (0.0, 0.0),
    normal_up: bool = True,
) -> np.ndarray:
    """Horizontal polygonal ring between two circles.

    Parameters
    ----------
    r_in, r_out : float
        Inner and outer radius, m (0 < r_in < r_out).
    z : float
        Height, m.
    n_segments : int
        Number of polygon sides (>= 3).
    centre : (float, float)
        Centre (x, y), m.
    normal_up : bool
        Normals along +z (True) or -z.

    Returns
    -------
    numpy.ndarray, shape (2 * n_segments, 3, 3)
        Triangles, m. Area ``n/2 (r_out^2 - r_in^2) sin(2 pi/n)``.
    """
    _check_positive("r_in", r_in)
    _check_positive("r_out", r_out)
    if not r_in < r_out:
        raise ValueError(f"annulus needs r_in < r_out, got r_in={r_in}, r_out={r_out}")
    _check_segments(n_segments)
    n = n_segments
    inner = _ring(r_in, n, centre)
    outer = _ring(r_out, n, centre)
    ia = np.column_stack((inner[:-1], np.full(n, z)))
    ib = np.column_stack((inner[1:], np.full(n, z)))
    oa = np.column_stack((outer[:-1], np.full(n, z)))
    ob = np.column_stack((outer[1:], np.full(n, z)))
    up = np.concatenate((np.stack((ia, oa, ob), axis=1), np.stack((ia, ob, ib), axis=1)))
    return up if normal_up else up[:, ::-1].copy()


def quad(p0: np.ndarray, p1: np.ndarray, p2: np.ndarray, p3: np.ndarray) -> np.ndarray:
    """Planar quadrilateral p0-p1-p2-p3 as two triangles (p0, p1, p2) and (p0, p2, p3).

    Parameters
    ----------
    p0, p1, p2, p3 : array_like, shape (3,)
        Corners in order around the boundary, m. The normal follows the right-hand rule of
        this order.

    Returns
    -------
    numpy.ndarray, shape (2, 3, 3)
        Triangles, m.
    """
    pts = np.array([p0, p1, p2, p3], dtype=float)
    if pts.shape != (4, 3):
        raise ValueError(f"quad corners must be four 3-vectors, got shape {pts.shape}")
    tris = np.stack((pts[[0, 1, 2]], pts[[0, 2, 3]]))
    areas = triangle_areas(tris)
    if np.any(areas <= 0):
        raise ValueError("quad corners are degenerate (a triangle has zero area)")
    n0, n1 = triangle_normals(tris)
    if float(np.dot(n0, n1)) < 1.0 - 1e-9:
        raise ValueError("quad corners are not coplanar or not in order around the boundary")
    return tris


def rectangle(
    x0: float, x1: float, y0: float, y1: float, z: float, normal_up: bool = True
) -> np.ndarray:
    """Horizontal rectangle [x0, x1] x [y0, y1] at height z.

    Returns
    -------
    numpy.ndarray, shape (2, 3, 3)
        Triangles, m; area ``(x1 - x0)(y1 - y0)``.
    """
    if not (x1 > x0 and y1 > y0):
        raise ValueError(f"rectangle needs x0 < x1 and y0 < y1, got {x0}, {x1}, {y0}, {y1}")
    corners = [(x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z)]
    if not normal_up:
        corners = corners[::-1]
    return quad(*(np.array(c, dtype=float) for c in corners))


def box_open_top(
    x0: float,
    x1: float,
    y0: float,
    y1: float,
    z0: float,
    z1: float,
    normals: Literal["inward", "outward"] = "inward",
) -> np.ndarray:
    """Axis-aligned box without a lid: the floor at z0 and four side walls up to z1.

    Parameters
    ----------
    x0, x1, y0, y1, z0, z1 : float
        Box bounds, m (each lower bound below its upper bound).
    normals : {"inward", "outward"}
        Normals into the box (towards material held in it) or out of it.

    Returns
    -------
    numpy.ndarray, shape (10, 3, 3)
        Triangles, m; area ``(x1-x0)(y1-y0) + 2 (z1-z0) ((x1-x0) + (y1-y0))``.
    """
    if not (x1 > x0 and y1 > y0 and z1 > z0):
        raise ValueError(
            f"box_open_top needs lower < upper bounds, got x [{x0}, {x1}], y [{y0}, {y1}], "
            f"z [{z0}, {z1}]"
        )
    if normals not in ("inward", "outward"):
        raise ValueError(f"normals must be 'inward' or 'outward', got {normals!r}")
    p = {
        (i, j, k): np.array((x, y, z), dtype=float)
        for i, x in enumerate((x0, x1))
        for j, y in enumerate((y0, y1))
        for k, z in enumerate((z0, z1))
    }
    # corner order around each face gives an outward normal
    faces = [
        ((0, 0, 0), (0, 1, 0), (1, 1, 0), (1, 0, 0)),  # floor, -z
        ((0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)),  # y0 wall, -y
        ((1, 0, 0), (1, 1, 0), (1, 1, 1), (1, 0, 1)),  # x1 wall, +x
        ((1, 1, 0), (0, 1, 0), (0, 1, 1), (1, 1, 1)),  # y1 wall, +y
        ((0, 1, 0), (0, 0, 0), (0, 0, 1), (0, 1, 1)),  # x0 wall, -x
    ]
    outward = np.concatenate([quad(*(p[c] for c in face)) for face in faces])
    return outward if normals == "outward" else outward[:, ::-1].copy()


# ----------------------------------------------------------------------------------------------
# transforms


def translate(triangles: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """Shift a surface by ``offset`` (shape (3,), m); returns a new (n, 3, 3) array."""
    off = np.asarray(offset, dtype=float)
    if off.shape != (3,):
        raise ValueError(f"offset must be a 3-vector, got shape {off.shape}")
    return _as_triangles(triangles) + off


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
    tri = _as_triangles(triangles)
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
    return np.concatenate([_as_triangles(p) for p in parts])


# ----------------------------------------------------------------------------------------------
# writing


def _check_name(name: str) -> None:
    if not _NAME_PATTERN.match(name):
        raise ValueError(f"STL solid name must match [A-Za-z0-9_.-]+, got {name!r}")


def _canonical(values: np.ndarray) -> np.ndarray:
    # adding 0.0 turns -0.0 into +0.0, so mirrored inputs do not print "-0"
    return np.asarray(values, dtype=float) + 0.0


def write_stl_ascii(path: str | Path, triangles: np.ndarray, name: str = "demcal") -> None:
    """Write an ASCII STL file.

    Parameters
    ----------
    path : str or Path
        Output file; parent directories are created.
    triangles : numpy.ndarray, shape (n, 3, 3)
        Vertices, m.
    name : str
        Solid name ([A-Za-z0-9_.-]+).
    """
    _check_name(name)
    tri = _canonical(_as_triangles(triangles))
    normals = _canonical(triangle_normals(tri))
    vec = f"{_NUM} {_NUM} {_NUM}"
    lines = [f"solid {name}"]
    for t, nrm in zip(tri, normals, strict=True):
        lines.append("  facet normal " + vec % tuple(nrm))
        lines.append("    outer loop")
        for v in t:
            lines.append("      vertex " + vec % tuple(v))
        lines.append("    endloop")
        lines.append("  endfacet")
    lines.append(f"endsolid {name}")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(("\n".join(lines) + "\n").encode("ascii"))


def write_stl_binary(path: str | Path, triangles: np.ndarray, name: str = "demcal") -> None:
    """Write a binary (little-endian float32) STL file.

    Parameters
    ----------
    path : str or Path
        Output file; parent directories are created.
    triangles : numpy.ndarray, shape (n, 3, 3)
        Vertices, m.
    name : str
        Stored in the 80-byte header (at most 70 characters, [A-Za-z0-9_.-]+); the header does
        not start with "solid" so that readers do not mistake the file for ASCII.
    """
    _check_name(name)
    header = f"binary {name}".encode("ascii")
    if len(header) > _BINARY_HEADER_BYTES:
        raise ValueError(f"STL solid name too long for a binary header: {name!r}")
    tri = _canonical(_as_triangles(triangles))
    normals = _canonical(triangle_normals(tri))
    record = np.zeros(
        len(tri),
        dtype=np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (9,)), ("attr", "<u2")]),
    )
    record["normal"] = normals
    record["vertices"] = tri.reshape(-1, 9)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("wb") as fh:
        fh.write(header.ljust(_BINARY_HEADER_BYTES, b"\0"))
        fh.write(struct.pack("<I", len(tri)))
        fh.write(record.tobytes())


# ----------------------------------------------------------------------------------------------
# reading


def _read_binary(path: Path, data: bytes) -> StlMesh:
    count = struct.unpack_from("<I", data, _BINARY_HEADER_BYTES)[0]
    record = np.frombuffer(
        data,
        dtype=np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (9,)), ("attr", "<u2")]),
        count=count,
        offset=_BINARY_HEADER_BYTES + 4,
    )
    header = data[:_BINARY_HEADER_BYTES].split(b"\0", 1)[0].decode("ascii", errors="replace")
    name = header.removeprefix("binary ").strip()
    tri = record["vertices"].astype(float).reshape(-1, 3, 3)
    if not np.all(np.isfinite(tri)):
        raise StlFormatError(f"{path}: binary STL holds non-finite vertex coordinates")
    return StlMesh(name=name, triangles=tri, normals=record["normal"].astype(float))


def _floats(path: Path, lineno: int, words: list[str], what: str) -> list[float]:
    try:
        values = [float(w) for w in words]
    except ValueError:
        values = []
    if len(values) != 3 or not all(np.isfinite(values)):
        raise StlFormatError(f"{path}:{lineno}: expected three finite numbers after '{what}'")
    return values


def _read_ascii(path: Path, data: bytes) -> StlMesh:
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError:
        raise StlFormatError(f"{path}: neither a valid binary nor an ASCII STL file") from None
    lines = [(i + 1, line.split()) for i, line in enumerate(text.splitlines())]
    lines = [(i, w) for i, w in lines if w]
    tris: list[list[list[float]]] = []
    norms: list[list[float]] = []
    name = ""
    pos = 0

    def expect(keywords: tuple[str, ...]) -> tuple[int, list[str]]:
        nonlocal pos
        if pos >= len(lines):
            raise StlFormatError(f"{path}: unexpected end of file, expected '{' '.join(keywords)}'")
        lineno, words = lines[pos]
        if tuple(words[: len(keywords)]) != keywords:
            raise StlFormatError(
                f"{path}:{lineno}: expected '{' '.join(keywords)}', found '{' '.join(words)}'"
            )
        pos += 1
        return lineno, words[len(keywords) :]

    n_solids = 0
    while pos < len(lines):
        _, rest = expect(("solid",))
        if n_solids == 0:
            name = " ".join(rest)
        n_solids += 1
        while pos < len(lines) and lines[pos][1][0] == "facet":
            lineno, rest = expect(("facet", "normal"))
            norms.append(_floats(path, lineno, rest, "facet normal"))
            expect(("outer", "loop"))
            tri = []
            for _ in range(3):
                lineno, rest = expect(("vertex",))
                tri.append(_floats(path, lineno, rest, "vertex"))
            expect(("endloop",))
            expect(("endfacet",))
            tris.append(tri)
        expect(("endsolid",))
    if n_solids == 0:
        raise StlFormatError(f"{path}: empty STL file")
    return StlMesh(
        name=name,
        triangles=np.array(tris, dtype=float).reshape(-1, 3, 3),
        normals=np.array(norms, dtype=float).reshape(-1, 3),
    )


def read_stl(path: str | Path) -> StlMesh:
    """Read an ASCII or binary STL file.

    A file is taken as binary when its size equals 84 + 50 * (facet count in bytes 80-83)
    (binary headers may legally start with "solid"), otherwise as ASCII.

    Parameters
    ----------
    path : str or Path
        STL file.

    Returns
    -------
    StlMesh
        Name, triangles (n, 3, 3) in file units (m for files written here) and stored normals.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    StlFormatError
        If the file is neither a consistent binary STL nor a well-formed ASCII STL; the
        message names the file and, for ASCII, the line.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"STL file not found: {path}")
    data = path.read_bytes()
    if len(data) >= _BINARY_HEADER_BYTES + 4:
        count = struct.unpack_from("<I", data, _BINARY_HEADER_BYTES)[0]
        if len(data) == _BINARY_HEADER_BYTES + 4 + _BINARY_FACET.size * count:
            return _read_binary(path, data)
    if not data.lstrip().startswith(b"solid"):
        if len(data) >= _BINARY_HEADER_BYTES + 4:
            count = struct.unpack_from("<I", data, _BINARY_HEADER_BYTES)[0]
            expected = _BINARY_HEADER_BYTES + 4 + _BINARY_FACET.size * count
            raise StlFormatError(
                f"{path}: binary STL declares {count} facets ({expected} bytes) but has "
                f"{len(data)} bytes"
            )
        raise StlFormatError(f"{path}: too short for a binary STL and not an ASCII STL")
    return _read_ascii(path, data)
