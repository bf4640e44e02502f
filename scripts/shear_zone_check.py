"""Where finished ring shear-cell decks shear: velocity profile, zone width, inertial numbers.

For every case directory given (a ring deck that ran to the end of its first pre-shear; every
shear-cell deck writes a particle snapshot there), reads the azimuthal velocity profile across
the bed in the deck's interior annulus (``demcal.bulk.shear_zone_check``) and prints per deck
the zone where the particles' speed falls from 0.9 to 0.1 of the floor's (its limits and width
in mean particle diameters d, from the floor) and the inertial numbers of the steepest slices,
of the interior region where rho_b is read, of the whole bed sheared evenly and of a nominal
band ten diameters wide; then the mean profile over the decks. ``--out`` writes the summaries
as CSV and the profiles beside them (``<out>_profile.csv``).

Example::

    python scripts/shear_zone_check.py results/cases/shear_cell/*/engine --out zone.csv
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import pandas as pd  # noqa: E402

from demcal.bulk.shear_zone_check import shear_zone_check  # noqa: E402
from demcal.bulk.values import MissingOutputError  # noqa: E402


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("case_dirs", nargs="+", type=Path, help="finished ring shear-cell decks")
    parser.add_argument(
        "--slice", type=float, default=0.5, help="slice height in mean particle diameters"
    )
    parser.add_argument("--out", type=Path, help="CSV of every deck's summary")
    args = parser.parse_args(argv)
    if not args.slice > 0.0:
        parser.error(f"--slice must be > 0, got {args.slice}")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    rows, profiles = [], []
    for case_dir in args.case_dirs:
        try:
            check = shear_zone_check(case_dir, args.slice)
        except (MissingOutputError, ValueError) as exc:
            print(f"error: {case_dir}: {exc}", file=sys.stderr)
            return 2
        rows.append({"case_dir": str(case_dir), **check.summary})
        profiles.append(check.profile.assign(case_dir=str(case_dir)))
    summary = pd.DataFrame(rows)
    shown = ["zone_lo_d", "zone_hi_d", "width_d", "I_peak", "I_interior", "I_bed", "I_nominal"]
    with pd.option_context("display.width", 200, "display.max_colwidth", 80):
        print(summary[["case_dir", "bed_d", *shown]].round(4).to_string(index=False))
        print(f"\nmeans over {len(summary)} decks:")
        print(summary[shown].mean().round(4).to_string())
        every = pd.concat(profiles, ignore_index=True)
        mean = every.groupby(every["z_d"].round(6))["u"].agg(["mean", "sem", "count"])
        print("\nfraction u of the floor's speed by height z / d (mean over decks, its sem):")
        print(mean.round(3).to_string())
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        summary.to_csv(args.out, index=False)
        every.to_csv(args.out.with_name(args.out.stem + "_profile.csv"), index=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
