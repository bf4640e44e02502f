"""Thread count and repeatability: 2 000 spheres settling in a walled box."""

from pathlib import Path

import numpy as np
import pytest

from demcal.engine_io.dump_file import read_dump_last

from .conftest import header, material_block, run_engine

pytestmark = pytest.mark.engine


def settling_deck(steps: int, seed: int = 5, cohesion: float | None = None) -> str:
    rng = np.random.default_rng(seed)
    spacing, nx, nz = 0.0022, 10, 20  # 10 x 10 x 20 = 2 000 spheres of radius 1 mm
    half = nx * spacing / 2
    atoms = []
    for i in range(nx):
        for j in range(nx):
            for k in range(nz):
                p = np.array(
                    [-half + (i + 0.5) * spacing, -half + (j + 0.5) * spacing, (k + 0.5) * spacing]
                ) + rng.uniform(-1e-4, 1e-4, 3)
                atoms.append(
                    "create_atoms 1 single {!r} {!r} {!r} units box".format(*map(float, p))
                )
    sjkr = " cohesion sjkr" if cohesion is not None else ""
    model = f"model hertz tangential history{sjkr} rolling_friction epsd2"
    walls = "\n".join(
        f"fix w{n} all wall/gran {model} primitive type 2 {plane} {pos!r}"
        for n, (plane, pos) in enumerate(
            [
                ("zplane", 0.0),
                ("xplane", -half),
                ("xplane", half),
                ("yplane", -half),
                ("yplane", half),
            ]
        )
    )
    return (
        header(half_width=0.05, ntypes=2, skin=2e-4).replace(
            "region box block -0.05 0.05 -0.05 0.05 -0.05 0.05",
            "region box block -0.05 0.05 -0.05 0.05 -0.01 0.09",
        )
        + material_block(5e6, 0.4, 0.6, 0.5, rolling=0.3, cohesion=cohesion, ntypes=2)
        + f"pair_style gran {model}\npair_coeff * *\ntimestep 1e-5\n"
        + "\n".join(atoms)
        + "\nset group all diameter 0.002 density 2500\n"
        + walls
        + "\nfix grav all gravity 9.81 vector 0 0 -1\nfix integr all nve/sphere\n"
        + f"dump d all custom {steps} final.dump id x y z vx vy vz\n"
        + f"thermo_style custom step atoms ke\nthermo 500\nrun {steps}\n"
    )


def _cpu_has_avx512() -> bool:
    cpuinfo = Path("/proc/cpuinfo")
    return cpuinfo.is_file() and " avx512f" in cpuinfo.read_text()


@pytest.mark.skipif(
    not _cpu_has_avx512(), reason="no AVX-512 on this CPU: the engine has only packs of 4"
)
@pytest.mark.parametrize(("threads", "cohesion"), [(1, None), (2, 2e4)])
def test_packs_of_eight_and_of_four_give_the_same_bits(tmp_path, threads, cohesion):
    # With AVX-512 the pair law runs on eight contacts at once, otherwise on four; both round
    # every operation lane by lane as one contact at a time, so every bit of the state agrees.
    fields = "x y z vx vy vz omegax omegay omegaz fx fy fz tqx tqy tqz"
    exact = " ".join(["%d"] + ["%.17g"] * len(fields.split()))
    deck = settling_deck(1500, cohesion=cohesion).replace(
        "final.dump id x y z vx vy vz\n",
        f'final.dump id {fields}\ndump_modify d sort id format "{exact}"\n',
    )
    assert "dump_modify d sort id" in deck
    wide = run_engine(tmp_path / "8", deck, threads=threads)
    narrow = run_engine(tmp_path / "4", deck, threads=threads, env={"DEM_ENGINE_NO_AVX512": "1"})
    assert "packs of 8" in wide.stdout
    assert "packs of 4" in narrow.stdout
    dump = (wide.directory / "final.dump").read_text()
    assert len(dump.splitlines()) == 2 * (9 + 2000)  # steps 0 and 1 500
    assert dump == (narrow.directory / "final.dump").read_text()


def _final(run):
    atoms = read_dump_last(run.directory / "final.dump").atoms.sort_values("id")
    return atoms[["x", "y", "z"]].to_numpy(), run.thermo()[0]["KinEng"].to_numpy()


def test_same_deck_one_thread_is_bitwise_repeatable(tmp_path):
    deck = settling_deck(1500)
    a = run_engine(tmp_path / "a", deck, threads=1)
    b = run_engine(tmp_path / "b", deck, threads=1)
    assert (a.directory / "final.dump").read_bytes() == (b.directory / "final.dump").read_bytes()


def test_same_deck_two_threads_is_bitwise_repeatable(tmp_path):
    # The split of the particles between threads depends on the contacts only, never on
    # timing, and thread sums are added in a fixed order.
    deck = settling_deck(1500)
    a = run_engine(tmp_path / "a", deck, threads=2)
    b = run_engine(tmp_path / "b", deck, threads=2)
    assert "on 2 threads" in a.stdout
    assert (a.directory / "final.dump").read_bytes() == (b.directory / "final.dump").read_bytes()


def test_one_and_two_threads_agree(tmp_path):
    deck = settling_deck(3000)
    x1, ke1 = _final(run_engine(tmp_path / "t1", deck, threads=1))
    x2, ke2 = _final(run_engine(tmp_path / "t2", deck, threads=2))
    # Thread-local force sums are added in a fixed order, so 2 threads differ from 1 only by
    # round-off, which the chaotic dynamics amplify slowly over 3 000 steps.
    assert np.abs(x1 - x2).max() < 1e-9
    assert ke2 == pytest.approx(ke1, rel=1e-6, abs=1e-12)
    assert ke1[-1] < 0.5 * ke1.max()  # the bed did settle


@pytest.mark.parametrize(
    ("dt", "message"),
    [("2.5e-4", "unstable simulation at step"), ("4e-4", "particles through a fixed boundary")],
)
def test_failing_run_reports_the_same_on_one_and_two_threads(tmp_path, dt, message):
    # Each thread checks its own share of the particles for speeds, non-finite values and
    # particles outside the box; the error must still be the one of a serial scan (the first
    # particle at fault in index order, the same count of lost particles).
    deck = settling_deck(200).replace("timestep 1e-5", f"timestep {dt}")
    errors = []
    for threads in (1, 2):
        run = run_engine(tmp_path / f"t{threads}", deck, threads=threads, check=False)
        assert run.returncode == 1
        errors.append(run.stderr.strip().splitlines()[-1])
    assert message in errors[0], errors[0]
    assert errors[1] == errors[0]


@pytest.mark.parametrize("threads", [1, 2])
def test_force_hooks_run_in_fix_order(tmp_path, threads):
    # post_force hooks run in the order the fixes were defined, also when several of them run
    # in one parallel region: freeze defined last zeroes gravity too (nothing moves); defined
    # first, it zeroes only the pair forces, and gravity and the walls act after it. LIGGGHTS
    # 3.8 gives the same on these decks (kinetic energy 0 and 8.956e-6 J at step 300).
    deck = settling_deck(300)
    last = deck.replace(
        "fix integr all nve/sphere\n", "fix integr all nve/sphere\nfix hold all freeze\n"
    )
    first = deck.replace("fix w0 all", "fix hold all freeze\nfix w0 all")
    ke_last = run_engine(tmp_path / "last", last, threads=threads).thermo()[0]["KinEng"]
    ke_first = run_engine(tmp_path / "first", first, threads=threads).thermo()[0]["KinEng"]
    assert ke_last.max() == 0.0
    # 2 000 spheres of 1 mm (10.5 mg each) falling for 3 ms: KE = m N (g t)^2 / 2, less that of
    # the few that start on the floor (their random offsets reach it).
    mass = 2500 * 4 / 3 * np.pi * 0.001**3
    free_fall = 0.5 * mass * 2000 * (9.81 * 3e-3) ** 2
    assert 0.95 * free_fall < ke_first.iloc[-1] <= free_fall * (1 + 1e-9)
