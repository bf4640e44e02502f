"""Deck tests of particle insertion, fix print / ave/time, dumps and computes in dem_engine.

Each test writes a small LIGGGHTS deck into tmp_path, runs the engine binary (``DEM_ENGINE`` or
the installed one, see conftest.py) and checks the numbers it writes.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from .conftest import EngineRun, run_engine

pytestmark = pytest.mark.engine


def sphere_volume(radius: float) -> float:
    """Volume (m^3) of a sphere of the given radius (m)."""
    return 4.0 / 3.0 * math.pi * radius**3


def header(ntypes: int = 1, boundary: str = "p p p", box: float = 0.012) -> str:
    """Deck lines up to the pair style: a cubic box of side ``box`` (m) with ``ntypes`` types."""
    pair = " ".join(["0.5"] * ntypes**2)
    return f"""units si
atom_style granular
atom_modify map array
boundary {boundary}
newton off
communicate single vel yes
region box block 0 {box} 0 {box} 0 {box} units box
create_box {ntypes} box
neighbor 0.0002 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype {" ".join(["5e6"] * ntypes)}
fix m2 all property/global poissonsRatio peratomtype {" ".join(["0.3"] * ntypes)}
fix m3 all property/global coefficientRestitution peratomtypepair {ntypes} {pair}
fix m4 all property/global coefficientFriction peratomtypepair {ntypes} {pair}
pair_style gran model hertz tangential history
pair_coeff * *
timestep 1e-5
"""


def run_deck(directory: Path, text: str) -> EngineRun:
    """Writes the deck to ``directory/in.deck`` and runs the engine there (must succeed)."""
    return run_engine(directory, text)


def read_dump(path: Path) -> list[tuple[int, pd.DataFrame]]:
    """Parses a LAMMPS text dump into (step, table) pairs, checking the ITEM layout."""
    lines = path.read_text().splitlines()
    snapshots = []
    i = 0
    while i < len(lines):
        assert lines[i] == "ITEM: TIMESTEP"
        step = int(lines[i + 1])
        assert lines[i + 2] == "ITEM: NUMBER OF ATOMS"
        n = int(lines[i + 3])
        assert lines[i + 4].startswith("ITEM: BOX BOUNDS ")
        assert lines[i + 8].startswith("ITEM: ATOMS ")
        columns = lines[i + 8].split()[2:]
        rows = [line.split() for line in lines[i + 9 : i + 9 + n]]
        table = pd.DataFrame(rows, columns=columns).apply(pd.to_numeric)
        snapshots.append((step, table))
        i += 9 + n
    return snapshots


def min_gap(x: np.ndarray, r: np.ndarray, box: float | None) -> float:
    """Smallest centre distance minus radii sum over all pairs (periodic when ``box`` given)."""
    d = x[:, None, :] - x[None, :, :]
    if box is not None:
        d -= box * np.round(d / box)
    dist = np.sqrt((d**2).sum(axis=2))
    gap = dist - r[:, None] - r[None, :]
    np.fill_diagonal(gap, np.inf)
    return float(gap.min())


TEMPLATE = (
    "fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 "
    "radius constant 0.0005\n"
    "fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0\n"
)


def test_volume_fraction_fill_count_and_no_overlap(tmp_path: Path) -> None:
    box, radius, phi = 0.012, 0.0005, 0.3
    deck = (
        header(box=box)
        + TEMPLATE
        + "fix ins all insert/pack seed 100001 distributiontemplate pdd1 insert_every once "
        f"overlapcheck yes all_in no volumefraction_region {phi} region box\n"
        + "dump d all custom 1 dump.txt id type x y z radius mass\n"
        + "dump_modify d sort id\n"
        + "run 1\n"
    )
    run_deck(tmp_path, deck)
    (step0, empty), (step1, table) = read_dump(tmp_path / "dump.txt")
    assert (step0, len(empty)) == (0, 0)
    expected = phi * box**3 / sphere_volume(radius)  # 990.3
    assert step1 == 1
    assert abs(len(table) - expected) <= 0.02 * expected
    assert list(table["id"]) == list(range(1, len(table) + 1))
    assert min_gap(table[["x", "y", "z"]].to_numpy(), table["radius"].to_numpy(), box) >= 0.0
    np.testing.assert_allclose(table["mass"], 2500 * sphere_volume(radius), rtol=1e-5)


def test_unreachable_target_inserts_what_fits_and_warns(tmp_path: Path) -> None:
    target = 0.45 * 0.012**3 / sphere_volume(0.0005)
    deck = (
        header()
        + TEMPLATE
        + "fix ins all insert/pack seed 100001 distributiontemplate pdd1 maxattempt 3 "
        "insert_every once volumefraction_region 0.45 region box\n"
        + "run 1\n"
        + 'print "inserted $(f_ins[1]) total $(count(all))"\n'
    )
    proc = run_deck(tmp_path, deck)
    assert "less insertions than requested" in proc.stderr
    inserted = [line for line in proc.stdout.splitlines() if line.startswith("inserted ")]
    words = inserted[0].split()
    assert words[1] == words[3]
    assert 0.3 * target < float(words[1]) < 0.95 * target


def test_particles_and_mass_in_region_targets(tmp_path: Path) -> None:
    radius, density = 0.0005, 2500.0
    target_mass = 150 * density * sphere_volume(radius)
    deck = (
        header(boundary="p p f", box=0.02)
        + TEMPLATE
        + "region lower block 0 0.02 0 0.02 0.001 0.009 units box\n"
        + "region upper cylinder z 0.01 0.01 0.008 0.011 0.019 units box\n"
        + "fix a all insert/pack seed 100003 distributiontemplate pdd1 insert_every once "
        "overlapcheck yes all_in yes particles_in_region 321 region lower\n"
        + "fix b all insert/pack seed 100019 distributiontemplate pdd1 insert_every once "
        f"overlapcheck yes all_in yes mass_in_region {target_mass:.17g} region upper\n"
        + "variable na equal f_a[1]\n"
        + "variable mb equal f_b[2]\n"
        + 'fix pr all print 1 "${na} ${mb}" file counts.txt screen no title none\n'
        + "dump d all custom 1 dump.txt id x y z radius mass\n"
        + "run 1\n"
    )
    run_deck(tmp_path, deck)
    _, table = read_dump(tmp_path / "dump.txt")[-1]
    z, x, y = table["z"], table["x"], table["y"]
    in_lower = (z - radius >= 0.001) & (z + radius <= 0.009)
    in_upper = ((x - 0.01) ** 2 + (y - 0.01) ** 2 <= (0.008 - radius) ** 2) & (z >= 0.011 + radius)
    assert in_lower.sum() == 321
    assert table.loc[in_upper, "mass"].sum() == pytest.approx(target_mass, rel=1e-4)
    assert len(table) == 321 + 150
    count, mass = (float(v) for v in (tmp_path / "counts.txt").read_text().split())
    assert count == 321
    assert mass == pytest.approx(target_mass, rel=1e-12)
    assert min_gap(table[["x", "y", "z"]].to_numpy(), table["radius"].to_numpy(), None) >= 0.0


@pytest.mark.parametrize(
    ("style", "weights"),
    [
        ("particledistribution/discrete", (0.3, 0.7)),
        ("particledistribution/discrete/numberbased", (0.6, 0.4)),
    ],
)
def test_discrete_distribution_fractions(tmp_path: Path, style: str, weights: tuple) -> None:
    r1, r2, rho1, rho2 = 0.0004, 0.0006, 2500.0, 1500.0
    deck = (
        header(ntypes=2, box=0.03)
        + f"fix t1 all particletemplate/sphere 15485863 atom_type 1 density constant {rho1} "
        f"radius constant {r1}\n"
        + f"fix t2 all particletemplate/sphere 15485867 atom_type 2 density constant {rho2} "
        f"radius constant {r2}\n"
        + f"fix pdd all {style} 32452843 2 t1 {weights[0]} t2 {weights[1]}\n"
        + "fix ins all insert/rate/region seed 100003 distributiontemplate pdd nparticles 1200 "
        "particlerate 1e6 insert_every 10 overlapcheck yes random_distribute uncorrelated "
        "region box\n" + "dump d all custom 200 dump.txt id type mass radius\n" + "run 200\n"
    )
    run_deck(tmp_path, deck)
    _, table = read_dump(tmp_path / "dump.txt")[-1]
    assert len(table) == 1200
    m1, m2 = rho1 * sphere_volume(r1), rho2 * sphere_volume(r2)
    n1 = int((table["type"] == 1).sum())
    np.testing.assert_allclose(table.loc[table["type"] == 2, "radius"], r2, rtol=1e-5)
    # Expected number fraction of type 1 and its binomial standard error.
    if style.endswith("numberbased"):
        p1 = weights[0]
    else:
        p1 = (weights[0] / m1) / (weights[0] / m1 + weights[1] / m2)
    sigma = math.sqrt(p1 * (1 - p1) / 1200)
    assert abs(n1 / 1200 - p1) < 4 * sigma
    mass_fraction = n1 * m1 / (n1 * m1 + (1200 - n1) * m2)
    if not style.endswith("numberbased"):
        assert mass_fraction == pytest.approx(weights[0], abs=0.03)


def test_insert_rate_region_delivers_rate(tmp_path: Path) -> None:
    rate, every, dt = 2500.0, 100, 1e-5  # 2.5 particles per event
    deck = (
        header(box=0.02)
        + TEMPLATE
        + "fix ins all insert/rate/region seed 100003 distributiontemplate pdd1 nparticles INF "
        f"particlerate {rate} insert_every {every} overlapcheck yes vel constant 0 0 -0.1 "
        "region box\n"
        + "fix integr all nve/sphere\n"
        + "variable n equal count(all)\n"
        + "fix av all ave/time 100 1 100 v_n f_ins[1] file count.txt\n"
        + "run 20000\n"
    )
    run_deck(tmp_path, deck)
    data = np.loadtxt(tmp_path / "count.txt")
    steps, counts, inserted = data[:, 0], data[:, 1], data[:, 2]
    assert np.array_equal(counts, inserted)
    # Events at steps 1, 101, ...: the count at step s holds ceil(s / every) events.
    events = np.ceil(steps / every)
    expected = rate * every * dt * events
    assert counts[-1] == pytest.approx(expected[-1], rel=0.05)  # 500 expected
    slope = np.polyfit(steps * dt, counts, 1)[0]
    assert slope == pytest.approx(rate, rel=0.05)
    assert set(np.diff(counts)) == {2.0, 3.0}


def test_insert_rate_region_stops_at_nparticles(tmp_path: Path) -> None:
    deck = (
        header(box=0.02)
        + TEMPLATE
        + "fix ins all insert/rate/region seed 100003 distributiontemplate pdd1 nparticles 30 "
        "particlerate 10000 insert_every 100 region box\n"
        + "run 1000\n"
        + 'print "inserted $(f_ins[1]) total $(count(all))"\n'
    )
    proc = run_deck(tmp_path, deck)
    assert "inserted 30 total 30" in proc.stdout


def test_print_and_ave_time_files(tmp_path: Path) -> None:
    deck = (
        header()
        + "variable a equal 2*step\n"
        + "variable s equal step\n"
        + 'fix pr all print 10 "step ${s} a ${a} half $(v_a/4)" file print.txt screen no\n'
        + "fix av all ave/time 2 5 20 v_a file ave.txt\n"
        + "fix run all ave/time 1 1 10 v_a v_s ave running file running.txt title1 none-title\n"
        + 'fix echo all print 20 "last average ${b} running ${c}" file echo.txt '
        + 'title "# averages"\n'
        + "variable b equal f_av\n"
        + "variable c equal f_run[2]\n"
        + "run 40\n"
    )
    run_deck(tmp_path, deck)
    assert (tmp_path / "print.txt").read_text() == (
        "# Fix print output for fix pr\n"
        "step 10 a 20 half 5\n"
        "step 20 a 40 half 10\n"
        "step 30 a 60 half 15\n"
        "step 40 a 80 half 20\n"
    )
    # Steps 12..20 (every 2) average to 2*16; steps 32..40 to 2*36.
    assert (tmp_path / "ave.txt").read_text() == (
        "# Time-averaged data for fix av\n# TimeStep v_a\n20 32\n40 72\n"
    )
    # Running averages over the outputs at steps 0, 10, 20, 30, 40 (step 0 at setup).
    assert (tmp_path / "running.txt").read_text() == (
        "none-title\n# TimeStep v_a v_s\n0 0 0\n10 10 5\n20 20 10\n30 30 15\n40 40 20\n"
    )
    assert (tmp_path / "echo.txt").read_text() == (
        "# averages\nlast average 32 running 10\nlast average 72 running 20\n"
    )


def test_dump_custom_and_vtk_agree_and_open_in_pyvista(tmp_path: Path) -> None:
    import pyvista as pv

    deck = (
        header()
        + TEMPLATE
        + "fix ins all insert/pack seed 100001 distributiontemplate pdd1 insert_every once "
        "vel constant 0.1 -0.2 0.3 omega constant 0 0 5 volumefraction_region 0.1 region box\n"
        + "fix integr all nve/sphere\n"
        + "compute cn all contact/atom\n"
        + "compute rot all erotate/sphere\n"
        + "dump t all custom 5 dump*.txt id type x y z vx vy vz omegaz radius mass density c_cn\n"
        + "dump v all custom/vtk 5 post/p*.vtk id type x y z vx vy vz radius c_cn\n"
        + "dump_modify t sort id pad 3\n"
        + "dump_modify v sort id\n"
        + 'fix pr all print 10 "$(c_rot)" file rot.txt screen no title none\n'
        + "run 10\n"
    )
    (tmp_path / "post").mkdir()
    run_deck(tmp_path, deck)
    assert sorted(p.name for p in tmp_path.glob("dump*.txt")) == [
        "dump000.txt",
        "dump005.txt",
        "dump010.txt",
    ]
    assert sorted(p.name for p in (tmp_path / "post").iterdir()) == ["p0.vtk", "p10.vtk", "p5.vtk"]
    [(step, table)] = read_dump(tmp_path / "dump010.txt")
    assert step == 10 and len(table) > 100
    np.testing.assert_allclose(table["density"], 2500.0)
    np.testing.assert_allclose(table["mass"], 2500 * sphere_volume(table["radius"]), rtol=1e-5)
    np.testing.assert_allclose(table[["vx", "vy", "vz"]], [[0.1, -0.2, 0.3]] * len(table))
    mesh = pv.read(tmp_path / "post" / "p10.vtk")
    assert mesh.n_points == len(table)
    assert {"id", "type", "v", "radius", "c_cn"} <= set(mesh.point_data.keys())
    assert mesh.point_data["v"].shape == (len(table), 3)
    np.testing.assert_array_equal(mesh.point_data["id"], table["id"])
    np.testing.assert_allclose(mesh.points, table[["x", "y", "z"]], rtol=1e-5, atol=1e-9)
    np.testing.assert_allclose(mesh.point_data["c_cn"], table["c_cn"])
    # Rotational energy of the inserted spheres: 1/2 (2/5 m r^2) w^2 each.
    expected = float((0.5 * 0.4 * table["mass"] * table["radius"] ** 2 * 25.0).sum())
    assert float((tmp_path / "rot.txt").read_text()) == pytest.approx(expected, rel=1e-5)
    assert not list(tmp_path.glob(".*part")) and not list((tmp_path / "post").glob(".*"))


def test_dump_every_first_and_no_duplicates(tmp_path: Path) -> None:
    deck = (
        header()
        + TEMPLATE
        + "fix ins all insert/pack seed 100001 distributiontemplate pdd1 insert_every once "
        "particles_in_region 5 region box\n"
        + "run 3\n"
        + "dump a all custom 4 a.txt id\n"
        + "dump b all custom 4 b.txt id\n"
        + "dump_modify b first yes\n"
        + "run 6\n"
        + "dump_modify a every 3\n"
        + "run 3\n"
    )
    run_deck(tmp_path, deck)
    assert [s for s, _ in read_dump(tmp_path / "a.txt")] == [4, 8, 9, 12]
    assert [s for s, _ in read_dump(tmp_path / "b.txt")] == [3, 4, 8, 12]


def test_same_seed_same_insertion(tmp_path: Path) -> None:
    def positions(seed: int, folder: str) -> str:
        (tmp_path / folder).mkdir()
        deck = (
            header()
            + TEMPLATE
            + f"fix ins all insert/pack seed {seed} distributiontemplate pdd1 insert_every once "
            "volumefraction_region 0.2 region box\n"
            + "dump d all custom 1 dump.txt id x y z\n"
            + "run 1\n"
        )
        run_deck(tmp_path / folder, deck)
        return (tmp_path / folder / "dump.txt").read_text()

    first, again, other = positions(100001, "a"), positions(100001, "b"), positions(100003, "c")
    assert first == again
    assert first != other


@pytest.mark.parametrize(
    ("line", "reason"),
    [
        ("fix t all particletemplate/sphere 1 radius gaussian 0.001 0.0001", "radius style"),
        (
            "fix ins all insert/pack seed 1 distributiontemplate pdd1 insert_every once region box",
            "exactly one of",
        ),
        ("dump d all custom 10 d.txt id xs", "dump field 'xs'"),
        ("dump d all custom/vtk 10 d.vtp id", "legacy VTK"),
        ("compute c all temp", "unknown compute style 'temp'"),
        ('fix p all print 10 "x" colour red', "unknown fix print keyword 'colour'"),
        ("fix av all ave/time 10 2 15 v_nosuch", "Nfreq must be a multiple"),
    ],
)
def test_bad_commands_name_line_and_reason(tmp_path: Path, line: str, reason: str) -> None:
    deck = header() + TEMPLATE + line + "\n"
    run = run_engine(tmp_path, deck, check=False)
    assert run.returncode != 0
    message = run.stdout + run.stderr
    assert f"in.deck:{len(deck.splitlines())}:" in message
    assert reason in message
