"""Running one deck with the configured engine and recording how it went."""

import json
import os
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

#: Warning lines kept in a run's ``status.json``.
MAX_WARNINGS = 20

#: Signals by which a run is stopped from outside (Ctrl-C, a stopped study, a cancelled or
#: timed-out batch job): such a run says nothing about its deck.
INTERRUPTS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class RunInterrupted(RuntimeError):
    """The engine was stopped by a signal from outside; no status is recorded, so the run
    starts again when the study resumes."""


def interrupting_signal(returncode: int) -> signal.Signals | None:
    """The interrupting signal behind ``returncode``, or None.

    A process killed by signal N returns -N to Python; through a shell, ``timeout
    --preserve-status`` or a batch wrapper it exits with 128 + N.
    """
    for sig in INTERRUPTS:
        if returncode in (-int(sig), 128 + int(sig)):
            return sig
    return None


def installed_liggghts() -> str | None:
    """``liggghts -in {deck}`` when LIGGGHTS is on the PATH, else None: the default engine of
    runs whose data must come from another code than the model under calibration."""
    return "liggghts -in {deck}" if shutil.which("liggghts") else None


def engine_command(template: str, deck: str, threads: int) -> list[str]:
    """The command line for one deck, from the ``engine.command`` template.

    Parameters
    ----------
    template : str
        E.g. ``"dem_engine -in {deck}"`` or ``"mpirun -np {threads} liggghts -in {deck}"``.
    deck : str
        Deck file name, relative to the case directory.
    threads : int
        Threads or MPI ranks.
    """
    try:
        text = template.format(deck=deck, threads=threads)
    except (KeyError, IndexError) as exc:
        raise ValueError(
            f"engine.command {template!r}: unknown placeholder {exc}; use {{deck}} and {{threads}}"
        ) from exc
    cmd = shlex.split(text)
    if not cmd:
        raise ValueError("engine.command is empty")
    # The bundled engine is installed beside the Python interpreter of the environment, which
    # need not be on PATH when snakemake is called by its full path.
    search = os.pathsep.join([os.environ.get("PATH", ""), str(Path(sys.executable).parent)])
    found = shutil.which(cmd[0], path=search)
    if found is None:
        raise FileNotFoundError(
            f"engine.command {template!r}: program {cmd[0]!r} not found (run `make engine`, "
            "activate .venv, or give the full path)"
        )
    cmd[0] = found
    return cmd


def error_lines(case_dir: Path) -> list[str]:
    """The ``ERROR`` lines of a finished run, in the order the engine wrote them.

    The bundled engine writes its errors to standard error; LIGGGHTS 3.8 writes them to standard
    output and its log file (``ERROR: ...`` or, under MPI, ``ERROR on proc N: ...``), so all three
    files are read and a line seen twice is kept once.
    """
    return marked_lines(case_dir, "ERROR")


def warning_lines(case_dir: Path) -> list[str]:
    """The non-empty ``WARNING`` lines of a finished run (as :func:`error_lines`).

    The bundled engine warns, for example, when a contact overlaps by more than half a radius (a
    particle pinched between walls) and carries on, as LIGGGHTS does.
    """
    return [line for line in marked_lines(case_dir, "WARNING") if line.rstrip(": ") != "WARNING"]


def marked_lines(case_dir: Path, marker: str) -> list[str]:
    """Lines starting with ``marker`` in the run's screen output and log, each once, in order."""
    seen: dict[str, None] = {}
    for name in ("engine.err", "engine.out", "log.liggghts"):
        path = case_dir / name
        if not path.is_file():
            continue
        with path.open(errors="replace") as f:
            for line in f:
                if line.startswith(marker):
                    seen.setdefault(line.strip(), None)
    return list(seen)


def run_deck(case_dir: str | Path, deck: str, template: str, threads: int) -> dict:
    """Run ``deck`` in ``case_dir`` and write ``status.json`` there.

    The engine's screen output goes to ``engine.out``/``engine.err`` in the case directory and
    its log to ``log.liggghts``. A failed run is recorded (status ``failed`` with the engine's
    error line), not raised, so that one bad case does not stop a study; a missing engine is a
    set-up error and raises ``FileNotFoundError`` before anything is written.

    Raises
    ------
    RunInterrupted
        When the engine was stopped by SIGINT, SIGTERM or SIGHUP (see :data:`INTERRUPTS`):
        nothing is recorded, so a resumed study runs the deck again instead of counting it
        as failed.

    Returns
    -------
    dict
        The status record: status, returncode, seconds, command, threads, error and warnings
        (the first :data:`MAX_WARNINGS` warning lines).
    """
    case_dir = Path(case_dir)
    cmd = engine_command(template, deck, threads)
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    start = time.monotonic()
    with (case_dir / "engine.out").open("w") as out, (case_dir / "engine.err").open("w") as err:
        proc = subprocess.run(cmd, cwd=case_dir, stdout=out, stderr=err, env=env, check=False)
        returncode = proc.returncode
    seconds = time.monotonic() - start
    stopped_by = interrupting_signal(returncode)
    if stopped_by is not None:
        (case_dir / "status.json").unlink(missing_ok=True)
        raise RunInterrupted(
            f"{case_dir / deck}: the engine was stopped by {stopped_by.name} after "
            f"{seconds:.0f} s (exit code {returncode}); nothing recorded, the run starts again "
            "when the study resumes"
        )
    errors = error_lines(case_dir)
    status = {
        "status": "ok" if returncode == 0 else "failed",
        "returncode": returncode,
        "seconds": round(seconds, 3),
        "command": cmd,
        "threads": threads,
        "error": errors[-1] if errors else ("" if returncode == 0 else f"exit code {returncode}"),
        "warnings": warning_lines(case_dir)[:MAX_WARNINGS],
    }
    (case_dir / "status.json").write_text(json.dumps(status, indent=2) + "\n")
    return status
