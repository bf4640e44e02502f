"""The readout cross-check refuses decks that cannot have one, naming the directory."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from demcal.bulk.plane_check import plane_check
from demcal.bulk.values import MissingOutputError
from demcal.core.config import load_config
from demcal.virtual_tests.deck import render_case

ROOT = Path(__file__).resolve().parents[2]
CASE = {
    "case_id": "c0001",
    "coefficientFriction": 0.5,
    "coefficientRollingFriction": 0.2,
    "coefficientRestitution": 0.6,
    "density": 2500.0,
    "normal_stress": 2029.0,
    "P": 0.8,
}


def test_a_deck_without_contact_snapshots_is_refused(tmp_path: Path) -> None:
    cfg = load_config(ROOT / "config" / "tiny.yaml")
    assert cfg["shear_cell"]["contact_snapshots"] == 0
    render_case("shear_cell", CASE, cfg, tmp_path)
    with pytest.raises(MissingOutputError, match="contact_snapshots"):
        plane_check(tmp_path)


def test_an_unrun_deck_names_its_missing_dump(tmp_path: Path) -> None:
    cfg = load_config(ROOT / "config" / "tiny.yaml")
    cfg["shear_cell"]["contact_snapshots"] = 10
    render_case("shear_cell", CASE, cfg, tmp_path)
    with pytest.raises(MissingOutputError, match=r"contacts\.dump: contact dump missing"):
        plane_check(tmp_path)
    # Bands across the plane are the ring's; the split cell is refused before anything is read.
    with pytest.raises(MissingOutputError, match="bands need the ring cell"):
        plane_check(tmp_path, bands=3)


def test_the_script_names_the_deck_it_cannot_check(tmp_path: Path) -> None:
    cfg = load_config(ROOT / "config" / "tiny.yaml")
    render_case("shear_cell", CASE, cfg, tmp_path)
    done = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "readout_check.py"), str(tmp_path)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 2
    assert f"error: {tmp_path}: not a shear-cell deck with contact snapshots" in done.stderr
