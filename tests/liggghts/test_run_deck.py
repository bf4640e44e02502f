"""The workflow's run step (:func:`demcal.engine_io.run.run_deck`) with LIGGGHTS as the engine.

A failed run must be recorded with the engine's own ERROR line whichever engine ran it: the
bundled engine writes errors to standard error, LIGGGHTS to standard output and its log.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from demcal.engine_io.run import run_deck

from .test_contact_parity import CASES, write_case

pytestmark = pytest.mark.liggghts

BAD_DECK = """atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block -0.01 0.01 -0.01 0.01 0.0 0.02 units box
create_box 1 box
no_such_command 1 2 3
"""

ENGINES = {
    "liggghts": "liggghts -in {deck}",
    "bundled": "dem_engine -in {deck}",
}


@pytest.mark.parametrize("engine", sorted(ENGINES))
def test_a_failed_run_records_the_engines_error_line(tmp_path: Path, engine: str) -> None:
    (tmp_path / "in.bad").write_text(BAD_DECK)
    status = run_deck(tmp_path, "in.bad", ENGINES[engine], 1)
    assert status["status"] == "failed"
    assert status["returncode"] != 0
    assert status["error"].startswith("ERROR"), status["error"]
    assert "no_such_command" in status["error"].lower() or "unknown" in status["error"].lower()
    assert json.loads((tmp_path / "status.json").read_text()) == status


@pytest.mark.parametrize("engine", sorted(ENGINES))
def test_a_pinched_particle_finishes_and_its_warning_is_recorded(
    tmp_path: Path, engine: str
) -> None:
    # Two particles squeezed by a plate until their contacts overlap by more than half a
    # radius: LIGGGHTS carries on, and so does the bundled engine, with a warning kept in the
    # status record.
    case = CASES["pinched_stack"]
    write_case(tmp_path, case.deck, case.files)
    status = run_deck(tmp_path, "in.deck", ENGINES[engine], 1)
    assert status["status"] == "ok", status["error"]
    assert json.loads((tmp_path / "status.json").read_text()) == status
    assert all(w.startswith("WARNING") and w.rstrip(": ") != "WARNING" for w in status["warnings"])
    pinched = [w for w in status["warnings"] if "overlaps a neighbour by" in w]
    if engine == "bundled":
        assert pinched and "the run goes on" in pinched[0], status["warnings"]
        assert any("steps of this run had a contact overlapping" in w for w in status["warnings"])
    else:
        assert not pinched, status["warnings"]
