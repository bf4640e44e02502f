"""A run stopped from outside (a stopped study, a cancelled batch job) leaves no status behind,
so that a resumed study runs it again instead of counting it as a failed case."""

import shutil
import signal
from pathlib import Path

import pytest

from demcal.engine_io.run import RunInterrupted, interrupting_signal, run_deck

from .conftest import engine_path

pytestmark = pytest.mark.engine

# A few particles at rest in a periodic box, for far longer than the test waits.
LONG_DECK = """units si
atom_style granular
atom_modify map array
boundary p p p
newton off
communicate single vel yes
region box block 0 0.01 0 0.01 0 0.01 units box
create_box 1 box
neighbor 0.0002 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5e6
fix m2 all property/global poissonsRatio peratomtype 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep 1e-6
fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 &
    radius constant 0.0005
fix pdd all particledistribution/discrete 32452843 1 pts 1.0
fix ins all insert/pack seed 100001 distributiontemplate pdd insert_every once &
    overlapcheck yes all_in yes particles_in_region 20 region box
fix integr all nve/sphere
run 1000000000
"""


def test_interrupting_signals_are_told_from_failures():
    assert interrupting_signal(-signal.SIGTERM) is signal.SIGTERM
    assert interrupting_signal(128 + signal.SIGINT) is signal.SIGINT
    # An engine error, a crash and the kernel's OOM kill are the deck's result, not an interrupt.
    for code in (0, 1, -signal.SIGSEGV, -signal.SIGKILL, 128 + signal.SIGKILL):
        assert interrupting_signal(code) is None


def test_engine_stopped_by_sigterm_records_nothing(tmp_path: Path):
    timeout = shutil.which("timeout")
    assert timeout, "coreutils timeout is part of every Debian system"
    (tmp_path / "in.deck").write_text(LONG_DECK)
    # A stale status from an earlier attempt must not survive either.
    (tmp_path / "status.json").write_text('{"status": "failed"}\n')
    command = f"{timeout} --preserve-status -s TERM 2 {engine_path()} -in {{deck}} -noprogress"
    with pytest.raises(RunInterrupted, match=r"in\.deck: the engine was stopped by SIGTERM"):
        run_deck(tmp_path, "in.deck", command, 1)
    assert not (tmp_path / "status.json").exists()


def test_engine_error_is_still_recorded(tmp_path: Path):
    (tmp_path / "in.deck").write_text(LONG_DECK.replace("run 1000000000", "run -5"))
    status = run_deck(tmp_path, "in.deck", f"{engine_path()} -in {{deck}} -noprogress", 1)
    assert status["status"] == "failed"
    assert status["returncode"] not in (0, -signal.SIGTERM)
    assert status["error"].startswith("ERROR")
    assert (tmp_path / "status.json").is_file()
