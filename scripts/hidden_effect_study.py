"""Set up a hidden-effect study for the discrepancy workflow.

Writes STUDY/config/config.yaml (the profile turned into the study model: one particle size, no
rolling resistance, no cohesion, a design over coefficientFriction and density),
STUDY/config/experiments/measured.yaml (the truth runs with the hidden effect switched on:
replicate runs from fresh packings, averaged, plus noise) and STUDY/truth.yaml (the drawn
truth, which the workflow never reads). The truth is drawn from TRUTH with --truth-seed; its
runs use --truth-engine (default LIGGGHTS 3.8 when installed, else the profile's engine), while
the model under calibration stays on the profile's engine. Then run, from the repository:

    snakemake -s Snakefile -d STUDY --configfile STUDY/config/config.yaml --cores 2 discrepancy

Usage: python scripts/hidden_effect_study.py --profile config/config.yaml \\
    --truth config/experiments/truth/hidden_cohesion.yaml --out studies/cohesion \\
    [--truth-seed 1] [--truth-engine "liggghts -in {deck}"] [--replicates 3] \\
    [--noise-friction 0.03] [--noise-density 0.01] [--noise-aor 0.03]
"""

import argparse

from demcal.discrepancy.synthetic import NOISE, prepare_study
from demcal.engine_io.run import installed_liggghts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--profile", required=True, help="configuration of the scale (tiny, quick)")
    parser.add_argument("--truth", required=True, help="truth specification (hidden effect)")
    parser.add_argument("--out", required=True, help="study directory to create")
    parser.add_argument("--truth-seed", type=int, default=1, help="seed of the truth draw")
    parser.add_argument(
        "--truth-engine",
        default=installed_liggghts(),
        help="command template of the truth runs (default: 'liggghts -in {deck}' when "
        "LIGGGHTS is installed, else the profile's engine)",
    )
    parser.add_argument(
        "--noise-friction",
        type=float,
        default=NOISE["mu_psh"],
        help="relative noise on mu_psh and mu_sh",
    )
    parser.add_argument(
        "--noise-density", type=float, default=NOISE["rho_b"], help="relative noise on rho_b"
    )
    parser.add_argument(
        "--noise-aor", type=float, default=NOISE["aor"], help="relative noise on the AoR"
    )
    parser.add_argument("--seed", type=int, default=1, help="seed of the noise")
    parser.add_argument("--workers", type=int, default=2, help="truth runs at the same time")
    parser.add_argument("--replicates", type=int, default=3, help="truth runs per condition")
    args = parser.parse_args()
    for name in ("noise_friction", "noise_density", "noise_aor"):
        if not 0.0 <= getattr(args, name) < 1.0:
            parser.error(f"--{name.replace('_', '-')} must lie in [0, 1)")
    if args.replicates < 1:
        parser.error("--replicates must be at least 1")
    noise = {
        "mu_psh": args.noise_friction,
        "mu_sh": args.noise_friction,
        "rho_b": args.noise_density,
        "aor": args.noise_aor,
    }
    path = prepare_study(
        args.profile,
        args.truth,
        args.out,
        noise,
        args.seed,
        workers=args.workers,
        replicates=args.replicates,
        truth_seed=args.truth_seed,
        truth_engine=args.truth_engine,
    )
    print(f"wrote {path} and its measured data; the drawn truth is in {path.parents[1]}/truth.yaml")


if __name__ == "__main__":
    main()
