"""Readout cross-check of finished shear-cell decks: wall forces against the contacts.

For every case directory given (a deck rendered with ``shear_cell.contact_snapshots`` > 0 and
run), sets the contacts' mu across the shear plane over each steady window beside the wall
readout's (``demcal.bulk.plane_check``), prints the table and, with ``--out``, writes it as CSV.
``--margin`` keeps that many largest-particle diameters away from the cell's walls. ``--bands N``
(ring decks) also splits the plane into N bands of equal width and prints, per phase and band,
the normal stress over the annulus's and the friction, averaged over decks and windows, beside
the contacts' friction over the whole annulus and the torque readout (written to
``<out>_bands.csv`` with ``--out``).

Example::

    python scripts/readout_check.py results/cycles/plane/cases/*/shear_cell/seed*/engine \
        --out results/cycles/plane/readout.csv
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import pandas as pd  # noqa: E402

from demcal.bulk.plane_check import plane_check  # noqa: E402
from demcal.bulk.values import MissingOutputError, read_case_record  # noqa: E402


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("case_dirs", nargs="+", type=Path, help="finished shear-cell decks")
    parser.add_argument(
        "--margin",
        type=float,
        default=0.0,
        help="distance kept from the walls, in largest-particle diameters",
    )
    parser.add_argument(
        "--bands", type=int, default=0, help="ring decks: bands of equal width (0: none)"
    )
    parser.add_argument("--out", type=Path, help="CSV of every deck's windows")
    args = parser.parse_args(argv)
    if not args.margin >= 0.0:
        parser.error(f"--margin must be >= 0, got {args.margin}")
    if args.bands < 0:
        parser.error(f"--bands must be >= 0, got {args.bands}")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    tables, profiles = [], []
    for case_dir in args.case_dirs:
        try:
            record = read_case_record(case_dir)
            margin = 2.0 * float(record["particles"]["max_radius"]) * args.margin
            table, profile = plane_check(case_dir, margin, args.bands)
        except (MissingOutputError, ValueError) as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
        table.insert(0, "case_dir", str(case_dir))
        tables.append(table)
        if profile is not None:
            profiles.append(profile.assign(case_dir=str(case_dir)))
    every = pd.concat(tables, ignore_index=True)
    every["ratio"] = every["mu_plane"] / every["mu_wall"]
    with pd.option_context("display.width", 200, "display.max_colwidth", 80):
        print(every.round(4).to_string(index=False))
    ratio = every["ratio"].dropna()
    print(
        f"\nplane / wall over {len(ratio)} windows: median {ratio.median():.4f}, "
        f"range {ratio.min():.4f}-{ratio.max():.4f}"
    )
    if profiles:
        bands = pd.concat(profiles, ignore_index=True)
        mean = bands.groupby(["phase", "band"])[
            ["r_lo", "r_hi", "sigma_rel", "mu", "mu_annulus", "mu_wall"]
        ].mean()
        print(f"\nbands (means over {bands['case_dir'].nunique()} decks and their windows):")
        print(mean.round(4).to_string())
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        every.to_csv(args.out, index=False)
        if profiles:
            bands.to_csv(args.out.with_name(args.out.stem + "_bands.csv"), index=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
