"""STL files of triangulated surfaces (:mod:`demcal.decks.triangle_surface`): writing and
reading.

ASCII STL with ``%.10e`` numbers and ``\\n`` line endings, binary STL with little-endian float32
(the binary format cannot hold more; about 1e-7 relative precision). Both writers are
deterministic, so the same triangles give byte-identical files.
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from demcal.decks.triangle_surface import as_triangles, triangle_normals

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
    tri = _canonical(as_triangles(triangles))
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
    tri = _canonical(as_triangles(triangles))
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
