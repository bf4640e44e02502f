"""Convergence study of the virtual bulk tests at a profile's settings.

Varies one numerical setting at a time (see ``demcal.bulk.convergence.FACTORS``) around the
configuration, for reference parameter sets (low, middle, high friction) and several seeds, runs
every deck on the bundled engine and writes to ``--out``:

* ``values.csv``: every run's bulk values and status;
* ``summary.csv``: seed mean, sd and deviation from the most refined level per factor level;
* ``convergence.md``: the summary as tables, with the cheapest converged level per factor;
* ``<factor>.png``: each bulk value against the factor, seed sd as error bars.

``--set SECTION.KEY=VALUE`` overrides a configuration key for every deck (validated like the
file), e.g. ``shear_cell.contact_snapshots=25`` for the readout cross-check
(``scripts/readout_check.py``). Runs already finished in ``--out`` are not run again (delete a
case directory to redo it), so an interrupted study continues where it stopped.

Example::

    python scripts/convergence_study.py --config config/config.yaml --seeds 2 \
        --factors shear_dCylDp shear_speed aor_dCylDp --out results/convergence/quick
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from demcal.bulk.convergence import (  # noqa: E402
    FACTORS,
    Factor,
    plan_study,
    quantities_of,
    restrict_levels,
    summarise,
)
from demcal.bulk.engine_comparison import (  # noqa: E402
    ENGINE_COMMANDS,
    collect_values,
    load_status,
    run_jobs,
)
from demcal.bulk.study_options import add_study_options, study_sets, study_settings  # noqa: E402
from demcal.core.parameters import PARAMETERS  # noqa: E402


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_study_options(
        parser,
        config="config/config.yaml",
        sets=["low", "middle", "high"],
        extra_set_help="a further parameter set, e.g. where a calibration landed",
    )
    parser.add_argument("--factors", nargs="+", default=list(FACTORS), help="factors to vary")
    parser.add_argument(
        "--levels",
        type=float,
        nargs="+",
        help="run only these levels of every factor named (the most refined of them is the "
        "reference), e.g. --factors aor_dCylDp --levels 9 14",
    )
    parser.add_argument("--seeds", type=int, default=3, help="seeds per level and set")
    parser.add_argument("--normal-stress", type=float, default=10070.0, help="pre-shear, Pa")
    parser.add_argument("--P", type=float, default=0.6, help="shear / pre-shear load ratio")
    parser.add_argument("--parallel", type=int, default=2, help="runs at a time")
    parser.add_argument("--threads", type=int, default=1, help="threads per run")
    parser.add_argument("--out", default="results/convergence", help="output directory")
    parser.add_argument(
        "--collect-only",
        action="store_true",
        help="run nothing; summarise the runs finished so far (the rest count as not run)",
    )
    return parser.parse_args(argv)


def _plot(summary: pd.DataFrame, name: str, label: str, path: Path) -> None:
    rows = summary[summary["factor"] == name]
    quantities = [q for q in ("mu_psh", "mu_sh", "rho_b", "aor") if q in set(rows["quantity"])]
    fig, axes = plt.subplots(1, len(quantities), figsize=(4.2 * len(quantities), 3.4))
    axes = [axes] if len(quantities) == 1 else list(axes)
    for ax, quantity in zip(axes, quantities, strict=True):
        for set_name, group in rows[rows["quantity"] == quantity].groupby("set"):
            group = group.sort_values("level")
            ax.errorbar(
                group["level"],
                group["mean"],
                yerr=group["sd"].fillna(0.0),
                marker="o",
                capsize=3,
                label=str(set_name),
            )
        ax.set_xlabel(label)
        ax.set_ylabel(quantity)
    axes[0].legend(title="set")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _set_text(params: dict[str, float]) -> str:
    return "(" + ", ".join(f"{PARAMETERS[k].symbol} {v:g}" for k, v in params.items()) + ")"


def _markdown(summary: pd.DataFrame, header: str, factors: dict[str, Factor]) -> str:
    lines = [header, ""]
    for name, rows in summary.groupby("factor", sort=False):
        factor = factors[str(name)]
        lines += [f"### {name}: {factor.label}", ""]
        lines += [
            "| level | set | quantity | n | mean | sd | deviation (+- 1 se) | within tolerance |"
            " beyond seed noise |"
        ]
        lines += ["| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for r in rows.sort_values(["quantity", "set", "level"]).itertuples():
            if r.quantity == "aor":
                dev = f"{r.deviation:+.1f} (+-{r.deviation_se:.1f}) deg"
            else:
                dev = f"{100 * r.deviation:+.1f} (+-{100 * r.deviation_se:.1f}) %"
            lines.append(
                f"| {r.level:g} | {r.set} | {r.quantity} | {r.n} | {r.mean:.4g} | "
                f"{r.sd:.2g} | {dev} | {'yes' if r.converged else 'no'} | "
                f"{'yes' if r.resolved else 'no'} |"
            )
        ok = rows.groupby("level")["converged"].all()
        cheapest = [float(level) for level, good in ok.items() if good]
        order = [factor.level_value(level) for level in factor.levels]
        first = next(
            (
                v
                for v in order
                if v in cheapest and all(w in cheapest for w in order[order.index(v) :])
            ),
            None,
        )
        if first is None or first == order[-1]:
            verdict = (
                f"No level cheaper than the reference ({order[-1]:g}) is within tolerance for "
                "every set and bulk value: not converged over the levels tried."
            )
        else:
            verdict = (
                "Cheapest level within tolerance for every set and bulk value, and every more "
                f"refined level too: **{first:g}** (reference {order[-1]:g})."
            )
        lines += ["", verdict, "", f"![{name}]({name}.png)", ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    unknown = [f for f in args.factors if f not in FACTORS]
    if unknown:
        raise SystemExit(f"unknown factors {unknown}; choose from {sorted(FACTORS)}")
    settings = study_settings(args)
    sets = study_sets(args, settings, "quick")
    chosen = {name: FACTORS[name] for name in args.factors}
    if args.levels:
        try:
            chosen = {name: restrict_levels(f, args.levels) for name, f in chosen.items()}
        except ValueError as exc:
            raise SystemExit(f"--levels: {exc}") from None
    factors = list(chosen.values())
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    seeds = list(range(1, args.seeds + 1))
    options = {
        "normal_stress": args.normal_stress,
        "P": args.P,
        "command": ENGINE_COMMANDS["engine"],
    }
    started = datetime.now(UTC)
    t0 = time.monotonic()
    try:
        planned = plan_study(
            settings, sets, factors, seeds, out / "cases", render=not args.collect_only, **options
        )
    except ValueError as exc:
        raise SystemExit(str(exc)) from None
    unique = {job.case_dir: job for job, _, _ in planned}
    jobs = [job for d, job in unique.items() if not (d / "status.json").is_file()]
    if jobs and not args.collect_only:
        print(f"{len(jobs)} runs to do ({args.parallel} at a time) in {out / 'cases'}", flush=True)
        run_jobs(jobs, parallel=args.parallel, threads=args.threads)
    load_status(list(unique.values()))
    frames = []
    for job, name, overrides in planned:
        values = collect_values([job])
        values["factor"] = name
        values["level"] = chosen[name].level_value(overrides)
        values["overrides"] = json.dumps(dict(overrides), sort_keys=True)
        frames.append(values[values["quantity"].isin(quantities_of(job.test))])
    values = pd.concat(frames, ignore_index=True)
    values.to_csv(out / "values.csv", index=False)
    summary = summarise(values, chosen)
    summary.to_csv(out / "summary.csv", index=False)
    for factor in factors:
        if factor.name in set(summary["factor"]):
            _plot(summary, factor.name, factor.label, out / f"{factor.name}.png")
    failed = values[values["status"] != "ok"].drop_duplicates(["factor", "level", "set", "seed"])
    header = (
        f"Config {' '.join([args.config, *args.overrides])}, sets "
        + ", ".join(f"{name} {_set_text(params)}" for name, params in sets.items())
        + f", seeds {seeds}, shear cell at "
        f"{args.normal_stress:g} Pa and P = {args.P:g}; started {started:%Y-%m-%d %H:%M} UTC, "
        f"wall time of this call {(time.monotonic() - t0) / 60:.1f} min, "
        f"{len(unique)} distinct runs, {len(failed)} without values."
    )
    text = _markdown(summary, header, chosen)
    if len(failed):
        text += "\nRuns without values:\n\n" + "\n".join(
            f"- {r.factor} = {r.level:g}, {r.set}, seed {r.seed}: {r.status}"
            for r in failed.itertuples()
        )
    (out / "convergence.md").write_text(text + "\n")
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
