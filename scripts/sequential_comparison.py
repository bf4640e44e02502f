"""Compare sequential and one-shot calibration on synthetic materials with a known truth.

For every truth specification (--spec; default the synthetic reference material and one with
drawn parameters) the truth is run --replicates times on --truth-engine (default LIGGGHTS
3.8 when installed) at the scale of --profile. The mean of the runs with --noise (default 1 %)
is written as the measurements: the shear-cell readings --observables (default mu_psh and
rho_b) at the load fractions --P (default 1, every stress) and the angle of repose, as in the
shipped synthetic reference data. (mu_sh at every load adds twelve values that scatter by 1-10 %
per quick run, so a 5 % acceptance of every one would mostly measure the scatter.) Then, in
directories of their own under OUT/<material>/:

* ``sequential/``: the study of --profile with --sequential on top (rounds, stopping rule,
  budget the largest of --budgets); every round is one point (its verification included);
* ``oneshot_<B>/``: for each budget B of --budgets, a one-shot Sobol' design of as many sets
  as B allows after one verification, screened and verified like the default study. The Sobol'
  designs of the budgets are nested, so the DEM runs of a smaller budget are reused by the next.
  The designs do not depend on the material, so a later material copies its one-shot cases
  from the earlier one's (counted as spent all the same: the copy only saves the driver time).

Writes OUT/comparison.csv, OUT/comparison.md (the table, with the command) and
OUT/comparison.png (error against DEM runs for both designs). Resumable: finished studies and
truth runs are read back, not run again, and an interrupted study continues (the driver unlocks
its own study directories, so do not run two drivers on the same OUT).

Usage: python scripts/sequential_comparison.py --out results/sequential_comparison \\
    [--profile config/config.yaml] [--sequential config/sequential.yaml] \\
    [--budgets 44 72 100] [--spec FILE ...] [--truth-engine "liggghts -in {deck}"] \
    [--observables mu_psh,rho_b] [--P 1.0] [--noise 0.01]
"""

from __future__ import annotations

import argparse
import copy
import shlex
import shutil
import sys
from pathlib import Path
from typing import Any

import pandas as pd
import yaml

from demcal.bulk.synthetic import replicate_record
from demcal.core.config import validate_config
from demcal.core.experiments import load_experiment
from demcal.core.snakemake_run import run_snakemake
from demcal.discrepancy.candidates import deep_merge
from demcal.discrepancy.synthetic import hidden_effect_bulk, write_truth
from demcal.discrepancy.truths import DrawnTruth, draw_truth, load_truth_spec
from demcal.engine_io.run import installed_liggghts
from demcal.sequential.comparison import (
    comparison_figure,
    comparison_markdown,
    oneshot_row,
    oneshot_sets,
    reuse_cases,
    sequential_rows,
    truth_row,
)
from demcal.sequential.rounds import design_ranges

ROOT = Path(__file__).resolve().parents[1]
TRUTHS = ROOT / "config" / "experiments" / "truth"
DEFAULT_SPECS = [TRUTHS / "synthetic_reference.yaml", TRUTHS / "synthetic_drawn.yaml"]
EXPERIMENT = "config/experiments/measured.yaml"


def write_if_changed(path: Path, text: str) -> None:
    """Write ``text`` unless the file already holds it: an unchanged file keeps its time stamp,
    so that a resumed study does not redo the steps that read it."""
    if not (path.is_file() and path.read_text() == text):
        path.write_text(text)


def write_study_config(work: Path, config: dict[str, Any], experiment: Path) -> dict[str, Any]:
    """Write a study directory's configuration and measurements; return it validated."""
    (work / "config" / "experiments").mkdir(parents=True, exist_ok=True)
    write_if_changed(work / EXPERIMENT, experiment.read_text())
    config = {**config, "experiment": EXPERIMENT}
    path = work / "config" / "config.yaml"
    write_if_changed(path, yaml.safe_dump(config, sort_keys=False))
    return validate_config(copy.deepcopy(config), str(path))


def run_truth(
    truth: DrawnTruth,
    config: dict[str, Any],
    bulk_file: Path,
    replicates: int,
    engine: str | None,
    cores: int,
) -> pd.DataFrame:
    """Bulk values of both tests at the truth, kept in ``bulk_file`` (read back when there)."""
    if not bulk_file.is_file():
        runs = bulk_file.with_suffix("")
        bulk = hidden_effect_bulk(
            truth,
            config,
            runs,
            tests=("shear_cell", "angle_of_repose"),
            workers=cores,
            replicates=replicates,
            engine_command=engine,
        )
        bulk.to_csv(bulk_file, index=False)
        shutil.rmtree(runs)
    return pd.read_csv(bulk_file)


def engine_truth_row(
    spec: Path, config: dict[str, Any], mdir: Path, experiment: Path, args: argparse.Namespace
) -> dict[str, Any]:
    """The truth run like a verification on the engine under calibration (the error floor)."""
    validated = validate_config(copy.deepcopy(config), str(spec))
    seeds = int(validated["verification"]["seeds"])
    truth = draw_truth(load_truth_spec(spec), validated, args.truth_seed, str(spec))
    bulk = run_truth(truth, validated, mdir / "engine_truth_bulk.csv", seeds, None, args.cores)
    measured = load_experiment(experiment)
    return truth_row(
        measured.material,
        bulk,
        measured,
        {k: float(v) for k, v in truth.parameters.items()},
        design_ranges(validated),
        float(validated["screening"]["tolerance"]),
        f"{seeds} seeds, `{validated['engine']['command']}`",
    )


def make_measurements(
    spec: Path, config: dict[str, Any], mdir: Path, args: argparse.Namespace
) -> tuple[Path, dict[str, float]]:
    """The material's truth and measurements (kept when they exist).

    The truth runs' bulk values are kept in ``truth_bulk.csv``, so that measurements of other
    observables or noise can be made from them without running the truth again.
    """
    experiment, truth_file = mdir / "measured.yaml", mdir / "truth.yaml"
    bulk_file = mdir / "truth_bulk.csv"
    validated = validate_config(copy.deepcopy(config), str(spec))
    if not (bulk_file.is_file() and truth_file.is_file()):
        truth = draw_truth(load_truth_spec(spec), validated, args.truth_seed, str(spec))
        run_truth(truth, validated, bulk_file, args.replicates, args.truth_engine, args.cores)
        write_truth(mdir, truth)
    truth = yaml.safe_load(truth_file.read_text())
    if not experiment.is_file():
        observables = args.observables.split(",")
        p_values = [float(p) for p in args.P.split(",")]
        noise = {name: args.noise for name in (*observables, "aor")}
        record = replicate_record(
            pd.read_csv(bulk_file),
            truth["material"],
            noise,
            args.truth_seed,
            f"`{args.truth_engine or validated['engine']['command']}` at the truth "
            f"({validated['profile']} profile, drawn with seed {args.truth_seed}), mean of "
            f"{args.replicates} runs, {', '.join(observables)} at P = {args.P} and the angle "
            f"of repose, noise {args.noise:.1%}",
            observables=observables,
            p_values=p_values,
        )
        experiment.write_text(yaml.safe_dump(record, sort_keys=False))
    return experiment, {k: float(v) for k, v in truth["parameters"].items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, type=Path, help="directory of the comparison")
    parser.add_argument("--profile", type=Path, default=ROOT / "config" / "config.yaml")
    parser.add_argument("--sequential", type=Path, default=ROOT / "config" / "sequential.yaml")
    parser.add_argument("--budgets", type=int, nargs="+", default=[44, 72, 100])
    parser.add_argument("--spec", type=Path, nargs="*", help="truth specifications")
    parser.add_argument("--truth-seed", type=int, default=1, help="seed of truth draw and noise")
    parser.add_argument("--truth-engine", default=installed_liggghts())
    parser.add_argument("--replicates", type=int, default=3, help="truth runs per test")
    parser.add_argument(
        "--observables", default="mu_psh,rho_b", help="shear-cell readings taken as measured"
    )
    parser.add_argument("--P", default="1.0", help="load fractions taken as measured")
    parser.add_argument("--noise", type=float, default=0.01, help="relative measurement noise")
    parser.add_argument("--cores", type=int, default=2)
    args = parser.parse_args()
    budgets = sorted(set(args.budgets))
    base = deep_merge(
        yaml.safe_load(args.profile.read_text()) or {},
        yaml.safe_load(args.sequential.read_text()) or {},
    )
    base.pop("experiment", None)
    seq_config = deep_merge(base, {"sequential": {"budget": budgets[-1]}})
    args.out.mkdir(parents=True, exist_ok=True)
    command = "python " + " ".join(shlex.quote(a) for a in sys.argv)
    rows = []
    # The designs do not depend on the measurements: every material's one-shot studies run the
    # same cases, so a later material reuses the largest one-shot study of an earlier one.
    donor: Path | None = None
    for spec in args.spec or DEFAULT_SPECS:
        mdir = args.out / spec.stem
        mdir.mkdir(parents=True, exist_ok=True)
        experiment, truth = make_measurements(spec, base, mdir, args)
        material = yaml.safe_load(experiment.read_text())["material"]
        work = mdir / "sequential"
        config = write_study_config(work, seq_config, experiment)
        ranges = design_ranges(config)
        tol = float(config["screening"]["tolerance"])
        # The driver owns its study directories: a lock left by an interrupted call goes.
        run_snakemake(work, args.cores, mdir / "sequential.log", "--unlock")
        run_snakemake(work, args.cores, mdir / "sequential.log", "sequential")
        rows += sequential_rows(work, material, truth, ranges, tol)
        rows.append(engine_truth_row(spec, base, mdir, experiment, args))
        previous = None
        for budget in budgets:
            sets = oneshot_sets(config, budget)
            work = mdir / f"oneshot_{budget}"
            one = deep_merge(base, {"sequential": {"enabled": False}})
            one["design"] = {
                **one["design"],
                "kind": "sobol",
                "n": sets,
                "repose_extra_sets": 0,
                "shear_extra_sets": 0,
                "shared_stresses": "all",
            }
            one_config = write_study_config(work, one, experiment)
            if not (work / "results" / "verification" / "verification.csv").is_file():
                log = mdir / f"oneshot_{budget}.log"
                run_snakemake(work, args.cores, log, "--unlock")
                run_snakemake(work, args.cores, log, "results/design/cases.csv")
                source = donor or previous
                if source is not None:
                    reuse_cases(source, work)
                run_snakemake(work, args.cores, log, "results/verification/verification.csv")
            rows.append(oneshot_row(work, material, one_config, truth))
            previous = work
        donor = previous
        table = pd.DataFrame(rows)
        table.to_csv(args.out / "comparison.csv", index=False, float_format="%.6g")
        (args.out / "comparison.md").write_text(comparison_markdown(table, tol, command))
        comparison_figure(table, tol, args.out / "comparison.png")
        print(f"{material}: done", flush=True)


if __name__ == "__main__":
    main()
