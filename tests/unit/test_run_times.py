"""Run times of the DEM cases from benchmark files written by Snakemake's own benchmark writer."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from snakemake.benchmark import BenchmarkRecord, write_benchmark_records

from demcal.bulk.run_times import (
    BenchmarkFileError,
    collect_run_times,
    read_benchmark,
    write_run_times,
)
from tests.figures import saved_figures


def _record(seconds: float, rss: float | None = None, cpu: float = 0.0) -> BenchmarkRecord:
    """A record as Snakemake fills it: memory and CPU only when a sample was taken."""
    record = BenchmarkRecord(running_time=seconds)
    if rss is not None:
        record.data_collected = True
        record.max_rss, record.max_vms, record.max_uss, record.max_pss = rss, 2 * rss, rss, rss
        record.io_in, record.io_out = 0.5, 1.25
        record.cpu_time = cpu
        record.cpu_usage = 95.0 * seconds
    else:
        record.process_gone = True  # ended before the first sample: NA, no warning
    return record


def _write(path: Path, *records: BenchmarkRecord, extended: bool = False) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    write_benchmark_records(list(records), str(path), extended)
    return path


def test_read_benchmark_of_a_sampled_run(tmp_path: Path) -> None:
    path = _write(tmp_path / "c0001.tsv", _record(83.4567, rss=412.0, cpu=80.5))
    assert path.read_text().splitlines()[0].split("\t")[:4] == ["s", "h:m:s", "max_rss", "max_vms"]
    table = read_benchmark(path)
    assert len(table) == 1
    row = table.iloc[0]
    # Snakemake writes floats with two decimals and the wall clock without fractions.
    assert row["s"] == pytest.approx(83.46)
    assert row["h:m:s"] == "0:01:23"
    assert row["max_rss"] == pytest.approx(412.0)
    assert row["max_vms"] == pytest.approx(824.0)
    assert row["io_out"] == pytest.approx(1.25)
    assert row["cpu_time"] == pytest.approx(80.5)
    assert row["mean_load"] == pytest.approx(95.0)


def test_read_benchmark_of_a_run_too_short_to_sample(tmp_path: Path) -> None:
    table = read_benchmark(_write(tmp_path / "fast.tsv", _record(0.734)))
    row = table.iloc[0]
    assert row["s"] == pytest.approx(0.73)
    assert row["h:m:s"] == "0:00:00"
    for column in ("max_rss", "max_vms", "io_in", "io_out", "mean_load", "cpu_time"):
        assert math.isnan(row[column]), column


def test_read_benchmark_of_extended_format_and_repeats(tmp_path: Path) -> None:
    records = [_record(10.0, rss=100.0, cpu=9.0), _record(12.5, rss=110.0, cpu=11.0)]
    for record in records:
        record.rule_name, record.jobid, record.threads = "run_case", 3, 1
        record.wildcards = {"stage": "cases", "test": "angle_of_repose", "case": "c0002"}
        record.params, record.resources, record.input = {}, {}, []
    table = read_benchmark(_write(tmp_path / "rep.tsv", *records, extended=True))
    assert table["s"].tolist() == [10.0, 12.5]
    assert table["max_rss"].tolist() == [100.0, 110.0]
    assert "rule_name" in table.columns


def test_read_benchmark_errors_name_the_file(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match=r"nope\.tsv"):
        read_benchmark(tmp_path / "nope.tsv")
    other = tmp_path / "other.tsv"
    other.write_text("seconds\tmemory\n1.0\t2.0\n")
    with pytest.raises(BenchmarkFileError, match=r"other\.tsv: missing column\(s\) s, h:m:s"):
        read_benchmark(other)
    path = _write(tmp_path / "broken.tsv", _record(5.0, rss=50.0, cpu=4.0))
    lines = path.read_text().splitlines()
    path.write_text(lines[0] + "\n" + lines[1].replace("50.00", "fifty", 1) + "\n")
    with pytest.raises(BenchmarkFileError, match=r"broken\.tsv: column 'max_rss' row 1"):
        read_benchmark(path)
    empty = tmp_path / "empty.tsv"
    empty.write_text(lines[0] + "\n")
    with pytest.raises(BenchmarkFileError, match=r"empty\.tsv: no benchmark row"):
        read_benchmark(empty)


def test_collect_and_write_run_times(tmp_path: Path) -> None:
    bench = tmp_path / "benchmarks" / "cases"
    cases = [
        ("shear_cell", "c0001_s1_p1", _record(20.25, rss=300.0, cpu=19.0)),
        ("shear_cell", "c0002_s1_p1", _record(31.5, rss=310.0, cpu=30.0)),
        ("angle_of_repose", "c0001", _record(45.0, rss=320.0, cpu=44.0)),
        ("angle_of_repose", "c0002", _record(0.5)),
    ]
    files = [
        (test, case, _write(bench / test / f"{case}.tsv", record)) for test, case, record in cases
    ]
    table = collect_run_times(files)
    assert table[["test", "case_id", "repeat"]].values.tolist() == [
        ["shear_cell", "c0001_s1_p1", 0],
        ["shear_cell", "c0002_s1_p1", 0],
        ["angle_of_repose", "c0001", 0],
        ["angle_of_repose", "c0002", 0],
    ]
    assert table["seconds"].tolist() == [20.25, 31.5, 45.0, 0.5]
    assert table["wall_clock"].tolist() == ["0:00:20", "0:00:31", "0:00:45", "0:00:00"]
    assert table["cpu_seconds"].iloc[:3].tolist() == [19.0, 30.0, 44.0]
    assert math.isnan(table["max_rss_mb"].iloc[3])

    out_csv, out_png = tmp_path / "bulk" / "run_times.csv", tmp_path / "bulk" / "run_times.png"
    with saved_figures() as figures:
        written = write_run_times(files, out_csv, out_png)
    pd.testing.assert_frame_equal(written, table)
    back = pd.read_csv(out_csv)
    assert back["seconds"].tolist() == [20.25, 31.5, 45.0, 0.5]
    assert back["case_id"].tolist() == ["c0001_s1_p1", "c0002_s1_p1", "c0001", "c0002"]
    assert out_png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    shear, repose = figures.named("run_times.png").axes
    # One bar per case, slowest first, and the median as a line.
    assert [p.get_height() for p in shear.patches] == [31.5, 20.25]
    assert [p.get_height() for p in repose.patches] == [45.0, 0.5]
    assert np.allclose(repose.lines[0].get_ydata(), 22.75)
    assert shear.get_title() == "shear_cell: 2 cases, 52 s in all, slowest c0002_s1_p1 (31.5 s)"


def test_collect_run_times_of_no_case() -> None:
    table = collect_run_times([])
    assert table.empty
    assert list(table.columns[:4]) == ["test", "case_id", "repeat", "seconds"]
