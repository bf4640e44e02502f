"""The ring cell's azimuthal velocity profile and its shear zone (synthetic particles)."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from demcal.bulk.shear_zone_check import shear_zone_check
from demcal.bulk.values import MissingOutputError
from demcal.core.config import load_config
from demcal.robustness.base_decks import RING_KEYS, with_quick_ring
from demcal.virtual_tests.deck import render_case
from demcal.virtual_tests.shear_cell.velocity_profile import (
    azimuthal_profile,
    mean_gradient,
    shear_zone,
)

ROOT = Path(__file__).resolve().parents[2]
# A zone from 6 to 14 mm in a bed 20 mm high: u = 1 below, 0 above, linear in between.
Z1, Z2 = 0.006, 0.014


def _particles(omega: float, n: int = 40_000, noise: float = 0.05, seed: int = 3):
    rng = np.random.default_rng(seed)
    r = np.sqrt(rng.uniform(0.02**2, 0.035**2, n))
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    z = rng.uniform(0.0, 0.02, n)
    u = np.clip((Z2 - z) / (Z2 - Z1), 0.0, 1.0)
    speed = omega * r * (u + noise * rng.standard_normal(n))
    points = np.column_stack([r * np.cos(phi), r * np.sin(phi), z])
    # Azimuthal motion plus radial and vertical jitter that the profile must ignore.
    velocity = np.column_stack(
        [-speed * np.sin(phi), speed * np.cos(phi), 0.01 * rng.standard_normal(n)]
    )
    velocity[:, :2] += 0.01 * rng.standard_normal(n)[:, None] * points[:, :2] / r[:, None]
    return points, velocity


@pytest.mark.parametrize("omega", [2.2, -6.8])
def test_profile_and_zone_of_a_known_linear_shear(omega: float) -> None:
    points, velocity = _particles(omega)
    profile = azimuthal_profile(points, velocity, omega, 0.02, 0.035, 0.001)
    assert len(profile) == 20 and profile["n"].sum() == len(points)
    truth = np.clip((Z2 - profile["z"]) / (Z2 - Z1), 0.0, 1.0)
    assert np.all(np.abs(profile["u"] - truth) < 4.0 * profile["u_se"]), profile
    zone = shear_zone(profile)
    # u falls through 0.9 at Z1 + 0.1 (Z2 - Z1) and through 0.1 at Z2 - 0.1 (Z2 - Z1).
    assert zone.z_floor_side == pytest.approx(Z1 + 0.1 * (Z2 - Z1), abs=2e-4)
    assert zone.z_lid_side == pytest.approx(Z2 - 0.1 * (Z2 - Z1), abs=2e-4)
    assert zone.width == pytest.approx(0.8 * (Z2 - Z1), abs=4e-4)
    assert zone.peak_gradient == pytest.approx(1.0 / (Z2 - Z1), rel=0.2)
    assert mean_gradient(profile, 0.008, 0.012) == pytest.approx(1.0 / (Z2 - Z1), rel=0.05)


def test_profile_keeps_to_its_annulus_and_refuses_what_it_cannot_read() -> None:
    points, velocity = _particles(2.0, n=2000)
    inner = azimuthal_profile(points, velocity, 2.0, 0.02, 0.025, 0.002)
    r = np.hypot(points[:, 0], points[:, 1])
    assert inner["n"].sum() == int(((r > 0.02) & (r < 0.025)).sum())
    with pytest.raises(ValueError, match="not 0"):
        azimuthal_profile(points, velocity, 0.0, 0.02, 0.035, 0.001)
    with pytest.raises(ValueError, match=re.escape("(n, 3)")):
        azimuthal_profile(points, velocity[:, :2], 2.0, 0.02, 0.035, 0.001)
    with pytest.raises(ValueError, match="no particle"):
        azimuthal_profile(points, velocity, 2.0, 0.05, 0.06, 0.001)
    with pytest.raises(ValueError, match="empty annulus"):
        azimuthal_profile(points, velocity, 2.0, 0.03, 0.02, 0.001)
    # A bed carried whole by the floor has no zone.
    with pytest.raises(ValueError, match="does not fall below"):
        shear_zone(inner.assign(u=1.0))
    with pytest.raises(ValueError, match="lower < upper"):
        shear_zone(inner, upper=0.1, lower=0.9)
    with pytest.raises(ValueError, match="not inside the slices"):
        mean_gradient(inner, 0.0, 0.5)


def test_zone_check_needs_a_finished_ring_deck(tmp_path: Path) -> None:
    case = {
        "case_id": "c0001",
        "coefficientFriction": 0.5,
        "coefficientRollingFriction": 0.2,
        "coefficientRestitution": 0.6,
        "density": 2500.0,
        "normal_stress": 1068.0,
        "P": 0.8,
    }
    tiny = ROOT / "config" / "tiny.yaml"
    render_case("shear_cell", case, load_config(tiny), tmp_path / "split")
    with pytest.raises(MissingOutputError, match="not a ring"):
        shear_zone_check(tmp_path / "split")
    render_case("shear_cell", case, with_quick_ring(tiny, RING_KEYS), tmp_path / "ring")
    assert json.loads((tmp_path / "ring" / "case.json").read_text())["setup"]["geometry"] == "ring"
    with pytest.raises(MissingOutputError, match="snapshot missing"):
        shear_zone_check(tmp_path / "ring")
    res = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "shear_zone_check.py"), str(tmp_path / "ring")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 2 and "snapshot missing" in res.stderr, res.stderr
