"""Derived quantities of the angle-of-repose deck against hand-computed values."""

from __future__ import annotations

import json
import math

import pytest

from demcal.core.config import validate_config
from demcal.core.config_values import SetupError
from demcal.particles.material import material_setup
from demcal.particles.run_setup import RunSetup
from demcal.particles.size_distribution import size_distribution
from demcal.virtual_tests.angle_of_repose.setup import lift_froude_number, repose_setup

CASE = {
    "case_id": "c0002",
    "coefficientFriction": 0.5,
    "coefficientRollingFriction": 0.3,
    "coefficientRestitution": 0.6,
    "density": 2500.0,
}


def setup_for(dCylDp: float = 10.0, particles: dict | None = None, **aor: object):
    cfg = validate_config(
        {"particles": particles or {"distribution": "monodisperse", "radius": 0.001}}, "t"
    )
    cfg["angle_of_repose"].update(aor)
    dist = size_distribution(cfg["particles"])
    mat = material_setup(CASE, cfg["material"], dist)
    return repose_setup(dCylDp, dist, mat, cfg["angle_of_repose"], 7), dist


def test_tube_diameter_is_dCylDp_largest_particle_diameters() -> None:
    fines = {"distribution": "sinter_fines", "scale": 1.0, "classes": 6}
    s, dist = setup_for(dCylDp=20.0, particles=fines)
    assert dist.max_radius == pytest.approx(1e-3)
    assert 2 * s.radius == pytest.approx(20 * 2e-3)


def test_particle_count_fills_the_nominal_height() -> None:
    s, _ = setup_for(dCylDp=10.0, fill_height=2.0, packing_fraction=0.6)
    # Equal spheres of radius r in a tube of radius 10 r filled to 20 r:
    # N = 0.6 pi (10 r)^2 20 r / (4/3 pi r^3) = 0.6 * 2000 * 3 / 4 = 900.
    assert s.n_particles == 900
    assert s.fill_height == pytest.approx(2.0 * s.radius)


def test_lift_distance_speed_and_froude_number() -> None:
    s, _ = setup_for(dCylDp=20.0, lift_height=1.2, lift_time=20.0)
    assert s.lift_distance == pytest.approx(1.2 * 2 * s.radius)
    assert s.lift_speed == pytest.approx(s.lift_distance / 20.0)
    assert s.lift_froude == pytest.approx(s.lift_speed / math.sqrt(9.81 * 2e-3))
    assert lift_froude_number(math.sqrt(9.81 * 0.004), 0.004) == pytest.approx(1.0)
    assert s.lift_steps * s.timestep == pytest.approx(20.0, rel=1e-6)


def test_steps_follow_the_free_fall_times() -> None:
    s, _ = setup_for(settle_fall_times=3.0, final_settle_fall_times=10.0)
    t_fill = 3.0 * math.sqrt(2.0 * s.insertion_zhi / 9.81)
    t_heap = 10.0 * math.sqrt(2.0 * s.fill_height / 9.81)
    assert abs(s.fill_steps * s.timestep - t_fill) <= s.timestep
    assert abs(s.settle_steps * s.timestep - t_heap) <= s.timestep
    assert s.total_steps == s.fill_steps + s.lift_steps + s.settle_steps


def test_box_holds_plate_and_lifted_tube() -> None:
    s, dist = setup_for(plate_radius=2.5)
    assert s.plate_radius == pytest.approx(2.5 * s.radius)
    assert s.box_hi[0] > s.plate_radius and s.box_lo[0] < -s.plate_radius
    assert s.box_hi[2] > s.tube_height + s.lift_distance
    # Particles that roll off the plate fall below it and leave the box: the floor is close.
    assert -10 * dist.max_radius < s.box_lo[2] < 0.0


def test_insertion_inside_tube_and_below_its_top() -> None:
    s, dist = setup_for()
    flat = s.radius * math.cos(math.pi / s.n_segments)
    assert s.insertion_radius + dist.max_radius < flat
    assert s.tube_height > s.insertion_zhi + dist.max_radius


def test_readout_settings_are_passed_on() -> None:
    s, _ = setup_for(n_slices=16, n_sectors=6, min_contacts=3)
    assert (s.n_slices, s.n_sectors, s.min_contacts) == (16, 6, 3)
    record = json.loads(json.dumps(s.as_dict()))  # as case.json holds them
    assert (record["n_slices"], record["n_sectors"], record["min_contacts"]) == (16, 6, 3)
    assert record["radius"] == pytest.approx(10 * 1e-3)
    assert record["box_lo"][2] < 0.0 < record["tube_height"] < record["box_hi"][2]


@pytest.mark.parametrize(
    ("aor", "key"),
    [
        ({"plate_radius": 1.0}, r"angle_of_repose\.plate_radius"),
        ({"lift_time": 0.0}, r"angle_of_repose\.lift_time"),
        ({"n_slices": 2}, r"angle_of_repose\.n_slices"),
        ({"packing_fraction": 1.2}, r"angle_of_repose\.packing_fraction"),
    ],
)
def test_bad_settings_name_the_key(aor: dict, key: str) -> None:
    with pytest.raises(SetupError, match=key):
        setup_for(**aor)


def test_too_small_tube_is_rejected() -> None:
    with pytest.raises(SetupError, match="dCylDp"):
        setup_for(dCylDp=2.5)


def test_run_fields_and_seeds_are_those_of_the_shared_run_setup() -> None:
    s, dist = setup_for()
    assert isinstance(s, RunSetup) and dist.n_classes == 1
    # seed 7: the primes above 10007 + 7000, one per insertion fix and size class
    assert s.seeds == {"insert": 17011, "distribution": 17021, "template1": 17027}
    record = s.as_dict()
    assert record["box_hi"] == list(s.box_hi)
    assert record["total_steps"] == s.fill_steps + s.lift_steps + s.settle_steps
