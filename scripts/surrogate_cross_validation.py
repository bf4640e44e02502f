"""Cross-validate the surrogates of a study's bulk values by parameter set.

Trains every bulk value's network and both baselines as the study does
(:func:`demcal.surrogates.training.train_output`, ``surrogate`` section of ``--config``) on a
finished dataset and prints one line per bulk value and method: rows, sets, CV R^2 and CV RMSE.
Use it to judge whether a dataset is enough to screen with, or to compare surrogate settings on
runs already made, without re-running the study:

    python scripts/surrogate_cross_validation.py --dataset results/bulk/dataset.csv \\
        --out /tmp/cv
    python scripts/surrogate_cross_validation.py \\
        --dataset results/cases/angle_of_repose/*/bulk.csv --outputs aor --out /tmp/cv_aor

Several ``--dataset`` files (a study's dataset, a sequential round's ``dataset.csv`` or the
per-case ``bulk.csv`` files) are concatenated. ``--design-cases`` keeps only the runs of the
cases that ``--config``'s design defines (``design`` section: n, extra sets, replicates), so
that a smaller or differently spread design can be scored on the runs of a larger one:

    python scripts/surrogate_cross_validation.py --dataset results/bulk/dataset.csv \
        --config smaller.yaml --design-cases --out /tmp/cv_smaller
 Artifacts of every bulk value (Table 4, folds,
parity plots) go to ``--out/<value>/``; the summary also to ``--out/cross_validation.md``.
"""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

import pandas as pd

from demcal.core.config import load_config
from demcal.design.cases import case_ids, design_from_config
from demcal.surrogates.training import TEST_OF, train_output

_ALL = tuple(TEST_OF)


def design_runs(data: pd.DataFrame, config: dict) -> tuple[pd.DataFrame, list[str]]:
    """The rows of ``data`` whose (test, case_id) the configuration's design defines, and the
    design's cases of the tests in ``data`` that have no row there."""
    design = design_from_config(config)
    tests = set(data["test"])
    wanted = {(t, case) for t in tests for case in case_ids(config, design, t)}
    have = set(zip(data["test"], data["case_id"], strict=True))
    keep = [(t, c) in wanted for t, c in zip(data["test"], data["case_id"], strict=True)]
    return data[keep], sorted(c for t, c in wanted - have)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", nargs="+", required=True, type=Path, help="tidy CSV files")
    parser.add_argument("--config", default="config/config.yaml", help="study configuration")
    parser.add_argument("--outputs", nargs="+", choices=_ALL, default=None, help="bulk values")
    parser.add_argument("--out", required=True, type=Path, help="output directory")
    parser.add_argument(
        "--design-cases",
        action="store_true",
        help="keep only the runs of the cases --config's design defines",
    )
    args = parser.parse_args(argv)
    missing = [str(p) for p in args.dataset if not p.is_file()]
    if missing:
        parser.error(f"no such dataset file: {', '.join(missing)}")
    config = load_config(args.config)
    settings = config["surrogate"]
    data = pd.concat([pd.read_csv(p) for p in args.dataset], ignore_index=True, sort=False)
    if args.design_cases:
        data, absent = design_runs(data, config)
        if absent:
            parser.error(
                f"{len(absent)} cases of the design of {args.config} have no run in the dataset "
                f"(first: {', '.join(absent[:5])})"
            )
    outputs = args.outputs or [o for o in _ALL if (data["test"] == TEST_OF[o]).any()]
    lines = ["| value | method | rows | sets | CV R^2 | CV RMSE |", "|---|---|---|---|---|---|"]
    for output in outputs:
        trained = train_output(data, output, settings, args.out / output)
        for method, row in trained.table4.iterrows():
            lines.append(
                f"| {output} | {method} | {int(row['cv_rows'])} | {int(row['cv_sets'])} | "
                f"{row['cv_r2']:.3f} | {row['cv_rmse']:.3g} |"
            )
            print(lines[-1], flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "cross_validation.md").write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(message)s")
    sys.exit(main())
