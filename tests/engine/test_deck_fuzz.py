"""Seeded mutations of the project's tiny decks never crash or hang the engine, and every
rejection names the deck file and line (scripts/fuzz_decks.py runs the same at any size)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from demcal.robustness.base_decks import render_base_decks
from demcal.robustness.deck_fuzz import (
    CRASH,
    HANG,
    INTERNAL,
    OK,
    REJECTED,
    UNLOCATED,
    classify,
    failures,
    fuzz,
    run_case,
    summary_table,
)
from demcal.robustness.mutation import BaseDeck, FuzzCase, cap_runs, make_cases

from .conftest import engine_path

pytestmark = pytest.mark.engine

CASES = 300
SEED = 20240601


def test_fuzzed_tiny_decks_are_run_or_rejected_with_file_and_line(tmp_path: Path) -> None:
    start = time.monotonic()
    outcomes = fuzz(
        CASES,
        SEED,
        tmp_path / "work",
        [engine_path()],
        timeout=20.0,
        max_steps=20,
        jobs=2,
        out_dir=tmp_path / "failures",
    )
    table = summary_table(outcomes)
    bad = failures(outcomes)
    detail = "\n".join(
        f"{o.kind} case {o.index} ({o.base}, exit {o.returncode}): {'; '.join(o.mutations)}\n"
        f"    {o.last_error or o.stderr_tail[-300:]}"
        for o in bad
    )
    assert not bad, f"{table}\n{detail}"
    assert len(outcomes) == CASES
    kinds = {o.kind for o in outcomes}
    # Both outcomes occur: some mutations leave a valid deck, most are refused.
    assert kinds == {OK, REJECTED}, table
    for o in outcomes:
        if o.kind == REJECTED:
            assert o.last_error.startswith("ERROR: "), o
    assert time.monotonic() - start < 120, table


def test_mutations_are_seeded_and_runs_capped(tmp_path: Path) -> None:
    bases = render_base_decks(tmp_path)
    first = make_cases(bases, 12, 3, max_steps=7)
    again = make_cases(bases, 12, 3, max_steps=7)
    assert [c.text for c in first] == [c.text for c in again]
    assert [c.text for c in make_cases(bases, 12, 4, 7)] != [c.text for c in first]
    assert {c.base for c in first} == {
        "shear_cell",
        "ring_shear_cell",
        "angle_of_repose",
        "chute_cooler",
    }
    for case in first:
        assert 1 <= len(case.mutations) <= 3
        for line in case.text.splitlines():
            words = line.split()
            if len(words) >= 2 and words[0] == "run" and words[1].isdigit():
                assert int(words[1]) <= 7, line
    assert cap_runs("run 6472\n  run 3 upto\nrun 1e300\nrun -5", 200) == (
        "run 200\n  run 3 upto\nrun 1e300\nrun -5"
    )


def test_classifier_reads_engine_errors(tmp_path: Path) -> None:
    (tmp_path / "in.deck").write_text("a\nb\nc\n")
    assert classify(0, "")[0] == OK
    assert classify(1, "WARNING: x\nERROR: in.deck:2: fix: bad value\n", tmp_path)[0] == REJECTED
    assert classify(1, "ERROR: in.deck:2: bad value\n", tmp_path)[0] == REJECTED
    assert classify(1, "ERROR: in.deck: no line\n", tmp_path)[0] == UNLOCATED
    assert classify(1, "ERROR: in.deck:9: fix: beyond the end\n", tmp_path)[0] == UNLOCATED
    assert classify(1, "ERROR: in.deck:0: fix: line 0\n", tmp_path)[0] == UNLOCATED
    assert classify(1, "ERROR: in.deck:1: run: vector::_M_fill_insert\n", tmp_path)[0] == INTERNAL
    assert classify(1, "ERROR: in.deck:1: run: std::bad_alloc\n", tmp_path)[0] == INTERNAL
    assert classify(1, "terminate called after throwing\n")[0] == CRASH
    assert classify(-11, "")[0] == CRASH
    assert classify(134, "ERROR: in.deck:1: x: y\n")[0] == CRASH
    assert classify(None, "")[0] == HANG


def _fake_case(tmp_path: Path) -> tuple[FuzzCase, BaseDeck]:
    base_dir = tmp_path / "base"
    base_dir.mkdir()
    (base_dir / "in.fake").write_text("run 10\n")
    return FuzzCase(0, "fake", ["none"], "run 10\n"), BaseDeck("fake", base_dir, "in.fake")


def test_a_real_crashing_process_is_flagged_as_crash_and_kept(tmp_path: Path) -> None:
    case, base = _fake_case(tmp_path)
    engine = ["sh", "-c", "kill -SEGV $$", "sh"]
    outcome = run_case(case, base, engine, tmp_path / "scratch", 10.0, tmp_path / "out")
    assert outcome.kind == CRASH and outcome.returncode == -11, outcome
    kept = tmp_path / "out" / CRASH / "000000_fake"
    assert (kept / "in.fake").read_text() == "run 10\n"
    assert (kept / "fuzz.json").is_file()
    assert not any((tmp_path / "scratch").iterdir())


def test_a_real_hanging_process_is_flagged_as_hang(tmp_path: Path) -> None:
    case, base = _fake_case(tmp_path)
    start = time.monotonic()
    outcome = run_case(case, base, ["sh", "-c", "sleep 10", "sh"], tmp_path / "scratch", 0.5)
    assert outcome.kind == HANG and outcome.returncode is None, outcome
    assert time.monotonic() - start < 5


def test_a_real_unlocated_error_is_flagged(tmp_path: Path) -> None:
    case, base = _fake_case(tmp_path)
    engine = ["sh", "-c", "echo 'ERROR: something went wrong' >&2; exit 1", "sh"]
    outcome = run_case(case, base, engine, tmp_path / "scratch", 10.0)
    assert outcome.kind == UNLOCATED, outcome


# Mutations the fuzzer found that the engine once took badly (an uncaught library exception
# from a huge allocation, an insertion or a run without end); each is now refused on its line.
RATE_INSERT = (
    "fix ins all insert/rate/region seed 49979687 distributiontemplate pdd nparticles INF "
    "massrate 1e300 insert_every 10 overlapcheck yes all_in yes vel constant 0 0 0 region ins"
)
FOUND = [
    ("radius constant 0.001", "radius constant 1e200", "fix pts", "not a finite number"),
    ("particles_in_region 20", "particles_in_region 2147483647", "run 100", "cannot fit"),
    ("particles_in_region 20", "mass_in_region 1e300", "run 100", "cannot fit"),
    ("run 100", "run 9223372036854775807", "run 9223372036854775807", "exceeds 2147483647"),
    ("1 pts 1.0", "2 pts 1e308 pts 1e308", "fix pdd", "finite"),
]


@pytest.mark.parametrize(("old", "new", "needle", "reason"), FOUND)
def test_found_mutations_are_refused_on_their_line(tmp_path, old, new, needle, reason):
    from .test_deck_errors import VALID, line_of, run_deck

    assert old in VALID
    text = VALID.replace(old, new, 1)
    res = run_deck(tmp_path, text, timeout=60)
    assert res.returncode == 1, res.stdout[-1000:]
    err = res.stderr.strip().splitlines()[-1]
    assert err.startswith(f"ERROR: in.deck:{line_of(text, needle)}: "), err
    assert reason in err, err
    assert classify(res.returncode, res.stderr, tmp_path)[0] == REJECTED


def test_a_rate_insertion_beyond_the_region_capacity_is_refused(tmp_path):
    from .test_deck_errors import VALID, line_of, run_deck

    start = VALID.index("fix ins all insert/pack")
    end = VALID.index("particles_in_region 20\n") + len("particles_in_region 20\n")
    text = VALID[:start] + RATE_INSERT + "\n" + VALID[end:]
    res = run_deck(tmp_path, text, timeout=60)
    assert res.returncode == 1, res.stdout[-1000:]
    err = res.stderr.strip().splitlines()[-1]
    assert err.startswith(f"ERROR: in.deck:{line_of(text, 'run 100')}: run: fix ins: "), err
    assert "cannot fit" in err, err
