"""Screening surrogates saved as JSON: a format tag, the model's plain numbers and the caller's
metadata under its own key, readable anywhere without the library that fitted the model."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any


def write_surrogate_json(
    path: str | Path, fields: Mapping[str, Any], metadata: Mapping[str, Any] | None = None
) -> Path:
    """Write ``fields`` (with their ``format`` tag) and ``metadata`` as one JSON object.

    Parameters
    ----------
    path : str or Path
        The file to write.
    fields : mapping
        The model's description, every number a Python float or int.
    metadata : mapping, optional
        Stored under the key ``metadata``.
    """
    path = Path(path)
    path.write_text(json.dumps({**fields, "metadata": dict(metadata or {})}) + "\n")
    return path


def read_surrogate_json(
    path: str | Path,
    file_format: str,
    kind: str,
    keys: Sequence[str],
    optional: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """The ``keys`` of a file written by :func:`write_surrogate_json`.

    Parameters
    ----------
    path : str or Path
        The file.
    file_format : str
        The format tag the file must carry.
    kind : str
        What the file holds, for the error message (e.g. ``"Gaussian-process"``).
    keys : sequence of str
        The fields to return.
    optional : mapping, optional
        Further fields to return, with the value taken when the file lacks one (a field added
        to the format later, so that files written before it still read).

    Raises
    ------
    ValueError
        If the file carries another format tag or lacks one of ``keys``.
    """
    data = json.loads(Path(path).read_text())
    if data.get("format") != file_format:
        raise ValueError(
            f"{path}: not a {kind} file of format {file_format} (format {data.get('format')!r})"
        )
    missing = [k for k in keys if k not in data]
    if missing:
        raise ValueError(f"{path}: {kind} file without {', '.join(missing)}")
    return {k: data[k] for k in keys} | {k: data.get(k, v) for k, v in (optional or {}).items()}
