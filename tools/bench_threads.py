#!/usr/bin/env python3
"""The speed-up of a second thread, run by run: alternating 1- and 2-thread runs of the mixsph
executable, each its own process, with nothing set in the environment but what the caller has.

    .venv/bin/python tools/bench_threads.py [--build build] [--pairs 10] [--runs dambreak,vajont]
                                            [--t-end T]

Runs, per pair, one 1-thread run and one 2-thread run (alternating which goes first, so that a
drift of the machine's speed does not favour one), of
  dambreak  cases/dambreak_water.json at dx = 0.0025 (20,000 water particles), to --t-end
            (default 0.2 s);
  vajont    cases/vajont_padua.json (V1) at dx = 0.01, to --t-end (default 0.1 s);
and prints each run's wall time, each pair's speed-up t1 / t2 and the speed-up's minimum, median
and maximum. A benchmark (docs/performance.md), not a test: wall times depend on the machine and
on what else runs on it; state the load beside the figures.
"""
import argparse
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]

RUNS = {
    "dambreak": ("cases/dambreak_water.json", ["numerics.dx=0.0025"], 0.2),
    "vajont": ("cases/vajont_padua.json", ["numerics.dx=0.01"], 0.1),
}


def run_once(mixsph, case, sets, t_end, threads, out):
    cmd = [str(mixsph), "run", str(ROOT / case), "--threads", str(threads), "--quiet", "--no-csv", "--out", out]
    for s in sets + [f"numerics.t_end={t_end}"]:
        cmd += ["--set", s]
    t0 = time.perf_counter()
    done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    if done.returncode != 0:
        sys.exit(f"bench_threads: {' '.join(cmd)} failed ({done.returncode}): {done.stderr.strip()}")
    return wall


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=str(ROOT / "build"), help="build folder holding mixsph")
    ap.add_argument("--pairs", type=int, default=10, help="1-/2-thread pairs per run (default 10)")
    ap.add_argument("--runs", default="dambreak,vajont", help="which runs, comma-separated")
    ap.add_argument("--t-end", type=float, default=None, help="end time [s] of every run (default: per run)")
    a = ap.parse_args(argv)
    mixsph = pathlib.Path(a.build) / "mixsph"
    if not mixsph.exists():
        sys.exit(f"bench_threads: {mixsph} not built (./tools/do build)")
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = float("nan")
    print(f"bench_threads: {mixsph}, load average {load:.2f} at the start, OMP_* set: "
          f"{sorted(k for k in os.environ if k.startswith(('OMP_', 'GOMP_')))}")
    with tempfile.TemporaryDirectory() as tmp:
        for name in a.runs.split(","):
            if name not in RUNS:
                sys.exit(f"bench_threads: unknown run {name!r} (one of {', '.join(RUNS)})")
            case, sets, t_default = RUNS[name]
            t_end = a.t_end if a.t_end is not None else t_default
            speedups = []
            for k in range(a.pairs):
                order = (1, 2) if k % 2 == 0 else (2, 1)
                wall = {th: run_once(mixsph, case, sets, t_end, th, f"{tmp}/{name}_{th}") for th in order}
                speedups.append(wall[1] / wall[2])
                print(f"{name} pair {k + 1}: 1 thread {wall[1]:.2f} s, 2 threads {wall[2]:.2f} s, "
                      f"speed-up {speedups[-1]:.2f}", flush=True)
            print(f"{name} (t_end {t_end} s): speed-up min {min(speedups):.2f}, median "
                  f"{statistics.median(speedups):.2f}, max {max(speedups):.2f} over {len(speedups)} pairs; "
                  f"{sum(s >= 1.7 for s in speedups)} of them at least 1.7")
    return 0


if __name__ == "__main__":
    sys.exit(main())
