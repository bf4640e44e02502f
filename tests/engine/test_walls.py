"""Walls and meshes on the real engine: fix wall/gran (primitive and mesh), fix mesh/surface,
mesh/surface/stress, mesh/surface/stress/servo and move/mesh.

Each case compares a number the engine writes with a closed-form value: the Hertz static
overlap of a resting sphere, the restitution of a wall impact, the weight and torque a resting
sphere puts on a stress mesh, the servo target force, and the 2/7 speed ratio of a sphere
dragged by a moving plate until it rolls.
"""

import math
from pathlib import Path

import numpy as np
import pytest

from .conftest import header, material_block, run_engine

pytestmark = pytest.mark.engine

G = 9.81
YOUNGS, POISSON = 1e7, 0.3
MODEL = "model hertz tangential history"


def write_stl(path: Path, triangles: list[tuple[tuple[float, float, float], ...]]) -> None:
    """ASCII STL of the given triangles (three (x, y, z) vertices each, m)."""
    lines = ["solid test"]
    for tri in triangles:
        lines += ["facet normal 0 0 0", "outer loop"]
        lines += [f"vertex {x!r} {y!r} {z!r}" for x, y, z in tri]
        lines += ["endloop", "endfacet"]
    lines.append("endsolid test")
    path.write_text("\n".join(lines) + "\n")


def square_plate(half: float) -> list[tuple[tuple[float, float, float], ...]]:
    """Two triangles covering [-half, half]^2 at z = 0, sharing the diagonal."""
    p0, p1, p2, p3 = (-half, -half, 0.0), (half, -half, 0.0), (half, half, 0.0), (-half, half, 0.0)
    return [(p0, p1, p2), (p0, p2, p3)]


def cylinder(radius: float, z0: float, z1: float, segments: int):
    """Side of a cylinder about the z axis, two triangles per segment."""
    tris = []
    for k in range(segments):
        a0, a1 = 2 * math.pi * k / segments, 2 * math.pi * (k + 1) / segments
        b0 = (radius * math.cos(a0), radius * math.sin(a0), z0)
        b1 = (radius * math.cos(a1), radius * math.sin(a1), z0)
        t0, t1 = (b0[0], b0[1], z1), (b1[0], b1[1], z1)
        tris += [(b0, b1, t1), (b0, t1, t0)]
    return tris


def sphere_mass(radius: float, density: float) -> float:
    return 4.0 / 3.0 * math.pi * radius**3 * density


def wall_y_star() -> float:
    """Effective modulus of a sphere on a wall of the same material (PHYSICS.md section 3)."""
    return YOUNGS / (2.0 * (1.0 - POISSON**2))


def hertz_static_overlap(force: float, radius: float) -> float:
    """Overlap at which the Hertz wall force 4/3 Y* sqrt(R) d^1.5 carries `force` (m)."""
    return (3.0 * force / (4.0 * wall_y_star() * math.sqrt(radius))) ** (2.0 / 3.0)


def preamble(
    restitution: float = 0.5, friction: float = 0.5, half_width: float = 0.05, dt: float = 1e-5
) -> str:
    return (
        header(half_width=half_width)
        + material_block(YOUNGS, POISSON, restitution, friction)
        + f"pair_style gran {MODEL}\npair_coeff * *\ntimestep {dt!r}\n"
    )


# --- resting on a plane --------------------------------------------------------------------


@pytest.mark.parametrize("wall", ["primitive", "mesh"])
@pytest.mark.parametrize("side", [1, -1], ids=["above", "below"])
def test_sphere_rests_on_plane_at_hertz_static_overlap(tmp_path, wall, side):
    r, rho, plane = 0.005, 2500.0, 0.01
    # On the mesh, right above the edge that the plate's two triangles share: one contact.
    x0, y0 = (0.003, 0.003) if wall == "mesh" else (0.003, -0.002)
    if wall == "primitive":
        wall_lines = f"fix wall all wall/gran {MODEL} primitive type 1 zplane {plane!r}\n"
    else:
        write_stl(tmp_path / "plate.stl", square_plate(0.02))
        wall_lines = (
            f"fix plate all mesh/surface file plate.stl type 1 move 0 0 {plane!r}\n"
            f"fix wall all wall/gran {MODEL} mesh n_meshes 1 meshes plate\n"
        )
    z0 = plane + side * (r + 2e-4)
    deck = (
        preamble()
        + f"fix gravi all gravity {G} vector 0 0 {-side}\n"
        + wall_lines
        + f"create_atoms 1 single {x0!r} {y0!r} {z0!r} units box\n"
        + f"set atom 1 diameter {2 * r!r} density {rho!r}\n"
        + "fix integr all nve/sphere\n"
        + "variable z equal xcm(all,z)\nvariable vz equal vcm(all,z)\n"
        + "thermo_style custom step v_z v_vz\nthermo 1000\nrun 20000\n"
    )
    t = run_engine(tmp_path, deck).thermo()[0]
    z, vz = t["v_z"].iloc[-1], t["v_vz"].iloc[-1]
    overlap = r - side * (z - plane)
    expected = hertz_static_overlap(sphere_mass(r, rho) * G, r)
    assert expected == pytest.approx(8.50e-6, rel=0.01)  # a visible overlap, 0.17 % of R
    assert overlap == pytest.approx(expected, rel=0.01)
    assert abs(vz) < 1e-6


# --- bouncing off a cylinder ---------------------------------------------------------------


@pytest.mark.parametrize(
    ("wall", "start", "neigh"),
    [
        ("primitive", "inside", ""),
        ("primitive", "outside", ""),
        ("mesh", "inside", ""),
        # Rebuilds 7 000 steps (4.2 mm of travel) apart: primitive walls must then check every
        # particle at every step instead of those near them at the last build.
        ("primitive", "outside", "neigh_modify delay 7000\n"),
    ],
)
def test_sphere_bounces_back_from_cylinder_wall(tmp_path, wall, start, neigh):
    r, rho, rc, e, speed = 0.002, 2500.0, 0.02, 0.8, 0.3
    cx, cy = 0.005, -0.003
    # Direction of travel: through the middle of a facet of the STL cylinder.
    angle = math.pi / 128 if wall == "mesh" else 0.0
    ux, uy = math.cos(angle), math.sin(angle)
    if wall == "primitive":
        wall_lines = (
            f"fix wall all wall/gran {MODEL} primitive type 1 zcylinder {rc!r} {cx!r} {cy!r}\n"
        )
    else:
        write_stl(tmp_path / "cyl.stl", cylinder(rc, -0.02, 0.02, 128))
        wall_lines = (
            f"fix cyl all mesh/surface file cyl.stl type 1 move {cx!r} {cy!r} 0\n"
            f"fix wall all wall/gran {MODEL} mesh n_meshes 1 meshes cyl\n"
        )
    if start == "inside":
        d0, v0 = 0.0, speed  # from the axis outwards
    else:
        d0, v0 = rc + 0.008, -speed  # from outside inwards
    x0, y0 = cx + d0 * ux, cy + d0 * uy
    deck = (
        preamble(restitution=e, friction=0.0, dt=2e-6)
        + neigh
        + wall_lines
        + f"create_atoms 1 single {x0!r} {y0!r} 0 units box\n"
        + f"set atom 1 diameter {2 * r!r} density {rho!r} vx {v0 * ux!r} vy {v0 * uy!r}\n"
        + "fix integr all nve/sphere\n"
        + f"variable ur equal (xcm(all,x)-{cx!r})*{ux!r}+(xcm(all,y)-{cy!r})*{uy!r}\n"
        + f"variable vr equal vcm(all,x)*{ux!r}+vcm(all,y)*{uy!r}\n"
        + "variable vz equal vcm(all,z)\n"
        + "thermo_style custom step v_ur v_vr v_vz\nthermo 100\nrun 40000\n"
    )
    t = run_engine(tmp_path, deck).thermo()[0]
    ur, vr = t["v_ur"].to_numpy(), t["v_vr"].to_numpy()
    # The particle came back: radial velocity reversed, scaled by the restitution.
    assert vr[-1] == pytest.approx(-e * v0, rel=0.02)
    # It never passed the wall: closest approach of the centre to the wall is about R.
    gap = (rc - ur.max()) if start == "inside" else (ur.min() - rc)
    assert r * 0.95 < gap < r
    assert abs(t["v_vz"].iloc[-1]) < 1e-9


# --- stress on a mesh ----------------------------------------------------------------------


def test_stress_mesh_reports_weight_and_torque_of_resting_spheres(tmp_path):
    r, rho, plane = 0.005, 2500.0, 0.01
    ref = (0.001, 0.002, 0.0)
    write_stl(tmp_path / "plate.stl", square_plate(0.02))
    z0 = plane + r + 1e-4
    deck = (
        preamble()
        + f"fix gravi all gravity {G} vector 0 0 -1\n"
        + f"create_atoms 1 single 0.004 -0.003 {z0!r} units box\n"
        + f"create_atoms 1 single -0.008 0.009 {z0!r} units box\n"
        + f"set group all diameter {2 * r!r} density {rho!r}\n"
        + "group counted id 1\n"
        + f"fix plate counted mesh/surface/stress file plate.stl type 1 move 0 0 {plane!r} "
        + "stress on reference_point {!r} {!r} {!r}\n".format(*ref)
        + f"fix wall all wall/gran {MODEL} mesh n_meshes 1 meshes plate\n"
        + "fix integr all nve/sphere\n"
        + "thermo_style custom step f_plate[1] f_plate[2] f_plate[3] f_plate[4] f_plate[5] "
        + "f_plate[6]\nthermo 1000\nrun 20000\n"
    )
    t = run_engine(tmp_path, deck).thermo()[0]
    last = t.iloc[-1]
    weight = sphere_mass(r, rho) * G  # only particle 1 is in the fix group
    assert last["f_plate[3]"] == pytest.approx(-weight, rel=0.01)
    assert abs(last["f_plate[1]"]) < 1e-4 * weight
    assert abs(last["f_plate[2]"]) < 1e-4 * weight
    # Torque about the reference point of -weight e_z applied at (0.004, -0.003, plane).
    arm = np.array([0.004, -0.003, plane]) - np.array(ref)
    torque = np.cross(arm, [0.0, 0.0, -weight])
    got = last[["f_plate[4]", "f_plate[5]", "f_plate[6]"]].to_numpy(dtype=float)
    np.testing.assert_allclose(got, torque, rtol=0.01, atol=1e-4 * weight * 0.01)


@pytest.mark.parametrize("threads", [1, 2])
def test_stress_mesh_sums_a_layer_of_resting_spheres(tmp_path, threads):
    # 4900 spheres (enough for the parallel loop) resting at the Hertz overlap on a plate.
    r, rho, n_side, spacing = 0.001, 2500.0, 70, 0.0025
    write_stl(tmp_path / "plate.stl", square_plate(0.1))
    z0 = r - hertz_static_overlap(sphere_mass(r, rho) * G, r)
    offset = -0.5 * spacing * (n_side - 1)
    coords = [offset + k * spacing for k in range(n_side)]
    atoms = "".join(
        f"create_atoms 1 single {x!r} {y!r} {z0!r} units box\n" for y in coords for x in coords
    )
    deck = (
        header(half_width=0.15)
        + material_block(YOUNGS, POISSON, 0.5, 0.5)
        + f"pair_style gran {MODEL}\npair_coeff * *\ntimestep 1e-5\n"
        + f"fix gravi all gravity {G} vector 0 0 -1\n"
        + "fix plate all mesh/surface/stress file plate.stl type 1\n"
        + f"fix wall all wall/gran {MODEL} mesh n_meshes 1 meshes plate\n"
        + atoms
        + f"set group all diameter {2 * r!r} density {rho!r}\n"
        + "fix integr all nve/sphere\n"
        + "thermo_style custom step f_plate[3] f_plate[4] f_plate[5]\nthermo 100\nrun 200\n"
    )
    last = run_engine(tmp_path, deck, threads=threads).thermo()[0].iloc[-1]
    weight = n_side**2 * sphere_mass(r, rho) * G
    assert last["f_plate[3]"] == pytest.approx(-weight, rel=1e-3)
    # The layer is centred on the reference point (the origin): no net torque.
    assert abs(last["f_plate[4]"]) < 1e-9 * weight
    assert abs(last["f_plate[5]"]) < 1e-9 * weight


# --- servo lid -----------------------------------------------------------------------------


def bed_deck(width: float, spacing: float, radius: float) -> str:
    """64 spheres on a 4 x 4 x 4 lattice with small offsets, in a box of primitive walls."""
    lines = []
    for k in range(4):
        for j in range(4):
            for i in range(4):
                dx = 3e-4 * ((i + j + k) % 3 - 1)
                dy = 3e-4 * ((i + 2 * j + k) % 3 - 1)
                x, y, z = (
                    spacing * (i + 0.5) + dx,
                    spacing * (j + 0.5) + dy,
                    spacing * (k + 0.5) * 1.05,
                )
                lines.append(f"create_atoms 1 single {x!r} {y!r} {z!r} units box")
    walls = [
        ("wx0", "xplane", 0.0),
        ("wx1", "xplane", width),
        ("wy0", "yplane", 0.0),
        ("wy1", "yplane", width),
        ("wz0", "zplane", 0.0),
    ]
    for name, kind, pos in walls:
        lines.append(f"fix {name} all wall/gran {MODEL} primitive type 1 {kind} {pos!r}")
    lines.append(f"set group all diameter {2 * radius!r} density 2500")
    return "\n".join(lines) + "\n"


def test_servo_lid_reaches_and_holds_target_force(tmp_path):
    width, spacing, radius = 0.0176, 0.0044, 0.002
    margin = 0.001
    write_stl(tmp_path / "lid.stl", square_plate(0.5 * width + margin))
    c = 0.5 * width
    deck = (
        preamble(restitution=0.3, half_width=0.05)
        + "neighbor 0.0005 bin\n"
        + f"fix gravi all gravity {G} vector 0 0 -1\n"
        + bed_deck(width, spacing, radius)
        + "fix integr all nve/sphere\n"
        + "variable ztop equal bound(all,zmax)\n"
        + "run 10000\n"
        + f"variable zlid equal v_ztop+{radius + 5e-4!r}\n"
        + f"fix lid all mesh/surface/stress/servo file lid.stl type 1 move {c!r} {c!r} ${{zlid}} "
        + f"com {c!r} {c!r} ${{zlid}} ctrlPV force axis 0 0 1 target_val -0.5 vel_max 0.05 kp 1\n"
        + f"fix wlid all wall/gran {MODEL} mesh n_meshes 1 meshes lid\n"
        + "thermo_style custom step f_lid[3] f_lid[7] f_lid[8] f_lid[9]\nthermo 200\n"
        + "run 20000\n"
        + "variable target equal -2*0.5\n"
        + "fix_modify lid target_val v_target\n"
        + "run 20000\n"
        + "fix_modify lid integrate stop\n"
        + "run 2000\n"
    )
    runs = run_engine(tmp_path, deck).thermo()
    weight_of_bed = 64 * sphere_mass(radius, 2500.0) * G
    assert weight_of_bed < 0.1  # the lid force, not the weight, dominates
    for run, target in ((runs[1], 0.5), (runs[2], 1.0)):
        tail = run["f_lid[3]"].to_numpy()[int(0.6 * len(run)) :]
        assert np.all(np.abs(tail / target - 1.0) < 0.02), (target, tail.min(), tail.max())
        # Only the z position of the servo moves.
        assert run["f_lid[7]"].to_numpy() == pytest.approx(c, abs=1e-12)
        assert run["f_lid[8]"].to_numpy() == pytest.approx(c, abs=1e-12)
    # A larger force compresses the bed further; with integration stopped the lid stays.
    assert runs[2]["f_lid[9]"].iloc[-1] < runs[1]["f_lid[9]"].iloc[-1]
    stopped = runs[3]["f_lid[9]"].to_numpy()
    assert np.ptp(stopped) == 0.0


# --- moving plate --------------------------------------------------------------------------


@pytest.mark.parametrize("speeds", [(0.1,), (0.06, 0.04)], ids=["one", "superposed"])
def test_moving_plate_drags_sphere_until_it_rolls(tmp_path, speeds):
    r, rho, mu = 0.005, 2500.0, 0.5
    write_stl(tmp_path / "plate.stl", square_plate(0.03))
    z0 = r - hertz_static_overlap(sphere_mass(r, rho) * G, r)
    moves = "".join(
        f"fix mv{k} all move/mesh mesh plate linear {v!r} 0 0\n" for k, v in enumerate(speeds)
    )
    deck = (
        preamble(friction=mu)
        + f"fix gravi all gravity {G} vector 0 0 -1\n"
        + "fix plate all mesh/surface file plate.stl type 1\n"
        + f"fix wall all wall/gran {MODEL} mesh n_meshes 1 meshes plate\n"
        + f"create_atoms 1 single 0.004 0.002 {z0!r} units box\n"
        + f"set atom 1 diameter {2 * r!r} density {rho!r}\n"
        + "fix integr all nve/sphere\n"
        + "variable vx equal vcm(all,x)\nvariable vy equal vcm(all,y)\n"
        + "thermo_style custom step v_vx v_vy\nthermo 500\n"
        + "run 2000\n"
        + moves
        + "run 10000\n"
    )
    runs = run_engine(tmp_path, deck).thermo()
    assert abs(runs[0]["v_vx"].iloc[-1]) < 1e-6  # at rest before the plate moves
    v_plate = sum(speeds)
    # Friction accelerates the sphere until it rolls without slip on the plate: by angular
    # momentum about the contact point (in the plate frame), at 2/7 of the plate speed.
    vx = runs[1]["v_vx"].to_numpy()
    assert vx[-1] == pytest.approx(2.0 / 7.0 * v_plate, rel=0.02)
    assert vx.max() < 0.3 * v_plate  # no overshoot beyond the rolling speed
    assert abs(runs[1]["v_vy"].iloc[-1]) < 1e-3 * v_plate


# --- errors --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("line", "reason"),
    [
        (
            f"fix w all wall/gran {MODEL} rolling_friction epsd2 primitive type 1 zplane 0",
            "differs from the pair style",
        ),
        (f"fix w all wall/gran {MODEL} primitive type 2 zplane 0", "wall type 2"),
        (f"fix w all wall/gran {MODEL} mesh n_meshes 1 meshes nope", "unknown mesh fix 'nope'"),
        ("fix m all mesh/surface file bad.stl type 1", "bad.stl' line 4"),
        (
            "fix m all mesh/surface file plate.stl type 1 scale 2 type 1",
            "wrong keyword order: type",
        ),
        (
            "fix m all mesh/surface/stress/servo file plate.stl type 1 com 0 0 0 ctrlPV force "
            "axis 0 0 1 target_val 0 vel_max 0.1",
            "target_val",
        ),
        ("fix mv all move/mesh mesh gravi linear 1 0 0", "not a fix mesh/surface"),
    ],
)
def test_bad_wall_commands_are_errors_with_deck_line(tmp_path, line, reason):
    write_stl(tmp_path / "plate.stl", square_plate(0.01))
    (tmp_path / "bad.stl").write_text(
        "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 zero\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid s\n"
    )
    deck = preamble() + f"fix gravi all gravity {G} vector 0 0 -1\n" + line + "\n"
    n_line = deck.count("\n")
    res = run_engine(tmp_path, deck, check=False)
    assert res.returncode != 0
    output = res.stdout + res.stderr
    assert f"ERROR: in.deck:{n_line}: fix" in output
    assert reason in output
