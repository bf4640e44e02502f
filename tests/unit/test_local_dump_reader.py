"""Reader of ``dump local`` files: the LIGGGHTS 3.8 layout, empty and truncated snapshots, and
errors naming the file and line."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from demcal.engine_io.local_dump import pair_gran_local_columns, read_local_dump
from demcal.engine_io.output_errors import (
    EngineOutputError,
    MissingColumnError,
    TruncatedOutputWarning,
)

# Written by LIGGGHTS 3.8 (compute c all pair/gran/local id force delta; dump local with index):
# the ENTRIES line and every row end with a blank.
LIGGGHTS_TEXT = """ITEM: TIMESTEP
0
ITEM: NUMBER OF ENTRIES
2
ITEM: BOX BOUNDS ff ff ff
-0.01 0.01
-0.01 0.01
-0.01 0.01
ITEM: ENTRIES index c_c[1] c_c[2] c_c[3] c_c[4] c_c[5] c_c[6] c_c[7] 
1 1 3 0 -0.00705288 0 0.00058561 1e-05 
2 1 2 0 -0.0011707 -0.00016173 -0.0032014 7.41374e-06 
ITEM: TIMESTEP
100
ITEM: NUMBER OF ENTRIES
0
ITEM: BOX BOUNDS ff ff ff
-0.01 0.01
-0.01 0.01
-0.01 0.01
ITEM: ENTRIES index c_c[1] c_c[2] c_c[3] c_c[4] c_c[5] c_c[6] c_c[7] 
ITEM: TIMESTEP
200
ITEM: NUMBER OF ENTRIES
1
ITEM: BOX BOUNDS pp pp ff
-0.01 0.01
-0.01 0.01
-0.01 0.01
ITEM: ENTRIES index c_c[1] c_c[2] c_c[3] c_c[4] c_c[5] c_c[6] c_c[7] 
1 3 1 1 -19.051 0 2.20776e-05 0.00198 
"""  # noqa: W291 - the trailing blanks are part of the format

COLUMNS = ["index"] + [f"c_c[{k}]" for k in range(1, 8)]


def _write(tmp_path: Path, text: str, name: str = "contacts.txt") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_reads_liggghts_layout_with_empty_snapshot(tmp_path: Path) -> None:
    snapshots = read_local_dump(_write(tmp_path, LIGGGHTS_TEXT), columns=["c_c[4]"])
    assert [step for step, _ in snapshots] == [0, 100, 200]
    first = snapshots[0][1]
    assert list(first.columns) == COLUMNS
    assert first.shape == (2, 8)
    assert first["index"].dtype == np.int64
    assert first["c_c[1]"].dtype == np.float64
    np.testing.assert_array_equal(first["c_c[2]"], [3.0, 2.0])
    assert first["c_c[4]"].iloc[0] == pytest.approx(-0.00705288)
    assert first["c_c[7]"].iloc[1] == pytest.approx(7.41374e-06)
    empty = snapshots[1][1]
    assert empty.shape == (0, 8)
    assert list(empty.columns) == COLUMNS
    assert snapshots[2][1]["c_c[3]"].tolist() == [1.0]


def test_truncated_last_snapshot_is_dropped_with_warning(tmp_path: Path) -> None:
    cut = LIGGGHTS_TEXT[: LIGGGHTS_TEXT.rindex("-19.051")]  # inside the last row
    with pytest.warns(TruncatedOutputWarning, match=r"contacts\.txt:21"):
        snapshots = read_local_dump(_write(tmp_path, cut))
    assert [step for step, _ in snapshots] == [0, 100]
    # The last row complete but without its newline: it may still be written.
    with pytest.warns(TruncatedOutputWarning):
        snapshots = read_local_dump(_write(tmp_path, LIGGGHTS_TEXT.rstrip("\n")))
    assert len(snapshots) == 2
    # Cut in the header of the last snapshot.
    cut = LIGGGHTS_TEXT[: LIGGGHTS_TEXT.rindex("ITEM: ENTRIES")]
    with pytest.warns(TruncatedOutputWarning):
        assert len(read_local_dump(_write(tmp_path, cut))) == 2


def test_complete_file_gives_no_warning(tmp_path: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(read_local_dump(_write(tmp_path, LIGGGHTS_TEXT))) == 3


@pytest.mark.parametrize(
    ("old", "new", "line", "message"),
    [
        ("2 1 2 0 -0.0011707", "2 1 2 0 abc", 11, "numeric fields"),
        ("2 1 2 0 -0.0011707 -0.00016173", "2 1 2 0 -0.0011707", 11, "numeric fields"),
        ("NUMBER OF ENTRIES\n2\n", "NUMBER OF ENTRIES\ntwo\n", 4, "integer"),
        ("NUMBER OF ENTRIES\n2\n", "NUMBER OF ENTRIES\n3\n", 12, "expected 3 entry rows"),
        ("NUMBER OF ENTRIES\n2\n", "NUMBER OF ENTRIES\n1\n", 11, "more than 1"),
        (
            "-0.01 0.01\n-0.01 0.01\n-0.01 0.01\nITEM: ENTRIES index",
            "-0.01\n-0.01 0.01\n-0.01 0.01\nITEM: ENTRIES index",
            6,
            "box bounds",
        ),
        ("ITEM: NUMBER OF ENTRIES\n2", "ITEM: NUMBER OF ATOMS\n2", 3, "unexpected line"),
        ("c_c[2] c_c[3]", "c_c[2] c_c[2]", 9, "duplicate column"),
    ],
)
def test_malformed_content_names_file_and_line(
    tmp_path: Path, old: str, new: str, line: int, message: str
) -> None:
    assert old in LIGGGHTS_TEXT
    path = _write(tmp_path, LIGGGHTS_TEXT.replace(old, new, 1), "bad.txt")
    with pytest.raises(EngineOutputError, match=rf"bad\.txt:{line}: .*{message}"):
        read_local_dump(path)


def test_files_without_snapshots_and_missing_columns(tmp_path: Path) -> None:
    with pytest.raises(EngineOutputError, match="no 'ITEM: TIMESTEP'"):
        read_local_dump(_write(tmp_path, ""))
    with pytest.raises(EngineOutputError, match="no complete snapshot"):
        with pytest.warns(TruncatedOutputWarning):
            read_local_dump(_write(tmp_path, "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ENTRIES\n"))
    with pytest.raises(EngineOutputError, match=r"x\.txt:1: text before"):
        read_local_dump(_write(tmp_path, "junk\n" + LIGGGHTS_TEXT, "x.txt"))
    with pytest.raises(MissingColumnError, match=r"c_c\[9\]"):
        read_local_dump(_write(tmp_path, LIGGGHTS_TEXT), columns=["c_c[9]"])


def test_pair_gran_local_column_names_follow_liggghts_order() -> None:
    default = pair_gran_local_columns()
    assert len(default) == 25
    assert default[:6] == ["x1", "y1", "z1", "x2", "y2", "z2"]
    assert default[12:18] == ["id1", "id2", "periodic", "fx", "fy", "fz"]
    assert default[-4:] == ["h1", "h2", "h3", "contact_area"]
    # Keyword order and repeats do not matter; delta comes last.
    assert pair_gran_local_columns(["delta", "pos", "pos"]) == [
        "x1",
        "y1",
        "z1",
        "x2",
        "y2",
        "z2",
        "delta",
    ]
    every = pair_gran_local_columns(
        [
            "pos",
            "vel",
            "id",
            "force",
            "force_normal",
            "force_tangential",
            "torque",
            "history",
            "contactArea",
            "delta",
        ],
        history_size=6,
    )
    assert len(every) == 35
    assert every[18:24] == ["fnx", "fny", "fnz", "ftx", "fty", "ftz"]
    with pytest.raises(ValueError, match="heatFlux"):
        pair_gran_local_columns(["force", "heatFlux"])
