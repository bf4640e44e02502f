"""Running the workflow on a study directory of its own (validation drivers, comparisons).

The validation scripts set up many studies, each a directory with its ``config/config.yaml``,
and run Snakemake on them as a user would; this is that one call.

The drivers run for hours and are resumed across upgrades of demcal, so a job is rerun when
its inputs, their times or its parameters changed, not when only the text of its rule or
script did (Snakemake's "code" trigger): the same choice as the quick start's advice for a
finished study. A change that alters results shows in a job's parameters or rendered inputs.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

SNAKEFILE = Path(__file__).resolve().parents[2] / "Snakefile"

#: What makes Snakemake rerun a finished job of a driven study (all triggers but "code").
RERUN_TRIGGERS = ("mtime", "input", "params")


def run_snakemake(work: str | Path, cores: int, log: str | Path, *args: str) -> None:
    """Run Snakemake on the study directory ``work`` with its own configuration.

    Parameters
    ----------
    work : path
        Study directory (``config/config.yaml`` inside).
    cores : int
        Cores for Snakemake.
    log : path
        File that receives Snakemake's output (appended, so that the calls of one study stay
        together).
    *args : str
        Targets and further options (before the options above, which take several values).

    Raises
    ------
    RuntimeError
        When Snakemake fails: names the directory and the log, with the log's last lines.
    """
    work, log = Path(work), Path(log)
    cmd = [
        sys.executable,
        "-m",
        "snakemake",
        *args,
        "--snakefile",
        str(SNAKEFILE),
        "--directory",
        str(work),
        "--configfile",
        str(work / "config" / "config.yaml"),
        "--cores",
        str(cores),
        # Rendering and bulk-value jobs in threads, not a new interpreter each.
        "--force-use-threads",
        # A study stopped part-way is resumed, and its finished jobs survive a code upgrade.
        "--rerun-incomplete",
        "--rerun-triggers",
        *RERUN_TRIGGERS,
    ]
    with log.open("a") as handle:
        res = subprocess.run(cmd, cwd=work, stdout=handle, stderr=subprocess.STDOUT, check=False)
    if res.returncode != 0:
        tail = "\n".join(log.read_text().splitlines()[-40:])
        raise RuntimeError(f"snakemake {' '.join(args)} in {work} failed ({log}):\n{tail}")
