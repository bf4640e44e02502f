"""Engine benchmark: the 8 000-sphere heap deck on dem_engine and on LIGGGHTS 3.8.

Usage: python dem_engine/bench/run_bench.py [--engine PATH] [--steps N] [--repeats K]
           [--runs R] [--settle-steps S] [--liggghts PATH | --no-liggghts] [--mpirun PATH]
           [--no-sjkr]

The same deck (heap.in: pour, settling, then the dense phase `repeats` times, each its own `run`)
runs on the engine at 1 and 2 OpenMP threads and on LIGGGHTS at 1 and 2 MPI ranks. Phase times
come from each program's own "Loop time of X on N threads|procs for M steps with P atoms" line
per `run` (the engine's screen output, LIGGGHTS' log.liggghts). One table puts side by side the
particle-steps per second of the whole run (all `run` segments: pour, settling, dense phase) and
of the dense phase (best and median of its repeats), engine against LIGGGHTS, with the cache-line
round trip between the two cores (dem_core_latency, built beside the engine) before and after each
2-thread / 2-rank run: on a shared virtual machine it changes while the host moves the virtual
CPUs, and the 2-way speed follows it. The cohesive variant (+ SJKR) then runs on the engine only,
as before, with its peak resident memory per particle.
"""

import argparse
import os
import platform
import re
import shutil
import statistics
import subprocess
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent

LOOP = re.compile(r"Loop time of (\S+) on (\d+) (?:threads|procs) for (\d+) steps with (\d+) atoms")
WHITELIST_WARNING = "not located in any whitelist"


def deck_text(cohesion: bool) -> str:
    text = (HERE / "heap.in").read_text()
    if cohesion:
        plain = "model hertz tangential history rolling_friction epsd2"
        sjkr = "model hertz tangential history cohesion sjkr rolling_friction epsd2"
        text = text.replace(f'variable model string "{plain}"', f'variable model string "{sjkr}"')
    return text


def core_round_trip_ns(probe: Path) -> str:
    """Cache-line round trip between cores 0 and 1 (ns): the range of three samples, or why not."""
    if not probe.exists():
        return f"not measured ({probe} is not built)"
    res = subprocess.run([str(probe), "0", "1", "3"], capture_output=True, text=True)
    if res.returncode != 0:
        return f"not measured ({res.stderr.strip()})"
    samples = [float(v) for v in res.stdout.split()]
    return f"{min(samples):.0f}-{max(samples):.0f} ns"


def phase_rates(text: str, repeats: int) -> dict:
    """Particle-steps per second of the whole run and of the dense phase from "Loop time" lines."""
    loops = [(float(secs), int(steps), int(atoms)) for secs, _, steps, atoms in LOOP.findall(text)]
    if len(loops) < repeats + 1:
        raise RuntimeError(f"expected at least {repeats + 1} 'Loop time' lines, got {len(loops)}")
    dense = [steps * atoms / secs for secs, steps, atoms in loops[-repeats:]]
    return {
        "atoms": loops[-1][2],
        "steps": sum(steps for _, steps, _ in loops),
        "seconds": sum(secs for secs, _, _ in loops),
        "whole": sum(steps * atoms for _, steps, atoms in loops) / sum(s for s, _, _ in loops),
        "dense": max(dense),
        "dense_median": statistics.median(dense),
    }


SETTLE = {"steps": 20000}  # the deck's default; --settle-steps shortens the run on a busy machine


def deck_vars(steps: int, repeats: int) -> list[str]:
    return [
        *("-var", "dense_steps", str(steps), "-var", "repeats", str(repeats)),
        *("-var", "settle_steps", str(SETTLE["steps"])),
    ]


def run_engine(engine: str, cohesion: bool, threads: int, steps: int, repeats: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "heap.in").write_text(deck_text(cohesion))
        env = dict(os.environ, OMP_NUM_THREADS=str(threads), OMP_PROC_BIND="close")
        cmd = [engine, "-in", "heap.in", "-log", "none", "-noprogress", *deck_vars(steps, repeats)]
        out_path = Path(tmp) / "screen.txt"
        with out_path.open("w") as out:
            proc = subprocess.Popen(cmd, cwd=tmp, stdout=out, stderr=subprocess.STDOUT, env=env)
            # wait4: this run's own peak resident memory (KiB), not that of earlier children.
            _, status, usage = os.wait4(proc.pid, 0)
            proc.returncode = os.waitstatus_to_exitcode(status)
        screen = out_path.read_text()
        if proc.returncode != 0:
            raise RuntimeError(f"engine failed ({' '.join(cmd)}):\n{screen[-2000:]}")
    return {**phase_rates(screen, repeats), "peak_kib": usage.ru_maxrss}


def run_liggghts(liggghts: str, mpirun: str, ranks: int, steps: int, repeats: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "heap.in").write_text(deck_text(False))
        cmd = [liggghts, "-in", "heap.in", "-echo", "none", *deck_vars(steps, repeats)]
        if ranks > 1:
            cmd = [mpirun, "--oversubscribe", "-np", str(ranks), *cmd]
        env = dict(
            os.environ,
            OMP_NUM_THREADS="1",
            OMPI_ALLOW_RUN_AS_ROOT="1",
            OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
        )
        res = subprocess.run(cmd, cwd=tmp, capture_output=True, text=True, env=env)
        log = Path(tmp) / "log.liggghts"
        text = log.read_text() if log.exists() else ""
        if res.returncode != 0:
            raise RuntimeError(
                f"LIGGGHTS failed ({' '.join(cmd)}):\n{res.stdout[-2000:]}{res.stderr[-2000:]}"
            )
    return {
        **phase_rates(text, repeats),
        "unoptimised": WHITELIST_WARNING in res.stdout + text,
    }


def best_of(runs: int, fn) -> dict:
    """The run with the fastest whole-run rate out of `runs` (each a separate process)."""
    results = [fn() for _ in range(runs)]
    return max(results, key=lambda r: r["whole"])


def mps(value: float) -> str:
    return f"{value / 1e6:.2f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--engine",
        default=shutil.which("dem_engine") or str(ROOT / "build" / "engine" / "dem_engine"),
    )
    parser.add_argument("--steps", type=int, default=4000, help="steps per dense-phase repeat")
    # Repeats in one process: on a shared machine one slow stretch (another job, a descheduled
    # core) must not decide the figure; the best repeat is the speed, the median shows the spread.
    parser.add_argument("--repeats", type=int, default=3, help="dense-phase repeats per process")
    parser.add_argument(
        "--settle-steps",
        type=int,
        default=SETTLE["steps"],
        help="settling steps before the dense phase",
    )
    parser.add_argument(
        "--runs", type=int, default=1, help="whole-deck runs per program and width (best kept)"
    )
    parser.add_argument("--liggghts", default=shutil.which("liggghts") or "liggghts")
    parser.add_argument("--mpirun", default=shutil.which("mpirun") or "mpirun")
    parser.add_argument("--no-liggghts", action="store_true", help="engine only")
    parser.add_argument("--no-sjkr", action="store_true", help="skip the cohesive variant")
    args = parser.parse_args()
    SETTLE["steps"] = args.settle_steps
    args.engine = str(Path(args.engine).resolve())  # the runs happen in temporary directories
    with_liggghts = not args.no_liggghts
    if with_liggghts and shutil.which(args.liggghts) is None:
        print(f"LIGGGHTS not found ({args.liggghts}): engine only")
        with_liggghts = False
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
        f"load average {' '.join(f'{v:.2f}' for v in os.getloadavg())}; engine: {args.engine}"
        + (f"; LIGGGHTS: {args.liggghts} (mpirun: {args.mpirun})" if with_liggghts else "")
    )
    probe = ROOT / "build" / "engine" / "dem_core_latency"

    # The bench deck as it is (hertz + history + EPSD2): engine against LIGGGHTS.
    name = "hertz+history+epsd2"
    rows = []
    for width in (1, 2):
        trip = [core_round_trip_ns(probe)] if width == 2 else []
        eng = best_of(
            args.runs, lambda w=width: run_engine(args.engine, False, w, args.steps, args.repeats)
        )
        if width == 2:
            trip.append(core_round_trip_ns(probe))
        lig = None
        if with_liggghts:
            lig = best_of(
                args.runs,
                lambda w=width: run_liggghts(
                    args.liggghts, args.mpirun, w, args.steps, args.repeats
                ),
            )
            if width == 2:
                trip.append(core_round_trip_ns(probe))
        rows.append((width, eng, lig, trip))
        print(
            f"{name} width {width}: engine {eng['atoms']} particles, {eng['steps']} steps in "
            f"{eng['seconds']:.1f} s"
            + (
                f"; LIGGGHTS {lig['atoms']} particles, {lig['steps']} steps in "
                f"{lig['seconds']:.1f} s"
                if lig
                else ""
            ),
            flush=True,
        )

    print()
    print(
        f"{name}, {rows[0][1]['atoms']} particles, whole run {rows[0][1]['steps']} steps "
        f"(pour, settling, dense phase {args.repeats} x {args.steps}); "
        f"M particle-steps/s, dense phase: best (median of {args.repeats}); "
        f"best of {args.runs} run(s)"
    )
    if with_liggghts:
        print(
            "| width | engine whole | LIGGGHTS whole | ratio | engine dense | LIGGGHTS dense "
            "| ratio | core-to-core round trip |"
        )
        print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    else:
        print("| width | engine whole | engine dense | core-to-core round trip |")
        print("| --- | --- | --- | --- |")
    for width, eng, lig, trip in rows:
        label = "1 thread / 1 rank" if width == 1 else f"{width} threads / {width} ranks"
        trip_text = " / ".join(trip)
        dense_e = f"{mps(eng['dense'])} ({mps(eng['dense_median'])})"
        if lig:
            if lig["atoms"] != eng["atoms"]:
                print(
                    f"WARNING: particle counts differ: engine {eng['atoms']}, "
                    f"LIGGGHTS {lig['atoms']}"
                )
            dense_l = f"{mps(lig['dense'])} ({mps(lig['dense_median'])})"
            print(
                f"| {label} | {mps(eng['whole'])} | {mps(lig['whole'])} "
                f"| {eng['whole'] / lig['whole']:.2f}x | {dense_e} | {dense_l} "
                f"| {eng['dense'] / lig['dense']:.2f}x | {trip_text} |"
            )
        else:
            print(f"| {label} | {mps(eng['whole'])} | {dense_e} | {trip_text} |")
    if with_liggghts:
        print(
            "core-to-core round trip: before the engine run / between the engine and LIGGGHTS runs "
            "/ after the LIGGGHTS run"
        )
        if any(lig and lig["unoptimised"] for _, _, lig, _ in rows):
            print(
                "LIGGGHTS warned that this contact model is not in its whitelist: it ran its "
                "generic (unoptimised) contact-model code path"
            )
    print(f"load average after these runs: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    e1, e2 = rows[0][1], rows[1][1]
    print(
        f"engine speed-up 2 threads / 1 thread: whole {e2['whole'] / e1['whole']:.2f}x, "
        f"dense {e2['dense'] / e1['dense']:.2f}x; peak memory "
        f"{e1['peak_kib'] / e1['atoms']:.2f} KiB/particle"
    )
    if with_liggghts and rows[0][2] and rows[1][2]:
        l1, l2 = rows[0][2], rows[1][2]
        print(
            f"LIGGGHTS speed-up 2 ranks / 1 rank: whole {l2['whole'] / l1['whole']:.2f}x, "
            f"dense {l2['dense'] / l1['dense']:.2f}x"
        )

    if args.no_sjkr:
        return
    # The cohesive variant, engine only.
    name = "hertz+history+epsd2+sjkr"
    print()
    rates = {}
    for threads in (1, 2):
        if threads == 2:
            print(f"{name:28s} core-to-core round trip before: {core_round_trip_ns(probe)}")
        r = run_engine(args.engine, True, threads, args.steps, args.repeats)
        rates[threads] = r["dense"]
        print(
            f"{name:28s} threads={threads}: {r['atoms']} particles, dense phase "
            f"{mps(r['dense'])} M particle-steps/s (median of {args.repeats}: "
            f"{mps(r['dense_median'])} M), whole run {mps(r['whole'])} M; "
            f"peak memory {r['peak_kib'] / r['atoms']:.2f} KiB/particle",
            flush=True,
        )
    print(f"{name:28s} core-to-core round trip after: {core_round_trip_ns(probe)}")
    print(f"{name:28s} speed-up 2 threads / 1 thread (dense): {rates[2] / rates[1]:.2f}x")


if __name__ == "__main__":
    main()
