"""Run the probe decks of a finished discrepancy study on a second engine and compare.

Every shear-cell probe deck under STUDY/results/discrepancy/probes (or those whose run id starts
with one of --runs) is copied with its case description and meshes to OUT/<case>, run with
--engine, and its bulk values are printed beside the study engine's. It tells a difference
between the codes from the scatter of single runs: the same deck, the same seed.

Usage: python scripts/compare_probe_engines.py STUDY --out DIR [--runs ref cohesion] \\
    [--engine "liggghts -in {deck}"] [--parallel 2]
"""

import argparse
import shutil
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pandas as pd

from demcal.bulk.values import extract
from demcal.engine_io.run import run_deck

COLUMNS = ("mu_psh", "mu_sh", "rho_b")


def rerun(case_dir: Path, out: Path, engine: str) -> pd.Series | None:
    """Bulk values of one probe deck run again with ``engine`` in ``out`` (None if it failed)."""
    if out.exists():
        shutil.rmtree(out)
    out.mkdir(parents=True)
    for name in ("in.shear_cell", "case.json"):
        shutil.copy(case_dir / name, out)
    shutil.copytree(case_dir / "meshes", out / "meshes")
    if run_deck(out, "in.shear_cell", engine, 1)["status"] != "ok":
        return None
    return extract("shear_cell", out).iloc[0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", type=Path, help="finished discrepancy study directory")
    parser.add_argument("--out", required=True, type=Path, help="directory of the new runs")
    parser.add_argument("--runs", nargs="*", default=[], help="run-id prefixes to keep")
    parser.add_argument("--engine", default="liggghts -in {deck}", help="command template")
    parser.add_argument("--parallel", type=int, default=2, help="runs at a time")
    args = parser.parse_args()
    probes = args.study / "results" / "discrepancy" / "probes" / "shear_cell"
    if not probes.is_dir():
        parser.error(f"{probes}: no shear-cell probe runs in this study")
    cases = sorted(
        d
        for d in probes.iterdir()
        if (d / "bulk.csv").is_file() and (not args.runs or d.name.startswith(tuple(args.runs)))
    )
    with ThreadPoolExecutor(max(1, args.parallel)) as pool:
        other = list(pool.map(lambda d: rerun(d, args.out / d.name, args.engine), cases))
    rows = []
    for case_dir, values in zip(cases, other, strict=True):
        own = pd.read_csv(case_dir / "bulk.csv").iloc[0]
        row = {"case": case_dir.name}
        for name in COLUMNS:
            row[f"{name} study"] = float(own[name])
            row[f"{name} other"] = float(values[name]) if values is not None else float("nan")
        rows.append(row)
    table = pd.DataFrame(rows)
    table.to_csv(args.out / "comparison.csv", index=False, float_format="%.6g")
    print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))


if __name__ == "__main__":
    main()
