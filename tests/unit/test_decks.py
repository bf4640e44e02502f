"""Deck rendering (byte-stable, StrictUndefined, header, switches, validation before writing)
and the bulk-value extraction of a rendered case from synthetic engine outputs."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import jinja2
import numpy as np
import pytest

from demcal.bulk.values import MissingOutputError, extract
from demcal.core.config import load_config, validate_config
from demcal.decks.case_validation import CaseValidationError, MissingColumnError
from demcal.decks.render import format_number, template_environment
from demcal.decks.stl_file import read_stl
from demcal.decks.triangle_surface import surface_area
from demcal.robustness.base_decks import with_quick_ring
from demcal.virtual_tests.deck import particle_steps, render_case

ROOT = Path(__file__).resolve().parents[2]

CASE = {
    "case_id": "c0007",
    "coefficientFriction": 0.5,
    "coefficientRollingFriction": 0.3,
    "coefficientRestitution": 0.6,
    "density": 2500.0,
    "normal_stress": 2029.0,
}


def tiny() -> dict:
    return load_config(ROOT / "config" / "tiny.yaml")


def files_of(directory: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(directory)): p.read_bytes()
        for p in sorted(directory.rglob("*"))
        if p.is_file()
    }


def run_lengths(deck: str) -> list[int]:
    return [int(n) for n in re.findall(r"^run (\d+)$", deck, flags=re.MULTILINE)]


# ---------------------------------------------------------------------------------------------
# formatting and template environment


def test_format_number_is_exact_and_canonical() -> None:
    assert format_number(3) == "3"
    assert format_number(np.int64(12)) == "12"
    assert format_number(0.1) == "0.1"
    assert format_number(-0.0) == "0.0"
    assert format_number(1e-6) == "1e-06"
    x = 0.1 + 0.2
    assert float(format_number(x)) == x
    for bad in (float("nan"), math.inf, True, "1"):
        with pytest.raises(ValueError):
            format_number(bad)


def test_templates_use_strict_undefined() -> None:
    env = template_environment()
    with pytest.raises(jinja2.UndefinedError):
        env.get_template("shear_cell.in.j2").render(case_id="c1", parameters=[])
    with pytest.raises(jinja2.UndefinedError):
        env.from_string("{{ missing | num }}").render()


# ---------------------------------------------------------------------------------------------
# rendering


@pytest.mark.parametrize("test", ["shear_cell", "angle_of_repose"])
def test_rendering_is_byte_stable(tmp_path: Path, test: str) -> None:
    first = render_case(test, CASE, tiny(), tmp_path / "a")
    second = render_case(test, dict(CASE), tiny(), tmp_path / "b")
    assert first == second
    a, b = files_of(tmp_path / "a"), files_of(tmp_path / "b")
    assert a.keys() == b.keys() and a == b
    deck = "in.shear_cell" if test == "shear_cell" else "in.angle_of_repose"
    assert {deck, "case.json"} <= a.keys()
    assert any(name.startswith("meshes/") and name.endswith(".stl") for name in a)


@pytest.mark.parametrize("test", ["shear_cell", "angle_of_repose"])
def test_deck_starts_with_case_comment(tmp_path: Path, test: str) -> None:
    render_case(test, CASE, tiny(), tmp_path)
    deck = next(tmp_path.glob("in.*")).read_text().splitlines()
    assert deck[0].startswith("# demcal ") and deck[0].endswith("case c0007")
    header = [line for line in deck[:12] if line.startswith("# ")]
    assert "# coefficientFriction = 0.5" in header
    assert "# coefficientRestitution = 0.6" in header
    assert "# dCylDp = " + format_number(float(tiny()[test]["dCylDp"])) in header


def test_run_lengths_add_up_to_the_setup(tmp_path: Path) -> None:
    record = render_case("shear_cell", CASE, tiny(), tmp_path)
    deck = (tmp_path / "in.shear_cell").read_text()
    runs = run_lengths(deck)
    assert runs.count(0) == 1  # the pre-shear snapshot
    assert sum(runs) == record["setup"]["total_steps"]
    record = render_case("angle_of_repose", CASE, tiny(), tmp_path / "aor")
    deck = (tmp_path / "aor" / "in.angle_of_repose").read_text()
    assert sum(run_lengths(deck)) == record["setup"]["total_steps"]


def test_shear_deck_numbers_match_the_setup(tmp_path: Path) -> None:
    record = render_case("shear_cell", CASE, tiny(), tmp_path)
    s = record["setup"]
    deck = (tmp_path / "in.shear_cell").read_text()
    assert f"timestep {format_number(s['timestep'])}\n" in deck
    assert f"target_val {format_number(-s['preshear_force'])} " in deck
    assert f"particles_in_region {s['n_particles']} " in deck
    # Four cycles of the return mode: a pre-shear, unload and shear each, and three returns.
    assert deck.count("variable phase equal 1\n") == 4
    assert deck.count("variable phase equal 3\n") == 4
    assert deck.count("fix shear all move/mesh mesh lower linear") == 4 * 2 + 3
    assert deck.count("fix shearfl all move/mesh mesh lflange linear") == 4 * 2 + 3
    assert s["preshear_force"] == pytest.approx(2029.0 * math.pi * s["radius"] ** 2)


def test_case_with_load_condition_runs_one_cycle(tmp_path: Path) -> None:
    record = render_case("shear_cell", {**CASE, "P": 0.6}, tiny(), tmp_path)
    assert [c["P"] for c in record["setup"]["cycles"]] == [0.6]
    deck = (tmp_path / "in.shear_cell").read_text()
    assert deck.count("variable phase equal 1\n") == 1
    assert "# P = 0.6" in deck


def test_young_modulus_follows_the_stress_in_tiny(tmp_path: Path) -> None:
    record = render_case("shear_cell", {**CASE, "normal_stress": 1500.0}, tiny(), tmp_path)
    assert record["material"]["youngsModulus"] == pytest.approx(1.5e6)
    deck = (tmp_path / "in.shear_cell").read_text()
    assert "soft_particles yes\n" in deck
    assert "youngsModulus peratomtype 1500000.0 1500000.0\n" in deck


def test_switches_rolling_friction_cohesion_and_wall_friction(tmp_path: Path) -> None:
    cfg = tiny()
    render_case("angle_of_repose", CASE, cfg, tmp_path / "plain")
    plain = (tmp_path / "plain" / "in.angle_of_repose").read_text()
    assert "pair_style gran model hertz tangential history rolling_friction epsd2\n" in plain
    assert "cohesion" not in plain
    assert "coefficientFriction peratomtypepair 2 0.5 0.5 0.5 0.5\n" in plain

    cfg["material"]["rolling_friction"] = False
    case = {**CASE, "cohesionEnergyDensity": 2.5e4, "wallFriction": 0.25}
    render_case("angle_of_repose", case, cfg, tmp_path / "sticky")
    sticky = (tmp_path / "sticky" / "in.angle_of_repose").read_text()
    commands = "\n".join(x for x in sticky.splitlines() if not x.startswith("#"))
    assert "pair_style gran model hertz tangential history cohesion sjkr\n" in sticky
    assert "rolling_friction" not in commands and "coefficientRollingFriction" not in commands
    assert "cohesionEnergyDensity peratomtypepair 2 25000.0 25000.0 25000.0 25000.0\n" in sticky
    assert "coefficientFriction peratomtypepair 2 0.5 0.25 0.25 0.25\n" in sticky
    assert sticky.count("wall/gran model hertz tangential history cohesion sjkr mesh") == 1


def test_size_distribution_switch(tmp_path: Path) -> None:
    cfg = tiny()
    render_case("angle_of_repose", CASE, cfg, tmp_path / "mono")
    mono = (tmp_path / "mono" / "in.angle_of_repose").read_text()
    assert mono.count("particletemplate/sphere") == 1
    assert "particledistribution/discrete" in mono and " 1 pts1 1.0\n" in mono
    cfg["particles"] = {"distribution": "sinter_fines", "scale": 1.0, "classes": 6}
    cfg["angle_of_repose"]["dCylDp"] = 8
    record = render_case("angle_of_repose", CASE, cfg, tmp_path / "fines")
    fines = (tmp_path / "fines" / "in.angle_of_repose").read_text()
    assert fines.count("particletemplate/sphere") == 6
    assert "radius constant 0.001\n" in fines and "radius constant 0.000315\n" in fines
    line = next(x for x in fines.splitlines() if "particledistribution/discrete" in x)
    weights = [float(w) for w in line.split()[7::2]]
    assert sum(weights) == pytest.approx(1.0)
    assert weights[0] == pytest.approx(0.4539)
    assert record["particles"]["max_radius"] == pytest.approx(1e-3)


def test_meshes_have_the_cell_geometry(tmp_path: Path) -> None:
    record = render_case("shear_cell", CASE, tiny(), tmp_path)
    s = record["setup"]
    n = s["n_segments"]
    lid = read_stl(tmp_path / "meshes" / "shear_lid.stl").triangles
    polygon = 0.5 * n * s["radius"] ** 2 * math.sin(2 * math.pi / n)
    assert surface_area(lid) == pytest.approx(polygon, rel=1e-9)
    lower = read_stl(tmp_path / "meshes" / "shear_lower.stl").triangles
    assert lower[..., 2].max() == pytest.approx(s["z_shear"])
    assert np.hypot(lower[..., 0], lower[..., 1]).max() == pytest.approx(s["radius"])
    upper = read_stl(tmp_path / "meshes" / "shear_upper.stl").triangles
    assert upper[..., 2].min() == pytest.approx(s["z_shear"])
    assert upper[..., 2].max() == pytest.approx(s["wall_top"])
    assert np.hypot(upper[..., 0], upper[..., 1]).max() == pytest.approx(s["radius"])
    # The flanges are meshes of their own, flat at the shear plane, from R to R + flange width.
    for name in ("shear_lower_flange.stl", "shear_upper_flange.stl"):
        flange = read_stl(tmp_path / "meshes" / name).triangles
        assert np.ptp(flange[..., 2]) == 0.0
        assert flange[..., 2].max() == pytest.approx(s["z_shear"])
        reach = np.hypot(flange[..., 0], flange[..., 1])
        assert reach.min() == pytest.approx(s["radius"])
        assert reach.max() == pytest.approx(s["radius"] + s["flange_width"])


def test_case_json_holds_the_readout_inputs(tmp_path: Path) -> None:
    render_case("shear_cell", CASE, tiny(), tmp_path)
    record = json.loads((tmp_path / "case.json").read_text())
    readout, cell = record["readout"], tiny()["shear_cell"]
    # Cell radius R = dCylDp * r_particle = 10 * 1.5 mm; shear plane at 0.5 * 1.5 R.
    radius = cell["dCylDp"] * tiny()["particles"]["radius"]
    assert radius == pytest.approx(0.015)
    assert readout["radius"] == pytest.approx(radius, rel=1e-12)
    assert readout["z_shear"] == pytest.approx(
        cell["shear_plane"] * cell["fill_height"] * radius, rel=1e-12
    )
    assert (readout["z_floor"], readout["gravity"]) == (0.0, 9.81)
    assert readout["min_fraction"] == cell["plateau_min_fraction"]
    # The stress the readout divides by is that of the lid the engine moves: its corners lie
    # on the readout radius, and the lower ring ends at the readout's shear plane.
    lid = read_stl(tmp_path / "meshes" / "shear_lid.stl").triangles
    assert np.hypot(lid[..., 0], lid[..., 1]).max() == pytest.approx(readout["radius"])
    lower = read_stl(tmp_path / "meshes" / "shear_lower.stl").triangles
    assert lower[..., 2].max() == pytest.approx(readout["z_shear"])
    assert record["case"]["case_id"] == "c0007"
    assert record["files"]["table"] == "shear_cell.txt"


# ---------------------------------------------------------------------------------------------
# invalid cases are rejected before anything is written


INVALID = [
    ({"coefficientFriction": -0.1}, "coefficientFriction"),
    ({"coefficientRestitution": 1.2}, "coefficientRestitution"),
    ({"coefficientRestitution": 0.05}, "coefficientRestitution"),
    ({"dCylDp": 4.0}, "dCylDp"),
    ({"wallFriction": -0.2}, "wallFriction"),
]


@pytest.mark.parametrize(
    ("test", "change", "field"),
    [
        *(("shear_cell", c, f) for c, f in INVALID),
        *(("angle_of_repose", c, f) for c, f in INVALID),
        ("shear_cell", {"P": 1.5}, "P"),
        ("shear_cell", {"normal_stress": -5.0}, "normal_stress"),
    ],
)
def test_invalid_case_is_rejected_before_writing(
    tmp_path: Path, test: str, change: dict, field: str
) -> None:
    out = tmp_path / "case"
    with pytest.raises(CaseValidationError) as err:
        render_case(test, {**CASE, **change}, tiny(), out)
    assert "case c0007" in str(err.value) and field in str(err.value)
    assert not out.exists()


def test_missing_normal_stress_is_named(tmp_path: Path) -> None:
    case = {k: v for k, v in CASE.items() if k != "normal_stress"}
    with pytest.raises(MissingColumnError, match="normal_stress"):
        render_case("shear_cell", case, tiny(), tmp_path / "x")
    assert not (tmp_path / "x").exists()


def test_too_soft_particles_need_soft_particles(tmp_path: Path) -> None:
    cfg = tiny()
    cfg["material"]["soft_particles"] = False
    with pytest.raises(CaseValidationError, match="youngsModulus"):
        render_case("angle_of_repose", CASE, cfg, tmp_path / "x")
    assert not (tmp_path / "x").exists()


def test_unknown_test_is_rejected(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="unknown test"):
        render_case("ring_shear", CASE, tiny(), tmp_path)


# ---------------------------------------------------------------------------------------------
# configuration profiles


@pytest.mark.parametrize("name", ["tiny.yaml", "config.yaml", "paper.yaml"])
def test_profiles_are_valid_and_render(tmp_path: Path, name: str) -> None:
    cfg = load_config(ROOT / "config" / name)
    dCylDp = max(cfg["shear_cell"]["min_dCylDp"], cfg["shear_cell"]["dCylDp"])
    case = {**CASE, "dCylDp": dCylDp, "normal_stress": cfg["shear_cell"]["normal_stresses"][0]}
    record = render_case("shear_cell", {**case, "P": cfg["shear_cell"]["P"][0]}, cfg, tmp_path)
    # The case follows the profile: its size classes, R = dCylDp * r_ref, and the time step
    # given, or else the Rayleigh fraction of the smallest particle's Rayleigh time.
    particles, setup = record["particles"], record["setup"]
    classes = 1 if cfg["particles"]["distribution"] == "monodisperse" else None
    assert len(particles["radii"]) == (classes or cfg["particles"]["classes"])
    assert setup["radius"] == pytest.approx(dCylDp * particles["mass_mean_radius"], rel=1e-12)
    fixed, fraction = cfg["material"]["timestep"], cfg["material"]["rayleigh_fraction"]
    rayleigh = fraction * record["material"]["rayleigh_time"]
    if fixed > 0:
        assert setup["timestep"] == fixed < rayleigh
    else:
        assert 0.99 * rayleigh < setup["timestep"] <= rayleigh
    deck = (tmp_path / "in.shear_cell").read_text()
    assert f"timestep {format_number(setup['timestep'])}\n" in deck


def test_paper_profile_has_table_1_values() -> None:
    cfg = load_config(ROOT / "config" / "paper.yaml")
    assert cfg["material"]["youngsModulus"] == 1.0e7
    assert cfg["material"]["poissonsRatio"] == 0.4
    assert cfg["material"]["timestep"] == 1.0e-6
    assert cfg["particles"]["distribution"] == "sinter_fines"
    assert cfg["design"]["levels"]["dCylDp"] == [20.0, 36.0, 38.0, 40.0]
    assert cfg["shear_cell"]["shear_speed"] == 3.0
    assert cfg["angle_of_repose"]["lift_time"] == 20.0
    assert cfg["angle_of_repose"]["lift_height"] == 1.2


# ---------------------------------------------------------------------------------------------
# bulk values of a rendered case from synthetic outputs with a known truth


def write_shear_table(
    directory: Path, mu_psh: float | list[float], mu_sh: float, rho_b: float
) -> None:
    """Print file of a steady run: mu = mu_psh in pre-shear (a value per cycle when a list)
    and mu_sh in shear."""
    record = json.loads((directory / "case.json").read_text())
    s = record["setup"]
    area = math.pi * s["radius"] ** 2
    lid_z = 1.4 * s["fill_height"]
    rows = [
        "# step time phase cycle lid_z lid_force shear_force travel mass target_force "
        "upper_force_z lower_flange_force_z"
    ]
    for seg in s["segments"]:
        start = seg["start_step"] - seg["start_step"] % s["print_every"] + s["print_every"]
        for step in range(start, seg["start_step"] + seg["steps"] + 1, s["print_every"]):
            travel = seg["offset_start"] + (step - seg["start_step"]) * seg["travel_per_step"]
            lid = seg["target_force"]
            weight = rho_b * 9.81 * area * (lid_z - s["z_shear"])
            psh = mu_psh[seg["cycle"]] if isinstance(mu_psh, list) else mu_psh
            mu = {1: psh, 3: mu_sh}.get(seg["phase"], 0.0)
            upper_z, flange_z = 0.3 * lid, -0.02 * lid
            shear = mu * (lid + weight + upper_z + flange_z)
            rows.append(
                f"{step} {step * s['timestep']!r} {seg['phase']} {seg['cycle']} {lid_z!r} "
                f"{lid!r} {shear!r} {travel!r} {rho_b * area * lid_z!r} {lid!r} "
                f"{upper_z!r} {flange_z!r}"
            )
    (directory / "shear_cell.txt").write_text("\n".join(rows) + "\n")


def test_extract_shear_cell_recovers_known_values(tmp_path: Path) -> None:
    render_case("shear_cell", {**CASE, "P": 0.8}, tiny(), tmp_path)
    write_shear_table(tmp_path, mu_psh=0.62, mu_sh=0.55, rho_b=1450.0)
    table = extract("shear_cell", tmp_path)
    assert len(table) == 1
    row = table.iloc[0]
    assert row["case_id"] == "c0007" and row["test"] == "shear_cell"
    assert (row["normal_stress"], row["P"]) == (2029.0, 0.8)
    assert row["mu_psh"] == pytest.approx(0.62, rel=1e-9)
    assert row["mu_sh"] == pytest.approx(0.55, rel=1e-9)
    assert row["rho_b"] == pytest.approx(1450.0, rel=1e-9)
    assert bool(row["steady_psh"]) and bool(row["steady_sh"])


def test_extract_shear_cell_cycles_in_one_deck(tmp_path: Path) -> None:
    render_case("shear_cell", CASE, tiny(), tmp_path)
    # Four pre-shears at one stress read 0.66-0.74: the deck's pre-shear point is their mean.
    write_shear_table(tmp_path, mu_psh=[0.66, 0.70, 0.74, 0.72], mu_sh=0.6, rho_b=1500.0)
    table = extract("shear_cell", tmp_path)
    assert table["P"].tolist() == [0.4, 0.6, 0.8, 1.0]
    assert table["mu_sh"].to_numpy() == pytest.approx([0.6] * 4, rel=1e-9)
    assert table["mu_psh_cycle"].to_numpy() == pytest.approx([0.66, 0.70, 0.74, 0.72], rel=1e-9)
    assert table["mu_psh"].to_numpy() == pytest.approx([0.705] * 4, rel=1e-9)
    assert table["rho_b"].to_numpy() == pytest.approx([1500.0] * 4, rel=1e-9)


def test_extract_names_a_missing_or_truncated_output(tmp_path: Path) -> None:
    render_case("shear_cell", {**CASE, "P": 0.8}, tiny(), tmp_path)
    with pytest.raises(MissingOutputError, match=r"shear_cell\.txt"):
        extract("shear_cell", tmp_path)
    write_shear_table(tmp_path, 0.6, 0.5, 1400.0)
    path = tmp_path / "shear_cell.txt"
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(lines[: len(lines) // 2]))
    with pytest.raises(MissingOutputError, match=r"shear_cell\.txt.*truncated"):
        extract("shear_cell", tmp_path)
    with pytest.raises(MissingOutputError, match=r"case\.json"):
        extract("shear_cell", tmp_path / "nowhere")
    with pytest.raises(ValueError, match="not 'angle_of_repose'"):
        extract("angle_of_repose", tmp_path)


def write_cone(directory: Path, angle_deg: float) -> None:
    """Dump of a lattice-packed cone of the given slope on the plate, and a print table."""
    record = json.loads((directory / "case.json").read_text())
    s = record["setup"]
    r = record["particles"]["max_radius"]
    height = 20 * r
    base = height / math.tan(math.radians(angle_deg))
    g = np.arange(-base, base + r, 2 * r)
    x, y, z = np.meshgrid(g, g, np.arange(r, height, 2 * r), indexing="ij")
    rho = np.hypot(x, y)
    keep = rho <= (height - z) / math.tan(math.radians(angle_deg))
    x, y, z = x[keep], y[keep], z[keep]
    lines = [
        "ITEM: TIMESTEP",
        str(s["total_steps"]),
        "ITEM: NUMBER OF ATOMS",
        str(x.size),
        "ITEM: BOX BOUNDS ff ff ff",
        *(f"{lo!r} {hi!r}" for lo, hi in zip(s["box_lo"], s["box_hi"], strict=True)),
        "ITEM: ATOMS id type x y z vx vy vz radius c_cn",
    ]
    for k in range(x.size):
        lines.append(f"{k + 1} 1 {float(x[k])!r} {float(y[k])!r} {float(z[k])!r} 0 0 0 {r!r} 6")
    (directory / "heap.dump").write_text("\n".join(lines) + "\n")
    every = s["print_every"]
    steps = range(every, s["total_steps"] + 1, every)
    table = ["# step time stage atoms ke", *(f"{n} {n * 1e-5!r} 2 {x.size} 1e-12" for n in steps)]
    (directory / "repose.txt").write_text("\n".join(table) + "\n")


def test_extract_repose_recovers_a_cone_angle(tmp_path: Path) -> None:
    render_case("angle_of_repose", CASE, tiny(), tmp_path)
    write_cone(tmp_path, 35.0)
    table = extract("angle_of_repose", tmp_path)
    row = table.iloc[0]
    assert row["test"] == "repose" and row["case_id"] == "c0007"
    assert row["aor"] == pytest.approx(35.0, abs=2.0)
    sectors = [c for c in table.columns if c.startswith("aor_sector_") and c[-1].isdigit()]
    assert len(sectors) == tiny()["angle_of_repose"]["n_sectors"]
    assert bool(row["settled"])
    (tmp_path / "heap.dump").unlink()
    with pytest.raises(MissingOutputError, match=r"heap\.dump"):
        extract("angle_of_repose", tmp_path)


def test_validate_config_defaults_cover_the_new_sections() -> None:
    cfg = validate_config({}, "empty")
    assert cfg["shear_cell"]["normal_stresses"] == [1068.0, 2029.0, 10070.0]
    assert cfg["shear_cell"]["P"] == [0.4, 0.6, 0.8, 1.0]
    assert cfg["material"]["youngsModulus"] == 1.0e7
    assert cfg["angle_of_repose"]["lift_height"] == 1.2


def ring() -> dict:
    """The tiny configuration with the quick profile's ring shear cell (6 particle diameters
    wide)."""
    return with_quick_ring(ROOT / "config" / "tiny.yaml")


def test_ring_deck_turns_the_lower_part_and_reads_the_torque(tmp_path: Path) -> None:
    record = render_case("shear_cell", {**CASE, "P": 0.6}, ring(), tmp_path)
    s = record["setup"]
    deck = (tmp_path / "in.shear_cell").read_text()
    assert f"target_val {format_number(-s['preshear_force'])} " in deck
    # Core emptied after the one insertion step, before the inner bands join the walls.
    core = deck.index(f"region core cylinder z 0.0 0.0 {format_number(s['core_radius'])} ")
    assert deck.index("run 1\n") < core < deck.index("meshes lower lowerin upper upperin\n")
    # Pre-shear and shear turn floor and lower bands about z; the held parts carry the torque.
    turns = re.findall(
        r"fix turn all move/mesh mesh lower rotate .* axis 0.0 0.0 (\S+) period (\S+)", deck
    )
    assert len(turns) == 2 == deck.count("fix turnin all move/mesh mesh lowerin rotate")
    for sign, period in turns:
        assert float(sign) == -1.0
        assert float(period) == pytest.approx(2 * math.pi * s["mean_radius"] / s["shear_speed"])
    assert "variable torque equal f_lid[6]+f_upper[6]+f_upperin[6]\n" in deck
    assert record["readout"]["inner_radius"] == pytest.approx(s["radius"] / 2)


def test_ring_meshes_have_the_cell_geometry(tmp_path: Path) -> None:
    record = render_case("shear_cell", CASE, ring(), tmp_path)
    s = record["setup"]
    n, bars = s["n_segments"], s["n_bars"]
    ring_area = 0.5 * n * (s["radius"] ** 2 - s["inner_radius"] ** 2) * math.sin(2 * math.pi / n)
    lid = read_stl(tmp_path / "meshes" / "ring_lid.stl").triangles
    # Annulus plus one radial plate (two triangles) per bar, hanging below the lid plane.
    assert len(lid) == 2 * n + 2 * bars
    plates = (s["radius"] - s["inner_radius"]) * s["bar_height"] * bars
    assert surface_area(lid) == pytest.approx(ring_area + plates, rel=1e-9)
    assert lid[..., 2].min() == pytest.approx(-s["bar_height"]) and lid[..., 2].max() == 0.0
    lower = read_stl(tmp_path / "meshes" / "ring_lower.stl").triangles
    assert lower[..., 2].max() == pytest.approx(s["z_shear"])
    reach = np.hypot(lower[..., 0], lower[..., 1])
    assert reach.min() == pytest.approx(s["inner_radius"]) and reach.max() == pytest.approx(
        s["radius"]
    )
    for name, r in (("ring_lower_inner.stl", s["inner_radius"]), ("ring_upper.stl", s["radius"])):
        band = read_stl(tmp_path / "meshes" / name).triangles
        assert np.hypot(band[..., 0], band[..., 1]).max() == pytest.approx(r)
    upper_in = read_stl(tmp_path / "meshes" / "ring_upper_inner.stl").triangles
    assert upper_in[..., 2].min() == pytest.approx(s["z_shear"])
    assert upper_in[..., 2].max() == pytest.approx(s["wall_top"])


# ---------------------------------------------------------------------------------------------
# run cost for scheduling (workflow/rules/common.smk: run_priority)


def test_particle_steps_are_the_rendered_decks_and_rank_runs_by_cost(tmp_path: Path) -> None:
    # The cost is the rendered deck's: particles inserted times the steps of its runs.
    record = render_case("angle_of_repose", CASE, tiny(), tmp_path / "heap")
    heap = particle_steps("angle_of_repose", CASE, tiny())
    assert heap == record["setup"]["n_particles"] * sum(
        run_lengths((tmp_path / "heap" / "in.angle_of_repose").read_text())
    )
    # Tiny profile: a heap is about 4 shear runs (14 s against 3.5 s measured side by side,
    # docs/benchmarks.md), so heaps start first.
    shear = particle_steps("shear_cell", {**CASE, "P": 1.0}, tiny())
    assert 3.0 < heap / shear < 6.0
    # Quick profile: the ring decks take longer the higher the stress (stiffer particles,
    # smaller time step: 84 / 132 / 263 s of CPU, 2026-12-07). The heap of dCylDp 14 has more
    # particle-steps than any (cheaper ones, 141 s), so the heaps start first, then the decks
    # from the highest stress down, and the shortest decks end the design.
    quick = load_config(ROOT / "config" / "config.yaml")
    rings = [
        particle_steps("shear_cell", {**CASE, "normal_stress": s, "P": 1.0}, quick)
        for s in quick["shear_cell"]["normal_stresses"]
    ]
    assert rings == sorted(rings)
    assert particle_steps("angle_of_repose", CASE, quick) > rings[-1]
