"""How far the ring's interior density by particle centres is from the volume inside it.

For every ring shear-cell case under CASES (a study's ``results/cases/shear_cell``) whose deck
measures rho_b in the interior (``shear_cell.bulk_density: interior``), the particle snapshot
at the end of the first pre-shear gives the interior's solid fraction twice
(:mod:`demcal.virtual_tests.shear_cell.interior_density`): by the centres inside, as the deck
counts, and by the spheres' volume inside. Printed per case with the whole cell's solid
fraction from the same run, then the median and range of the ratios.

Usage: python scripts/interior_density_check.py CASES [--csv FILE]
"""

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

from demcal.bulk.values import extract, read_case_record
from demcal.engine_io.vtk_file import read_vtk_particles
from demcal.virtual_tests.shear_cell.interior_density import interior_fractions


def case_row(case_dir: Path) -> dict | None:
    """The two interior fractions and the cell's of one case (None unless its run finished
    and it is a ring case with an interior region and a snapshot)."""
    status = case_dir / "status.json"
    if not status.is_file() or json.loads(status.read_text())["status"] != "ok":
        return None
    record = read_case_record(case_dir)
    setup = record["setup"]
    snapshot = case_dir / record["files"]["snapshot"]
    if setup.get("bulk_density") != "interior" or not snapshot.is_file():
        return None
    vtk = read_vtk_particles(snapshot, arrays=["radius"])
    fractions = interior_fractions(
        vtk.points,
        vtk.arrays["radius"],
        setup["interior_r_lo"],
        setup["interior_r_hi"],
        setup["interior_z_lo"],
        setup["interior_z_hi"],
    )
    density = float(record["material"]["density"])
    first = extract("shear_cell", case_dir).iloc[0]
    return {
        "case_id": record["case_id"],
        "by_centre": fractions.by_centre,
        "by_volume": fractions.by_volume,
        "centre_over_volume": fractions.by_centre / fractions.by_volume,
        # The first cycle's pre-shear, which the snapshot ends.
        "cell": float(first["rho_b_cell"]) / density,
        "n_centres": fractions.n_centres,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cases", type=Path, help="directory of shear-cell case directories")
    parser.add_argument("--csv", type=Path, help="write the table here too")
    args = parser.parse_args()
    rows = [row for d in sorted(args.cases.iterdir()) if (row := case_row(d)) is not None]
    if not rows:
        raise SystemExit(f"{args.cases}: no ring case with an interior region and a snapshot")
    table = pd.DataFrame(rows)
    table["volume_over_cell"] = table["by_volume"] / table["cell"]
    print(table.to_string(index=False, float_format="%.4f"))
    for key in ("centre_over_volume", "volume_over_cell"):
        values = table[key].to_numpy()
        print(
            f"{key}: median {np.median(values):.4f}, range {values.min():.4f}-{values.max():.4f}"
            f" over {len(values)} runs"
        )
    if args.csv:
        table.to_csv(args.csv, index=False, float_format="%.6g")


if __name__ == "__main__":
    main()
