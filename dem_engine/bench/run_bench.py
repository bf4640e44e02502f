"""Engine benchmark: particle-steps per second of a packed 8 000-sphere heap at 1 and 2 threads.

Usage: python dem_engine/bench/run_bench.py [--engine PATH] [--steps N] [--repeats K]
Prints, per variant (hertz + history + EPSD2, and with SJKR) and thread count, the dense-phase
particle-steps per second (best and median of K timed repeats in one process, after the heap has
come to rest) and the peak resident memory per particle. Around each 2-thread run it prints the
cache-line round trip between the two cores (dem_core_latency, built beside the engine): on a
shared virtual machine it changes while the host moves the virtual CPUs, and the 2-thread speed
follows it.
"""

import argparse
import os
import platform
import re
import resource
import shutil
import statistics
import subprocess
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent


def deck_text(cohesion: bool) -> str:
    text = (HERE / "heap.in").read_text()
    if cohesion:
        plain = "model hertz tangential history rolling_friction epsd2"
        sjkr = "model hertz tangential history cohesion sjkr rolling_friction epsd2"
        text = text.replace(f'variable model string "{plain}"', f'variable model string "{sjkr}"')
    return text.replace("if_cohesion_placeholder", "pair_style gran ${model}")


def core_round_trip_ns(probe: Path) -> str:
    """Cache-line round trip between cores 0 and 1 (ns): the range of three samples, or why not."""
    if not probe.exists():
        return f"not measured ({probe} is not built)"
    res = subprocess.run([str(probe), "0", "1", "3"], capture_output=True, text=True)
    if res.returncode != 0:
        return f"not measured ({res.stderr.strip()})"
    samples = [float(v) for v in res.stdout.split()]
    return f"{min(samples):.0f}-{max(samples):.0f} ns"


def run_once(engine: str, cohesion: bool, threads: int, steps: int, repeats: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        deck = Path(tmp) / "heap.in"
        deck.write_text(deck_text(cohesion))
        env = dict(os.environ, OMP_NUM_THREADS=str(threads), OMP_PROC_BIND="close")
        before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        res = subprocess.run(
            [
                engine,
                "-in",
                "heap.in",
                "-log",
                "none",
                "-noprogress",
                "-var",
                "dense_steps",
                str(steps),
                "-var",
                "repeats",
                str(repeats),
            ],
            cwd=tmp,
            capture_output=True,
            text=True,
            env=env,
            check=True,
        )
        peak_kib = max(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, before)
    loops = re.findall(
        r"Loop time of (\S+) on \d+ threads for (\d+) steps with (\d+) atoms "
        r"\((\S+) particle-steps/s",
        res.stdout,
    )
    timed = loops[-repeats:]
    rates = [float(rate) for _, _, _, rate in timed]
    best = max(range(len(timed)), key=lambda k: rates[k])
    return {
        "seconds": float(timed[best][0]),
        "steps": int(timed[best][1]),
        "atoms": int(timed[best][2]),
        "rate": rates[best],
        "median": statistics.median(rates),
        "peak_kib": peak_kib,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--engine",
        default=shutil.which("dem_engine") or str(ROOT / "build" / "engine" / "dem_engine"),
    )
    parser.add_argument("--steps", type=int, default=4000)
    # Repeats in one process: on a shared machine one slow stretch (another job, a descheduled
    # core) must not decide the figure; the best repeat is the engine's speed, the median shows
    # the spread.
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    args.engine = str(Path(args.engine).resolve())  # the runs happen in temporary directories
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
        f"engine: {args.engine}"
    )
    probe = ROOT / "build" / "engine" / "dem_core_latency"
    for cohesion in (False, True):
        name = "hertz+history+epsd2" + ("+sjkr" if cohesion else "")
        rates = {}
        for threads in (1, 2):
            if threads == 2:
                print(f"{name:28s} core-to-core round trip before: {core_round_trip_ns(probe)}")
            r = run_once(args.engine, cohesion, threads, args.steps, args.repeats)
            rates[threads] = r["rate"]
            print(
                f"{name:28s} threads={threads}: {r['atoms']} particles, {r['steps']} dense steps "
                f"in {r['seconds']:.2f} s -> {r['rate'] / 1e6:.2f} M particle-steps/s "
                f"(median of {args.repeats}: {r['median'] / 1e6:.2f} M); "
                f"peak memory {r['peak_kib'] / r['atoms']:.2f} KiB/particle"
            )
        print(f"{name:28s} core-to-core round trip after: {core_round_trip_ns(probe)}")
        print(f"{name:28s} speed-up 2 threads / 1 thread: {rates[2] / rates[1]:.2f}x")


if __name__ == "__main__":
    main()
