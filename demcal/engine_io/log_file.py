"""Reader of the thermo tables of a LIGGGHTS/LAMMPS (or DEM engine) log file, one per ``run``."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from demcal.engine_io.output_errors import (
    EngineOutputError,
    TruncatedOutputWarning,
    require_columns,
)
from demcal.engine_io.text_table import (
    check_unique,
    is_last_content_line,
    numeric_frame,
    parse_row,
    read_lines,
)


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
    lines, ends_nl = read_lines(path)
    tables: list[pd.DataFrame] = []
    header: list[str] | None = None
    header_line = 0
    rows: list[list[float]] = []
    for i, ln in enumerate(lines):
        stripped = ln.strip()
        if header is None:
            tokens = stripped.split()
            if tokens and tokens[0] == "Step" and all(parse_row([w]) is None for w in tokens):
                header, header_line, rows = tokens, i + 1, []
                check_unique(header, path, header_line)
            continue
        if stripped.startswith("Loop time of"):
            tables.append(_log_table(header, rows, path, header_line, columns))
            header = None
            continue
        tokens = stripped.split()
        if not tokens:
            continue
        if parse_row(tokens[:1]) is None:
            # A message printed during the run (WARNING, INFO, ...), not thermo data.
            continue
        values = parse_row(tokens) if len(tokens) == len(header) else None
        is_last = is_last_content_line(lines, i)
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
    frame = numeric_frame(header, rows)
    require_columns(header, columns, f"{path}:{header_line}")
    return frame
