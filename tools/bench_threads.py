#!/usr/bin/env python3
"""The speed-up of a second thread, run by run: alternating 1- and 2-thread runs of mixsph through
the executable and through the FMU, each run its own process, with no OMP_* or GOMP_* variable in
its environment.

    .venv/bin/python tools/bench_threads.py [--build build] [--pairs 10] [--t-end T]
                                            [--runs dambreak,vajont,dambreak10k] [--modes exe,fmu]
                                            [--json FILE]

Runs, per pair, one 1-thread run and one 2-thread run (alternating which goes first, so that a
drift of the machine's speed does not favour one), of
  dambreak     cases/dambreak_water.json at dx = 0.0025 (20,000 water particles), to 0.1 s;
  vajont       cases/vajont_padua.json (V1) at dx = 0.01, to 0.1 s;
  dambreak10k  the dam break at dx = 0.0035 (10,153 particles), to 0.1 s;
(--t-end sets another end time for all), each through
  exe  `mixsph run --threads N --fixed-threads --no-csv` (the CLI's governor off: this measures a
       thread count), timed as the process's wall time;
  fmu  fmpy's simulate_fmu of LandslideWave.fmu with case_file the same case, the parameter `dx`
       and `threads` = N, in a child Python process, timed over the simulate_fmu call.
With --ceiling (exe mode) each pair also runs two 1-thread processes at once, each on the whole
case: no shared data, no barrier, no serial part. 2 t1 / (the slower of the two) is what a perfectly
parallel 2-thread step could reach on this host at that moment, its memory and caches shared as
the two threads share them (somewhat pessimistic: each process holds its own copy of the data).
It prints each run's wall time with the 1-minute load average before it, each pair's speed-up
t1 / t2, and per run and mode the speed-up's minimum, median and maximum and how many pairs
reached the issue's bar (1.7; 1.5 at 10,000 particles). A benchmark (docs/performance.md), not a
test: wall times depend on the machine and on what else runs on it; a 2-thread speed-up measured
while other processes run is not evidence of the code's.
"""
import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]

# name: (case file, dx, default end time [s], the speed-up the issue asks for)
RUNS = {
    "dambreak": ("cases/dambreak_water.json", 0.0025, 0.1, 1.7),
    "vajont": ("cases/vajont_padua.json", 0.01, 0.1, 1.7),
    "dambreak10k": ("cases/dambreak_water.json", 0.0035, 0.1, 1.5),
}


def clean_env():
    """The caller's environment without OpenMP's variables: nothing set, as a host would run."""
    return {k: v for k, v in os.environ.items() if not k.startswith(("OMP_", "GOMP_"))}


def load1():
    try:
        return os.getloadavg()[0]
    except OSError:
        return float("nan")


def exe_command(build, case, dx, t_end, threads, out):
    return [str(build / "mixsph"), "run", str(ROOT / case), "--threads", str(threads), "--fixed-threads",
            "--quiet", "--no-csv", "--out", out, "--set", f"numerics.dx={dx!r}", "--set", f"numerics.t_end={t_end!r}"]


def run_exe(build, case, dx, t_end, threads, out):
    return run_exe_together(build, case, dx, t_end, [(threads, out)])[0]


def run_exe_together(build, case, dx, t_end, runs):
    """Starts one process per (threads, out) at once and returns each one's wall time."""
    t0 = time.perf_counter()
    procs = [subprocess.Popen(exe_command(build, case, dx, t_end, th, out), stdout=subprocess.DEVNULL,
                              stderr=subprocess.PIPE, text=True, env=clean_env()) for th, out in runs]
    walls = [None] * len(procs)
    while any(w is None for w in walls):
        for i, p in enumerate(procs):
            if walls[i] is None and p.poll() is not None:
                walls[i] = time.perf_counter() - t0
        time.sleep(0.005)
    for p in procs:
        if p.returncode != 0:
            sys.exit(f"bench_threads: {' '.join(p.args)} failed ({p.returncode}): {p.stderr.read().strip()}")
    return walls


def run_fmu(build, case, dx, t_end, threads):
    """simulate_fmu in a child process (its own process, like the executable's runs)."""
    child = [sys.executable, str(pathlib.Path(__file__).resolve()), "--fmu-child",
             json.dumps({"fmu": str(build / "LandslideWave.fmu"), "case": str(ROOT / case), "dx": dx,
                         "t_end": t_end, "threads": threads})]
    done = subprocess.run(child, capture_output=True, text=True, env=clean_env())
    if done.returncode != 0:
        sys.exit(f"bench_threads: the FMU run failed ({done.returncode}): {done.stderr.strip()[-2000:]}")
    return float(done.stdout.strip().splitlines()[-1])


def fmu_child(spec):
    from fmpy import simulate_fmu

    a = json.loads(spec)
    t0 = time.perf_counter()
    simulate_fmu(a["fmu"], start_values={"case_file": a["case"], "dx": a["dx"], "threads": a["threads"]},
                 stop_time=a["t_end"], step_size=a["t_end"] / 10, output_interval=a["t_end"] / 10)
    print(time.perf_counter() - t0)
    return 0


def machine():
    """The CPU model and count, for the record."""
    model = "unknown CPU"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} logical CPUs"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=str(ROOT / "build"), help="build folder holding mixsph and LandslideWave.fmu")
    ap.add_argument("--pairs", type=int, default=10, help="1-/2-thread pairs per run and mode (default 10)")
    ap.add_argument("--runs", default="dambreak,vajont,dambreak10k", help="which runs, comma-separated")
    ap.add_argument("--modes", default="exe,fmu", help="exe, fmu or both, comma-separated")
    ap.add_argument("--t-end", type=float, default=None, help="end time [s] of every run (default: per run, 0.1 s)")
    ap.add_argument("--json", default=None, help="write every run's record to this file")
    ap.add_argument("--ceiling", action="store_true",
                    help="exe mode: per pair also run two 1-thread processes at once (the host's ceiling)")
    ap.add_argument("--fmu-child", default=None, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.fmu_child:
        return fmu_child(a.fmu_child)
    build = pathlib.Path(a.build)
    modes = a.modes.split(",")
    for m in modes:
        if m not in ("exe", "fmu"):
            sys.exit(f"bench_threads: unknown mode {m!r} (exe, fmu)")
        need = build / ("mixsph" if m == "exe" else "LandslideWave.fmu")
        if not need.exists():
            sys.exit(f"bench_threads: {need} not built (./tools/do build)")
    for name in a.runs.split(","):
        if name not in RUNS:
            sys.exit(f"bench_threads: unknown run {name!r} (one of {', '.join(RUNS)})")
    dropped = sorted(k for k in os.environ if k.startswith(("OMP_", "GOMP_")))
    print(f"bench_threads: {build}, {machine()}, load average {load1():.2f} at the start; "
          f"OMP_*/GOMP_* left out of the runs' environment: {dropped or 'none were set'}", flush=True)
    records = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in a.runs.split(","):
            case, dx, t_default, bar = RUNS[name]
            t_end = a.t_end if a.t_end is not None else t_default
            for mode in modes:
                speedups, ceilings = [], []
                for k in range(a.pairs):
                    order = (1, 2) if k % 2 == 0 else (2, 1)
                    wall, load = {}, {}
                    for th in order:
                        load[th] = load1()
                        if mode == "exe":
                            wall[th] = run_exe(build, case, dx, t_end, th, f"{tmp}/{name}_{th}")
                        else:
                            wall[th] = run_fmu(build, case, dx, t_end, th)
                        records.append({"run": name, "mode": mode, "pair": k + 1, "threads": th, "wall_s": wall[th],
                                        "load1_before": load[th], "t_end": t_end, "dx": dx})
                    speedups.append(wall[1] / wall[2])
                    print(f"{name} {mode} pair {k + 1}: 1 thread {wall[1]:.2f} s (load {load[1]:.2f}), "
                          f"2 threads {wall[2]:.2f} s (load {load[2]:.2f}), speed-up {speedups[-1]:.2f}", flush=True)
                    if a.ceiling and mode == "exe":
                        both = run_exe_together(build, case, dx, t_end, [(1, f"{tmp}/{name}_a"), (1, f"{tmp}/{name}_b")])
                        ceilings.append(2.0 * wall[1] / max(both))
                        records.append({"run": name, "mode": "two_1_thread_processes", "pair": k + 1,
                                        "wall_s": both, "t_end": t_end, "dx": dx})
                        print(f"{name} ceiling pair {k + 1}: two 1-thread runs at once {both[0]:.2f} s and "
                              f"{both[1]:.2f} s, ceiling 2 t1 / max {ceilings[-1]:.2f}", flush=True)
                print(f"{name} {mode} (dx {dx}, t_end {t_end} s): speed-up min {min(speedups):.2f}, median "
                      f"{statistics.median(speedups):.2f}, max {max(speedups):.2f} over {len(speedups)} pairs; "
                      f"{sum(s >= bar for s in speedups)} of {len(speedups)} at least {bar}", flush=True)
                if ceilings:
                    print(f"{name} ceiling (two independent 1-thread processes at once): min {min(ceilings):.2f}, "
                          f"median {statistics.median(ceilings):.2f}, max {max(ceilings):.2f}; "
                          f"{sum(c >= bar for c in ceilings)} of {len(ceilings)} at least {bar}", flush=True)
    if a.json:
        pathlib.Path(a.json).write_text(json.dumps({"machine": machine(), "build": str(build), "runs": records},
                                                   indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
