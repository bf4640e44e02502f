"""The workflow's run step (:func:`demcal.engine_io.run.run_deck`) with LIGGGHTS as the engine.

A failed run must be recorded with the engine's own ERROR line whichever engine ran it: the
bundled engine writes errors to standard error, LIGGGHTS to standard output and its log.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from demcal.engine_io.run import run_deck

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
