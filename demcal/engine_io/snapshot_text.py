"""Snapshot framing shared by the text dump readers (``dump custom`` and ``dump local``).

Both formats are a sequence of blocks that start with ``ITEM: TIMESTEP``; a run that was
interrupted may leave its last block cut anywhere. The readers parse one block at a time with a
:class:`SnapshotLines` cursor, which raises :class:`IncompleteSnapshot` where the file simply ends
(the block is dropped with a warning) and :class:`EngineOutputError` where it is malformed.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path
from typing import TypeVar

from demcal.engine_io.output_errors import (
    EngineOutputError,
    TruncatedOutputWarning,
    require_columns,
)

__all__ = ["IncompleteSnapshot", "SnapshotLines", "read_snapshots", "snapshot_starts"]

T = TypeVar("T")


class IncompleteSnapshot(Exception):
    """The snapshot runs into the end of the file."""


@dataclass(frozen=True)
class SnapshotLines:
    """The lines ``[.., stop)`` of one snapshot, read with file line numbers in errors.

    Attributes
    ----------
    lines : list of str
        Every line of the file.
    stop : int
        Index of the first line after the snapshot.
    path : str or Path
        The file, for messages.
    at_end : bool
        The snapshot is the file's last: running out of lines means it was cut.
    """

    lines: list[str]
    stop: int
    path: str | Path
    at_end: bool

    def need(self, i: int) -> str:
        """Line ``i``; raises where the snapshot ends before it."""
        if i >= self.stop:
            if self.at_end:
                raise IncompleteSnapshot
            raise EngineOutputError(self.path, "snapshot ends early", i + 1)
        return self.lines[i]

    def integer(self, i: int) -> int:
        """Line ``i`` as an integer."""
        text = self.need(i).strip()
        try:
            return int(text)
        except ValueError:
            if self.at_end and i == self.stop - 1:
                raise IncompleteSnapshot from None
            raise EngineOutputError(
                self.path, f"expected an integer, got {text[:40]!r}", i + 1
            ) from None


def snapshot_starts(lines: list[str]) -> list[int]:
    """Indices of the ``ITEM: TIMESTEP`` lines."""
    return [i for i, ln in enumerate(lines) if ln.startswith("ITEM: TIMESTEP")]


def read_snapshots(
    lines: list[str],
    ends_nl: bool,
    path: str | Path,
    parse: Callable[[list[str], int, int, str | Path, bool, bool], T],
    columns_of: Callable[[T], Sequence[str]],
    columns: Sequence[str] | None = None,
) -> list[T]:
    """Parse every snapshot of a text dump, dropping a cut last one with a warning.

    Parameters
    ----------
    lines : list of str
        The file's lines; ``ends_nl`` whether it ends with a newline.
    ends_nl : bool
        The file ends with a newline (a last row without one may be cut).
    path : str or Path
        The file, for messages.
    parse : callable
        ``parse(lines, start, stop, path, at_end, ends_nl)`` -> one snapshot; raises
        :class:`IncompleteSnapshot` or :class:`EngineOutputError`.
    columns_of : callable
        The column names of a parsed snapshot.
    columns : sequence of str, optional
        Columns every snapshot must have.

    Returns
    -------
    list
        The parsed snapshots in file order.

    Raises
    ------
    EngineOutputError
        No ``ITEM: TIMESTEP`` line, malformed content or no complete snapshot.
    demcal.engine_io.output_errors.MissingColumnError
        A column in ``columns`` is absent from a snapshot.
    """
    starts = snapshot_starts(lines)
    if not starts:
        raise EngineOutputError(path, "no 'ITEM: TIMESTEP' line found")
    snapshots: list[T] = []
    for k, (s, e) in enumerate(pairwise([*starts, len(lines)])):
        try:
            snap = parse(lines, s, e, path, k == len(starts) - 1, ends_nl)
        except IncompleteSnapshot:
            warnings.warn(
                f"{path}:{s + 1}: dropped incomplete last snapshot",
                TruncatedOutputWarning,
                stacklevel=3,
            )
            break
        require_columns(list(columns_of(snap)), columns, f"{path}:{s + 1}")
        snapshots.append(snap)
    if not snapshots:
        raise EngineOutputError(path, "no complete snapshot")
    return snapshots
