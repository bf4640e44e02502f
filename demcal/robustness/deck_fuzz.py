"""Running mutated decks on the engine and classifying how it took them.

An outcome is one of

``ok``
    exit status 0;
``rejected``
    exit status 1 and a last standard-error line ``ERROR: FILE:LINE: ...`` naming an existing
    line of the deck (or of a file it includes);

and the failures

``crash``
    killed by a signal, or another exit status, or status 1 without an ``ERROR:`` line;
``hang``
    still running at the time limit;
``unlocated``
    an ``ERROR:`` line without ``FILE:LINE:`` (or with a line the file does not have);
``internal``
    a located error whose reason is a raw C++ library exception (``std::bad_alloc``,
    ``stod``, ``vector::...``): input that no check caught.
"""

from __future__ import annotations

import json
import math
import os
import re
import resource
import shutil
import signal
import subprocess
import time
from collections import Counter
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from demcal.robustness.base_decks import render_base_decks
from demcal.robustness.mutation import BaseDeck, FuzzCase, make_cases

OK = "ok"
REJECTED = "rejected"
CRASH = "crash"
HANG = "hang"
UNLOCATED = "unlocated"
INTERNAL = "internal"
OUTCOMES = (OK, REJECTED, CRASH, HANG, UNLOCATED, INTERNAL)
FAILURES = (CRASH, HANG, UNLOCATED, INTERNAL)

#: ``ERROR: FILE:LINE: `` - the engine's form of a located error (see dem_engine/README.md).
LOCATED = re.compile(r"^ERROR: (?P<file>[^\s:][^:]*):(?P<line>[0-9]+): ")
#: Reasons that are a C++ library exception's own text rather than a message of the engine.
RAW_EXCEPTION = re.compile(
    r"std::|bad_alloc|bad_array_new_length|vector::|basic_string|\bstod\b|\bstoi\b|\bstol\b"
    r"|\bstoll\b|\bstoul\b|out_of_range|length_error|unknown error"
)


@dataclass
class Outcome:
    """How the engine took one fuzz case."""

    index: int
    base: str
    mutations: list[str]
    kind: str
    returncode: int | None
    seconds: float
    last_error: str = ""
    stderr_tail: str = ""
    extra: dict[str, Any] = field(default_factory=dict)


def classify(returncode: int | None, stderr: str, directory: Path | None = None) -> tuple[str, str]:
    """The outcome kind of one engine run and its last ``ERROR:`` line.

    Parameters
    ----------
    returncode : int or None
        Exit status (negative: killed by that signal); None when the run timed out.
    stderr : str
        Standard error of the run.
    directory : Path, optional
        Working directory of the run; when given, a located error must name a line that
        its file has.

    Returns
    -------
    (str, str)
        One of :data:`OUTCOMES` and the last ``ERROR:`` line (empty if none).
    """
    if returncode is None:
        return HANG, ""
    errors = [line for line in stderr.splitlines() if line.startswith("ERROR:")]
    last = errors[-1] if errors else ""
    if returncode == 0:
        return OK, last
    if returncode != 1 or not last:
        return CRASH, last
    m = LOCATED.match(last)
    if not m or int(m.group("line")) < 1:
        return UNLOCATED, last
    if directory is not None:
        path = directory / m.group("file")
        if path.is_file():
            with path.open("rb") as f:
                n_lines = sum(1 for _ in f)
            if int(m.group("line")) > max(n_lines, 1):
                return UNLOCATED, last
    if RAW_EXCEPTION.search(last[m.end() :]):
        return INTERNAL, last
    return REJECTED, last


def run_command(
    command: Sequence[str],
    directory: Path,
    timeout: float,
    memory_limit: int | None = 2 << 30,
) -> tuple[int | None, str, float]:
    """Run ``command`` in ``directory`` on one OpenMP thread with a time and memory limit.

    The address-space limit (``memory_limit`` bytes, Linux ``prlimit``) is set right after the
    start, so that an unbounded allocation fails in the engine instead of exhausting the machine.

    Returns
    -------
    (int or None, str, float)
        Exit status (None on timeout), standard error and wall time in seconds.
    """
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    start = time.monotonic()
    with subprocess.Popen(
        list(command),
        cwd=directory,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        errors="replace",
        env=env,
        start_new_session=True,  # its own process group: a timeout ends its children too
    ) as proc:
        if memory_limit and hasattr(resource, "prlimit"):
            try:
                resource.prlimit(proc.pid, resource.RLIMIT_AS, (memory_limit, memory_limit))
            except (ProcessLookupError, PermissionError, ValueError, OSError):
                pass  # already finished, or limits not available
        try:
            _, stderr = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            _, stderr = proc.communicate()
            return None, stderr or "", time.monotonic() - start
    return proc.returncode, stderr or "", time.monotonic() - start


def run_case(
    case: FuzzCase,
    base: BaseDeck,
    engine: Sequence[str],
    scratch: Path,
    timeout: float,
    out_dir: Path | None = None,
) -> Outcome:
    """Run the engine on one mutated deck in a fresh copy of its case directory.

    Parameters
    ----------
    case : FuzzCase
        The mutated deck.
    base : BaseDeck
        The deck it was made from (its directory holds the meshes).
    engine : sequence of str
        Engine command; ``-in DECK -log log.txt -noprogress`` is appended.
    scratch : Path
        Where the case directory is made (removed afterwards).
    timeout : float
        Time limit in seconds.
    out_dir : Path, optional
        A failing case's directory is kept as ``out_dir/KIND/NNNNNN_BASE`` with the mutated
        deck, the meshes and ``fuzz.json`` (mutations, command, standard error).
    """
    directory = scratch / f"{case.index:06d}_{case.base}"
    shutil.copytree(base.directory, directory)
    (directory / base.deck).write_text(case.text)
    command = [*engine, "-in", base.deck, "-log", "log.txt", "-noprogress"]
    code, stderr, seconds = run_command(command, directory, timeout)
    kind, last = classify(code, stderr, directory)
    outcome = Outcome(
        case.index, case.base, case.mutations, kind, code, seconds, last, stderr[-2000:]
    )
    try:
        if out_dir is not None and kind in FAILURES:
            keep = out_dir / kind / directory.name
            if keep.exists():
                shutil.rmtree(keep)
            keep.parent.mkdir(parents=True, exist_ok=True)
            shutil.copytree(base.directory, keep)
            (keep / base.deck).write_text(case.text)
            record = {**asdict(outcome), "command": command, "stderr_tail": stderr[-4000:]}
            (keep / "fuzz.json").write_text(json.dumps(record, indent=1) + "\n")
    finally:
        shutil.rmtree(directory, ignore_errors=True)
    return outcome


def run_cases(
    cases: Iterable[FuzzCase],
    bases: Sequence[BaseDeck],
    engine: Sequence[str],
    scratch: Path,
    timeout: float,
    jobs: int = 2,
    out_dir: Path | None = None,
    progress: Callable[[Outcome], None] | None = None,
) -> list[Outcome]:
    """Run every case, ``jobs`` engine processes at a time; outcomes in case order."""
    by_name = {b.name: b for b in bases}
    scratch.mkdir(parents=True, exist_ok=True)

    def one(case: FuzzCase) -> Outcome:
        outcome = run_case(case, by_name[case.base], engine, scratch, timeout, out_dir)
        if progress is not None:
            progress(outcome)
        return outcome

    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        return list(pool.map(one, cases))


def summary_table(outcomes: Sequence[Outcome]) -> str:
    """A text table: outcome counts per base deck and in total."""
    bases = sorted({o.base for o in outcomes})
    counts = Counter((o.base, o.kind) for o in outcomes)
    header = ["outcome", *bases, "total"]
    rows = [header]
    for kind in OUTCOMES:
        row = [kind, *(str(counts[(b, kind)]) for b in bases)]
        row.append(str(sum(counts[(b, kind)] for b in bases)))
        rows.append(row)
    rows.append(
        ["all", *(str(sum(o.base == b for o in outcomes)) for b in bases), str(len(outcomes))]
    )
    widths = [max(len(r[k]) for r in rows) for k in range(len(header))]
    lines = []
    for n, r in enumerate(rows):
        lines.append("| " + " | ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)) + " |")
        if n == 0:
            lines.append("| " + " | ".join("-" * w for w in widths) + " |")
    return "\n".join(lines)


def failures(outcomes: Sequence[Outcome]) -> list[Outcome]:
    """The outcomes that are failures (crash, hang, unlocated, internal)."""
    return [o for o in outcomes if o.kind in FAILURES]


def fuzz(
    cases: int,
    seed: int,
    work_dir: Path,
    engine: Sequence[str],
    timeout: float = 20.0,
    max_steps: int = 20,
    jobs: int = 2,
    out_dir: Path | None = None,
    progress: Callable[[Outcome], None] | None = None,
) -> list[Outcome]:
    """Render the base decks into ``work_dir``, make ``cases`` mutations and run them.

    Parameters
    ----------
    cases, seed : int
        Number of mutated decks and the seed of the mutations.
    work_dir : Path
        Receives the rendered decks (``base/``) and the per-case directories (``cases/``).
    engine : sequence of str
        Engine command, e.g. ``["/path/dem_engine"]``.
    timeout : float
        Time limit per case, seconds.
    max_steps : int
        Cap on every ``run`` step count.
    jobs : int
        Engine processes at a time (each on one OpenMP thread).
    out_dir : Path, optional
        Where failing cases are kept for reproduction.
    progress : callable, optional
        Called with each outcome as it arrives.

    Returns
    -------
    list of Outcome
        In case order.
    """
    if cases < 0 or max_steps < 0 or not math.isfinite(timeout) or timeout <= 0:
        raise ValueError("cases and max_steps must be >= 0 and timeout > 0")
    bases = render_base_decks(work_dir / "base")
    todo = make_cases(bases, cases, seed, max_steps)
    return run_cases(todo, bases, engine, work_dir / "cases", timeout, jobs, out_dir, progress)
