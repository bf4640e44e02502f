"""Per-contact output parity of dem_engine with LIGGGHTS 3.8: ``compute pair/gran/local`` with
every keyword, written by ``dump local``.

Each case is a small deterministic deck (3-4 particles on a wall under gravity, sliding and
spinning, one case with contacts across a periodic boundary) that both programs run. The two
local dumps must have the same layout (every line but the rows identical, rows ending with a
blank) and, at every snapshot, the same contacts (matched by the pair of ids, whatever the row
order) with every value equal to REL_TOL relative to the LIGGGHTS value; values below FLOOR times
the largest magnitude of the same column in the snapshot are compared against that floor (as in
test_contact_parity).

LIGGGHTS evaluates the contact law again when the compute is read (end of step: full-step
velocities, stored history not advanced), and takes the second particle of a pair across a
periodic boundary from its ghost (velocities of the force evaluation); dem_engine does the same,
which these cases check.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from demcal.engine_io.local_dump import pair_gran_local_columns, read_local_dump

from .test_contact_parity import (
    DT,
    RADIUS,
    deck_header,
    gravity,
    model,
    particle,
    run_engine,
    run_reference,
)

pytestmark = pytest.mark.liggghts

REL_TOL = 1e-6
FLOOR = 1e-3
KEYWORDS = [
    "pos",
    "vel",
    "id",
    "force",
    "force_normal",
    "force_tangential",
    "torque",
    "history",
    "contactArea",
    "delta",
]
NAMES = pair_gran_local_columns(KEYWORDS, history_size=6)  # rolling_friction epsd2
# Columns that change sign, or swap with the other particle's, when a pair is listed the other
# way round; torque (on the first particle) cannot be converted and is compared only for pairs
# listed the same way.
SWAP = {"x1": "x2", "y1": "y2", "z1": "z2", "vx1": "vx2", "vy1": "vy2", "vz1": "vz2"}
SWAP |= {v: k for k, v in SWAP.items()}
NEGATE = {"fx", "fy", "fz", "fnx", "fny", "fnz", "ftx", "fty", "ftz"} | {
    f"h{k}" for k in range(1, 7)
}
EVERY = 50
STEPS = 400


def contact_deck(body: str, periodic: bool = False) -> str:
    """Materials, walls, `body` (particles), gravity, the compute, the local dump and the run."""
    header = deck_header()
    if periodic:
        header = header.replace("boundary f f f", "boundary p p f")
    columns = " ".join(f"c_c[{k}]" for k in range(1, len(NAMES) + 1))
    fmt = " ".join(["%.17g"] * len(NAMES))
    return (
        header
        + f"pair_style gran {model()}\npair_coeff * *\ntimestep {DT!r}\n"
        + f"fix w all wall/gran {model()} primitive type 2 zplane 0.0\n"
        + body
        + gravity(9.81, (0.0, 0.0, -1.0))
        + "fix integr all nve/sphere\n"
        + f"compute c all pair/gran/local {' '.join(KEYWORDS)}\n"
        + f"dump d all local {EVERY} contacts.txt {columns}\n"
        + f'dump_modify d format "{fmt}"\n'
        + f"run {STEPS}\n"
    )


R = RADIUS
SPIN = {"omegax": 20.0, "omegay": -50.0, "omegaz": 10.0}

CASES = {
    # Particle 1 on the wall touches 3 and 4 beside it and 2 above it; all slide and spin.
    "stack": contact_deck(
        particle(1, 1, (0.0, 0.0, 0.99 * R), vx=0.01, omegay=30.0)
        + particle(2, 2, (0.2 * R, 0.1 * R, 2.97 * R), vy=0.02, omegax=-20.0)
        + particle(3, 1, (1.99 * R, 0.0, 0.99 * R), **SPIN)
        + particle(4, 2, (1.0 * R, 1.72 * R, 0.99 * R), vx=-0.02)
    ),
    # Particles 1 and 2 touch across the periodic x boundary, particle 3 rests on both.
    "periodic": contact_deck(
        particle(1, 1, (9.9 * R, 0.0, 0.99 * R), vx=0.02, **SPIN)
        + particle(2, 2, (-8.11 * R, 0.0, 0.99 * R), vy=-0.01)
        + particle(3, 1, (-9.105 * R, 0.0, 0.99 * R + math.sqrt(1.99**2 - 0.995**2) * R))
        + "",
        periodic=True,
    ),
}


def layout(path: Path) -> list[str]:
    """Every line of a local dump but the rows (which must end with a blank)."""
    lines = path.read_text().splitlines()
    kept, k = [], 0
    while k < len(lines):
        n = int(lines[k + 3])
        kept += lines[k : k + 9]
        rows = lines[k + 9 : k + 9 + n]
        assert all(row.endswith(" ") for row in rows), f"{path}: a row lacks the final blank"
        k += 9 + n
    return kept


def contacts(frame) -> dict[frozenset[int], dict[str, float]]:
    """Rows of one snapshot by the (unordered) pair of ids, with the column names of NAMES."""
    rows = {}
    for values in frame.to_numpy():
        row = dict(zip(NAMES, values.tolist(), strict=True))
        rows[frozenset((int(row["id1"]), int(row["id2"])))] = row
    return rows


def as_listed(row: dict[str, float], first: int) -> dict[str, float]:
    """`row` with `first` as particle 1 (converted when it is listed the other way)."""
    if int(row["id1"]) == first:
        return row
    out = {SWAP.get(k, k): (-v if k in NEGATE else v) for k, v in row.items()}
    out["id1"], out["id2"] = row["id2"], row["id1"]
    return out


@pytest.mark.parametrize("name", sorted(CASES))
def test_local_dump_matches_liggghts(name: str, tmp_path: Path) -> None:
    deck = CASES[name]
    ok, out = run_reference(tmp_path / "liggghts", deck, {})
    assert ok, out
    ok, out = run_engine(tmp_path / "engine", deck, {})
    assert ok, out
    ours_path = tmp_path / "engine" / "contacts.txt"
    ref_path = tmp_path / "liggghts" / "contacts.txt"
    assert layout(ours_path) == layout(ref_path)
    ours, ref = read_local_dump(ours_path), read_local_dump(ref_path)
    assert [s for s, _ in ours] == [s for s, _ in ref] == list(range(0, STEPS + 1, EVERY))

    worst, where, same_way, periodic_rows = 0.0, "nothing differs", 0, 0
    for (step, a_frame), (_, b_frame) in zip(ours, ref, strict=True):
        a, b = contacts(a_frame), contacts(b_frame)
        assert sorted(map(sorted, a)) == sorted(map(sorted, b)), f"step {step}: other contacts"
        scale = {c: max(abs(row[c]) for row in b.values()) for c in NAMES} if b else {}
        for pair, ref_row in b.items():
            row = as_listed(a[pair], int(ref_row["id1"]))
            same_way += a[pair]["id1"] == ref_row["id1"]
            periodic_rows += ref_row["periodic"] == 1.0
            assert row["periodic"] == ref_row["periodic"], f"step {step}, pair {sorted(pair)}"
            for c in NAMES:
                if c.startswith("tq") and a[pair]["id1"] != ref_row["id1"]:
                    continue
                diff = abs(row[c] - ref_row[c])
                if diff == 0.0:
                    continue
                denominator = max(abs(ref_row[c]), FLOOR * scale[c])
                rel = diff / denominator if denominator > 0.0 else math.inf
                if rel > worst:
                    worst = rel
                    where = (
                        f"step {step}, pair {sorted(pair)}, {c}: engine {row[c]!r}, "
                        f"LIGGGHTS {ref_row[c]!r}"
                    )
    assert worst <= REL_TOL, where

    # The cases reach what they are for (checked on the LIGGGHTS output).
    rows = [row for _, frame in ref for row in contacts(frame).values()]
    assert max(len(contacts(frame)) for _, frame in ref) >= 2, "never two contacts at once"
    assert any(abs(row["h1"]) + abs(row["h2"]) > 0.0 for row in rows), "no tangential spring"
    assert any(abs(row["h4"]) + abs(row["h5"]) > 0.0 for row in rows), "no rolling torque"
    assert any(math.hypot(row["ftx"], row["fty"]) > 0.0 for row in rows), "no tangential force"
    # Before LIGGGHTS sorts its particles in memory (every 1000 steps) both list each pair the
    # same way round: the smaller id first, the larger one across a periodic boundary.
    assert same_way == len(rows)
    if name == "periodic":
        assert periodic_rows >= len(ref), "no contact across the periodic boundary"
