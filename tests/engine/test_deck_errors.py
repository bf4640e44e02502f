"""Malformed decks give a clean `ERROR: DECK:LINE: command: reason`; fuzzed decks never crash."""

import os
import random
import subprocess

import pytest

from .conftest import engine_path, header, material_block

pytestmark = pytest.mark.engine

VALID = (
    header(half_width=0.05, ntypes=2)
    + material_block(5e6, 0.4, 0.6, 0.5, rolling=0.3, ntypes=2)
    + """pair_style gran model hertz tangential history rolling_friction epsd2
pair_coeff * *
timestep 1e-5
region ins block -0.01 0.01 -0.01 0.01 0.0 0.02 units box
fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.001
fix pdd all particledistribution/discrete 32452843 1 pts 1.0
fix ins all insert/pack seed 49979687 distributiontemplate pdd maxattempt 50 insert_every once &
    overlapcheck yes all_in yes vel constant 0 0 0 region ins particles_in_region 20
fix floor all wall/gran model hertz tangential history rolling_friction epsd2 &
    primitive type 2 zplane -0.01
fix grav all gravity 9.81 vector 0 0 -1
fix integr all nve/sphere
variable z equal xcm(all,z)
thermo_style custom step atoms ke v_z
thermo 50
run 100
"""
)


def run_deck(tmp_path, text, timeout=30):
    (tmp_path / "in.deck").write_text(text)
    return subprocess.run(
        [engine_path(), "-in", "in.deck", "-log", "none", "-noprogress"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=timeout,
        env=dict(os.environ, OMP_NUM_THREADS="1"),
    )


def line_of(text: str, needle: str) -> int:
    for n, line in enumerate(text.splitlines(), 1):
        if needle in line:
            return n
    raise ValueError(needle)


def test_valid_deck_runs(tmp_path):
    res = run_deck(tmp_path, VALID)
    assert res.returncode == 0, res.stderr
    assert "Loop time of" in res.stdout


# (replace this, with that, the command named in the error, a word of the reason)
CORRUPTIONS = [
    ("timestep 1e-5", "timestep 1e-5x", "timestep", "number"),
    ("timestep 1e-5", "timestep", "timestep", "usage"),
    ("pair_coeff * *", "pair_coeff * * 3", "pair_coeff", "pair_coeff"),
    ("pair_style gran model hertz", "pair_style gran model hooke", "pair_style", "hooke"),
    (
        "fix grav all gravity 9.81 vector 0 0 -1",
        "fix grav all gravity 9.81 vector 0 0",
        "fix",
        "gravity",
    ),
    ("fix integr all nve/sphere", "fix integr all nve/ellipsoid", "fix", "nve/ellipsoid"),
    ("fix integr all nve/sphere", "fix integr nogroup nve/sphere", "fix", "nogroup"),
    ("region ins block", "region ins sphere", "region", "sphere"),
    ("thermo 50", "thermo fifty", "thermo", "fifty"),
    (
        "thermo_style custom step atoms ke v_z",
        "thermo_style custom step atoms ke v_nope",
        "run",
        "nope",
    ),
    ("variable z equal xcm(all,z)", "variable z equal xcm(all,z", "run", "z"),
    ("run 100", "run 100 sometimes", "run", "sometimes"),
    ("run 100", "shell rm -rf /", "shell", "shell"),
    ("run 100", "include missing_file.in", "include", "missing_file.in"),
    ("run 100", "frobnicate 3", "frobnicate", "unknown"),
    ("peratomtype 5000000.0 5000000.0", "peratomtype 5000000.0", "run", "youngsModulus"),
    (
        "coefficientRestitution peratomtypepair 2 0.6 0.6 0.6 0.6",
        "coefficientRestitution peratomtypepair 2 1.6 1.6 1.6 1.6",
        "run",
        "coefficientRestitution",
    ),
]


@pytest.mark.parametrize(("old", "new", "command", "reason"), CORRUPTIONS)
def test_malformed_deck_reports_file_line_and_command(tmp_path, old, new, command, reason):
    assert old in VALID
    text = VALID.replace(old, new, 1)
    res = run_deck(tmp_path, text)
    assert res.returncode == 1
    err = res.stderr.strip().splitlines()[-1]
    expected_line = line_of(text, new if command != "run" else "run 100")
    assert err.startswith(f"ERROR: in.deck:{expected_line}: {command}: "), err
    assert reason.lower() in err.lower(), err


def test_truncated_continuation_at_end_of_file(tmp_path):
    text = VALID.replace("run 100\n", "run 100 &\n")
    res = run_deck(tmp_path, text)
    assert res.returncode == 1
    assert res.stderr.startswith(f"ERROR: in.deck:{line_of(text, 'run 100')}:")


def test_unstable_time_step_is_stopped_with_step_and_particle(tmp_path):
    text = VALID.replace("timestep 1e-5", "timestep 5e-3")
    res = run_deck(tmp_path, text)
    assert res.returncode == 1
    err = res.stderr.strip().splitlines()[-1]
    assert "unstable simulation at step" in err and "particle" in err
    assert "WARNING: time step" in res.stderr  # the set-up check warned first


def test_fuzzed_decks_never_crash_or_hang(tmp_path):
    rng = random.Random(12345)
    alphabet = "abcxyz0123456789 .-*&#$\"'{}()[]\n"
    outcomes = set()
    for trial in range(150):
        chars = list(VALID)
        for _ in range(rng.randint(1, 4)):
            op = rng.random()
            pos = rng.randrange(len(chars))
            if op < 0.4:
                del chars[pos]
            elif op < 0.8:
                chars.insert(pos, rng.choice(alphabet))
            else:
                chars = chars[:pos]
        res = run_deck(tmp_path, "".join(chars), timeout=60)
        assert res.returncode in (0, 1), f"trial {trial}: exit {res.returncode}\n{res.stderr}"
        if res.returncode == 1:
            assert res.stderr.strip().splitlines()[-1].startswith("ERROR: "), res.stderr
        outcomes.add(res.returncode)
    assert outcomes == {0, 1}


# ---------------------------------------------------------------------------------------------
# Decks that LIGGGHTS 3.8 rejects: the engine rejects them too, naming the file and line.

FLOOR_WALL = """fix floor all wall/gran model hertz tangential history rolling_friction epsd2 &
    primitive type 2 zplane -0.01
"""
WALL_MODEL = "model hertz tangential history rolling_friction epsd2"
MESHES = (
    "fix floor all mesh/surface file floor.stl type 2\n"
    "fix roof all mesh/surface file roof.stl type 2\n"
)
# The valid counterpart: one mesh wall/gran fix lists every mesh.
ONE_MESH_WALL = VALID.replace(
    FLOOR_WALL, MESHES + f"fix walls all wall/gran {WALL_MODEL} mesh n_meshes 2 meshes floor roof\n"
)

# (name, deck, the line the engine names, its command, a word of its reason, what LIGGGHTS says
# or None when it crashes instead of reporting)
LIGGGHTS_REJECTS = [
    (
        "second mesh wall/gran",
        VALID.replace(
            FLOOR_WALL,
            MESHES
            + f"fix wfloor all wall/gran {WALL_MODEL} mesh n_meshes 1 meshes floor\n"
            + f"fix wroof all wall/gran {WALL_MODEL} mesh n_meshes 1 meshes roof\n",
        ),
        "fix wroof",
        "fix",
        "second fix wall/gran with meshes",
        "More than one wall of type 'mesh' is not supported",
    ),
    (
        "wall/gran defined again without unfix",
        ONE_MESH_WALL.replace(
            "run 100\n",
            "run 50\n"
            + f"fix walls all wall/gran {WALL_MODEL} mesh n_meshes 1 meshes floor\n"
            + "run 50\n",
        ),
        "meshes floor\n",
        "fix",
        "without unfix",
        None,  # LIGGGHTS 3.8 ends with a segmentation fault
    ),
    (
        "fix replaced by another style",
        ONE_MESH_WALL.replace("run 100\n", "run 50\nfix grav all nve/sphere\nrun 50\n"),
        "fix grav all nve/sphere",
        "fix",
        "another style",
        "Replacing a fix, but new style != old style",
    ),
]


def _plate_stl(half: float, z: float) -> str:
    corners = [(-half, -half), (half, -half), (half, half), (-half, half)]
    facets = []
    for a, b, c in ((0, 1, 2), (0, 2, 3)):
        vertices = "".join(
            f"      vertex {corners[k][0]!r} {corners[k][1]!r} {z!r}\n" for k in (a, b, c)
        )
        facets.append(f"  facet normal 0 0 1\n    outer loop\n{vertices}    endloop\n  endfacet\n")
    return "solid plate\n" + "".join(facets) + "endsolid plate\n"


def _write_meshes(directory):
    (directory / "floor.stl").write_text(_plate_stl(0.04, -0.01))
    (directory / "roof.stl").write_text(_plate_stl(0.04, 0.04))


@pytest.mark.liggghts
def test_one_mesh_wall_listing_every_mesh_runs_on_both_engines(tmp_path):
    from tests.liggghts.conftest import require_liggghts, run_liggghts

    require_liggghts()
    _write_meshes(tmp_path)
    res = run_deck(tmp_path, ONE_MESH_WALL)
    assert res.returncode == 0, res.stderr
    lig = run_liggghts(tmp_path, "in.deck", timeout=120)
    assert lig.returncode == 0, lig.describe()


@pytest.mark.liggghts
@pytest.mark.parametrize(
    ("name", "text", "needle", "command", "reason", "liggghts_says"),
    LIGGGHTS_REJECTS,
    ids=[case[0] for case in LIGGGHTS_REJECTS],
)
def test_decks_liggghts_rejects_are_rejected_with_file_and_line(
    tmp_path, name, text, needle, command, reason, liggghts_says
):
    from tests.liggghts.conftest import require_liggghts, run_liggghts

    require_liggghts()
    _write_meshes(tmp_path)
    res = run_deck(tmp_path, text)
    assert res.returncode == 1, f"{name}: the engine accepted the deck\n{res.stdout[-1500:]}"
    err = res.stderr.strip().splitlines()[-1]
    lines = [n for n, line in enumerate(text.splitlines(), 1) if needle.strip() in line]
    assert err.startswith(f"ERROR: in.deck:{lines[-1]}: {command}: "), err
    assert reason in err, err
    lig = run_liggghts(tmp_path, "in.deck", timeout=120)
    assert lig.returncode != 0 or "ERROR" in lig.output, f"{name}: LIGGGHTS accepted the deck"
    if liggghts_says is not None:
        assert liggghts_says in lig.output, lig.describe()
