"""Chute-cooler set-up: geometry, feed rate, timing, meshes, parameter resolution and rendering."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

from demcal.application.chute_cooler.contact_parameters import application_parameters
from demcal.application.chute_cooler.deck import (
    DECK_NAME,
    IdentifiedParametersError,
    application_distribution,
    read_identified_parameters,
    render_chute_cooler,
)
from demcal.application.chute_cooler.layout import ChuteCoolerSetup
from demcal.application.chute_cooler.meshes import (
    box_row_triangles,
    chute_triangles,
    hole_grid,
    perforated_plate,
)
from demcal.application.chute_cooler.setup import chute_cooler_setup, stream_estimate
from demcal.core.config import load_config, validate_config
from demcal.core.config_values import SetupError
from demcal.core.parameters import GRAVITY
from demcal.decks.stl_file import read_stl
from demcal.decks.triangle_surface import surface_area, triangle_areas, triangle_normals
from demcal.particles.material import material_setup

ROOT = Path(__file__).resolve().parents[2]
PARAMS = {
    "coefficientFriction": 0.5,
    "coefficientRollingFriction": 0.3,
    "coefficientRestitution": 0.6,
    "density": 3000.0,
}


def settings(**application) -> dict:
    """A validated configuration with explicit application parameters."""
    cfg = {"application": {"parameters": dict(PARAMS), **application}}
    return validate_config(cfg, "test")


def make_setup(**application):
    cfg = settings(**application)
    section = cfg["application"]
    dist = application_distribution(section)
    mat = material_setup(application_parameters(section, None), cfg["material"], dist)
    return chute_cooler_setup(section, dist, mat, seed=cfg["seed"]), dist, mat, section


# --- floor and meshes ---------------------------------------------------------------------


def test_hole_grid_is_centred_with_floor_length_over_pitch_holes():
    b = hole_grid(0.01, 0.003, 0.001)
    assert b.size == 2 * 3 + 2
    holes = b[1:-1].reshape(-1, 2)
    np.testing.assert_allclose(holes[:, 1] - holes[:, 0], 0.001)
    np.testing.assert_allclose(np.diff(holes[:, 0]), 0.003)
    assert holes[0, 0] - 0.0 == pytest.approx(0.01 - holes[-1, 1])
    assert hole_grid(0.01, 0.003, 0.0).tolist() == [0.0, 0.01]


def test_perforated_plate_area_and_normals():
    tri = perforated_plate(-0.01, 0.02, 0.0, 0.012, 0.0, pitch=0.003, hole=0.002)
    nx, ny = 10, 4
    assert surface_area(tri) == pytest.approx(0.03 * 0.012 - nx * ny * 0.002**2, rel=1e-12)
    # cells: (2 nx + 1)(2 ny + 1) minus the holes, two triangles each
    assert len(tri) == 2 * ((2 * nx + 1) * (2 * ny + 1) - nx * ny)
    np.testing.assert_allclose(triangle_normals(tri), [[0.0, 0.0, 1.0]] * len(tri))
    # no slivers: the smallest triangle is a quarter of the bar width squared or more
    assert triangle_areas(tri).min() >= 0.5 * (0.0005 * 0.0005) * 0.99
    assert len(perforated_plate(0, 1, 0, 1, 0, pitch=0.3, hole=0.0)) == 2
    with pytest.raises(ValueError, match="hole < pitch"):
        perforated_plate(0, 1, 0, 1, 0, pitch=0.1, hole=0.2)


def test_box_row_mesh_area_and_extent():
    s, *_ = make_setup()
    tri = box_row_triangles(s)
    L, W, H, n = s.box_length, s.box_width, s.box_height, s.n_boxes
    nx, ny = s.holes_per_box
    floors = n * (L * W - nx * ny * s.hole_size**2)
    walls = W * s.lead_wall_height + n * W * H + 2 * n * L * s.rim_height
    assert surface_area(tri) == pytest.approx(floors + walls, rel=1e-12)
    assert len(tri) == s.n_triangles["boxes"]
    assert tri[..., 0].max() == pytest.approx(s.box_front_x0)
    assert tri[..., 0].min() == pytest.approx(s.box_front_x0 - n * L)
    assert H < s.lead_wall_height <= s.rim_height


def test_chute_mesh_and_clearances():
    s, *_ = make_setup()
    tri = chute_triangles(s)
    (xe, ze), (xu, zu) = s.chute_edge, s.chute_top
    assert math.degrees(math.atan2(zu - ze, xu - xe)) == pytest.approx(s.chute_angle)
    # the chute is narrower than the row, but by less than the smallest particle
    y0, y1 = s.chute_y
    assert 0.0 < y0 < 2.0 * s.r_min and s.box_width - 2.0 * s.r_min < y1 < s.box_width
    assert tri[..., 1].min() == pytest.approx(y0) and tri[..., 1].max() == pytest.approx(y1)
    # the partitions pass under the discharge edge, the leading wall stays below the chute
    assert ze - s.box_height >= 2.0 * s.r_max
    chute_floor_at_wall = ze + s.box_front_x0 * math.tan(math.radians(s.chute_angle))
    assert s.lead_wall_height < chute_floor_at_wall
    # the feed block sits above the chute floor, inside the chute
    assert s.feed_lo[2] > ze + s.feed_hi[0] * math.tan(math.radians(s.chute_angle))
    assert y0 < s.feed_lo[1] < s.feed_hi[1] < y1
    assert s.feed_hi[0] < xu


# --- feed, stream and timing -----------------------------------------------------------------


def test_feed_rate_fills_the_row_to_the_fill_ratio():
    s, dist, mat, section = make_setup()
    expected = section["fill_ratio"] * section["bulk_density"] * s.box_width * s.box_height
    assert s.mass_rate == pytest.approx(expected * section["box_speed"])
    assert s.particle_mass == pytest.approx(mat.density * dist.mean_particle_volume)
    assert s.particle_rate * s.particle_mass == pytest.approx(s.mass_rate)
    assert s.particles_per_box == pytest.approx(
        section["bulk_density"] * s.box_length * s.box_width * s.box_height / s.particle_mass
    )
    assert s.expected_particles == pytest.approx(s.particle_rate * s.total_steps * s.timestep)


def test_insertion_events_fit_in_the_block_and_clear_it():
    s, _, mat, section = make_setup()
    dt = s.timestep
    block = np.subtract(s.feed_hi, s.feed_lo)
    solid_per_event = s.mass_rate * s.insert_every * dt / mat.density
    assert solid_per_event / np.prod(block) <= section["insertion_fraction"]
    # a particle starting with the feed speed has fallen through the block before the next event
    v0 = -s.feed_velocity[2]
    t = s.insert_every * dt
    assert v0 * t + 0.5 * GRAVITY * t * t >= block[2] * (1 - 1e-9)
    speed = math.hypot(s.feed_velocity[0], s.feed_velocity[2])
    assert speed == pytest.approx(section["feed_speed"])


def test_stream_estimate_against_closed_forms():
    # frictionless slide from rest: v = sqrt(2 g sin(theta) s)
    v, throw, t_slide, t_fall = stream_estimate(0.0, 0.1, 30.0, 0.0, 0.05)
    assert v == pytest.approx(math.sqrt(2 * GRAVITY * 0.5 * 0.1))
    assert t_slide == pytest.approx(v / (GRAVITY * 0.5))
    vz = v * 0.5
    assert vz * t_fall + 0.5 * GRAVITY * t_fall**2 == pytest.approx(0.05)
    assert throw == pytest.approx(v * math.cos(math.radians(30)) * t_fall)
    # Coulomb friction slows the slide
    assert stream_estimate(0.0, 0.1, 30.0, 0.3, 0.05)[0] < v
    with pytest.raises(SetupError, match="chute_angle"):
        stream_estimate(0.0, 0.1, 30.0, 0.6, 0.05)


def test_timing_covers_the_analysed_box_and_ends_on_a_dump():
    s, _, _, section = make_setup()
    assert s.total_steps == s.startup_steps + s.travel_steps
    assert s.total_steps % s.vtk_every == 0 and s.vtk_every % s.dump_every == 0
    assert s.total_steps / s.dump_every >= section["n_snapshots"]
    t_end = s.total_steps * s.timestep
    assert s.row_offset(t_end) == pytest.approx(s.travel)
    assert s.row_offset(0.5 * s.startup_time) == 0.0
    # at the end the analysed box is past the landing point by run_after_fill box lengths
    x0, *_ = s.box_bounds(s.analysed_box, t_end)
    assert x0 - s.landing_x >= section["run_after_fill"] * s.box_length * (1 - 1e-9)
    # and the stream still lands on the row
    back = s.box_front_x0 - s.n_boxes * s.box_length + s.travel
    assert back <= s.landing_x - 0.25 * s.box_length
    # stage 0 lasts at least until the stream reaches the floor
    assert s.startup_time >= s.arrival_time


def test_simulation_box_holds_the_walls_over_the_whole_run():
    s, *_ = make_setup()
    lo, hi = np.array(s.box_lo), np.array(s.box_hi)
    start = box_row_triangles(s)
    end = start + np.array([s.travel, 0.0, 0.0])
    for tri in (start, end, chute_triangles(s)):
        pts = tri.reshape(-1, 3)
        assert np.all(pts > lo) and np.all(pts < hi)
    assert np.all(np.array(s.feed_lo) > lo) and np.all(np.array(s.feed_hi) < hi)


def test_box_bounds_follow_the_row():
    s, *_ = make_setup()
    t = s.startup_time + 0.1
    x0, x1, y0, y1, z0, z1 = s.box_bounds(2, t)
    assert x1 == pytest.approx(s.box_front_x0 - s.box_length + s.box_speed * 0.1)
    assert x1 - x0 == pytest.approx(s.box_length)
    assert (y0, y1, z0, z1) == (0.0, s.box_width, 0.0, s.box_height)
    with pytest.raises(ValueError, match="box must be"):
        s.box_bounds(s.n_boxes + 1, t)


def test_setup_round_trips_through_a_dict():
    s, *_ = make_setup()
    back = ChuteCoolerSetup.from_dict(json.loads(json.dumps(s.as_dict())))
    assert back == s
    record = s.as_dict()
    del record["travel"]
    with pytest.raises(KeyError, match="travel"):
        ChuteCoolerSetup.from_dict(record, "case.json")


@pytest.mark.parametrize(
    ("change", "key"),
    [
        ({"rim_height": 1.1, "fill_ratio": 1.3}, "rim_height"),
        ({"hole_size": 0.5, "hole_pitch": 0.5}, "hole_pitch"),
        ({"n_boxes": 2, "analysed_box": 2}, "n_boxes"),
        ({"box_height": 0.004}, "box_height"),
        ({"chute_length": 0.01}, "chute_length"),
        ({"chute_drop": 0.001}, "chute_drop"),
        ({"chute_wall_height": 0.005}, "chute_wall_height"),
        ({"chute_angle": 20.0}, "chute_angle"),
    ],
)
def test_impossible_settings_name_their_key(change, key):
    with pytest.raises(SetupError, match=key):
        make_setup(**change)


# --- parameters ------------------------------------------------------------------------------


def test_parameters_explicit_identified_or_error():
    identified = {k: {"mean": v * 1.1, "sd": 0.1} for k, v in PARAMS.items()}
    section = {"parameters": None, "wall_friction": 0.4}
    out = application_parameters(section, identified, "ident.json")
    assert out["coefficientFriction"] == pytest.approx(0.55)
    assert out["wallFriction"] == 0.4
    explicit = application_parameters({"parameters": PARAMS, "wall_friction": None}, identified)
    assert explicit == PARAMS
    with pytest.raises(KeyError, match=r"ident\.json.*density"):
        application_parameters(
            section, {k: v for k, v in identified.items() if k != "density"}, "ident.json"
        )
    with pytest.raises(SetupError, match="null"):
        application_parameters(section, None)
    bad = dict(identified, coefficientRestitution={"mean": 1.5})
    with pytest.raises(SetupError, match="coefficientRestitution"):
        application_parameters(section, bad, "ident.json")


def test_read_identified_parameters(tmp_path):
    # The record as the identification writes it (demcal.identification.calibration).
    good = tmp_path / "p.json"
    stats = {"mean": 2900.0, "sd": 10.0, "min": 2800, "max": 3000}
    good.write_text(
        json.dumps({"group": "SSC & AoR", "n_total": 10, "parameters": {"density": stats}})
    )
    assert read_identified_parameters(good)["density"]["min"] == 2800.0
    bad = tmp_path / "bad.json"
    bad.write_text('{"parameters": {"density": {"mean": "heavy"}}}')
    with pytest.raises(IdentifiedParametersError, match=r"bad\.json.*density\.mean"):
        read_identified_parameters(bad)
    flat = tmp_path / "flat.json"
    flat.write_text(json.dumps({"density": stats}))
    with pytest.raises(IdentifiedParametersError, match=r"flat\.json.*'parameters'"):
        read_identified_parameters(flat)
    empty = tmp_path / "empty.json"
    empty.write_text('{"group": "SSC", "parameters": {}}')
    with pytest.raises(IdentifiedParametersError, match="no parameter set was identified"):
        read_identified_parameters(empty)
    with pytest.raises(IdentifiedParametersError, match=r"missing\.json"):
        read_identified_parameters(tmp_path / "missing.json")


# --- rendering and the shipped configurations ----------------------------------------------------


def test_render_writes_a_stable_deck_with_the_numbers(tmp_path):
    cfg = settings()
    a = render_chute_cooler(cfg, tmp_path / "a")
    render_chute_cooler(cfg, tmp_path / "b")
    for name in (DECK_NAME, "case.json", "meshes/chute.stl", "meshes/boxes.stl"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()
    deck = (tmp_path / "a" / DECK_NAME).read_text()
    s = a["setup"]
    assert f"massrate {s['mass_rate']!r}" in deck
    assert f"run {s['startup_steps']}\n" in deck and f"run {s['travel_steps']}\n" in deck
    assert f"linear {s['box_speed']!r} 0.0 0.0" in deck
    assert "coefficientFriction peratomtypepair 2 0.5 0.5 0.5 0.5" in deck
    assert deck.count("particletemplate/sphere") == len(s["radii"])
    boxes = read_stl(tmp_path / "a" / "meshes" / "boxes.stl")
    assert len(boxes.triangles) == s["n_triangles"]["boxes"]
    assert (tmp_path / "a" / "vtk").is_dir()


def test_render_refuses_before_writing(tmp_path):
    cfg = settings(chute_angle=10.0)
    with pytest.raises(SetupError, match="chute_angle"):
        render_chute_cooler(cfg, tmp_path / "x")
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("name", ["tiny.yaml", "config.yaml", "paper.yaml"])
def test_shipped_configurations_give_a_workable_case(name):
    cfg = load_config(ROOT / "config" / name)
    section = dict(cfg["application"])
    if section["parameters"] is None:
        section["parameters"] = dict(PARAMS)
    dist = application_distribution(section)
    mat = material_setup(application_parameters(section, None), cfg["material"], dist)
    s = chute_cooler_setup(section, dist, mat, seed=cfg["seed"])
    limits = {"tiny.yaml": 2_000, "config.yaml": 30_000, "paper.yaml": 500_000}
    assert s.expected_particles <= limits[name]
    assert s.particles_per_box >= 50
