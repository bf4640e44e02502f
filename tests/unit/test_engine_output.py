"""Readers of engine output: round trips of known arrays and clear errors for bad content."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from demcal.engine_io.dump_file import read_dump, read_dump_last
from demcal.engine_io.fix_output import read_ave_time, read_print_file
from demcal.engine_io.log_file import read_log
from demcal.engine_io.output_errors import (
    EngineOutputError,
    MissingColumnError,
    TruncatedOutputWarning,
)
from demcal.engine_io.vtk_file import read_vtk_particles

PRINT_COLUMNS = [
    "step",
    "time",
    "phase",
    "cycle",
    "lid_z",
    "lid_force",
    "shear_force",
    "travel",
    "mass",
    "target_force",
]


def _print_table(n: int = 6) -> pd.DataFrame:
    rng = np.random.default_rng(3)
    step = np.arange(n) * 1000
    return pd.DataFrame(
        {
            "step": step,
            "time": step * 1e-6,
            "phase": np.minimum(np.arange(n) // 2, 3).astype(float),
            "cycle": np.zeros(n),
            "lid_z": 0.03 + 1e-5 * rng.standard_normal(n),
            "lid_force": 2.5 + 0.1 * rng.standard_normal(n),
            "shear_force": -1.2 + 0.05 * rng.standard_normal(n),
            "travel": -2.2e-3 * step * 1e-6,
            "mass": np.full(n, 0.0412),
            "target_force": np.full(n, 2.55),
        }
    )


def _write_print(path: Path, table: pd.DataFrame, tail: str = "") -> None:
    lines = ["# " + " ".join(table.columns)]
    lines += [" ".join(f"{v:.15g}" for v in row) for row in table.to_numpy()]
    path.write_text("\n".join(lines) + "\n" + tail)


# ---------------------------------------------------------------------------------- fix print


def test_print_file_round_trip(tmp_path: Path) -> None:
    table = _print_table()
    path = tmp_path / "shear.print"
    _write_print(path, table)
    got = read_print_file(path, columns=["time", "lid_force"])
    assert list(got.columns) == PRINT_COLUMNS
    assert got["step"].dtype == np.int64
    np.testing.assert_array_equal(got["step"].to_numpy(), table["step"].to_numpy())
    np.testing.assert_allclose(got.to_numpy(dtype=float), table.to_numpy(dtype=float), rtol=1e-14)


def test_print_file_drops_truncated_last_line_with_warning(tmp_path: Path) -> None:
    table = _print_table()
    path = tmp_path / "shear.print"
    _write_print(path, table, tail="6000 0.006 3 0 0.03")  # cut mid-line, no newline
    with pytest.warns(TruncatedOutputWarning, match=r"shear\.print:8"):
        got = read_print_file(path)
    assert len(got) == len(table)


def test_print_file_drops_last_line_cut_inside_a_number(tmp_path: Path) -> None:
    # Full field count, but the last number lost its tail: no final newline gives it away.
    table = _print_table()
    path = tmp_path / "shear.print"
    _write_print(path, table, tail="6000 0.006 3 0 0.03 2.5 -1.2 -1.3e-05 0.0412 2.5")
    with pytest.warns(TruncatedOutputWarning):
        got = read_print_file(path)
    assert len(got) == len(table)


def test_print_file_skips_repeated_title_and_blank_lines(tmp_path: Path) -> None:
    table = _print_table(4)
    path = tmp_path / "p.txt"
    _write_print(path, table.iloc[:2])
    with path.open("a") as fh:
        fh.write("\n# " + " ".join(table.columns) + "\n")
        for row in table.iloc[2:].to_numpy():
            fh.write(" ".join(f"{v:.15g}" for v in row) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = read_print_file(path)
    np.testing.assert_allclose(got["lid_force"], table["lid_force"], rtol=1e-14)


def test_print_file_malformed_middle_line_names_file_and_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.print"
    path.write_text("# step time value\n0 0.0 1.5\n1000 0.001 oops\n2000 0.002 1.7\n")
    with pytest.raises(EngineOutputError, match=r"bad\.print:3"):
        read_print_file(path)


def test_print_file_missing_column_is_key_error_naming_it(tmp_path: Path) -> None:
    path = tmp_path / "p.print"
    path.write_text("# step time value\n0 0.0 1.5\n")
    with pytest.raises(KeyError, match="lid_force") as info:
        read_print_file(path, columns=["time", "lid_force"])
    assert isinstance(info.value, MissingColumnError)
    assert "p.print" in str(info.value)


def test_print_file_without_title_needs_names(tmp_path: Path) -> None:
    path = tmp_path / "p.print"
    path.write_text("0 0.0 1.5\n1000 0.001 1.6\n")
    with pytest.raises(EngineOutputError, match="names"):
        read_print_file(path)
    got = read_print_file(path, names=["step", "time", "value"])
    np.testing.assert_allclose(got["value"], [1.5, 1.6])
    default_title = tmp_path / "q.print"
    default_title.write_text("# Fix print output for fix out\n0 0.0 1.5\n1000 0.001 1.6\n")
    with pytest.raises(EngineOutputError, match=r"q\.print:1.*names"):
        read_print_file(default_title)
    got = read_print_file(default_title, names=["step", "time", "value"])
    np.testing.assert_array_equal(got["step"], [0, 1000])


def test_print_file_empty_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "empty.print"
    path.write_text("")
    with pytest.raises(EngineOutputError, match="empty"):
        read_print_file(path)


# ----------------------------------------------------------------------------------- ave/time


def test_ave_time_scalar_mode(tmp_path: Path) -> None:
    path = tmp_path / "force.ave"
    path.write_text(
        "# Time-averaged data for fix lidforce\n"
        "# TimeStep v_fz c_ke f_lid[3]\n"
        "1000 2.5 1e-06 -2.5\n"
        "2000 2.75 2e-06 -2.75\n"
        "3000 3 3e-06 -3\n"
    )
    got = read_ave_time(path, columns=["f_lid[3]"])
    assert list(got.columns) == ["TimeStep", "v_fz", "c_ke", "f_lid[3]"]
    assert got["TimeStep"].dtype == np.int64
    np.testing.assert_allclose(got["v_fz"], [2.5, 2.75, 3.0])
    np.testing.assert_allclose(got["f_lid[3]"], -got["v_fz"])


def test_ave_time_vector_mode_long_form_and_truncated_block(tmp_path: Path) -> None:
    path = tmp_path / "profile.ave"
    path.write_text(
        "# Time-averaged data for fix prof\n"
        "# TimeStep Number-of-rows\n"
        "# Row c_rho c_vx\n"
        "100 3\n1 10 0.1\n2 20 0.2\n3 30 0.3\n"
        "200 3\n1 11 0.4\n2 21 0.5\n3 31 0.6\n"
        "300 3\n1 12 0.7\n"
    )
    with pytest.warns(TruncatedOutputWarning):
        got = read_ave_time(path)
    assert list(got.columns) == ["TimeStep", "Row", "c_rho", "c_vx"]
    np.testing.assert_array_equal(got["TimeStep"], [100, 100, 100, 200, 200, 200])
    np.testing.assert_array_equal(got["Row"], [1, 2, 3, 1, 2, 3])
    np.testing.assert_allclose(got["c_rho"], [10, 20, 30, 11, 21, 31])


def test_ave_time_bad_header(tmp_path: Path) -> None:
    path = tmp_path / "x.ave"
    path.write_text("# Time-averaged data for fix a\n1000 2.5\n")
    with pytest.raises(EngineOutputError, match=r"x\.ave"):
        read_ave_time(path)


# ------------------------------------------------------------------------------------ log file

LOG = """LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0)
variable dt equal 1e-6
timestep ${dt}
timestep 1e-6
Setting up run ...
Memory usage per processor = 5.2 Mbytes
Step Atoms KinEng c_1 f_lid[3] v_t
       0        0            0            0            0            0
     500      120    0.0012501        1e-05      -0.0125       0.0005
    1000      240   0.00250025        2e-05       -0.025        0.001
Loop time of 1.5 on 2 procs for 1000 steps with 240 atoms

Pair  time (%) = 0.1 (10)
WARNING: Particle insertion: less insertions than requested (../fix_insert.cpp:700)
run 2000
Setting up run ...
Step Atoms KinEng c_1 f_lid[3] v_t
    1000      240   0.00250025        2e-05       -0.025        0.001
WARNING: Lost atoms via mesh wall
    2000      239       0.0011        3e-05       -0.031        0.002
    3000      239       0.0009        4e-05       -0.033        0.003
Loop time of 3.0 on 2 procs for 2000 steps with 239 atoms
"""


def test_log_two_runs_with_interleaved_text(tmp_path: Path) -> None:
    path = tmp_path / "log.liggghts"
    path.write_text(LOG)
    tables = read_log(path, columns=["Step", "f_lid[3]"])
    assert len(tables) == 2
    first, second = tables
    assert list(first.columns) == ["Step", "Atoms", "KinEng", "c_1", "f_lid[3]", "v_t"]
    np.testing.assert_array_equal(first["Step"], [0, 500, 1000])
    np.testing.assert_array_equal(second["Step"], [1000, 2000, 3000])
    np.testing.assert_allclose(second["f_lid[3]"], [-0.025, -0.031, -0.033])
    np.testing.assert_allclose(first["v_t"], first["Step"] * 1e-6)


def test_log_interrupted_run_keeps_table_and_drops_partial_line(tmp_path: Path) -> None:
    path = tmp_path / "log.liggghts"
    tail = "Step Atoms KinEng c_1 f_lid[3] v_t\n3000 239 0.0009 4e-05 -0.033 0.003\n40"
    path.write_text(LOG + tail)
    with pytest.warns(TruncatedOutputWarning):
        tables = read_log(path)
    assert len(tables) == 3
    np.testing.assert_array_equal(tables[2]["Step"], [3000])


def test_log_malformed_row_names_line(tmp_path: Path) -> None:
    text = LOG.replace("     500      120    0.0012501", "     500      120")
    path = tmp_path / "log.bad"
    path.write_text(text)
    with pytest.raises(EngineOutputError, match=r"log\.bad:9"):
        read_log(path)


def test_log_missing_column_and_no_table(tmp_path: Path) -> None:
    path = tmp_path / "log.liggghts"
    path.write_text(LOG)
    with pytest.raises(MissingColumnError, match="c_servo"):
        read_log(path, columns=["c_servo"])
    empty = tmp_path / "log.empty"
    empty.write_text("LIGGGHTS (Version 3.8.0)\nERROR: Unknown command\n")
    with pytest.raises(EngineOutputError, match="no thermo table"):
        read_log(empty)


# ---------------------------------------------------------------------------------------- dump


def _snapshot_text(step: int, atoms: np.ndarray, box: np.ndarray) -> str:
    head = [
        "ITEM: TIMESTEP",
        str(step),
        "ITEM: NUMBER OF ATOMS",
        str(atoms.shape[0]),
        "ITEM: BOX BOUNDS ff ff ff",
        *(f"{lo:.10g} {hi:.10g}" for lo, hi in box),
        "ITEM: ATOMS id type x y z radius",
    ]
    rows = [
        f"{int(a[0])} {int(a[1])} {a[2]:.12g} {a[3]:.12g} {a[4]:.12g} {a[5]:.12g}" for a in atoms
    ]
    return "\n".join(head + rows) + "\n"


def _atoms(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    ids = np.arange(1, n + 1)
    types = rng.integers(1, 3, n)
    xyz = rng.uniform(-0.02, 0.02, (n, 3))
    radius = rng.uniform(3e-4, 1e-3, n)
    return np.column_stack([ids, types, xyz, radius])


BOX = np.array([[-0.05, 0.05], [-0.05, 0.05], [0.0, 0.1]])


def test_dump_all_and_last(tmp_path: Path) -> None:
    snaps = [(1000 * (k + 1), _atoms(7, k)) for k in range(3)]
    path = tmp_path / "dump.heap"
    path.write_text("".join(_snapshot_text(s, a, BOX) for s, a in snaps))
    got = read_dump(path, columns=["x", "y", "z", "radius"])
    assert [g.timestep for g in got] == [1000, 2000, 3000]
    for g, (_, atoms) in zip(got, snaps, strict=True):
        assert g.atoms["id"].dtype == np.int64
        np.testing.assert_allclose(g.atoms[["x", "y", "z", "radius"]], atoms[:, 2:], rtol=1e-11)
        np.testing.assert_allclose(g.box, BOX)
        assert g.boundary == ("ff", "ff", "ff")
        assert g.tilt is None
    last = read_dump_last(path)
    assert last.timestep == 3000
    np.testing.assert_array_equal(last.atoms["type"], snaps[2][1][:, 1].astype(int))


def test_dump_truncated_last_snapshot(tmp_path: Path) -> None:
    text = "".join(_snapshot_text(1000 * (k + 1), _atoms(5, k), BOX) for k in range(3))
    cut = text[: text.rindex("\n", 0, len(text) - 1) - 7]  # last snapshot loses its tail
    path = tmp_path / "dump.cut"
    path.write_text(cut)
    with pytest.warns(TruncatedOutputWarning):
        got = read_dump(path)
    assert [g.timestep for g in got] == [1000, 2000]
    with pytest.warns(TruncatedOutputWarning):
        last = read_dump_last(path)
    assert last.timestep == 2000


def test_dump_malformed_middle_snapshot_names_line(tmp_path: Path) -> None:
    good = _snapshot_text(1000, _atoms(5, 0), BOX)
    short = _snapshot_text(2000, _atoms(5, 1), BOX).replace(
        "ITEM: NUMBER OF ATOMS\n5", "ITEM: NUMBER OF ATOMS\n6"
    )
    path = tmp_path / "dump.bad"
    path.write_text(good + short + good.replace("1000", "3000", 1))
    with pytest.raises(EngineOutputError, match=r"dump\.bad:23"):
        read_dump(path)


def test_dump_triclinic_box_and_missing_column(tmp_path: Path) -> None:
    text = _snapshot_text(10, _atoms(3, 0), BOX).replace(
        "ITEM: BOX BOUNDS ff ff ff\n-0.05 0.05\n-0.05 0.05\n0 0.1",
        "ITEM: BOX BOUNDS xy xz yz pp pp ff\n-0.05 0.05 0.01\n-0.05 0.05 0\n0 0.1 -0.002",
    )
    path = tmp_path / "dump.tri"
    path.write_text(text)
    snap = read_dump_last(path)
    np.testing.assert_allclose(snap.tilt, [0.01, 0.0, -0.002])
    np.testing.assert_allclose(snap.box, BOX)
    assert snap.boundary == ("pp", "pp", "ff")
    with pytest.raises(MissingColumnError, match="c_contacts"):
        read_dump(path, columns=["x", "c_contacts"])


# ----------------------------------------------------------------------------------------- VTK


def _legacy_vtk(points: np.ndarray, radius: np.ndarray, vel: np.ndarray) -> str:
    n = points.shape[0]
    lines = [
        "# vtk DataFile Version 2.0",
        "Generated by LIGGGHTS",
        "ASCII",
        "DATASET POLYDATA",
        f"POINTS {n} float",
        *(" ".join(f"{v:.9g}" for v in p) for p in points),
        f"VERTICES {n} {2 * n}",
        *(f"1 {i}" for i in range(n)),
        f"POINT_DATA {n}",
        "VECTORS v float",
        *(" ".join(f"{v:.9g}" for v in row) for row in vel),
        "SCALARS radius float 1",
        "LOOKUP_TABLE default",
        *(f"{r:.9g}" for r in radius),
    ]
    return "\n".join(lines) + "\n"


def test_vtk_legacy_particles(tmp_path: Path) -> None:
    rng = np.random.default_rng(5)
    pts = rng.uniform(-0.01, 0.01, (9, 3))
    rad = rng.uniform(3e-4, 1e-3, 9)
    vel = rng.normal(size=(9, 3))
    path = tmp_path / "dump_100.vtk"
    path.write_text(_legacy_vtk(pts, rad, vel))
    got = read_vtk_particles(path, arrays=["radius", "v"])
    np.testing.assert_allclose(got.points, pts, rtol=1e-6)
    np.testing.assert_allclose(got.arrays["radius"], rad, rtol=1e-6)
    np.testing.assert_allclose(got.arrays["v"], vel, rtol=1e-6)
    with pytest.raises(MissingColumnError, match="omega"):
        read_vtk_particles(path, arrays=["omega"])


def test_vtk_unreadable_and_missing(tmp_path: Path) -> None:
    path = tmp_path / "junk.vtk"
    path.write_text("this is not a VTK file\n")
    with pytest.raises(EngineOutputError, match=r"junk\.vtk"):
        read_vtk_particles(path)
    with pytest.raises(FileNotFoundError, match="nothere"):
        read_vtk_particles(tmp_path / "nothere.vtk")
