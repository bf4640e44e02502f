"""Fuzz the engine with seeded mutations of the project's tiny decks.

Renders the shear cell, angle of repose and chute cooler decks of ``config/tiny.yaml`` once,
makes ``--cases`` mutated copies (dropped, duplicated and swapped lines, numbers replaced by 0,
negative, 1e300, nan, inf or text, truncated lines, random tokens), caps every ``run N`` at
``--max-steps`` steps and runs the engine on each, two at a time. Prints the outcome counts
(ok, rejected with ``ERROR: FILE:LINE:``, and the failures crash, hang, unlocated, internal)
and keeps every failing case, with its meshes, under ``--out`` for reproduction. Exit status
1 when any case failed.

Example::

    python scripts/fuzz_decks.py --cases 2000 --seed 1 --out fuzz_failures
"""

from __future__ import annotations

import argparse
import shlex
import shutil
import sys
import tempfile
import time
from pathlib import Path

from demcal.robustness.deck_fuzz import failures, fuzz, summary_table

ROOT = Path(__file__).resolve().parents[1]


def default_engine() -> str:
    """The venv's engine, else the build tree's, else ``dem_engine`` on PATH."""
    places = (ROOT / ".venv" / "bin" / "dem_engine", ROOT / "build" / "engine" / "dem_engine")
    for candidate in places:
        if candidate.is_file():
            return str(candidate)
    return shutil.which("dem_engine") or "dem_engine"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=1000, help="mutated decks (default 1000)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the mutations (default 0)")
    parser.add_argument(
        "--timeout", type=float, default=20.0, help="time limit per case in seconds (default 20)"
    )
    parser.add_argument(
        "--max-steps",
        type=int,
        default=20,
        help="cap on the step count of every `run` (default 20)",
    )
    parser.add_argument("--jobs", type=int, default=2, help="engine runs at a time (default 2)")
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("fuzz_failures"),
        help="directory for failing cases (default fuzz_failures)",
    )
    parser.add_argument(
        "--engine", default=None, help="engine command (default: the venv's dem_engine)"
    )
    parser.add_argument(
        "--work",
        type=Path,
        default=None,
        help="work directory (default: a temporary one, removed at the end)",
    )
    args = parser.parse_args(argv)

    engine = shlex.split(args.engine) if args.engine else [default_engine()]
    start = time.monotonic()
    done = 0

    def progress(_outcome: object) -> None:
        nonlocal done
        done += 1
        if done % 500 == 0:
            print(f"{done}/{args.cases} cases, {time.monotonic() - start:.0f} s", flush=True)

    with tempfile.TemporaryDirectory(prefix="fuzz_decks_") as tmp:
        work = args.work or Path(tmp)
        outcomes = fuzz(
            args.cases,
            args.seed,
            work,
            engine,
            args.timeout,
            args.max_steps,
            args.jobs,
            args.out,
            progress,
        )
    wall = time.monotonic() - start
    print(summary_table(outcomes))
    print(
        f"{len(outcomes)} cases, seed {args.seed}, max steps {args.max_steps}, "
        f"timeout {args.timeout:g} s, {args.jobs} jobs, wall time {wall:.0f} s"
    )
    bad = failures(outcomes)
    for o in bad[:50]:
        print(
            f"{o.kind}: case {o.index} ({o.base}) exit {o.returncode}: {'; '.join(o.mutations)}"
            f"\n    {o.last_error or o.stderr_tail.strip()[-300:]}"
        )
    if bad:
        print(f"{len(bad)} failing cases kept under {args.out}/")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
