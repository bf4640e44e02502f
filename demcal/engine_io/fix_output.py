"""Readers of ``fix print`` and ``fix ave/time`` output files (DEM engine or LIGGGHTS 3.8).

* ``fix print`` files: a title line (column names after ``#``) and whitespace-separated rows.
* ``fix ave/time`` files (LAMMPS layout), scalar mode and vector mode.

Each file is read into a plain DataFrame; no physics is computed here.
"""

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
    parse_table_rows,
    read_lines,
)


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
    lines, ends_nl = read_lines(path)
    first = next((i for i, ln in enumerate(lines) if ln.strip()), None)
    if first is None:
        raise EngineOutputError(path, "file is empty")
    title = lines[first].strip()
    title_tokens = title.lstrip("#").split()
    title_is_header = parse_row(title_tokens) is None
    if names is None:
        # Without a title keyword LIGGGHTS writes "# Fix print output for fix ID".
        if not title_is_header or title.startswith("# Fix print output for fix"):
            raise EngineOutputError(
                path, "first line is not a title with column names; pass names=", first + 1
            )
        names = title_tokens
    check_unique(names, path, first + 1)
    start = first + 1 if title_is_header else first
    rows = parse_table_rows(lines, start, len(names), path, ends_nl)
    frame = numeric_frame(names, rows)
    require_columns(list(frame.columns), columns, path)
    return frame


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
    lines, ends_nl = read_lines(path)
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
        check_unique(head, path, comments[1] + 1)
        rows = parse_table_rows(lines, comments[1] + 1, len(head), path, ends_nl)
        frame = numeric_frame(head, rows)
    else:
        row_names = lines[comments[2]].lstrip("#").split()
        names = ["TimeStep", *row_names]
        check_unique(names, path, comments[2] + 1)
        frame = numeric_frame(
            names, _parse_vector_blocks(lines, comments[2] + 1, len(row_names), path)
        )
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
        block_head = parse_row(tokens) if len(tokens) == 2 else None
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
            values = parse_row(toks) if len(toks) == n_fields else None
            if values is None:
                if is_last_content_line(lines, j):
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
