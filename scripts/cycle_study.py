"""Cycle-to-cycle drift of multi-cycle shear-cell decks.

Renders one deck per reference parameter set and seed in which every value of
``shear_cell.P`` runs as a cycle of one sample (as ``separate_runs: false`` does), runs them on
the bundled engine (or LIGGGHTS, ``--engine liggghts``) and writes to ``--out``:

* ``values.csv``: every cycle's readings;
* ``cycles.md``: per cycle, the pre-shear friction and bulk density over their deck's mean and
  mu_sh over the same cycle's pre-shear friction (``demcal.bulk.cycle_drift.cycle_table``),
  then the deck means per set.

``--dataset`` only tabulates the shear-cell rows of a study's ``results/bulk/dataset.csv``.
``--set KEY=VALUE`` overrides a configuration key for the decks (validated like the file).
Finished decks in ``--out`` are read back, not run again.

Example::

    python scripts/cycle_study.py --config config/config.yaml --normal-stress 1068 --seeds 3 \
        --set shear_cell.run_in_travel=2.25 --out results/cycles/run_in
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import pandas as pd  # noqa: E402

from demcal.bulk.cycle_drift import collect_cycle_values, cycle_table  # noqa: E402
from demcal.bulk.engine_comparison import (  # noqa: E402
    ENGINE_COMMANDS,
    load_status,
    plan_runs,
    run_jobs,
)
from demcal.bulk.study_options import add_study_options, study_sets, study_settings  # noqa: E402


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_study_options(parser, config="config/config.yaml", sets=["low", "middle", "high"])
    parser.add_argument("--seeds", type=int, default=3, help="decks per set")
    parser.add_argument("--normal-stress", type=float, default=1068.0, help="pre-shear, Pa")
    parser.add_argument(
        "--engine",
        choices=sorted(ENGINE_COMMANDS),
        default="engine",
        help="code that runs the decks (liggghts: LIGGGHTS 3.8, one rank)",
    )
    parser.add_argument("--parallel", type=int, default=2, help="runs at a time")
    parser.add_argument("--out", default="results/cycles", help="output directory")
    parser.add_argument(
        "--collect-only", action="store_true", help="run nothing; tabulate the finished decks"
    )
    parser.add_argument(
        "--dataset", help="tabulate this study's results/bulk/dataset.csv instead of running"
    )
    return parser.parse_args(argv)


def markdown(table: pd.DataFrame, values: pd.DataFrame | None, header: str) -> str:
    """The cycle table (and the deck means per set, when given) as Markdown."""
    lines = [header, "", "| cycle | P | decks | steady pre-shears | mu_psh / deck mean |"]
    lines[-1] += " rho_b / deck mean | mu_sh / mu_psh of the cycle |"
    lines.append("| --- | --- | --- | --- | --- | --- | --- |")
    for cycle, r in table.iterrows():
        lines.append(
            f"| {cycle:g} | {r.P:g} | {r.decks:g} | {r.steady:.0%} | "
            f"{r.psh:.3f} +- {r.psh_se:.3f} | {r.rho:.3f} +- {r.rho_se:.3f} | "
            f"{r.sh:.3f} +- {r.sh_se:.3f} |"
        )
    if values is not None:
        means = values.groupby("set", sort=False)[["mu_psh", "rho_b"]].mean()
        lines += ["", "| set | mu_psh (deck mean) | rho_b (kg/m^3, deck mean) |"]
        lines.append("| --- | --- | --- |")
        lines += [f"| {s} | {r.mu_psh:.4g} | {r.rho_b:.4g} |" for s, r in means.iterrows()]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if args.dataset:
        data = pd.read_csv(args.dataset)
        data = data[data["test"] == "shear_cell"]
        try:
            table = cycle_table(data)
        except ValueError as exc:
            raise SystemExit(f"{args.dataset}: {exc}") from None
        print(markdown(table, None, f"Shear-cell decks of {args.dataset}"))
        return 0
    settings = study_settings(args)
    if len(settings["shear_cell"]["P"]) < 2:
        raise SystemExit("shear_cell.P: a deck with cycles needs at least two values of P")
    sets = study_sets(args, settings, "quick")
    try:
        out = Path(args.out)
        # P=None: every value of shear_cell.P runs as a cycle of one deck.
        jobs = plan_runs(
            settings,
            sets,
            list(range(1, args.seeds + 1)),
            out / "cases",
            engines={args.engine: ENGINE_COMMANDS[args.engine]},
            tests=("shear_cell",),
            normal_stress=args.normal_stress,
            P=None,
            render=not args.collect_only,
        )
    except ValueError as exc:
        raise SystemExit(str(exc)) from None
    todo = [job for job in jobs if not (job.case_dir / "status.json").is_file()]
    if todo and not args.collect_only:
        print(f"{len(todo)} decks to run ({args.parallel} at a time) in {out}", flush=True)
        run_jobs(todo, parallel=args.parallel)
    values = collect_cycle_values(load_status(jobs))
    if values.empty:
        raise SystemExit(f"{out}: no finished deck")
    values.to_csv(out / "values.csv", index=False)
    header = (
        f"Config {' '.join([args.config, *args.overrides])}, {args.engine}, sets "
        f"{', '.join(sets)}, seeds "
        f"1-{args.seeds}, {args.normal_stress:g} Pa, {values['deck'].nunique()} of {len(jobs)} "
        "decks finished."
    )
    text = markdown(cycle_table(values, deck="deck"), values, header)
    (out / "cycles.md").write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
