"""Running LIGGGHTS 3.8 (the Debian package ``liggghts``) on decks the project renders.

``make setup`` installs ``liggghts`` and ``openmpi-bin`` (scripts/install_system_packages.sh).
The tests here do not skip without them: a missing program fails every test with a message
that says what to install, so a run without LIGGGHTS is never mistaken for a pass.

LIGGGHTS writes its messages to the screen (stdout) and the log file. A warning is a block that
starts with ``WARNING:`` and ends with the source location in parentheses, e.g.
``(./src/contact_models.h:364)``; only the blocks in :data:`ALLOWED_WARNINGS` are accepted.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

LIGGGHTS = Path("/usr/bin/liggghts")

#: Warnings a clean run may print, with the reason they are harmless. Every other WARNING block
#: (an unknown, ignored or deprecated keyword, anything else) fails the tests.
ALLOWED_WARNINGS = {
    # Printed once per pair_style/wall model whose combination of sub-models (here any with
    # rolling_friction epsd2 or cohesion sjkr) the Debian build did not pre-generate: LIGGGHTS
    # then runs the generic, slower code path of the same model. It is about speed, not input.
    "The contact model you specified is not located in any whitelist": "unoptimised model",
}

_SOURCE_LOCATION = re.compile(r"\(\./src/[^()\s]+:\d+\)\s*$")


def missing_programs() -> list[str]:
    """What of LIGGGHTS and mpirun is not installed, as messages (empty if both are)."""
    missing = []
    if not LIGGGHTS.is_file():
        missing.append(f"{LIGGGHTS} (Debian package liggghts)")
    if shutil.which("mpirun") is None:
        missing.append("mpirun (Debian package openmpi-bin)")
    return missing


def require_liggghts() -> None:
    """Fail the calling test if LIGGGHTS or mpirun is missing."""
    missing = missing_programs()
    if missing:
        pytest.fail(
            "LIGGGHTS 3.8 is needed for this test but not installed: missing "
            + ", ".join(missing)
            + ". Run `make setup` (as root or with sudo), which installs the Debian packages "
            "liggghts and openmpi-bin.",
            pytrace=False,
        )


@pytest.fixture(scope="session", autouse=True)
def liggghts_installed() -> None:
    require_liggghts()


def warning_blocks(text: str) -> list[str]:
    """The WARNING blocks of LIGGGHTS output, each as one line of text."""
    blocks: list[str] = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        if not lines[i].lstrip().startswith("WARNING"):
            i += 1
            continue
        block = [lines[i].strip()]
        # A block runs to its source location; 12 lines bound a block that has none.
        j = i
        while not _SOURCE_LOCATION.search(lines[j]) and j + 1 < len(lines) and j - i < 12:
            j += 1
            if lines[j].lstrip().startswith("WARNING"):
                j -= 1
                break
            block.append(lines[j].strip())
        blocks.append(" ".join(part for part in block if part))
        i = j + 1
    return blocks


def unexpected_warnings(text: str) -> list[str]:
    """WARNING blocks of ``text`` that are not in :data:`ALLOWED_WARNINGS`."""
    return [b for b in warning_blocks(text) if not any(a in b for a in ALLOWED_WARNINGS)]


@dataclass
class LiggghtsRun:
    """One finished LIGGGHTS run."""

    command: list[str]
    returncode: int
    stdout: str
    stderr: str
    directory: Path

    @property
    def output(self) -> str:
        """Screen output and error stream together."""
        return self.stdout + "\n" + self.stderr

    def log(self) -> str:
        path = self.directory / "log.liggghts"
        return path.read_text(errors="replace") if path.is_file() else ""

    def describe(self) -> str:
        return (
            f"{' '.join(self.command)} in {self.directory}: exit {self.returncode}\n"
            f"--- end of output ---\n{self.output[-3000:]}"
        )


def liggghts_env() -> dict[str, str]:
    """Environment of a run: one OpenMP thread, and Open MPI allowed to run as root."""
    return {
        **os.environ,
        "OMP_NUM_THREADS": "1",
        "OMPI_ALLOW_RUN_AS_ROOT": "1",
        "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
    }


def liggghts_command(deck: str, ranks: int = 1) -> list[str]:
    """``liggghts -in DECK`` (one rank) or ``mpirun -np RANKS liggghts -in DECK``.

    The screen output is line-buffered (``stdbuf``): LIGGGHTS stops on some errors with
    MPI_Abort, which would otherwise lose the buffered ERROR line.
    """
    cmd = [str(LIGGGHTS), "-in", deck, "-log", "log.liggghts"]
    if ranks > 1:
        mpirun = shutil.which("mpirun") or "mpirun"
        cmd = [mpirun, "--oversubscribe", "-np", str(ranks), *cmd]
    stdbuf = shutil.which("stdbuf")
    return [stdbuf, "-oL", *cmd] if stdbuf else cmd


def run_liggghts(directory: Path, deck: str, ranks: int = 1, timeout: float = 300) -> LiggghtsRun:
    """Run LIGGGHTS on ``directory/deck`` in ``directory``; never raises on a failed run."""
    cmd = liggghts_command(deck, ranks)
    res = subprocess.run(
        cmd,
        cwd=directory,
        capture_output=True,
        text=True,
        errors="replace",
        timeout=timeout,
        env=liggghts_env(),
    )
    return LiggghtsRun(cmd, res.returncode, res.stdout, res.stderr, Path(directory))
