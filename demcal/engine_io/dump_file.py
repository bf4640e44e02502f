"""Reader of ``dump custom`` text files: one snapshot per ``ITEM: TIMESTEP`` block."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from demcal.engine_io.output_errors import (
    EngineOutputError,
    TruncatedOutputWarning,
    require_columns,
)
from demcal.engine_io.snapshot_text import (
    IncompleteSnapshot,
    SnapshotLines,
    read_snapshots,
    snapshot_starts,
)
from demcal.engine_io.text_table import check_unique, numeric_frame, parse_row, read_lines


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


def _parse_dump_snapshot(
    lines: list[str],
    start: int,
    stop: int,
    path: str | Path,
    at_end: bool,
    ends_nl: bool,
) -> DumpSnapshot:
    """Parse ``lines[start:stop]``, one snapshot beginning with ``ITEM: TIMESTEP``."""

    cursor = SnapshotLines(lines, stop, path, at_end)
    need, integer = cursor.need, cursor.integer

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
                vals = parse_row(toks) if len(toks) == (3 if triclinic else 2) else None
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
    check_unique(names, path, i + 1)
    first_row = i + 1
    if stop - first_row < n_atoms:
        if at_end:
            raise IncompleteSnapshot
        raise EngineOutputError(
            path, f"expected {n_atoms} atom rows, found {stop - first_row}", first_row
        )
    if stop - first_row > n_atoms and any(ln.strip() for ln in lines[first_row + n_atoms : stop]):
        raise EngineOutputError(
            path, f"more than {n_atoms} atom rows in snapshot", first_row + n_atoms + 1
        )
    if at_end and n_atoms > 0 and not ends_nl and first_row + n_atoms == len(lines):
        raise IncompleteSnapshot
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
            if len(toks) != len(names) or parse_row(toks) is None:
                if at_end and k == n_atoms - 1:
                    raise IncompleteSnapshot
                raise EngineOutputError(
                    path, f"expected {len(names)} numeric fields in atom row", first_row + k + 1
                )
    atoms = numeric_frame(names, data)
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
    lines, ends_nl = read_lines(path)
    return read_snapshots(
        lines, ends_nl, path, _parse_dump_snapshot, lambda snap: snap.atoms.columns, columns
    )


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
    lines, ends_nl = read_lines(path)
    starts = snapshot_starts(lines)
    if not starts:
        raise EngineOutputError(path, "no 'ITEM: TIMESTEP' line found")
    bounds = [*starts, len(lines)]
    for k in range(len(starts) - 1, -1, -1):
        try:
            snap = _parse_dump_snapshot(
                lines, bounds[k], bounds[k + 1], path, k == len(starts) - 1, ends_nl
            )
        except IncompleteSnapshot:
            warnings.warn(
                f"{path}:{bounds[k] + 1}: dropped incomplete last snapshot",
                TruncatedOutputWarning,
                stacklevel=2,
            )
            continue
        require_columns(list(snap.atoms.columns), columns, f"{path}:{bounds[k] + 1}")
        return snap
    raise EngineOutputError(path, "no complete snapshot")
