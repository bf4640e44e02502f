"""Produce a synthetic experiment file by running the virtual tests at the true parameters.

The truth runs use --truth-engine (default LIGGGHTS 3.8 when installed, else the profile's
engine), so that the measurements come from another code than the model under calibration.

Usage: python scripts/make_synthetic_experiment.py --config config/tiny.yaml \\
    --truth config/experiments/truth/synthetic_reference.yaml \\
    --out config/experiments/synthetic_reference_tiny.yaml [--noise 0.01] [--seed 1] \\
    [--truth-engine "liggghts -in {deck}"] [--normal-stresses 2029] [--replicates 4] \\
    [--work-dir DIR] [--workers 2]

Each value is the mean of --replicates runs from fresh packings (as a laboratory repeats a
test), its sd their standard error combined with the added noise. Runs kept in --work-dir are
read back when the set is made again, so an interrupted set resumes.
"""

import argparse

from demcal.bulk.synthetic import write_synthetic_experiment
from demcal.engine_io.run import installed_liggghts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", required=True, help="workflow configuration (profile)")
    parser.add_argument("--truth", required=True, help="file with the true parameters")
    parser.add_argument("--out", required=True, help="experiment file to write")
    parser.add_argument("--noise", type=float, default=0.0, help="relative measurement noise")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument(
        "--observables", default="mu_psh,mu_sh,rho_b", help="shear-cell readings to keep"
    )
    parser.add_argument("--P", default=None, help="shear load fractions to keep, comma-separated")
    parser.add_argument(
        "--normal-stresses",
        default=None,
        help="normal stresses (Pa) of the shear-cell truth runs, comma-separated "
        "(default: the profile's shear_cell.normal_stresses)",
    )
    parser.add_argument(
        "--truth-engine",
        default=installed_liggghts(),
        help="command template of the truth runs (default: 'liggghts -in {deck}' when "
        "LIGGGHTS is installed, else the profile's engine)",
    )
    parser.add_argument(
        "--replicates", type=int, default=1, help="truth runs per test, from fresh packings"
    )
    parser.add_argument("--work-dir", default=None, help="where the truth runs are kept")
    parser.add_argument("--workers", type=int, default=1, help="truth runs at the same time")
    args = parser.parse_args()
    if args.replicates < 1 or args.workers < 1:
        parser.error("--replicates and --workers must be at least 1")
    write_synthetic_experiment(
        args.config,
        args.truth,
        args.out,
        args.noise,
        args.seed,
        observables=args.observables.split(","),
        p_values=[float(p) for p in args.P.split(",")] if args.P else None,
        truth_engine=args.truth_engine,
        normal_stresses=(
            [float(s) for s in args.normal_stresses.split(",")] if args.normal_stresses else None
        ),
        replicates=args.replicates,
        work_dir=args.work_dir,
        workers=args.workers,
    )
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
