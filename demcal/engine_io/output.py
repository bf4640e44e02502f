"""Readers for the text and VTK files that the DEM engine (or LIGGGHTS 3.8) writes.

Five formats are read, each into plain numpy/pandas objects and nothing else; no physics is
computed here.

* ``fix print`` files: a title line (column names after ``#``) and whitespace-separated rows.
* ``fix ave/time`` files (LAMMPS layout), scalar mode and vector mode.
* LIGGGHTS/LAMMPS log files: one thermo table per ``run``.
* ``dump custom`` text files: one snapshot per ``ITEM: TIMESTEP`` block.
* legacy VTK particle dumps (``dump custom/vtk``), read with :func:`pyvista.read`.

A run that is interrupted leaves an incomplete last line (or snapshot) behind. Such a tail is
dropped with a :class:`TruncatedOutputWarning`; anything malformed before it raises
:class:`EngineOutputError`, which names the file and the 1-based line number. A column that the
caller asks for and the file lacks raises :class:`MissingColumnError`.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from itertools import pairwise
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = [
    "DumpSnapshot",
    "EngineOutputError",
    "MissingColumnError",
    "TruncatedOutputWarning",
    "VtkParticles",
    "read_ave_time",
    "read_dump",
    "read_dump_last",
    "read_log",
    "read_print_file",
    "read_vtk_particles",
    "require_columns",
]

# Columns that hold step counters or particle labels and are stored as integers.
_INTEGER_COLUMNS = frozenset({"step", "timestep", "id", "type", "row", "number-of-rows"})


class EngineOutputError(ValueError):
    """Malformed content in an engine output file.

    Parameters
    ----------
    path : str or Path
        The file being read.
    message : str
        What is wrong.
    line : int, optional
        1-based line number of the offending line.
    """

    def __init__(self, path: str | Path, message: str, line: int | None = None) -> None:
        self.path = str(path)
        self.line = line
        where = f"{self.path}:{line}" if line is not None else self.path
        super().__init__(f"{where}: {message}")


class MissingColumnError(KeyError):
    """A column the caller requires is absent from a file or table.

    Parameters
    ----------
    source : str or Path
        File name (or a description of the table) that lacks the columns.
    missing : sequence of str
        The absent column names.
    available : sequence of str
        The columns that are present.
    """

    def __init__(
        self, source: str | Path, missing: Sequence[str], available: Sequence[str]
    ) -> None:
        self.source = str(source)
        self.missing = tuple(missing)
        self.available = tuple(available)
        super().__init__(
            f"{self.source}: missing column(s) {', '.join(map(repr, self.missing))}; "
            f"available: {', '.join(self.available)}"
        )

    def __str__(self) -> str:
        # KeyError would otherwise print the message wrapped in quotes.
        return str(self.args[0])


class TruncatedOutputWarning(UserWarning):
    """An incomplete tail of an output file (interrupted run) was dropped."""


def require_columns(
    columns: Sequence[str], required: Sequence[str] | None, source: str | Path
) -> None:
    """Raise :class:`MissingColumnError` if any of ``required`` is not in ``columns``.

    Parameters
    ----------
    columns : sequence of str
        Columns that are present.
    required : sequence of str or None
        Columns the caller needs; ``None`` requires nothing.
    source : str or Path
        Named in the error message.
    """
    if required is None:
        return
    present = set(columns)
    missing = [c for c in required if c not in present]
    if missing:
        raise MissingColumnError(source, missing, list(columns))


# --------------------------------------------------------------------------------------------
# Shared line handling
# --------------------------------------------------------------------------------------------


def _read_lines(path: str | Path) -> tuple[list[str], bool]:
    """Return the lines of ``path`` and whether the file ends with a newline."""
    text = Path(path).read_text(encoding="utf-8", errors="replace")
    return text.splitlines(), text.endswith("\n")


def _parse_row(tokens: list[str]) -> list[float] | None:
    """Floats of ``tokens``, or ``None`` if any token is not a number."""
    try:
        return [float(tok) for tok in tokens]
    except ValueError:
        return None


def _is_last_content_line(lines: list[str], index: int) -> bool:
    """True if no non-blank line follows ``lines[index]``."""
    return all(not ln.strip() for ln in lines[index + 1 :])


def _frame(names: Sequence[str], rows: list[list[float]] | np.ndarray) -> pd.DataFrame:
    """Build a DataFrame of float columns; step and label columns become int64."""
    data = np.asarray(rows, dtype=np.float64).reshape(-1, len(names))
    frame = pd.DataFrame(data, columns=list(names))
    for name in frame.columns:
        col = frame[name].to_numpy()
        if name.lower() in _INTEGER_COLUMNS and np.all(np.isfinite(col)):
            frame[name] = col.astype(np.int64)
    return frame


def _check_unique(names: Sequence[str], path: str | Path, line: int) -> None:
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise EngineOutputError(path, f"duplicate column name {name!r} in header", line)
        seen.add(name)


def _parse_table_rows(
    lines: list[str],
    start: int,
    n_columns: int,
    path: str | Path,
    ends_with_newline: bool,
) -> list[list[float]]:
    """Parse data rows of a flat table from ``lines[start:]``.

    Comment lines (``#``) and blank lines are skipped. The last content line is dropped with a
    warning if it is incomplete (wrong field count, a broken number, or no final newline).
    """
    rows: list[list[float]] = []
    for i in range(start, len(lines)):
        stripped = lines[i].strip()
        if not stripped or stripped.startswith("#"):
            continue
        tokens = stripped.split()
        values = _parse_row(tokens) if len(tokens) == n_columns else None
        is_last = _is_last_content_line(lines, i)
        if is_last and (values is None or not ends_with_newline):
            warnings.warn(
                f"{path}:{i + 1}: dropped incomplete last line {stripped[:60]!r}",
                TruncatedOutputWarning,
                stacklevel=3,
            )
            continue
        if values is None:
            raise EngineOutputError(
                path,
                f"expected {n_columns} numeric fields, got {len(tokens)}: {stripped[:80]!r}",
                i + 1,
            )
        rows.append(values)
    return rows


# --------------------------------------------------------------------------------------------
# fix print
# --------------------------------------------------------------------------------------------


def read_print_file(
    path: str | Path,
    columns: Sequence[str] | None = None,
    names: Sequence[str] | None = None,
) -> pd.DataFrame:
    """Read a ``fix print`` output file.

    The first line is the title given in the deck; its words after a leading ``#`` are taken as
    column names (e.g. ``# step time phase cycle lid_z ...``). Later ``#`` lines (a title
    written again after a restart) and blank lines are skipped.

    Parameters
    ----------
    path : str or Path
        The print file.
    columns : sequence of str, optional
        Columns the caller needs; a missing one raises :class:`MissingColumnError`.
    names : sequence of str, optional
        Column names to use instead of the title (needed if the deck gave no title).

    Returns
    -------
    pandas.DataFrame
        One row per printed line, shape (n_rows, n_columns); float64 columns, a ``step``
        column as int64. Units are whatever the deck printed (SI for demcal decks).

    Raises
    ------
    EngineOutputError
        Empty file, no usable title, or a malformed row before the last line.
    MissingColumnError
        A column in ``columns`` is absent.
    """
    lines, ends_nl = _read_lines(path)
    first = next((i for i, ln in enumerate(lines) if ln.strip()), None)
    if first is None:
        raise EngineOutputError(path, "file is empty")
    title = lines[first].strip()
    title_tokens = title.lstrip("#").split()
    title_is_header = _parse_row(title_tokens) is None
    if names is None:
        # Without a title keyword LIGGGHTS writes "# Fix print output for fix ID".
        if not title_is_header or title.startswith("# Fix print output for fix"):
            raise EngineOutputError(
                path, "first line is not a title with column names; pass names=", first + 1
            )
        names = title_tokens
    _check_unique(names, path, first + 1)
    start = first + 1 if title_is_header else first
    rows = _parse_table_rows(lines, start, len(names), path, ends_nl)
    frame = _frame(names, rows)
    require_columns(list(frame.columns), columns, path)
    return frame


# --------------------------------------------------------------------------------------------
# fix ave/time
# --------------------------------------------------------------------------------------------


def read_ave_time(
    path: str | Path,
    columns: Sequence[str] | None = None,
) -> pd.DataFrame:
    """Read a LAMMPS/LIGGGHTS ``fix ave/time`` output file.

    Scalar mode has two comment lines, ``# Time-averaged data for fix ID`` and
    ``# TimeStep v_a c_b f_c[1] ...``, then one row per output step. Vector mode has a third
    comment line ``# Row c_x[1] ...`` and blocks of a ``step nrows`` line followed by ``nrows``
    rows; it is returned in long form with columns ``TimeStep``, ``Row`` and the values.

    Parameters
    ----------
    path : str or Path
        The ave/time file.
    columns : sequence of str, optional
        Columns the caller needs; a missing one raises :class:`MissingColumnError`.

    Returns
    -------
    pandas.DataFrame
        Shape (n_rows, n_columns); ``TimeStep`` and ``Row`` are int64, the rest float64.

    Raises
    ------
    EngineOutputError
        Missing or malformed header lines, or a malformed row before the end of the file.
    MissingColumnError
        A column in ``columns`` is absent.
    """
    lines, ends_nl = _read_lines(path)
    comments = []
    for i, ln in enumerate(lines):
        if ln.startswith("#"):
            comments.append(i)
        elif ln.strip():
            break
    if len(comments) < 2:
        raise EngineOutputError(path, "expected two '#' header lines of fix ave/time", 1)
    head = lines[comments[1]].lstrip("#").split()
    if not head or head[0] != "TimeStep":
        raise EngineOutputError(path, "second header line must start with '# TimeStep'", 2)
    vector_mode = len(comments) >= 3 and lines[comments[2]].lstrip("#").split()[:1] == ["Row"]
    if not vector_mode:
        _check_unique(head, path, comments[1] + 1)
        rows = _parse_table_rows(lines, comments[1] + 1, len(head), path, ends_nl)
        frame = _frame(head, rows)
    else:
        row_names = lines[comments[2]].lstrip("#").split()
        names = ["TimeStep", *row_names]
        _check_unique(names, path, comments[2] + 1)
        frame = _frame(names, _parse_vector_blocks(lines, comments[2] + 1, len(row_names), path))
    require_columns(list(frame.columns), columns, path)
    return frame


def _parse_vector_blocks(
    lines: list[str], start: int, n_fields: int, path: str | Path
) -> list[list[float]]:
    """Rows ``[step, row, values...]`` of vector-mode ave/time blocks from ``lines[start:]``."""
    rows: list[list[float]] = []
    i = start
    n = len(lines)
    while i < n:
        stripped = lines[i].strip()
        if not stripped or stripped.startswith("#"):
            i += 1
            continue
        tokens = stripped.split()
        block_head = _parse_row(tokens) if len(tokens) == 2 else None
        if block_head is None:
            raise EngineOutputError(path, "expected a 'TimeStep Number-of-rows' line", i + 1)
        step, n_rows = block_head
        block: list[list[float]] = []
        j = i + 1
        truncated = False
        while len(block) < int(n_rows):
            if j >= n:
                truncated = True
                break
            toks = lines[j].split()
            values = _parse_row(toks) if len(toks) == n_fields else None
            if values is None:
                if _is_last_content_line(lines, j):
                    truncated = True
                    break
                raise EngineOutputError(
                    path, f"expected {n_fields} numeric fields in vector block", j + 1
                )
            block.append([step, *values])
            j += 1
        if truncated:
            warnings.warn(
                f"{path}:{i + 1}: dropped incomplete last block (step {int(step)})",
                TruncatedOutputWarning,
                stacklevel=3,
            )
            break
        rows.extend(block)
        i = j
    return rows


# --------------------------------------------------------------------------------------------
# log file
# --------------------------------------------------------------------------------------------


def read_log(
    path: str | Path,
    columns: Sequence[str] | None = None,
) -> list[pd.DataFrame]:
    """Read the thermo tables of a LIGGGHTS/LAMMPS log file, one per ``run``.

    A table starts at a header line whose first word is ``Step`` (``thermo_style`` one/custom)
    and ends at a line starting with ``Loop time of``. Text lines inside a table (warnings,
    info messages) are skipped; a numeric line of the wrong width inside a table is an error,
    unless it is the last line of the file (run interrupted), which is dropped with a warning.
    A table that is still open at the end of the file is kept, with a warning. The
    ``thermo_style multi`` layout is not supported.

    Parameters
    ----------
    path : str or Path
        The log file.
    columns : sequence of str, optional
        Columns every table must have; a missing one raises :class:`MissingColumnError`.

    Returns
    -------
    list of pandas.DataFrame
        One table per run, each of shape (n_thermo_outputs, n_columns); ``Step`` as int64.

    Raises
    ------
    EngineOutputError
        A malformed thermo row, or no thermo table in the file.
    MissingColumnError
        A column in ``columns`` is absent from a table.
    """
    lines, ends_nl = _read_lines(path)
    tables: list[pd.DataFrame] = []
    header: list[str] | None = None
    header_line = 0
    rows: list[list[float]] = []
    for i, ln in enumerate(lines):
        stripped = ln.strip()
        if header is None:
            tokens = stripped.split()
            if tokens and tokens[0] == "Step" and all(_parse_row([w]) is None for w in tokens):
                header, header_line, rows = tokens, i + 1, []
                _check_unique(header, path, header_line)
            continue
        if stripped.startswith("Loop time of"):
            tables.append(_log_table(header, rows, path, header_line, columns))
            header = None
            continue
        tokens = stripped.split()
        if not tokens:
            continue
        if _parse_row(tokens[:1]) is None:
            # A message printed during the run (WARNING, INFO, ...), not thermo data.
            continue
        values = _parse_row(tokens) if len(tokens) == len(header) else None
        is_last = _is_last_content_line(lines, i)
        if is_last and (values is None or not ends_nl):
            warnings.warn(
                f"{path}:{i + 1}: dropped incomplete last thermo line",
                TruncatedOutputWarning,
                stacklevel=2,
            )
            continue
        if values is None:
            raise EngineOutputError(
                path,
                f"thermo row has {len(tokens)} fields, header at line {header_line} has "
                f"{len(header)}",
                i + 1,
            )
        rows.append(values)
    if header is not None:
        warnings.warn(
            f"{path}:{header_line}: thermo table has no 'Loop time of' line (run interrupted)",
            TruncatedOutputWarning,
            stacklevel=2,
        )
        tables.append(_log_table(header, rows, path, header_line, columns))
    if not tables:
        raise EngineOutputError(path, "no thermo table (line starting with 'Step') found")
    return tables


def _log_table(
    header: list[str],
    rows: list[list[float]],
    path: str | Path,
    header_line: int,
    columns: Sequence[str] | None,
) -> pd.DataFrame:
    frame = _frame(header, rows)
    require_columns(header, columns, f"{path}:{header_line}")
    return frame


# --------------------------------------------------------------------------------------------
# dump custom (text)
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class DumpSnapshot:
    """One snapshot of a ``dump custom`` text file.

    Attributes
    ----------
    timestep : int
        Time step of the snapshot.
    box : numpy.ndarray
        Shape (3, 2): lower and upper bounds per axis x, y, z (m). For a triclinic box these
        are the bounding-box values as written.
    boundary : tuple of str
        The boundary flags after ``BOX BOUNDS`` (e.g. ``("ff", "ff", "ff")``).
    atoms : pandas.DataFrame
        Shape (n_atoms, n_fields) with the columns named in ``ITEM: ATOMS``; ``id`` and
        ``type`` as int64, the rest float64 (SI units in demcal decks).
    tilt : numpy.ndarray or None
        Shape (3,): xy, xz, yz tilt factors (m) of a triclinic box, else ``None``.
    """

    timestep: int
    box: np.ndarray
    boundary: tuple[str, ...]
    atoms: pd.DataFrame
    tilt: np.ndarray | None = field(default=None)


class _IncompleteSnapshot(Exception):
    """The snapshot runs into the end of the file."""


def _dump_starts(lines: list[str]) -> list[int]:
    return [i for i, ln in enumerate(lines) if ln.startswith("ITEM: TIMESTEP")]


def _parse_dump_snapshot(
    lines: list[str],
    start: int,
    stop: int,
    path: str | Path,
    at_end: bool,
    ends_nl: bool,
) -> DumpSnapshot:
    """Parse ``lines[start:stop]``, one snapshot beginning with ``ITEM: TIMESTEP``."""

    def need(i: int) -> str:
        if i >= stop:
            if at_end:
                raise _IncompleteSnapshot
            raise EngineOutputError(path, "snapshot ends early", i + 1)
        return lines[i]

    def integer(i: int) -> int:
        text = need(i).strip()
        try:
            return int(text)
        except ValueError:
            if at_end and i == stop - 1:
                raise _IncompleteSnapshot from None
            raise EngineOutputError(
                path, f"expected an integer, got {text[:40]!r}", i + 1
            ) from None

    i = start + 1
    timestep = integer(i)
    i += 1
    n_atoms: int | None = None
    box: np.ndarray | None = None
    tilt: np.ndarray | None = None
    boundary: tuple[str, ...] = ()
    while True:
        item = need(i)
        if item.startswith("ITEM: NUMBER OF ATOMS"):
            n_atoms = integer(i + 1)
            i += 2
        elif item.startswith("ITEM: BOX BOUNDS"):
            flags = item.split()[3:]
            triclinic = len(flags) >= 3 and flags[0] == "xy"
            boundary = tuple(flags[3:] if triclinic else flags)
            bounds = []
            for k in range(3):
                toks = need(i + 1 + k).split()
                vals = _parse_row(toks) if len(toks) == (3 if triclinic else 2) else None
                if vals is None:
                    raise EngineOutputError(path, "malformed box bounds line", i + 2 + k)
                bounds.append(vals)
            arr = np.asarray(bounds, dtype=np.float64)
            box = arr[:, :2].copy()
            tilt = arr[:, 2].copy() if triclinic else None
            i += 4
        elif item.startswith(("ITEM: TIME", "ITEM: UNITS")):
            i += 2
        elif item.startswith("ITEM: ATOMS"):
            break
        else:
            raise EngineOutputError(path, f"unexpected line {item[:60]!r}", i + 1)
    if n_atoms is None or box is None:
        raise EngineOutputError(path, "snapshot lacks NUMBER OF ATOMS or BOX BOUNDS", start + 1)
    names = item.split()[2:]
    _check_unique(names, path, i + 1)
    first_row = i + 1
    if stop - first_row < n_atoms:
        if at_end:
            raise _IncompleteSnapshot
        raise EngineOutputError(
            path, f"expected {n_atoms} atom rows, found {stop - first_row}", first_row
        )
    if stop - first_row > n_atoms and any(ln.strip() for ln in lines[first_row + n_atoms : stop]):
        raise EngineOutputError(
            path, f"more than {n_atoms} atom rows in snapshot", first_row + n_atoms + 1
        )
    if at_end and n_atoms > 0 and not ends_nl and first_row + n_atoms == len(lines):
        raise _IncompleteSnapshot
    block = [ln.split() for ln in lines[first_row : first_row + n_atoms]]
    data = np.empty((0, len(names)))
    well_formed = n_atoms == 0
    if n_atoms:
        try:
            data = np.array(block, dtype=np.float64)
            well_formed = data.shape == (n_atoms, len(names))
        except ValueError:
            well_formed = False
    if not well_formed:
        for k, toks in enumerate(block):
            if len(toks) != len(names) or _parse_row(toks) is None:
                if at_end and k == n_atoms - 1:
                    raise _IncompleteSnapshot
                raise EngineOutputError(
                    path, f"expected {len(names)} numeric fields in atom row", first_row + k + 1
                )
    atoms = _frame(names, data)
    return DumpSnapshot(timestep=timestep, box=box, boundary=boundary, atoms=atoms, tilt=tilt)


def read_dump(
    path: str | Path,
    columns: Sequence[str] | None = None,
) -> list[DumpSnapshot]:
    """Read all snapshots of a ``dump custom`` text file.

    Parameters
    ----------
    path : str or Path
        The dump file.
    columns : sequence of str, optional
        Per-atom columns the caller needs (e.g. ``["x", "y", "z", "radius"]``).

    Returns
    -------
    list of DumpSnapshot
        In file order. An incomplete last snapshot is dropped with a warning.

    Raises
    ------
    EngineOutputError
        Malformed content, or no snapshot at all.
    MissingColumnError
        A column in ``columns`` is absent from a snapshot.
    """
    lines, ends_nl = _read_lines(path)
    starts = _dump_starts(lines)
    if not starts:
        raise EngineOutputError(path, "no 'ITEM: TIMESTEP' line found")
    snapshots = []
    bounds = [*starts, len(lines)]
    for k, (s, e) in enumerate(pairwise(bounds)):
        at_end = k == len(starts) - 1
        try:
            snap = _parse_dump_snapshot(lines, s, e, path, at_end, ends_nl)
        except _IncompleteSnapshot:
            warnings.warn(
                f"{path}:{s + 1}: dropped incomplete last snapshot",
                TruncatedOutputWarning,
                stacklevel=2,
            )
            break
        require_columns(list(snap.atoms.columns), columns, f"{path}:{s + 1}")
        snapshots.append(snap)
    if not snapshots:
        raise EngineOutputError(path, "no complete snapshot")
    return snapshots


def read_dump_last(
    path: str | Path,
    columns: Sequence[str] | None = None,
) -> DumpSnapshot:
    """Read only the last complete snapshot of a ``dump custom`` text file.

    Parameters
    ----------
    path : str or Path
        The dump file.
    columns : sequence of str, optional
        Per-atom columns the caller needs.

    Returns
    -------
    DumpSnapshot
        The last complete snapshot (an incomplete final one is dropped with a warning).

    Raises
    ------
    EngineOutputError
        Malformed content or no complete snapshot.
    MissingColumnError
        A column in ``columns`` is absent.
    """
    lines, ends_nl = _read_lines(path)
    starts = _dump_starts(lines)
    if not starts:
        raise EngineOutputError(path, "no 'ITEM: TIMESTEP' line found")
    bounds = [*starts, len(lines)]
    for k in range(len(starts) - 1, -1, -1):
        try:
            snap = _parse_dump_snapshot(
                lines, bounds[k], bounds[k + 1], path, k == len(starts) - 1, ends_nl
            )
        except _IncompleteSnapshot:
            warnings.warn(
                f"{path}:{bounds[k] + 1}: dropped incomplete last snapshot",
                TruncatedOutputWarning,
                stacklevel=2,
            )
            continue
        require_columns(list(snap.atoms.columns), columns, f"{path}:{bounds[k] + 1}")
        return snap
    raise EngineOutputError(path, "no complete snapshot")


# --------------------------------------------------------------------------------------------
# VTK particle dumps
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class VtkParticles:
    """Particle positions and per-particle arrays of one VTK dump.

    Attributes
    ----------
    points : numpy.ndarray
        Shape (n, 3), particle centres (m).
    arrays : dict of str to numpy.ndarray
        Point-data arrays by name, each of shape (n,) or (n, k) (SI units as dumped).
    """

    points: np.ndarray
    arrays: dict[str, np.ndarray]


def read_vtk_particles(
    path: str | Path,
    arrays: Sequence[str] | None = None,
) -> VtkParticles:
    """Read a particle dump written by ``dump custom/vtk`` (legacy ``.vtk`` or XML) with pyvista.

    Parameters
    ----------
    path : str or Path
        The VTK file.
    arrays : sequence of str, optional
        Point-data arrays the caller needs (e.g. ``["radius"]``).

    Returns
    -------
    VtkParticles
        Points of shape (n, 3) and the point-data arrays.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    EngineOutputError
        The file cannot be parsed or holds no points.
    MissingColumnError
        An array in ``arrays`` is absent.
    """
    import pyvista

    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"{p}: no such VTK file")
    try:
        mesh = pyvista.read(str(p))
    except Exception as exc:  # VTK raises assorted types for unreadable files
        raise EngineOutputError(p, f"cannot read VTK data ({exc})") from exc
    if isinstance(mesh, pyvista.MultiBlock):
        blocks = [b for b in mesh if b is not None and b.n_points > 0]
        if len(blocks) != 1:
            raise EngineOutputError(p, f"expected one particle block, found {len(blocks)}")
        mesh = blocks[0]
    points = np.asarray(mesh.points, dtype=np.float64)
    if points.ndim != 2 or points.shape[0] == 0:
        raise EngineOutputError(p, "no points in VTK file (empty or unparsable)")
    data = {name: np.asarray(mesh.point_data[name]) for name in list(mesh.point_data.keys())}
    require_columns(list(data), arrays, p)
    return VtkParticles(points=points, arrays=data)
