"""Deck control flow: `if` with `jump` loops, as used to run until a condition holds."""

import pytest

from .conftest import header, material_block, run_engine

pytestmark = pytest.mark.engine


def test_if_elif_else_and_jump_out_of_loop(tmp_path):
    deck = """variable n loop 10
label top
variable x equal ${n}*2
if "${x} > 9" then "print 'stop at ${n}'" "jump SELF done" elif "${n} == 2" "print two" &
    else "print 'n=${n}'"
next n
jump SELF top
label done
print after
"""
    out = run_engine(tmp_path, deck).stdout.splitlines()
    assert out[1:] == ["n=1", "two", "n=3", "n=4", "stop at 5", "after"]


def test_run_until_a_condition_holds(tmp_path):
    # A dissipative sphere bouncing on a wall: run in chunks until it is at rest.
    deck = (
        header(half_width=0.1, ntypes=2)
        + material_block(1e7, 0.3, 0.3, 0.5, ntypes=2)
        + """pair_style gran model hertz tangential history
pair_coeff * *
timestep 1e-5
create_atoms 1 single 0 0 0.02 units box
set atom 1 diameter 0.01 density 2500
fix floor all wall/gran model hertz tangential history primitive type 2 zplane 0.0
fix grav all gravity 9.81 vector 0 0 -1
fix integr all nve/sphere
variable ke equal ke
variable chunks loop 200
label settle
run 1000
if "${ke} < 1e-9" then "jump SELF settled"
next chunks
jump SELF settle
label settled
print "settled after ${chunks} chunks"
"""
    )
    out = run_engine(tmp_path, deck).stdout
    chunks = int(out.split("settled after ")[1].split()[0])
    assert 2 <= chunks < 200


def test_malformed_if_names_its_line(tmp_path):
    run = run_engine(tmp_path, 'print a\nif "1 > 0" "print b"\n', check=False)
    assert run.returncode == 1
    assert run.stderr.startswith("ERROR: in.deck:2: if: expected 'if")
