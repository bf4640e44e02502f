"""Reader of ``dump local`` text files (LIGGGHTS 3.8 and dem_engine write the same layout).

A local dump holds one table per snapshot with one row per entry of a local compute, e.g. one row
per touching particle pair from ``compute ID group pair/gran/local KEYWORDS``::

    ITEM: TIMESTEP
    1000
    ITEM: NUMBER OF ENTRIES
    2
    ITEM: BOX BOUNDS ff ff ff
    -0.01 0.01
    -0.01 0.01
    -0.01 0.01
    ITEM: ENTRIES c_c[1] c_c[2] c_c[3]
    1 2 0
    1 3 0

(the ENTRIES line and every row end with a blank). :func:`pair_gran_local_columns` names the
columns of ``pair/gran/local`` in the order LIGGGHTS 3.8 writes them.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from demcal.engine_io.output_errors import (
    EngineOutputError,
)
from demcal.engine_io.snapshot_text import (
    IncompleteSnapshot,
    SnapshotLines,
    read_snapshots,
    snapshot_starts,
)
from demcal.engine_io.text_table import check_unique, numeric_frame, parse_row, read_lines

#: Columns of each ``pair/gran/local`` keyword, in the order LIGGGHTS 3.8 writes the blocks
#: (whatever the order of the keywords). Pair 1 -> 2: ``force`` is the contact force on particle 1
#: from particle 2 (N), ``force_normal`` its projection on the line of centres and
#: ``force_tangential`` the rest; ``torque`` is the contact torque on particle 1 (N m), rolling
#: resistance included; ``periodic`` is 1 for a contact across a periodic boundary.
PAIR_GRAN_LOCAL_BLOCKS: dict[str, tuple[str, ...]] = {
    "pos": ("x1", "y1", "z1", "x2", "y2", "z2"),
    "vel": ("vx1", "vy1", "vz1", "vx2", "vy2", "vz2"),
    "id": ("id1", "id2", "periodic"),
    "force": ("fx", "fy", "fz"),
    "force_normal": ("fnx", "fny", "fnz"),
    "force_tangential": ("ftx", "fty", "ftz"),
    "torque": ("tqx", "tqy", "tqz"),
    "history": (),  # history_size columns h1, h2, ...
    "contactArea": ("contact_area",),
    "delta": ("delta",),
}

#: Blocks written when the compute has no keywords.
PAIR_GRAN_LOCAL_DEFAULT = ("pos", "vel", "id", "force", "torque", "history", "contactArea")


def pair_gran_local_columns(keywords: Sequence[str] = (), history_size: int = 3) -> list[str]:
    """Names of the columns of ``compute pair/gran/local KEYWORDS``, in file order.

    Parameters
    ----------
    keywords : sequence of str
        The keywords of the compute (``pos vel id force force_normal force_tangential torque
        history contactArea delta``); empty for the default set. Order and repeats do not matter.
    history_size : int
        Number of history values: 3 (tangential spring, m) or 6 with ``rolling_friction epsd2``
        (then also the rolling torque, N m).

    Returns
    -------
    list of str
        One name per column: c_ID[i] is the i-th name (1-based). Positions in m, velocities in
        m/s, forces in N, torques in N m, contact area in m^2, overlap ``delta`` in m.

    Raises
    ------
    ValueError
        An unknown keyword.
    """
    chosen = set(keywords) if keywords else set(PAIR_GRAN_LOCAL_DEFAULT)
    unknown = sorted(chosen - set(PAIR_GRAN_LOCAL_BLOCKS))
    if unknown:
        raise ValueError(f"unknown pair/gran/local keyword(s): {', '.join(unknown)}")
    names: list[str] = []
    for keyword, block in PAIR_GRAN_LOCAL_BLOCKS.items():
        if keyword not in chosen:
            continue
        if keyword == "history":
            names += [f"h{k + 1}" for k in range(history_size)]
        else:
            names += block
    return names


def _parse_snapshot(
    lines: list[str], start: int, stop: int, path: str | Path, at_end: bool, ends_nl: bool
) -> tuple[int, pd.DataFrame]:
    """Parse ``lines[start:stop]``, one snapshot beginning with ``ITEM: TIMESTEP``."""

    cursor = SnapshotLines(lines, stop, path, at_end)
    need, integer = cursor.need, cursor.integer

    timestep = integer(start + 1)
    i = start + 2
    n_entries: int | None = None
    while True:
        item = need(i)
        if item.startswith("ITEM: NUMBER OF ENTRIES"):
            n_entries = integer(i + 1)
            i += 2
        elif item.startswith("ITEM: BOX BOUNDS"):
            for k in range(1, 4):
                toks = need(i + k).split()
                if len(toks) not in (2, 3) or parse_row(toks) is None:
                    raise EngineOutputError(path, "malformed box bounds line", i + k + 1)
            i += 4
        elif item.startswith(("ITEM: TIME", "ITEM: UNITS")):
            i += 2
        elif item.startswith("ITEM: ENTRIES"):
            break
        else:
            raise EngineOutputError(path, f"unexpected line {item[:60]!r}", i + 1)
    if n_entries is None or n_entries < 0:
        raise EngineOutputError(path, "snapshot lacks a valid NUMBER OF ENTRIES", start + 1)
    names = item.split()[2:]
    if not names:
        raise EngineOutputError(path, "ITEM: ENTRIES names no column", i + 1)
    check_unique(names, path, i + 1)
    first_row = i + 1
    available = stop - first_row
    if available < n_entries:
        if at_end:
            raise IncompleteSnapshot
        raise EngineOutputError(  # at the line where the next row is missing
            path, f"expected {n_entries} entry rows, found {available}", stop + 1
        )
    if any(ln.strip() for ln in lines[first_row + n_entries : stop]):
        raise EngineOutputError(
            path, f"more than {n_entries} entry rows in snapshot", first_row + n_entries + 1
        )
    if at_end and n_entries > 0 and not ends_nl and first_row + n_entries == len(lines):
        raise IncompleteSnapshot  # the last row may be cut
    data = np.empty((n_entries, len(names)))
    for k, line in enumerate(lines[first_row : first_row + n_entries]):
        toks = line.split()
        values = parse_row(toks) if len(toks) == len(names) else None
        if values is None:
            if at_end and k == n_entries - 1:
                raise IncompleteSnapshot
            raise EngineOutputError(
                path, f"expected {len(names)} numeric fields in entry row", first_row + k + 1
            )
        data[k] = values
    frame = numeric_frame(names, data)
    if "index" in frame.columns:
        frame["index"] = frame["index"].to_numpy().astype(np.int64)
    return timestep, frame


def read_local_dump(
    path: str | Path, columns: Sequence[str] | None = None
) -> list[tuple[int, pd.DataFrame]]:
    """Read all snapshots of a ``dump local`` text file.

    Parameters
    ----------
    path : str or Path
        The dump file.
    columns : sequence of str, optional
        Columns the caller needs (e.g. ``["c_c[13]", "c_c[14]"]``).

    Returns
    -------
    list of (int, pandas.DataFrame)
        In file order: the time step and a table of shape (n_entries, n_columns) with the
        column names of ``ITEM: ENTRIES`` (e.g. ``c_c[1]``), float64 (``index`` as int64), in
        the units of the compute (SI in demcal decks; see :func:`pair_gran_local_columns`). A
        snapshot without entries gives an empty table with those columns. An incomplete last
        snapshot (interrupted run) is dropped with a :class:`TruncatedOutputWarning`.

    Raises
    ------
    EngineOutputError
        Malformed content (naming the file and line), or no complete snapshot.
    MissingColumnError
        A column in ``columns`` is absent from a snapshot.
    """
    lines, ends_nl = read_lines(path)
    starts = snapshot_starts(lines)
    if starts and any(ln.strip() for ln in lines[: starts[0]]):
        raise EngineOutputError(path, "text before the first 'ITEM: TIMESTEP'", 1)
    return read_snapshots(
        lines, ends_nl, path, _parse_snapshot, lambda snap: snap[1].columns, columns
    )
