"""Errors and warnings of the readers of engine output files.

A run that is interrupted leaves an incomplete last line (or snapshot) behind. Such a tail is
dropped with a :class:`TruncatedOutputWarning`; anything malformed before it raises
:class:`EngineOutputError`, which names the file and the 1-based line number. A column that the
caller asks for and the file lacks raises :class:`MissingColumnError`.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path


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
