"""Derived quantities of the shear-cell deck: geometry, particle counts, forces, time step and
the step/offset bookkeeping of the Schulze sequence, against hand-computed values."""

from __future__ import annotations

import itertools
import math

import pytest

from demcal.core.config import ConfigError, validate_config
from demcal.core.config_values import SetupError
from demcal.particles.material import material_setup, rayleigh_time, round_down_sig, time_step
from demcal.particles.run_setup import prime_seed, steps_for
from demcal.particles.size_distribution import monodisperse, sinter_fines, size_distribution
from demcal.virtual_tests.shear_cell.setup import (
    inertial_number,
    shear_cell_setup,
    shear_cell_youngs_modulus,
)

CASE = {
    "case_id": "c0001",
    "coefficientFriction": 0.5,
    "coefficientRollingFriction": 0.3,
    "coefficientRestitution": 0.6,
    "density": 2500.0,
    "normal_stress": 2029.0,
}


def settings(**cell: object) -> dict:
    """Validated default configuration with a monodisperse 1 mm radius and cell overrides."""
    cfg = validate_config({"particles": {"distribution": "monodisperse", "radius": 0.001}}, "t")
    cfg["shear_cell"].update(cell)
    return cfg


def setup_for(dCylDp: float = 10.0, stress: float = 2029.0, **cell: object):
    """The deck's setup as the workflow renders it: the modulus follows the cell's settings."""
    cfg = settings(**cell)
    dist = size_distribution(cfg["particles"])
    case = {**CASE, "normal_stress": stress}
    modulus = shear_cell_youngs_modulus(case, cfg["material"], cfg["shear_cell"])
    mat = material_setup(case, cfg["material"], dist, modulus)
    return shear_cell_setup(dCylDp, stress, dist, mat, cfg["shear_cell"], 7), mat, dist


# ---------------------------------------------------------------------------------------------
# particles, material, time step


def test_size_distribution_from_settings() -> None:
    mono = size_distribution({"distribution": "monodisperse", "radius": 0.002})
    assert list(mono.radii) == [0.002]
    fines = size_distribution({"distribution": "sinter_fines", "scale": 2.0, "classes": 4})
    assert fines.radii.tolist() == pytest.approx([2.0e-3, 1.6e-3, 1.25e-3, 1.0e-3])
    assert fines.mass_fractions.sum() == pytest.approx(1.0)
    # The four largest sieve classes hold 0.4539 + 0.1571 + 0.1033 + 0.2264 of the mass.
    assert fines.mass_fractions[0] == pytest.approx(0.4539 / 0.9407)


@pytest.mark.parametrize(
    ("particles", "key"),
    [
        ({"distribution": "cubes", "radius": 1e-3}, "particles.distribution"),
        ({"distribution": "monodisperse", "radius": -1e-3}, "particles.radius"),
        ({"distribution": "sinter_fines", "scale": 1.0, "classes": 7}, "particles.classes"),
    ],
)
def test_size_distribution_errors_name_the_key(particles: dict, key: str) -> None:
    with pytest.raises(SetupError, match=key.replace(".", r"\.")):
        size_distribution(particles)


def test_rayleigh_time_reproduces_the_papers_time_step_fraction() -> None:
    # Paper: dt = 1e-6 s was 1.29-1.53 % of the Rayleigh time (mean R 0.732 mm, 10 MPa, 0.4,
    # rho_p 2500-3500). The formula gives 1.31 % and 1.55 %.
    heavy = 1e-6 / rayleigh_time(0.732e-3, 3500.0, 1e7, 0.4)
    light = 1e-6 / rayleigh_time(0.732e-3, 2500.0, 1e7, 0.4)
    assert heavy == pytest.approx(0.0131, abs=3e-4)
    assert light == pytest.approx(0.0155, abs=3e-4)


def test_rayleigh_time_hand_value() -> None:
    # G = 1e6 / 2.8, sqrt(2800 / 357142.857) = 0.0885438, denominator 0.1631 * 0.4 + 0.8766.
    expected = math.pi * 2e-3 * math.sqrt(2800.0 / (1e6 / 2.8)) / 0.94184
    assert rayleigh_time(2e-3, 2800.0, 1e6, 0.4) == pytest.approx(expected, rel=1e-12)


def test_round_down_sig_is_exact_and_below() -> None:
    assert round_down_sig(4.44999e-5) == 4.44e-5
    assert repr(round_down_sig(4.44999e-5)) == "4.44e-05"
    assert round_down_sig(1.0) == 1.0
    assert round_down_sig(9.999e-7, 2) == 9.9e-7
    with pytest.raises(ValueError):
        round_down_sig(0.0)


def test_time_step_fixed_or_from_rayleigh_time() -> None:
    dist = sinter_fines(scale=2.0, n_largest=4)
    assert time_step(dist, 2500.0, 1e7, 0.4, 1e-6, 0.15) == 1e-6
    dt = time_step(dist, 2500.0, 2e6, 0.4, 0.0, 0.15)
    t_r = rayleigh_time(1e-3, 2500.0, 2e6, 0.4)  # smallest radius 1 mm
    assert 0.999 * 0.15 * t_r < dt <= 0.15 * t_r


def test_material_setup_switches_and_wall_friction() -> None:
    cfg = settings()
    dist = monodisperse(1e-3)
    mat = material_setup(CASE, cfg["material"], dist)
    assert (mat.cohesion, mat.rolling_friction, mat.wall_friction) == (False, True, 0.5)
    assert mat.pair_matrix(0.5, 0.2) == [0.5, 0.2, 0.2, 0.2]
    sticky = material_setup(
        {**CASE, "cohesionEnergyDensity": 3e4, "wallFriction": 0.2}, cfg["material"], dist
    )
    assert sticky.cohesion and sticky.cohesion_energy_density == 3e4
    assert sticky.wall_friction == 0.2
    assert material_setup(CASE, cfg["material"], dist, 3e6).youngs_modulus == 3e6


def test_youngs_modulus_scales_with_stress_when_asked() -> None:
    cfg = settings()
    assert shear_cell_youngs_modulus(CASE, cfg["material"], cfg["shear_cell"]) == 1e7
    cfg["shear_cell"]["youngs_modulus_per_stress"] = 1000.0
    assert shear_cell_youngs_modulus(CASE, cfg["material"], cfg["shear_cell"]) == 2.029e6
    high = {**CASE, "normal_stress": 10070.0}
    cfg["shear_cell"]["youngs_modulus_per_stress"] = 3000.0
    assert shear_cell_youngs_modulus(high, cfg["material"], cfg["shear_cell"]) == 1e7
    own = {**CASE, "youngsModulus": 5e6}
    assert shear_cell_youngs_modulus(own, cfg["material"], cfg["shear_cell"]) == 5e6


def test_prime_seeds_are_distinct_large_primes() -> None:
    seeds = [prime_seed(20240611, k) for k in range(8)]
    assert len(set(seeds)) == 8 and min(seeds) > 10000
    for s in seeds:
        assert all(s % d for d in range(2, int(s**0.5) + 1))
    # Seed 7: the primes above 10007 + 7000 = 17007.
    assert [prime_seed(7, k) for k in range(4)] == [17011, 17021, 17027, 17029]
    assert prime_seed(8, 0) == 18013  # the first prime above 18007


def test_steps_and_inertial_number() -> None:
    assert steps_for(1e-3, 1e-5) == 100
    assert steps_for(1.0000001e-3, 1e-5) == 101
    assert steps_for(1e-9, 1e-5) == 1
    # v = 0.01 m/s, band of 10 diameters, p = 2500 Pa, rho = 2500: sqrt(p / rho) = 1 m/s.
    assert inertial_number(0.01, 10.0, 2500.0, 2500.0) == pytest.approx(1e-3)


# ---------------------------------------------------------------------------------------------
# geometry and counts


def test_geometry_and_particle_count_of_monodisperse_cell() -> None:
    s, _, _ = setup_for(dCylDp=20.0, overfill=0.0)
    assert s.radius == pytest.approx(20 * 1e-3)
    assert s.fill_height == pytest.approx(1.5 * s.radius)
    assert s.z_shear == pytest.approx(0.5 * 1.5 * s.radius)
    # PHYSICS.md: about 0.73 dCylDp^3 equal spheres fill 1.5 R at a packing fraction of 0.65.
    assert s.n_particles == round(0.65 * 1.5 * 0.75 * 20**3)
    assert s.n_particles == pytest.approx(5800, rel=0.02)
    big, _, _ = setup_for(dCylDp=40.0, overfill=0.0)
    assert big.n_particles == pytest.approx(47000, rel=0.02)


def test_overfill_adds_particles_and_scrape_height_is_fill_height() -> None:
    flat, _, _ = setup_for(overfill=0.0)
    more, _, _ = setup_for(overfill=0.5)
    assert more.n_particles / flat.n_particles == pytest.approx(2.0 / 1.5, rel=2e-3)
    assert more.scrape_height == more.fill_height
    assert more.insertion_zhi > flat.insertion_zhi


def test_reference_radius_is_mass_weighted_mean() -> None:
    cfg = settings()
    cfg["particles"] = {"distribution": "sinter_fines", "scale": 1.0, "classes": 6}
    dist = size_distribution(cfg["particles"])
    mat = material_setup(CASE, cfg["material"], dist)
    s = shear_cell_setup(20.0, 2029.0, dist, mat, cfg["shear_cell"], 7)
    assert s.reference_radius == pytest.approx(dist.mass_mean_radius)
    assert s.radius == pytest.approx(20.0 * 0.778e-3, rel=2e-3)


def test_insertion_region_inside_the_polygonal_tube() -> None:
    s, _, dist = setup_for()
    flat = s.radius * math.cos(math.pi / s.n_segments)
    assert s.insertion_radius + dist.max_radius < flat
    # Volume fraction of the insertion region equals the configured one.
    solid = s.n_particles * dist.mean_particle_volume
    region = math.pi * s.insertion_radius**2 * (s.insertion_zhi - s.insertion_zlo)
    assert solid / region == pytest.approx(0.3)
    assert s.wall_top > s.insertion_zhi


def test_too_small_cell_is_rejected() -> None:
    with pytest.raises(SetupError, match="dCylDp"):
        setup_for(dCylDp=2.5)


# ---------------------------------------------------------------------------------------------
# loads, speeds, Schulze sequence


def test_forces_speeds_and_durations() -> None:
    s, _, _ = setup_for(stress=10070.0)
    area = math.pi * s.radius**2
    assert s.preshear_force == pytest.approx(10070.0 * area)
    assert s.lid_target_val == -s.preshear_force
    assert s.shear_speed == pytest.approx(3.0 * 1e-3)
    assert s.preshear_time == pytest.approx(0.1875 * s.radius / s.shear_speed)
    assert s.shear_time == pytest.approx(0.95 * s.preshear_time)
    assert s.servo_vel_max == pytest.approx(5.0 * s.shear_speed)
    for cycle, p in zip(s.cycles, (0.4, 0.6, 0.8, 1.0), strict=True):
        assert cycle.P == p
        assert cycle.shear_force == pytest.approx(p * s.preshear_force)
    smallest = 10070.0 * 0.4
    assert s.inertial_number_min_stress == pytest.approx(
        s.shear_speed / (10.0 * math.sqrt(smallest / 2500.0))
    )


def test_speed_keeps_the_inertial_number_of_the_reference_stress() -> None:
    def deck(stress: float, reference: float):
        return setup_for(
            stress=stress,
            youngs_modulus_per_stress=3000.0,
            youngs_modulus_max=1.0e9,
            shear_speed_reference_stress=reference,
        )[0]

    low, high = deck(1068.0, 1068.0), deck(10070.0, 1068.0)
    assert low.shear_speed == pytest.approx(3.0e-3)
    assert high.shear_speed == pytest.approx(3.0e-3 * math.sqrt(10070.0 / 1068.0))
    assert high.inertial_number_min_stress == pytest.approx(low.inertial_number_min_stress)
    # Modulus and speed both follow the stress: the time step shrinks as the speed grows, so
    # the pre-shears and shears take the steps of the reference stress (to the rounding of
    # the time step); one speed at every stress takes sqrt(10070 / 1068) = 3.07 times more.
    sheared = [d.total_steps - d.fill_steps for d in (low, high, deck(10070.0, 0.0))]
    assert sheared[1] / sheared[0] == pytest.approx(1.0, rel=0.05)
    assert sheared[2] / sheared[1] == pytest.approx(math.sqrt(10070.0 / 1068.0), rel=1e-3)
    # Below the reference stress the cell shears slower, and 0 leaves shear_speed alone.
    assert deck(534.0, 1068.0).shear_speed == pytest.approx(3.0e-3 / math.sqrt(2.0), rel=1e-3)
    assert deck(534.0, 0.0).shear_speed == pytest.approx(3.0e-3)
    with pytest.raises(ConfigError, match="shear_speed_reference_stress"):
        validate_config({"shear_cell": {"shear_speed_reference_stress": -1.0}}, "t")


def test_segments_are_contiguous_and_cover_the_run() -> None:
    s, _, _ = setup_for()
    segs = s.segments
    assert segs[0].start_step == s.fill_steps
    for a, b in itertools.pairwise(segs):
        assert b.start_step == a.end_step
        assert b.offset_start == pytest.approx(a.offset_end, abs=1e-15)
    assert s.total_steps == segs[-1].end_step
    assert [g.phase for g in segs[:4]] == [0, 1, 2, 3]


def test_return_mode_starts_every_cycle_at_zero_offset_towards_minus_x() -> None:
    s, _, _ = setup_for(cycles="return")
    travel = s.shear_speed * s.timestep
    for cycle in s.cycles:
        assert cycle.direction == -1
        assert cycle.offset_preshear_start == pytest.approx(0.0, abs=1e-12)
        n = (cycle.preshear_end_step - cycle.preshear_start_step) + (
            cycle.shear_end_step - cycle.shear_start_step
        )
        assert cycle.offset_shear_end == pytest.approx(-n * travel, rel=1e-12)
    # Pre-shear travel is 0.1875 R within one step.
    first = s.cycles[0]
    moved = (first.preshear_end_step - first.preshear_start_step) * travel
    assert abs(moved - 0.1875 * s.radius) <= travel
    returns = [g for g in s.segments if g.phase == 0 and g.moving]
    assert len(returns) == 3
    assert all(g.velocity > 0 for g in returns)
    assert s.max_offset == pytest.approx(-min(c.offset_shear_end for c in s.cycles))


def test_alternate_mode_swings_symmetrically() -> None:
    s, _, _ = setup_for(cycles="alternate")
    assert [c.direction for c in s.cycles] == [-1, 1, -1, 1]
    h = s.cycles[0].offset_preshear_start
    assert h > 0
    for cycle in s.cycles:
        assert abs(cycle.offset_preshear_start) == pytest.approx(
            h, abs=2 * s.shear_speed * s.timestep
        )
        assert abs(cycle.offset_shear_end) <= h + 2 * s.shear_speed * s.timestep
    position = s.segments[1]
    assert position.phase == 0 and position.moving and position.velocity > 0


def test_run_in_lengthens_the_first_preshear_only() -> None:
    def preshears(deck) -> list[int]:
        return [c.preshear_end_step - c.preshear_start_step for c in deck.cycles]

    plain, _, _ = setup_for(cycles="return")
    run_in, _, _ = setup_for(cycles="return", run_in_travel=0.375)
    # 0.375 R at the shear speed, in whole steps, on top of the 0.1875 R of every pre-shear.
    extra = steps_for(0.375 * run_in.radius / run_in.shear_speed, run_in.timestep)
    assert preshears(run_in) == [preshears(plain)[0] + extra, *preshears(plain)[1:]]
    assert extra * run_in.shear_speed * run_in.timestep == pytest.approx(
        0.375 * run_in.radius, abs=run_in.shear_speed * run_in.timestep
    )
    assert run_in.total_steps == plain.total_steps + extra
    assert run_in.snapshot_step == run_in.cycles[0].preshear_end_step


def test_run_in_keeps_the_alternate_swing_symmetric() -> None:
    plain, _, _ = setup_for(cycles="alternate")
    s, _, _ = setup_for(cycles="alternate", run_in_travel=0.375)
    step = 2 * s.shear_speed * s.timestep
    h = -plain.cycles[0].offset_shear_end
    # The first swing starts further out and ends where the plain one does.
    assert s.cycles[0].offset_preshear_start == pytest.approx(h + 0.375 * s.radius, abs=step)
    for plain_cycle, cycle in zip(plain.cycles, s.cycles, strict=True):
        assert cycle.offset_shear_end == pytest.approx(plain_cycle.offset_shear_end, abs=step)
    assert s.max_offset == pytest.approx(h + 0.375 * s.radius, abs=step)
    assert s.flange_width > s.max_offset


def test_negative_run_in_names_the_key() -> None:
    with pytest.raises(ConfigError, match="run_in_travel"):
        validate_config({"shear_cell": {"run_in_travel": -0.1}}, "t")
    with pytest.raises(SetupError, match=r"shear_cell\.run_in_travel"):
        setup_for(run_in_travel=-0.1)


def test_single_load_condition_runs_one_cycle() -> None:
    s, _, _ = setup_for(P=[0.6])
    assert len(s.cycles) == 1 and s.cycles[0].P == 0.6
    assert [g.phase for g in s.segments] == [0, 1, 2, 3]
    assert s.snapshot_step == s.cycles[0].preshear_end_step
    assert [g.snapshot for g in s.segments] == [False, True, False, False]


def test_servo_gains_scale_with_the_target() -> None:
    s, _, _ = setup_for(servo_kp=2.0, servo_ki=0.5)
    for g in s.segments:
        factor = g.target_force / s.preshear_force
        assert g.ctrl == pytest.approx((2.0 * factor, 0.5 * factor, 0.0))
        assert g.target_val == -g.target_force
    unload = [g for g in s.segments if g.phase == 2]
    assert all(g.target_force == pytest.approx(1e-3 * s.preshear_force) for g in unload)


def test_travel_per_step_integrates_to_the_offsets() -> None:
    s, _, _ = setup_for(cycles="alternate")
    for g in s.segments:
        assert g.offset_end == pytest.approx(g.offset_start + g.steps * g.travel_per_step)
        assert g.travel_per_step == pytest.approx(g.velocity * s.timestep)


def test_box_holds_the_walls_in_every_position() -> None:
    for mode in ("return", "alternate"):
        s, _, _ = setup_for(cycles=mode)
        reach = s.radius + s.flange_width + s.max_offset
        assert s.box_lo[0] < -reach and s.box_hi[0] > reach
        assert s.box_hi[1] > s.radius + s.flange_width
        assert s.box_hi[2] > s.wall_top and s.box_lo[2] < 0.0
        assert s.flange_width > s.max_offset


def test_print_interval_gives_the_requested_samples() -> None:
    s, _, _ = setup_for(samples_per_preshear=100)
    n_psh = s.cycles[0].preshear_end_step - s.cycles[0].preshear_start_step
    assert n_psh // s.print_every >= 100
    assert n_psh // s.print_every < 200


@pytest.mark.parametrize("samples", [20, 99, 100, 137, 200, 250])
def test_print_interval_is_odd(samples: int) -> None:
    # A lid force oscillating at every time step must alternate between print rows (so that
    # the ringing flag sees it), not be printed at one phase of its swing.
    s, _, _ = setup_for(samples_per_preshear=samples)
    n_psh = s.cycles[0].preshear_end_step - s.cycles[0].preshear_start_step
    assert s.print_every % 2 == 1
    assert n_psh // s.print_every >= samples
    assert s.print_every >= n_psh // samples - 1


def test_servo_speed_above_skin_limit_names_the_key() -> None:
    with pytest.raises(SetupError, match=r"shear_cell\.servo_speed"):
        setup_for(servo_speed=1e6)


@pytest.mark.parametrize(
    ("cell", "key"),
    [
        ({"P": [0.0]}, r"shear_cell\.P"),
        ({"P": []}, r"shear_cell\.P"),
        ({"cycles": "zigzag"}, r"shear_cell\.cycles"),
        ({"shear_plane": 1.5}, r"shear_cell\.shear_plane"),
        ({"servo_kp": 0.0, "servo_ki": 0.0, "servo_kd": 0.0}, "servo_kp"),
        ({"overfill": -0.1}, r"shear_cell\.overfill' must be >= 0, got -0\.1"),
    ],
)
def test_bad_settings_name_the_key(cell: dict, key: str) -> None:
    with pytest.raises(SetupError, match=key):
        setup_for(**cell)


def test_missing_key_is_named() -> None:
    cfg = settings()
    del cfg["shear_cell"]["shear_speed"]
    dist = size_distribution(cfg["particles"])
    mat = material_setup(CASE, cfg["material"], dist)
    with pytest.raises(KeyError, match=r"shear_cell\.shear_speed"):
        shear_cell_setup(10.0, 2029.0, dist, mat, cfg["shear_cell"], 7)


def test_non_positive_stress_is_rejected() -> None:
    with pytest.raises(SetupError, match="normal_stress"):
        setup_for(stress=0.0)


# ---------------------------------------------------------------------------------------------
# ring cell

RING = {"geometry": "ring", "fill_height": 0.5, "overfill": 0.15, "ring_radius_ratio": 2.0}


def test_ring_geometry_force_and_rotation() -> None:
    s, _, _ = setup_for(dCylDp=24.0, **RING)
    assert s.geometry == "ring"
    assert s.radius == pytest.approx(0.024)
    assert s.inner_radius == pytest.approx(0.012)
    assert s.mean_radius == pytest.approx(0.018)
    # Inner polygon vertices on R_i; a centre 1.05 r_max further out clears it.
    assert s.core_radius == pytest.approx(0.012 + 1.05e-3)
    assert s.cross_section == pytest.approx(math.pi * (0.024**2 - 0.012**2))
    assert s.preshear_force == pytest.approx(2029.0 * math.pi * (0.024**2 - 0.012**2))
    assert (s.n_bars, s.bar_height) == (24, pytest.approx(2e-3))
    # The lid starts with its bars one particle radius (and 5 %) above the bed.
    assert s.lid_gap == pytest.approx(1.05e-3 + 2e-3)
    assert s.wall_top >= s.fill_height + s.lid_gap + 2e-3
    # The ring turns in place: the box is the cell plus a margin, no flange.
    assert s.flange_width == 0.0
    assert s.box_hi[0] == pytest.approx(0.024 + 4e-3) and s.box_lo[1] == pytest.approx(-0.028)
    assert len(s.rotation) == len(s.segments)
    for seg, (period, sign) in zip(s.segments, s.rotation, strict=True):
        if seg.moving:
            # One turn of the mean circle at the shear speed; sign of the turning sense.
            assert period == pytest.approx(2 * math.pi * 0.018 / abs(seg.velocity))
            assert sign == (1 if seg.velocity > 0 else -1)
        else:
            assert (period, sign) == (0.0, 0)
    assert s.settle_steps == s.fill_steps - 1
    # Particles are inserted clear of the floor bars (they overlapped them at step 1 before).
    assert s.insertion_zlo == pytest.approx(2e-3 + 1.05e-3)


def test_continue_mode_shears_on_in_one_direction_without_return() -> None:
    s, _, _ = setup_for(dCylDp=24.0, cycles="continue", **RING)
    r, _, _ = setup_for(dCylDp=24.0, cycles="return", **RING)
    assert [c.direction for c in s.cycles] == [-1, -1, -1, -1]
    # Compression once, then pre-shear / unload / shear per cycle, nothing in between.
    assert [g.phase for g in s.segments] == [0] + [1, 2, 3] * 4
    for a, b in itertools.pairwise(s.cycles):
        assert b.preshear_start_step == a.shear_end_step
        assert b.offset_preshear_start == pytest.approx(a.offset_shear_end, abs=1e-12)
    assert all(g.velocity <= 0.0 for g in s.segments)
    assert all(p > 0.0 and sign == -1 for p, sign in s.rotation if p)
    # The same cycles as the return mode, without its three unload / return / compress blocks.
    saved = sum(g.steps for g in r.segments if g.phase == 0 and g.cycle > 0)
    assert r.total_steps - s.total_steps == saved
    for a, b in zip(s.cycles, r.cycles, strict=True):
        assert (
            a.preshear_end_step - a.preshear_start_step
            == b.preshear_end_step - b.preshear_start_step
        )
        assert a.shear_end_step - a.shear_start_step == b.shear_end_step - b.shear_start_step


def test_continue_mode_needs_the_ring() -> None:
    with pytest.raises(SetupError, match=r"shear_cell\.cycles.*continue.*ring"):
        setup_for(cycles="continue")
    with pytest.raises(ConfigError, match=r"shear_cell\.cycles: 'continue' needs"):
        validate_config({"shear_cell": {"cycles": "continue", "geometry": "split"}}, "t")
    cfg = validate_config({"shear_cell": {"cycles": "continue", "geometry": "ring"}}, "t")
    assert cfg["shear_cell"]["cycles"] == "continue"


def test_split_cell_has_no_ring_fields() -> None:
    s, _, _ = setup_for(dCylDp=24.0)
    assert (s.geometry, s.inner_radius, s.n_bars, s.rotation) == ("split", 0.0, 0, ())
    assert s.cross_section == pytest.approx(math.pi * 0.024**2)


@pytest.mark.parametrize(
    ("dCylDp", "cell", "match"),
    [
        # R = 8 mm at ratio 1.2: a ring 1.3 mm wide, narrower than three particle diameters
        (8.0, {**RING, "ring_radius_ratio": 1.2}, "ring_radius_ratio"),
        (24.0, {**RING, "ring_radius_ratio": 1.0}, "ring_radius_ratio"),
        (24.0, {**RING, "bar_height": 6.0}, "bar_height"),
        (24.0, {**RING, "n_bars": -1}, "n_bars"),
        (24.0, {**RING, "bar_height": float("nan")}, "bar_height' must be >= 0"),
        (24.0, {**RING, "geometry": "box"}, "geometry"),
    ],
)
def test_bad_ring_settings_name_the_key(dCylDp: float, cell: dict, match: str) -> None:
    with pytest.raises(SetupError, match=match):
        setup_for(dCylDp=dCylDp, **cell)


def test_interior_region_keeps_the_margin_from_walls_and_bar_tips() -> None:
    # R = 24 mm, R_i = 12 mm, bed 12 mm high, bars 2 mm, margin 1 mean diameter = 2 mm.
    s, _, _ = setup_for(dCylDp=24.0, bulk_density="interior", interior_margin=1.0, **RING)
    assert s.bulk_density == "interior"
    assert (s.interior_r_lo, s.interior_r_hi) == (pytest.approx(0.014), pytest.approx(0.022))
    # Floor bar tips at 2 mm; the lid's bar tips at the scraped bed height 12 mm minus 2 mm.
    assert (s.interior_z_lo, s.interior_z_hi) == (pytest.approx(0.004), pytest.approx(0.008))
    assert s.interior_z_lo < s.z_shear < s.interior_z_hi
    assert s.interior_volume == pytest.approx(math.pi * (0.022**2 - 0.014**2) * 0.004)
    assert s.as_dict()["interior_volume"] == pytest.approx(s.interior_volume)
    wide, _, _ = setup_for(dCylDp=24.0, bulk_density="interior", interior_margin=0.5, **RING)
    assert wide.interior_volume > s.interior_volume


def test_whole_cell_density_has_no_interior_region() -> None:
    s, _, _ = setup_for(dCylDp=24.0, **RING)
    assert s.bulk_density == "cell" and s.interior_volume == 0.0


def test_interior_density_needs_the_ring_before_any_work() -> None:
    with pytest.raises(ConfigError, match=r"shear_cell\.bulk_density: 'interior' needs"):
        validate_config({"shear_cell": {"bulk_density": "interior"}}, "t")
    cfg = validate_config({"shear_cell": {"bulk_density": "interior", "geometry": "ring"}}, "t")
    assert cfg["shear_cell"]["interior_margin"] == 1.0


@pytest.mark.parametrize(
    ("cell", "match"),
    [
        # the split cell's bed moves against its walls: no fixed interior
        ({"bulk_density": "interior"}, r"bulk_density: interior' needs .*geometry: ring"),
        # 3 diameters from the floor bars leave no height below the lid's bars
        ({**RING, "bulk_density": "interior", "interior_margin": 3.0}, "interior_margin"),
        ({**RING, "bulk_density": "interior", "interior_margin": -1.0}, "interior_margin"),
        ({**RING, "bulk_density": "middle"}, "bulk_density"),
    ],
)
def test_bad_interior_settings_name_the_key(cell: dict, match: str) -> None:
    with pytest.raises(SetupError, match=match):
        setup_for(dCylDp=24.0, **cell)
