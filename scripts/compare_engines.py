"""Bulk values of the bundled engine against LIGGGHTS 3.8: same decks, several seeds.

Renders the shear cell (one load condition) and the angle of repose for a few parameter sets
and seeds, runs every deck on each engine (one thread / one rank), extracts mu_psh, mu_sh,
rho_b and aor, and compares the seed means per engine with Welch's t-test, Bonferroni-corrected
so that the family-wise false-alarm rate is ``--alpha``. Writes ``values.csv`` (every run),
``comparison.csv`` and ``comparison.md`` (the table) to ``--out`` and prints the table.
``--set SECTION.KEY=VALUE`` overrides a configuration key for every deck (validated like the
file).

Example::

    python scripts/compare_engines.py --config config/tiny.yaml --seeds 4 \
        --sets low middle cohesion --out results/engine_comparison/tiny
    python scripts/compare_engines.py --config config/tiny.yaml --seeds 6 --sets \
        --extra-set wet=coefficientFriction:0.57,coefficientRollingFriction:0,\
coefficientRestitution:0.7,density:2800,cohesionEnergyDensity:5.6e4 \
        --out results/engine_comparison/wet
"""

from __future__ import annotations

import argparse
import hashlib
import os
import shutil
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from demcal.bulk.engine_comparison import (  # noqa: E402
    ENGINE_COMMANDS,
    collect_values,
    load_status,
    plan_runs,
    run_jobs,
)
from demcal.bulk.engine_statistics import (  # noqa: E402
    compare_engines,
    markdown_table,
)
from demcal.bulk.study_options import add_study_options, study_sets, study_settings  # noqa: E402


def freeze_engine(out: Path) -> tuple[str, str]:
    """Copy the engine binary into ``out/bin`` and describe the build.

    Returns
    -------
    tuple of str
        The command template with the copy's full path, and ``sha256 ..., built <mtime> UTC``.
    """
    template = ENGINE_COMMANDS["engine"]
    program = template.split()[0]
    search = os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])
    found = shutil.which(program, path=search)
    if found is None:
        raise SystemExit(f"{program} not found (run `make engine`)")
    data = Path(found).read_bytes()
    built = datetime.fromtimestamp(Path(found).stat().st_mtime, UTC)
    copy = out / "bin" / program
    copy.parent.mkdir(parents=True, exist_ok=True)
    copy.write_bytes(data)
    copy.chmod(0o755)
    digest = hashlib.sha256(data).hexdigest()[:12]
    describe = f"{found}, sha256 {digest}, built {built:%Y-%m-%d %H:%M:%S} UTC"
    return template.replace(program, str(copy.resolve()), 1), describe


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_study_options(parser, config="config/tiny.yaml", sets=["low", "middle", "cohesion"])
    parser.add_argument("--seeds", type=int, default=4, help="seeds per engine, set and test")
    parser.add_argument(
        "--first-seed", type=int, default=1, help="seeds are first-seed, first-seed + 1, ..."
    )
    parser.add_argument(
        "--engines",
        nargs="*",
        default=["liggghts", "engine"],
        help="engines to run now (liggghts, engine; none: only compare earlier runs in --out)",
    )
    parser.add_argument(
        "--compare",
        nargs=2,
        default=["liggghts", "engine"],
        metavar=("REFERENCE", "OTHER"),
        help="the two engines compared, from the runs in --out (difference OTHER - REFERENCE)",
    )
    parser.add_argument(
        "--tests",
        nargs="+",
        default=["shear_cell", "angle_of_repose"],
        help="virtual tests to run",
    )
    parser.add_argument("--normal-stress", type=float, default=None, help="pre-shear stress, Pa")
    parser.add_argument("--P", type=float, default=0.8, help="shear / pre-shear load ratio")
    parser.add_argument("--alpha", type=float, default=0.01, help="family-wise significance")
    parser.add_argument("--parallel", type=int, default=2, help="runs at a time")
    parser.add_argument("--threads", type=int, default=1, help="threads per engine run")
    parser.add_argument("--out", default="results/engine_comparison", help="output directory")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    settings = study_settings(args)
    sets = study_sets(args, settings, "tiny")
    names = set(args.engines) | set(args.compare)
    if any(e not in ENGINE_COMMANDS for e in names):
        raise SystemExit(f"engines must be among {sorted(ENGINE_COMMANDS)}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    seeds = list(range(args.first_seed, args.first_seed + args.seeds))
    engines = {name: ENGINE_COMMANDS[name] for name in args.engines}
    if "engine" in engines:
        # A private copy of the engine binary, so that a rebuild during the runs cannot mix
        # two builds in one comparison.
        engines["engine"], build = freeze_engine(out)
        (out / "engine_build.txt").write_text(build + "\n")
    started = datetime.now(UTC)
    t0 = time.monotonic()
    options = {
        "tests": args.tests,
        "normal_stress": args.normal_stress,
        "P": args.P,
    }
    if engines:
        jobs = plan_runs(settings, sets, seeds, out / "cases", engines=engines, **options)
        print(f"{len(jobs)} runs ({args.parallel} at a time) in {out / 'cases'}", flush=True)
        run_jobs(jobs, parallel=args.parallel, threads=args.threads)
    compared = {name: ENGINE_COMMANDS[name] for name in args.compare}
    jobs = load_status(
        plan_runs(settings, sets, seeds, out / "cases", engines=compared, render=False, **options)
    )
    values = collect_values(jobs)
    values.to_csv(out / "values.csv", index=False)
    comparison = compare_engines(
        values, reference=args.compare[0], other=args.compare[1], alpha=args.alpha
    )
    comparison.table.to_csv(out / "comparison.csv", index=False)
    wall = time.monotonic() - t0
    bad = values[values["status"] != "ok"].drop_duplicates(["set", "engine", "seed", "test"])
    stress = args.normal_stress or settings["shear_cell"]["normal_stresses"][0]
    text = (
        f"Config {' '.join([args.config, *args.overrides])}, sets {', '.join(sets)}, "
        f"seeds {seeds}, shear cell at "
        f"{stress:g} Pa and P = {args.P:g}; started {started:%Y-%m-%d %H:%M} UTC, "
        f"wall time of this call {wall / 60:.1f} min ({len(jobs)} runs compared).\n"
    )
    build_file = out / "engine_build.txt"
    if build_file.is_file():
        text += f"Engine build: {build_file.read_text().strip()}.\n"
    text += "\n" + markdown_table(comparison)
    if len(bad):
        text += "\nRuns without values:\n\n" + "\n".join(
            f"- {r.set} {r.test} seed {r.seed} {r.engine}: {r.status}" for r in bad.itertuples()
        )
        text += "\n"
    (out / "comparison.md").write_text(text)
    print(text)
    return 0 if comparison.all_passed else 1


if __name__ == "__main__":
    raise SystemExit(main())
