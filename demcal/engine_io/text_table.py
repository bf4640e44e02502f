"""Line handling shared by the readers of the engine's text output: numeric rows, headers, and
the incomplete last line an interrupted run leaves behind.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from demcal.engine_io.output_errors import EngineOutputError, TruncatedOutputWarning

# Columns that hold step counters or particle labels and are stored as integers.
_INTEGER_COLUMNS = frozenset({"step", "timestep", "id", "type", "row", "number-of-rows"})


def read_lines(path: str | Path) -> tuple[list[str], bool]:
    """Return the lines of ``path`` and whether the file ends with a newline."""
    text = Path(path).read_text(encoding="utf-8", errors="replace")
    return text.splitlines(), text.endswith("\n")


def parse_row(tokens: list[str]) -> list[float] | None:
    """Floats of ``tokens``, or ``None`` if any token is not a number."""
    try:
        return [float(tok) for tok in tokens]
    except ValueError:
        return None


def is_last_content_line(lines: list[str], index: int) -> bool:
    """True if no non-blank line follows ``lines[index]``."""
    return all(not ln.strip() for ln in lines[index + 1 :])


def numeric_frame(names: Sequence[str], rows: list[list[float]] | np.ndarray) -> pd.DataFrame:
    """Build a DataFrame of float columns; step and label columns become int64."""
    data = np.asarray(rows, dtype=np.float64).reshape(-1, len(names))
    frame = pd.DataFrame(data, columns=list(names))
    for name in frame.columns:
        col = frame[name].to_numpy()
        if name.lower() in _INTEGER_COLUMNS and np.all(np.isfinite(col)):
            frame[name] = col.astype(np.int64)
    return frame


def check_unique(names: Sequence[str], path: str | Path, line: int) -> None:
    """Raise :class:`EngineOutputError` (at ``line``) if a column name occurs twice."""
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise EngineOutputError(path, f"duplicate column name {name!r} in header", line)
        seen.add(name)


def parse_table_rows(
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
        values = parse_row(tokens) if len(tokens) == n_columns else None
        is_last = is_last_content_line(lines, i)
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
