"""Run the validation matrix of the discrepancy workflow (hidden effects x drawn truths).

For every truth specification (default: every config/experiments/truth/hidden_*.yaml whose
effect is in the profile's catalogue, or which hides nothing or an effect outside it) and each
of --truths seeds, a blind study is set up (truth drawn, run on --truth-engine with replicates
and noise) and `snakemake discrepancy` runs on it. The current model is made once under
OUT/base. Writes OUT/matrix.csv (one row per study) and OUT/matrix.md (scores, confusion
matrix, rows). Resumable: finished studies, and the finished truth runs of an interrupted one,
are read back, not run again.

Usage: python scripts/discrepancy_matrix.py --profile config/tiny.yaml --out matrix/tiny \\
    [--truths 5] [--first-seed 101] [--spec FILE ...] [--truth-engine "liggghts -in {deck}"]
"""

import argparse
import shlex
import sys
from pathlib import Path

import pandas as pd
import yaml

from demcal.discrepancy.candidates import parse_candidates
from demcal.discrepancy.synthetic import study_config
from demcal.discrepancy.truths import load_truth_spec
from demcal.discrepancy.validation_matrix import (
    matrix_cases,
    matrix_markdown,
    prepare_base,
    run_case,
    study_outcome,
    with_signal,
)
from demcal.engine_io.run import installed_liggghts

ROOT = Path(__file__).resolve().parents[1]
TRUTHS = ROOT / "config" / "experiments" / "truth"


def default_specs(profile: Path) -> list[Path]:
    """Truth specifications the profile's catalogue can be tested on."""
    config = study_config(yaml.safe_load(profile.read_text()) or {})
    names = {c.name for c in parse_candidates(config["discrepancy"]["candidates"])}
    specs = []
    for path in sorted(TRUTHS.glob("hidden_*.yaml")):
        effect = load_truth_spec(path).get("effect")
        if effect is None or effect in names:
            specs.append(path)
    return specs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--profile", required=True, type=Path, help="configuration of the scale")
    parser.add_argument("--out", required=True, type=Path, help="directory of the matrix")
    parser.add_argument("--truths", type=int, default=5, help="drawn truths per hidden effect")
    parser.add_argument("--first-seed", type=int, default=101, help="seed of the first truth")
    parser.add_argument("--spec", type=Path, nargs="*", help="truth specifications to use")
    parser.add_argument("--truth-engine", default=installed_liggghts())
    parser.add_argument("--replicates", type=int, default=3, help="truth runs per condition")
    parser.add_argument("--cores", type=int, default=2)
    args = parser.parse_args()
    specs = args.spec or default_specs(args.profile)
    cases = matrix_cases(specs, args.truths, args.first_seed)
    args.out.mkdir(parents=True, exist_ok=True)
    base = prepare_base(args.profile, args.out / "base", args.cores)
    rows = []
    for case in cases:
        work = args.out / case.name
        if (work / "results" / "discrepancy" / "summary.json").is_file():
            row = study_outcome(case, work)
        else:
            try:
                row = run_case(
                    case,
                    base,
                    args.out,
                    args.truth_engine,
                    replicates=args.replicates,
                    cores=args.cores,
                )
            except RuntimeError as exc:
                print(f"{case.name}: {exc}", file=sys.stderr)
                continue
        rows.append(row)
        print(f"{case.name}: {row['outcome']}", flush=True)
        table = with_signal(pd.DataFrame(rows), args.out)
        table.to_csv(args.out / "matrix.csv", index=False, float_format="%.6g")
        command = "python " + " ".join(shlex.quote(a) for a in sys.argv)
        (args.out / "matrix.md").write_text(
            matrix_markdown(table, f"Discrepancy validation matrix ({args.profile.stem})", command)
        )


if __name__ == "__main__":
    main()
