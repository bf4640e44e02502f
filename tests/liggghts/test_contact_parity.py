"""Contact-level parity of dem_engine with LIGGGHTS 3.8.

Each case is a small deterministic deck (one or two particles made by `create_atoms single`, no
insertion) that both programs run for the same steps. A `dump custom` of id, x, v, omega, f and
tq written every few steps is compared snapshot by snapshot: every value must agree to
REL_TOL relative to the LIGGGHTS value, where values smaller than FLOOR times the largest
magnitude of the same quantity (x, v, omega, f or tq) in that snapshot are compared against that
floor instead (so a force of 1e-20 N beside one of 1e-3 N must agree to 1e-12 N).

Every case also checks, on the LIGGGHTS output, that it reaches the regime it is named for
(sliding at the Coulomb cap, rolling torque at its cap, a contact that opens and closes, ...),
so that agreement is not reached trivially.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from .conftest import run_liggghts, unexpected_warnings

pytestmark = pytest.mark.liggghts

ROOT = Path(__file__).resolve().parents[2]
REL_TOL = 1e-6
FLOOR = 1e-3

FIELDS = "id x y z vx vy vz omegax omegay omegaz fx fy fz tqx tqy tqz".split()
QUANTITIES = {
    "x": ("x", "y", "z"),
    "v": ("vx", "vy", "vz"),
    "omega": ("omegax", "omegay", "omegaz"),
    "f": ("fx", "fy", "fz"),
    "tq": ("tqx", "tqy", "tqz"),
}

# Materials: type 1 particles, type 2 the second particle or the wall.
RADIUS = 1e-3
DENSITY = 2500.0
DT = 1e-6
YOUNGS = (1e7, 2e7)
POISSON = (0.3, 0.25)
RESTITUTION = ((0.5, 0.6), (0.6, 0.7))
FRICTION = ((0.4, 0.3), (0.3, 0.5))
ROLLING = ((0.1, 0.05), (0.05, 0.08))
COHESION = ((4e4, 3e4), (3e4, 5e4))

Snapshot = tuple[int, dict[int, dict[str, float]]]


# --- running both programs ---------------------------------------------------------------------


def engine_path() -> str:
    for candidate in (
        os.environ.get("DEM_ENGINE"),
        str(ROOT / ".venv" / "bin" / "dem_engine"),
        str(ROOT / "build" / "engine" / "dem_engine"),
        shutil.which("dem_engine"),
    ):
        if candidate and Path(candidate).is_file():
            return candidate
    raise RuntimeError("dem_engine not found: run `make engine`")


def read_dump(path: Path) -> list[Snapshot]:
    """All snapshots of a `dump custom` text file: (step, {id: {field: value}})."""
    lines = path.read_text().splitlines()
    snapshots = []
    k = 0
    while k < len(lines):
        if not lines[k].startswith("ITEM: TIMESTEP"):
            k += 1
            continue
        step, n = int(lines[k + 1]), int(lines[k + 3])
        names = lines[k + 8].split()[2:]
        rows = {}
        for line in lines[k + 9 : k + 9 + n]:
            row = dict(zip(names, map(float, line.split()), strict=True))
            rows[int(row["id"])] = row
        snapshots.append((step, rows))
        k += 9 + n
    return snapshots


def write_case(directory: Path, deck: str, files: dict[str, str]) -> None:
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "in.deck").write_text(deck)
    for name, text in files.items():
        (directory / name).write_text(text)


def run_reference(directory: Path, deck: str, files: dict[str, str]) -> tuple[bool, str]:
    """LIGGGHTS 3.8 on one rank: (success, output). A success prints no unexpected warning."""
    write_case(directory, deck, files)
    run = run_liggghts(directory, "in.deck")
    ok = run.returncode == 0 and "ERROR" not in run.output
    if ok:
        assert not unexpected_warnings(run.output), run.describe()
    return ok, run.describe()


def run_engine(directory: Path, deck: str, files: dict[str, str]) -> tuple[bool, str]:
    """dem_engine on one thread: (success, output)."""
    write_case(directory, deck, files)
    res = subprocess.run(
        [engine_path(), "-noprogress", "-in", "in.deck"],
        cwd=directory,
        capture_output=True,
        text=True,
        errors="replace",
        timeout=300,
        env=dict(os.environ, OMP_NUM_THREADS="1"),
    )
    ok = res.returncode == 0 and "ERROR" not in res.stdout + res.stderr
    return ok, f"dem_engine in {directory}: exit {res.returncode}\n{res.stdout[-2000:]}{res.stderr}"


def max_relative_difference(
    ours: list[Snapshot], reference: list[Snapshot], scales: dict[str, float] | None = None
) -> tuple[float, str]:
    """Largest difference over all snapshots, particles and fields (see the module doc).

    ``scales`` gives, per quantity, a magnitude that its floor is taken from when larger than
    the snapshot's own largest value (e.g. the contact forces of a particle at rest, whose net
    force is their residual).
    """
    scales = scales or {}
    assert [s for s, _ in ours] == [s for s, _ in reference], "different dump steps"
    worst, where = 0.0, "nothing differs"
    for (step, a), (_, b) in zip(ours, reference, strict=True):
        assert sorted(a) == sorted(b), f"step {step}: different particles"
        for quantity, columns in QUANTITIES.items():
            scale = max(abs(row[c]) for row in b.values() for c in columns)
            scale = max(scale, scales.get(quantity, 0.0))
            floor = FLOOR * scale
            for pid, row in b.items():
                for c in columns:
                    diff = abs(a[pid][c] - row[c])
                    if diff == 0.0:
                        continue
                    denominator = max(abs(row[c]), floor)
                    rel = diff / denominator if denominator > 0.0 else math.inf
                    if rel > worst:
                        worst = rel
                        where = (
                            f"step {step}, particle {pid}, {c}: engine {a[pid][c]!r}, "
                            f"LIGGGHTS {row[c]!r}"
                        )
    return worst, where


# --- decks -------------------------------------------------------------------------------------


def matrix(values: tuple[tuple[float, float], ...]) -> str:
    return " ".join(repr(v) for row in values for v in row)


def deck_header(cohesion: bool = False, extra: str = "", skin: float = 0.0005) -> str:
    text = f"""units si
atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
{extra}region box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box
create_box 2 box
neighbor {skin!r} bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype {YOUNGS[0]!r} {YOUNGS[1]!r}
fix m2 all property/global poissonsRatio peratomtype {POISSON[0]!r} {POISSON[1]!r}
fix m3 all property/global coefficientRestitution peratomtypepair 2 {matrix(RESTITUTION)}
fix m4 all property/global coefficientFriction peratomtypepair 2 {matrix(FRICTION)}
fix m5 all property/global coefficientRollingFriction peratomtypepair 2 {matrix(ROLLING)}
"""
    if cohesion:
        text += (
            "fix m6 all property/global cohesionEnergyDensity peratomtypepair 2 "
            f"{matrix(COHESION)}\n"
        )
    return text


def dump_and_run(every: int, runs: list[str]) -> str:
    fmt = '"%d' + " %.17g" * (len(FIELDS) - 1) + '"'
    return (
        "fix integr all nve/sphere\n"
        f"dump d all custom {every} dump.txt {' '.join(FIELDS)}\n"
        f"dump_modify d format {fmt} sort id\n" + "".join(f"{r}\n" for r in runs)
    )


def model(cohesion: bool = False, rolling: bool = True) -> str:
    text = "model hertz tangential history"
    if cohesion:
        text += " cohesion sjkr"
    if rolling:
        text += " rolling_friction epsd2"
    return text


def particle(pid: int, ptype: int, pos, diameter: float = 2 * RADIUS, **values: float) -> str:
    x, y, z = pos
    settings = " ".join(f"{k} {v!r}" for k, v in values.items())
    return (
        f"create_atoms {ptype} single {x!r} {y!r} {z!r} units box\n"
        f"set atom {pid} diameter {diameter!r} density {DENSITY!r} {settings}\n"
    )


def unit(v) -> tuple[float, float, float]:
    n = math.sqrt(sum(c * c for c in v))
    return (v[0] / n, v[1] / n, v[2] / n)


def gravity(g: float, direction) -> str:
    d = unit(direction)
    return f"fix grav all gravity {g!r} vector {d[0]!r} {d[1]!r} {d[2]!r}\n"


def stl(triangles) -> str:
    lines = ["solid parity"]
    for tri in triangles:
        lines += ["  facet normal 0 0 0", "    outer loop"]
        lines += [f"      vertex {x!r} {y!r} {z!r}" for x, y, z in tri]
        lines += ["    endloop", "  endfacet"]
    lines.append("endsolid parity")
    return "\n".join(lines) + "\n"


MM = 1e-3
PLATE = [
    ((-5 * MM, -5 * MM, 0.0), (5 * MM, -5 * MM, 0.0), (5 * MM, 5 * MM, 0.0)),
    ((-5 * MM, -5 * MM, 0.0), (5 * MM, 5 * MM, 0.0), (-5 * MM, 5 * MM, 0.0)),
]


def hinge(angle_deg: float, convex: bool):
    """Two rectangles (two triangles each) meeting along the y axis, each sloping by half of
    `angle_deg` (the angle between their normals): a ridge when convex, a valley otherwise."""
    w = 4 * MM
    tris = []
    for x0, x1 in ((-w, 0.0), (0.0, w)):
        a, b = (
            (x0, -0.5 * w, hinge_z(x0, angle_deg, convex)),
            (x1, -0.5 * w, hinge_z(x1, angle_deg, convex)),
        )
        c, d = (x1, 0.5 * w, b[2]), (x0, 0.5 * w, a[2])
        tris += [(a, b, c), (a, c, d)]
    return tris


def hinge_z(x: float, angle_deg: float, convex: bool) -> float:
    slope = math.tan(math.radians(0.5 * angle_deg))
    return (-slope if convex else slope) * abs(x)


# One triangle whose edge x = 0 (along y) faces +x, and one whose vertex at the origin points
# into the +x +y quadrant.
EDGE = [((0.0, -5 * MM, 0.0), (0.0, 5 * MM, 0.0), (-5 * MM, 0.0, 0.0))]
VERTEX = [((0.0, 0.0, 0.0), (-5 * MM, -1 * MM, 0.0), (-1 * MM, -5 * MM, 0.0))]


# --- what each case must reach (checked on the LIGGGHTS output) ---------------------------------


def mass(radius: float = RADIUS) -> float:
    return 4.0 / 3.0 * math.pi * radius**3 * DENSITY


def dot(a, b) -> float:
    return sum(x * y for x, y in zip(a, b, strict=True))


def pair_contact(rows, g_vec, r1=RADIUS, r2=RADIUS):
    """Normal, overlap, normal force and tangential force on particle 1 from particle 2."""
    p1, p2 = rows[1], rows[2]
    d = (p1["x"] - p2["x"], p1["y"] - p2["y"], p1["z"] - p2["z"])
    dist = math.sqrt(dot(d, d))
    n = tuple(c / dist for c in d)
    m = mass(r1)
    f = (p1["fx"] - m * g_vec[0], p1["fy"] - m * g_vec[1], p1["fz"] - m * g_vec[2])
    fn = dot(f, n)
    ft = tuple(f[k] - fn * n[k] for k in range(3))
    return n, r1 + r2 - dist, dist, fn, ft


def sjkr_area(dist: float, ri: float, rj: float) -> float:
    prod = (dist - ri - rj) * (dist + ri - rj) * (dist - ri + rj) * (dist + ri + rj)
    return math.pi / 4.0 * abs(prod) / dist**2


def count_snapshots(snapshots, predicate) -> int:
    return sum(1 for _, rows in snapshots if predicate(rows))


def contact_intervals(snapshots, touching) -> int:
    """Number of separate runs of snapshots in which `touching(rows)` holds."""
    runs, previous = 0, False
    for _, rows in snapshots:
        now = touching(rows)
        runs += now and not previous
        previous = now
    return runs


# --- cases -------------------------------------------------------------------------------------


@dataclass
class Case:
    deck: str
    files: dict[str, str] = field(default_factory=dict)
    check: Callable[[list[Snapshot]], None] | None = None
    scales: dict[str, float] = field(default_factory=dict)  # see max_relative_difference
    engine_warns: str = ""  # text the engine's output must contain


def loaded_pair(
    n_dir, g: float, v1=(0.0, 0.0, 0.0), w1=(0.0, 0.0, 0.0), cohesion=False, keywords=""
) -> str:
    """Particle 2 (type 2) frozen at the origin, particle 1 (type 1) touching it along n_dir and
    pressed onto it by gravity g along -n_dir."""
    n = unit(n_dir)
    pos = tuple(c * (2 * RADIUS - 2e-7) for c in n)
    return (
        deck_header(cohesion)
        + f"pair_style gran {model(cohesion)}{keywords}\npair_coeff * *\ntimestep {DT!r}\n"
        + particle(
            1, 1, pos, vx=v1[0], vy=v1[1], vz=v1[2], omegax=w1[0], omegay=w1[1], omegaz=w1[2]
        )
        + particle(2, 2, (0.0, 0.0, 0.0))
        + gravity(g, tuple(-c for c in n))
        + "group frozen id 2\nfix hold frozen freeze\n"
    )


def g_vector(g: float, n_dir):
    n = unit(n_dir)
    return tuple(-g * c for c in n)


def sliding_check(g: float, n_dir, mu: float, cohesion: float = 0.0, reduce: bool = False):
    def check(snapshots):
        def at_cap(rows):
            _, _, dist, fn, ft = pair_contact(rows, g_vector(g, n_dir))
            if fn == 0.0:
                return False
            f_coh = cohesion * sjkr_area(dist, RADIUS, RADIUS)
            limit = mu * abs(fn if reduce or not cohesion else fn + f_coh)
            return abs(math.sqrt(dot(ft, ft)) - limit) <= 1e-9 * limit

        assert count_snapshots(snapshots, at_cap) >= 3, "the contact never slides"

    return check


def rolling_cap_check(g: float, n_dir, mu_r: float):
    def check(snapshots):
        def at_cap(rows):
            n, overlap, _, fn, ft = pair_contact(rows, g_vector(g, n_dir))
            if fn == 0.0:
                return False
            cri = RADIUS - 0.5 * overlap
            arm = (
                n[1] * ft[2] - n[2] * ft[1],
                n[2] * ft[0] - n[0] * ft[2],
                n[0] * ft[1] - n[1] * ft[0],
            )
            tq = (rows[1]["tqx"], rows[1]["tqy"], rows[1]["tqz"])
            m_roll = [-(tq[k] + cri * arm[k]) for k in range(3)]
            limit = mu_r * 0.5 * RADIUS * abs(fn)
            return abs(math.sqrt(dot(m_roll, m_roll)) - limit) <= 1e-6 * limit

        assert count_snapshots(snapshots, at_cap) >= 3, "the rolling torque never reaches its cap"

    return check


def bounce_check(snapshots):
    def touching(rows):
        return any(abs(rows[1][c]) > 0.0 for c in ("tqx", "tqy", "tqz"))

    assert contact_intervals(snapshots, touching) >= 2, "the contact does not open and close"


def wall_bounce_check(snapshots):
    def touching(rows):
        return any(rows[1][c] != 0.0 for c in ("tqx", "tqy", "tqz"))

    assert contact_intervals(snapshots, touching) >= 2, "the contact does not open and close"


def pinched_check(snapshots):
    _, rows = snapshots[-1]
    pair_overlap = 2 * RADIUS - abs(rows[2]["z"] - rows[1]["z"])
    floor_overlap = RADIUS - rows[1]["z"]
    assert pair_overlap > 0.5 * RADIUS and floor_overlap > 0.5 * RADIUS, (
        f"not pinched: overlaps {pair_overlap / RADIUS:.2f} R (pair), "
        f"{floor_overlap / RADIUS:.2f} R (floor)"
    )


def head_on_check(snapshots):
    forces = [abs(rows[1]["fx"]) for _, rows in snapshots]
    assert max(forces) > 0.0 and forces[-1] == 0.0, "no collision that ends"


def wall_cases() -> dict[str, Case]:
    g_down = gravity(9.81, (0.0, 0.0, -1.0))
    wall_model = model()
    mesh_fix = "fix m all mesh/surface file mesh.stl type 2\n"
    mesh_wall = f"fix w all wall/gran {wall_model} mesh n_meshes 1 meshes m\n"
    pair_line = f"pair_style gran {wall_model}\npair_coeff * *\ntimestep {DT!r}\n"
    spin = {"omegax": 20.0, "omegay": -50.0, "omegaz": 10.0}
    cases = {}
    cases["wall_zplane"] = Case(
        deck_header()
        + pair_line
        + f"fix w all wall/gran {wall_model} primitive type 2 zplane 0.0\n"
        + particle(1, 1, (0.0, 0.0, 1.0005 * RADIUS), vx=0.2, vy=0.05, vz=-0.05, **spin)
        + g_down
        + dump_and_run(100, ["run 2000", "run 2000 pre no post no"])
    )
    cases["wall_zplane_cohesion"] = Case(
        deck_header(cohesion=True)
        + f"pair_style gran {model(cohesion=True)}\npair_coeff * *\ntimestep {DT!r}\n"
        + f"fix w all wall/gran {model(cohesion=True)} primitive type 2 zplane 0.0\n"
        + particle(1, 1, (0.0, 0.0, 0.9999 * RADIUS), vx=0.05, **spin)
        + g_down
        + dump_and_run(100, ["run 2000", "run 2000"])
    )
    cases["wall_zplane_cohesion_reduce"] = Case(
        deck_header(cohesion=True)
        + f"pair_style gran {model(cohesion=True)} tangential_reduce on\npair_coeff * *\n"
        + f"timestep {DT!r}\n"
        + f"fix w all wall/gran {model(cohesion=True)} primitive type 2 zplane 0.0 "
        "tangential_reduce on\n"
        + particle(1, 1, (0.0, 0.0, 0.9999 * RADIUS), vx=0.05, **spin)
        + g_down
        + dump_and_run(100, ["run 2000", "run 2000"])
    )
    # Inside a cylinder along y whose axis passes through z = 4 mm, x = 1 mm (LIGGGHTS reads
    # the axis of a ycylinder as z, x): the particle rests on its bottom line and slides round.
    cases["wall_ycylinder"] = Case(
        deck_header()
        + pair_line
        + f"fix w all wall/gran {wall_model} primitive type 2 ycylinder 0.005 0.004 0.001\n"
        + particle(1, 1, (0.001, 0.0, -1e-7), vx=0.1, vy=0.05, **spin)
        + g_down
        + dump_and_run(100, ["run 3000"])
    )
    cases["mesh_face"] = Case(
        deck_header()
        + pair_line
        + mesh_fix
        + mesh_wall
        + particle(1, 1, (2 * MM, -2 * MM, 1.0005 * RADIUS), vx=0.2, vy=0.05, vz=-0.05, **spin)
        + g_down
        + dump_and_run(100, ["run 2000", "run 2000"]),
        {"mesh.stl": stl(PLATE)},
    )
    coh_model = model(cohesion=True)
    for name, tris, direction, velocity, cohesion in (
        ("mesh_edge", EDGE, (0.4, 0.0, 0.9), {"vy": 0.05}, False),
        ("mesh_edge_cohesion", EDGE, (0.4, 0.0, 0.9), {"vy": 0.05}, True),
        ("mesh_vertex", VERTEX, (1.0, 1.0, 2.0), {"vx": -0.02, "vy": 0.02}, False),
    ):
        n = unit(direction)
        pos = tuple(c * (RADIUS - 5e-8) for c in n)
        cases[name] = Case(
            deck_header(cohesion=cohesion)
            + (
                f"pair_style gran {coh_model}\npair_coeff * *\ntimestep {DT!r}\n"
                if cohesion
                else pair_line
            )
            + mesh_fix
            + (mesh_wall.replace(wall_model, coh_model) if cohesion else mesh_wall)
            + particle(1, 1, pos, **velocity, **spin)
            + gravity(30.0, tuple(-c for c in n))
            + dump_and_run(100, ["run 2000", "run 2000"]),
            {"mesh.stl": stl(tris)},
        )
    # Dropped from 50 um with spin: the wall contact opens and closes several times.
    for name, wall, files in (
        (
            "wall_zplane_bounce",
            f"fix w all wall/gran {wall_model} primitive type 2 zplane 0.0\n",
            {},
        ),
        ("mesh_face_bounce", mesh_fix + mesh_wall, {"mesh.stl": stl(PLATE)}),
    ):
        cases[name] = Case(
            deck_header()
            + pair_line
            + wall
            + particle(1, 1, (2 * MM, -2 * MM, RADIUS + 0.05 * MM), vx=0.02, **spin)
            + gravity(100.0, (0.0, 0.0, -1.0))
            + dump_and_run(20, ["run 4000"]),
            files,
            check=wall_bounce_check,
        )
    # Sliding across the shared diagonal of two coplanar triangles, off the boundary edge
    # x = 5 mm of the plate, over a convex ridge (with the default curvature, and with a
    # curvature larger than the bend), and along a concave valley.
    cases["mesh_plate_crossing"] = Case(
        deck_header()
        + pair_line
        + mesh_fix
        + mesh_wall
        + particle(1, 1, (0.0, 0.3 * MM, RADIUS - 1e-7), vx=0.3, vy=0.1, **spin)
        + g_down
        + dump_and_run(50, ["run 3000"]),
        {"mesh.stl": stl(PLATE)},
    )
    # The same crossing with each triangle in a mesh of its own, both in one wall/gran fix.
    cases["mesh_two_meshes_crossing"] = Case(
        deck_header()
        + pair_line
        + "fix ma all mesh/surface file tri0.stl type 2\n"
        + "fix mb all mesh/surface file tri1.stl type 2\n"
        + f"fix w all wall/gran {wall_model} mesh n_meshes 2 meshes mb ma\n"
        + particle(1, 1, (0.0, 0.3 * MM, RADIUS - 1e-7), vx=0.3, vy=0.1, **spin)
        + g_down
        + dump_and_run(50, ["run 3000"]),
        {"tri0.stl": stl(PLATE[:1]), "tri1.stl": stl(PLATE[1:])},
    )
    cases["mesh_plate_boundary"] = Case(
        deck_header()
        + pair_line
        + mesh_fix
        + mesh_wall
        + particle(1, 1, (4.2 * MM, 4.3 * MM, RADIUS - 1e-7), vx=0.2, vy=0.15, **spin)
        + g_down
        + dump_and_run(50, ["run 4000"]),
        {"mesh.stl": stl(PLATE)},
    )
    for name, angle, convex, curvature, reverse in (
        ("mesh_ridge", 20.0, True, None, False),
        ("mesh_ridge_reversed", 20.0, True, None, True),
        ("mesh_ridge_curvature", 20.0, True, 30.0, False),
        ("mesh_valley", 40.0, False, None, False),
        ("mesh_valley_curvature", 40.0, False, 42.0, False),
        ("mesh_valley_curvature_reversed", 40.0, False, 42.0, True),
    ):
        triangles = hinge(angle, convex)
        if reverse:  # the same surface, triangles listed in the opposite order
            triangles = triangles[::-1]
        fix = mesh_fix if curvature is None else mesh_fix.rstrip() + f" curvature {curvature!r}\n"
        x0 = -0.3 * MM
        # Moving along the first panel towards the hinge, pressed on by a strong gravity
        c, sn = math.cos(math.radians(angle / 2)), math.sin(math.radians(angle / 2))
        sn = sn if convex else -sn
        z0 = hinge_z(x0, angle, convex) + RADIUS / math.cos(math.radians(angle / 2)) - 1e-7
        cases[name] = Case(
            deck_header()
            + pair_line
            + fix
            + mesh_wall
            + particle(1, 1, (x0, 0.0, z0), vx=0.3 * c, vy=0.05, vz=0.3 * sn, **spin)
            + gravity(300.0, (0.0, 0.0, -1.0))
            + dump_and_run(50, ["run 4000"]),
            {"mesh.stl": stl(triangles)},
        )
    cases["mesh_moving"] = Case(
        deck_header()
        + pair_line
        + mesh_fix
        + "fix mv all move/mesh mesh m linear 0.05 0.02 0.0\n"
        + mesh_wall
        + particle(1, 1, (0.0, 0.0, RADIUS - 1e-7), **spin)
        + g_down
        + dump_and_run(100, ["run 2000", "run 2000"]),
        {"mesh.stl": stl(PLATE)},
    )
    lid_z = 2 * RADIUS + 0.05 * MM
    lid = [tuple((x, y, lid_z) for x, y, _ in tri) for tri in PLATE]
    # Two particles stacked on the floor and squeezed by a plate that keeps moving down: the
    # contacts overlap by more than half a radius, as for a particle pinched at the rim of the
    # split shear cell. LIGGGHTS has no stop for that; the engine warns and carries on alike.
    squeeze_z = 4 * RADIUS + 0.05 * MM
    squeeze = [tuple((x, y, squeeze_z) for x, y, _ in tri) for tri in PLATE]
    cases["pinched_stack"] = Case(
        deck_header()
        + pair_line
        + f"fix w all wall/gran {wall_model} primitive type 2 zplane 0.0\n"
        + "fix lid all mesh/surface file lid.stl type 2\n"
        + "fix mv all move/mesh mesh lid linear 0.0 0.0 -0.05\n"
        + f"fix wl all wall/gran {wall_model} mesh n_meshes 1 meshes lid\n"
        + particle(1, 1, (0.0, 0.0, RADIUS - 1e-7))
        + particle(2, 1, (0.0, 0.0, 3 * RADIUS - 2e-7))
        + g_down
        + dump_and_run(1000, ["run 20000", "run 20000"]),
        {"lid.stl": stl(squeeze)},
        check=pinched_check,
        # The stack is at rest: its net forces (1e-11 N) are the residual of contact forces of
        # about 1 N, which agree to rounding; they are compared on the scale of the weight.
        scales={"f": mass() * 9.81},
        engine_warns="overlaps a neighbour by",
    )
    cases["mesh_servo"] = Case(
        deck_header()
        + pair_line
        + f"fix w all wall/gran {wall_model} primitive type 2 zplane 0.0\n"
        + "fix lid all mesh/surface/stress/servo file lid.stl type 2 "
        f"com 0.0 0.0 {lid_z!r} ctrlPV force axis 0.0 0.0 -1.0 target_val 0.01 "
        "vel_max 0.02 kp 0.5\n" + "fix wl all wall/gran "
        f"{wall_model} mesh n_meshes 1 meshes lid\n"
        + particle(1, 1, (0.0, 0.0, RADIUS - 1e-7), vx=0.01, **spin)
        + g_down
        + dump_and_run(100, ["run 1500", "run 1500"]),
        {"lid.stl": stl(lid)},
    )
    return cases


def pair_cases() -> dict[str, Case]:
    cases = {}
    d2 = 1.6 * MM
    cases["pair_head_on"] = Case(
        deck_header()
        + f"pair_style gran {model()}\npair_coeff * *\ntimestep {DT!r}\n"
        + particle(1, 1, (-RADIUS - 0.02 * MM, 0.0, 0.0), vx=0.3)
        + particle(2, 2, (0.5 * d2, 0.0, 0.0), diameter=d2, vx=-0.3)
        + dump_and_run(10, ["run 600"]),
        check=head_on_check,
    )
    n_dir, g = (0.6, 0.0, 0.8), 50.0
    cases["pair_oblique_sliding"] = Case(
        loaded_pair(n_dir, g, v1=(0.08, 0.2, -0.06), w1=(30.0, -20.0, 10.0))
        + dump_and_run(50, ["run 1500", "run 1500"]),
        check=sliding_check(g, n_dir, FRICTION[0][1]),
    )
    cases["pair_rolling_cap"] = Case(
        loaded_pair(n_dir, g, w1=(0.0, 60.0, 0.0)) + dump_and_run(50, ["run 3000"]),
        check=rolling_cap_check(g, n_dir, ROLLING[0][1]),
    )
    cases["pair_cohesion_sliding"] = Case(
        loaded_pair(n_dir, g, v1=(0.0, 0.1, 0.0), w1=(0.0, 0.0, 20.0), cohesion=True)
        + dump_and_run(50, ["run 1500", "run 1500"]),
        check=sliding_check(g, n_dir, FRICTION[0][1], cohesion=COHESION[0][1]),
    )
    cases["pair_cohesion_sliding_reduce"] = Case(
        loaded_pair(
            n_dir,
            g,
            v1=(0.0, 0.1, 0.0),
            w1=(0.0, 0.0, 20.0),
            cohesion=True,
            keywords=" tangential_reduce on",
        )
        + dump_and_run(50, ["run 1500", "run 1500"]),
        check=sliding_check(g, n_dir, FRICTION[0][1], cohesion=COHESION[0][1], reduce=True),
    )
    for name, keywords in (
        ("pair_head_on_limit_force", " limitForce on"),
        ("pair_head_on_no_tangential_damping", " tangential_damping off"),
    ):
        cases[name] = Case(
            deck_header()
            + f"pair_style gran {model()}{keywords}\npair_coeff * *\ntimestep {DT!r}\n"
            + particle(1, 1, (-RADIUS - 0.02 * MM, 0.0, 0.0), vx=0.3, omegaz=30.0)
            + particle(2, 2, (0.5 * d2, 0.3 * MM, 0.0), diameter=d2, vx=-0.3)
            + dump_and_run(10, ["run 600"]),
            check=head_on_check,
        )
    # Particle 2 resting on particle 1, which rests on a plane: pair and wall contacts at once.
    cases["pair_on_wall"] = Case(
        deck_header(cohesion=True)
        + f"pair_style gran {model(cohesion=True)}\npair_coeff * *\ntimestep {DT!r}\n"
        + f"fix w all wall/gran {model(cohesion=True)} primitive type 2 zplane 0.0\n"
        + particle(1, 1, (0.0, 0.0, RADIUS - 1e-7), omegay=5.0)
        + particle(
            2,
            2,
            (0.3 * MM, 0.1 * MM, RADIUS + math.sqrt((2 * RADIUS - 3e-7) ** 2 - 0.1 * MM**2)),
            vx=-0.02,
        )
        + gravity(9.81, (0.0, 0.0, -1.0))
        + dump_and_run(100, ["run 2000", "run 2000"]),
    )
    # A particle far away is deleted between two runs of a sliding contact (delete_atoms
    # renumbers the ids): the history survives if one of the two ids is unchanged.
    far = (-6 * MM, -6 * MM, -6 * MM)
    for name, layout in (
        ("pair_delete_atoms_ids_kept", ("m", "x", "f")),
        ("pair_delete_atoms_ids_changed", ("x", "m", "f")),
    ):
        n = unit(n_dir)
        body = ""
        for pid, role in enumerate(layout, start=1):
            if role == "m":
                body += particle(
                    pid, 1, tuple(c * (2 * RADIUS - 2e-7) for c in n), vx=0.08, vy=0.2, omegax=30.0
                )
            elif role == "f":
                body += particle(pid, 2, (0.0, 0.0, 0.0))
            else:
                body += particle(pid, 1, far)
        cases[name] = Case(
            deck_header()
            + f"pair_style gran {model()}\npair_coeff * *\ntimestep {DT!r}\n"
            + body
            + gravity(g, tuple(-c for c in n))
            + f"group frozen id {layout.index('f') + 1}\nfix hold frozen freeze\n"
            + f"group gone id {layout.index('x') + 1}\n"
            + dump_and_run(50, ["run 1000", "delete_atoms group gone", "run 1000"]),
        )
    # Particle 1 dropped from 50 um onto the frozen particle 2, off-centre and spinning. The
    # history of a pair that opened is kept until the next neighbour build (the skin of 0.5 mm
    # allows none during the flights, 20 um several, and so does the set-up of a run unless it
    # is `pre no`); the second run starts during the flight between the first two contacts.
    drop_dir = unit((0.2, 0.1, 1.0))
    for name, skin, runs in (
        ("pair_bounce", 0.0005, ["run 4000"]),
        ("pair_bounce_small_skin", 0.00002, ["run 4000"]),
        ("pair_bounce_two_runs", 0.0005, ["run 2000", "run 2000"]),
        ("pair_bounce_two_runs_pre_no", 0.0005, ["run 2000", "run 2000 pre no post no"]),
    ):
        cases[name] = Case(
            deck_header(skin=skin)
            + f"pair_style gran {model()}\npair_coeff * *\ntimestep {DT!r}\n"
            + particle(
                1,
                1,
                tuple(c * (2 * RADIUS + 0.05 * MM) for c in drop_dir),
                omegax=40.0,
                omegay=-20.0,
            )
            + particle(2, 2, (0.0, 0.0, 0.0))
            + gravity(100.0, (0.0, 0.0, -1.0))
            + "group frozen id 2\nfix hold frozen freeze\n"
            + dump_and_run(20, runs),
            check=bounce_check,
        )
    # The same drop with neighbour builds forced at chosen steps. LIGGGHTS keeps the history of
    # a pair across a build only if the pair touches at the positions of the build (those of
    # the force evaluation that follows it), whatever it did at the previous evaluation: the
    # first contact is still closed at step 1452 and open at the build of step 1453, which
    # drops its spring (the second contact starts from zero); the second contact opens at step
    # 3053, and the build of step 3443 (the set-up of the second run at 2800, then every 643)
    # comes at the first step of the third contact, which resumes the spring of the second.
    cases["pair_bounce_build_at_open_and_close"] = Case(
        deck_header().replace("neigh_modify delay 0", "neigh_modify every 1453 delay 0 check no")
        + f"pair_style gran {model()}\npair_coeff * *\ntimestep {DT!r}\n"
        + particle(
            1,
            1,
            tuple(c * (2 * RADIUS + 0.05 * MM) for c in drop_dir),
            omegax=40.0,
            omegay=-20.0,
        )
        + particle(2, 2, (0.0, 0.0, 0.0))
        + gravity(100.0, (0.0, 0.0, -1.0))
        + "group frozen id 2\nfix hold frozen freeze\n"
        + dump_and_run(1, ["run 2800", "neigh_modify every 643 delay 0 check no", "run 1200"]),
        check=builds_at_open_and_close_check,
    )
    return cases


def builds_at_open_and_close_check(snapshots):
    """The contacts of pair_bounce_build_at_open_and_close open and close at its builds."""
    runs: list[list[int]] = []
    for step, rows in snapshots:
        if all(rows[1][c] == 0.0 for c in ("tqx", "tqy", "tqz")):
            continue
        if runs and step <= runs[-1][1] + 1:
            runs[-1][1] = step
        else:
            runs.append([step, step])
    assert len(runs) == 3, f"three contacts expected, got {runs}"
    assert runs[0][1] + 1 == 1453, "the first contact does not open at the build of step 1453"
    assert runs[1][1] + 1 < 3443 == runs[2][0], "the third contact does not close at the build"


CASES = {**pair_cases(), **wall_cases()}


@pytest.mark.parametrize("name", sorted(CASES))
def test_contact_parity(name: str, tmp_path: Path) -> None:
    case = CASES[name]
    ok, output = run_reference(tmp_path / "liggghts", case.deck, case.files)
    assert ok, output
    ok, output = run_engine(tmp_path / "engine", case.deck, case.files)
    assert ok, output
    assert case.engine_warns in output, output
    reference = read_dump(tmp_path / "liggghts" / "dump.txt")
    ours = read_dump(tmp_path / "engine" / "dump.txt")
    if case.check is not None:
        case.check(reference)
    worst, where = max_relative_difference(ours, reference, case.scales)
    print(f"{name}: max relative difference {worst:.3g} ({where})")
    assert worst <= REL_TOL, f"{name}: {worst:.3g} at {where}"


# --- decks both programs must accept or both refuse ---------------------------------------------


def verdict_deck(
    youngs: float = 1e7,
    settings: str = "",
    pair: str = "",
    wall: str = "",
    mesh: str = "",
    run: str = "run 10",
) -> str:
    text = deck_header(extra=settings).replace(
        f"youngsModulus peratomtype {YOUNGS[0]!r} {YOUNGS[1]!r}",
        f"youngsModulus peratomtype {youngs!r} {youngs!r}",
    )
    return (
        text
        + f"pair_style gran {pair or model()}\npair_coeff * *\ntimestep {DT!r}\n"
        + mesh
        + wall
        + particle(1, 1, (0.0, 0.0, 0.0))
        + f"fix integr all nve/sphere\n{run}\n"
    )


# Smallest angle 26.57 degrees; 5 mm below the particle.
SKEWED = [((0.0, 0.0, -5 * MM), (4 * MM, 0.0, -5 * MM), (4 * MM, 2 * MM, -5 * MM))]
MESH_FIX = "fix m all mesh/surface file mesh.stl type 2{}\n"
MESH_WALL = f"fix w all wall/gran {model()} mesh n_meshes 1 meshes m\n"
VERDICTS = {
    # name: (deck, files, accepted)
    "youngs_4.9e6": (verdict_deck(youngs=4.9e6), {}, False),
    "youngs_4.9e6_soft": (verdict_deck(youngs=4.9e6, settings="soft_particles yes\n"), {}, True),
    "youngs_1e9": (verdict_deck(youngs=1e9), {}, True),
    "youngs_1.1e9": (verdict_deck(youngs=1.1e9), {}, False),
    "youngs_1.1e9_soft": (verdict_deck(youngs=1.1e9, settings="soft_particles yes\n"), {}, False),
    "youngs_1.1e9_hard": (verdict_deck(youngs=1.1e9, settings="hard_particles yes\n"), {}, True),
    "youngs_1.1e9_hard_no": (verdict_deck(youngs=1.1e9, settings="hard_particles no\n"), {}, False),
    "youngs_4.9e6_hard": (verdict_deck(youngs=4.9e6, settings="hard_particles yes\n"), {}, False),
    "hard_particles_on": (verdict_deck(settings="hard_particles on\n"), {}, False),
    "soft_particles_on": (verdict_deck(settings="soft_particles on\n"), {}, False),
    "tangential_reduce": (
        verdict_deck(pair=model(cohesion=True) + " tangential_reduce on").replace(
            "fix m5 ",
            "fix m6 all property/global cohesionEnergyDensity peratomtypepair 2 "
            "1e4 1e4 1e4 1e4\nfix m5 ",
        ),
        {},
        True,
    ),
    "tangential_reduce_before_rolling": (
        verdict_deck(
            pair="model hertz tangential history cohesion sjkr tangential_reduce on "
            "rolling_friction epsd2"
        ),
        {},
        False,
    ),
    "tangential_reduce_without_cohesion": (
        verdict_deck(pair=model() + " tangential_reduce on"),
        {},
        False,
    ),
    "limitForce_yes": (verdict_deck(pair=model() + " limitForce yes"), {}, False),
    "rolling_before_cohesion": (
        verdict_deck(pair="model hertz tangential history rolling_friction epsd2 cohesion sjkr"),
        {},
        False,
    ),
    "wall_keyword_after_primitive": (
        verdict_deck(
            pair=model() + " limitForce on",
            wall=f"fix w all wall/gran {model()} primitive type 2 zplane -0.005 limitForce on\n",
        ),
        {},
        True,
    ),
    "wall_keyword_before_primitive": (
        verdict_deck(
            pair=model() + " limitForce on",
            wall=f"fix w all wall/gran {model()} limitForce on primitive type 2 zplane -0.005\n",
        ),
        {},
        False,
    ),
    "curvature_26.5": (
        verdict_deck(mesh=MESH_FIX.format(" curvature 26.5"), wall=MESH_WALL),
        {"mesh.stl": stl(SKEWED)},
        True,
    ),
    "curvature_26.6": (
        verdict_deck(mesh=MESH_FIX.format(" curvature 26.6"), wall=MESH_WALL),
        {"mesh.stl": stl(SKEWED)},
        False,
    ),
    "curvature_60": (
        verdict_deck(mesh=MESH_FIX.format(" curvature 60"), wall=MESH_WALL),
        {"mesh.stl": stl(SKEWED)},
        False,
    ),
    "run_pre_no_post_no": (verdict_deck(run="run 10\nrun 10 pre no post no"), {}, True),
    "run_pre_on": (verdict_deck(run="run 10\nrun 10 pre on"), {}, False),
}


@pytest.mark.parametrize("name", sorted(VERDICTS))
def test_same_verdict(name: str, tmp_path: Path) -> None:
    deck, files, accepted = VERDICTS[name]
    ok, output = run_reference(tmp_path / "liggghts", deck, files)
    assert ok == accepted, output
    ok, output = run_engine(tmp_path / "engine", deck, files)
    assert ok == accepted, output
