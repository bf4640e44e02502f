"""Set up a hidden-effect study for the discrepancy workflow.

Writes STUDY/config/config.yaml (the profile turned into the study model: one particle size, no
rolling resistance, no cohesion, a design over coefficientFriction and density) and
STUDY/config/experiments/measured.yaml (the engine at the true parameters of TRUTH with its
hidden effect switched on, plus noise). Then run, from the repository:

    snakemake -s Snakefile -d STUDY --configfile STUDY/config/config.yaml --cores 2 discrepancy

Usage: python scripts/hidden_effect_study.py --profile config/config.yaml \\
    --truth config/experiments/truth/hidden_cohesion.yaml --out studies/cohesion [--noise 0.005]
"""

import argparse

from demcal.discrepancy.synthetic import prepare_study


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--profile", required=True, help="configuration of the scale (tiny, quick)")
    parser.add_argument("--truth", required=True, help="truth file with the hidden effect")
    parser.add_argument("--out", required=True, help="study directory to create")
    parser.add_argument("--noise", type=float, default=0.005, help="relative measurement noise")
    parser.add_argument("--seed", type=int, default=1, help="seed of the noise")
    parser.add_argument("--workers", type=int, default=2, help="truth runs at the same time")
    parser.add_argument("--replicates", type=int, default=3, help="truth runs per condition")
    args = parser.parse_args()
    path = prepare_study(
        args.profile,
        args.truth,
        args.out,
        args.noise,
        args.seed,
        workers=args.workers,
        replicates=args.replicates,
    )
    print(f"wrote {path} and its measured data; the truth stays in {args.truth}")


if __name__ == "__main__":
    main()
