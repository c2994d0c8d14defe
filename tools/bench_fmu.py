#!/usr/bin/env python3
"""Overhead of the LandslideWave FMU over the mixsph executable on the same run.

    .venv/bin/python tools/bench_fmu.py [--build build] [--dx 0.02] [--mu0 1000] [--t-end 1.6]
                                        [--step 0.01] [--repeat 3]

Runs the Vajont case (cases/vajont_padua.json) with the same overrides, one OpenMP thread,
alternately as `mixsph run` (a child process) and through fmpy's simulate_fmu (in this process,
communication step --step), --repeat times each, and compares the CPU time (user + system) of
the two: for the executable the whole process (case reading, the run, monitors.csv and
summary.json; its particle snapshots are switched off unless --cli-snapshots, since the FMU
writes none), for the FMU the simulate_fmu call (unzip, instantiate, the run, reading every
output at every communication step). CPU time rather than wall time, so that other work on the
machine does not enter; the best of the repeats is compared. It checks first that both gave the
same max run-up and step count (the same run), and prints the overhead in percent.

Exit code 0; 1 if the two runs differ.
"""
import argparse
import json
import os
import pathlib
import resource
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "vajont_padua.json"


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_cli(mixsph, args, out_dir):
    cmd = [str(mixsph), "run", str(CASE), "--threads", "1", "--quiet", "--out", str(out_dir),
           "--set", f"numerics.dx={args.dx!r}", "--set", f"parameters.mu0={args.mu0!r}",
           "--set", f"numerics.t_end={args.t_end!r}"]
    if not args.cli_snapshots:
        cmd += ["--set", "output.snapshot_interval=0"]  # the FMU writes no files either
    c0, w0 = child_cpu(), time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    cpu, wall = child_cpu() - c0, time.perf_counter() - w0
    summary = json.loads((pathlib.Path(out_dir) / "summary.json").read_text())
    return cpu, wall, summary["outputs"]["run_up"]["max"], summary["steps"]


def run_fmu(fmu, args):
    from fmpy import simulate_fmu
    c0, w0 = time.process_time(), time.perf_counter()
    res = simulate_fmu(str(fmu), start_values={"dx": args.dx, "mu0": args.mu0}, stop_time=args.t_end,
                       step_size=args.step, output_interval=args.step)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    return cpu, wall, float(res["max_run_up"][-1]), int(res["steps"][-1]), len(res)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    ap.add_argument("--build", default=str(ROOT / "build"))
    ap.add_argument("--dx", type=float, default=0.02)
    ap.add_argument("--mu0", type=float, default=1000.0)
    ap.add_argument("--t-end", type=float, default=1.6)
    ap.add_argument("--step", type=float, default=0.01, help="communication step of the FMU run [s]")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--cli-snapshots", action="store_true",
                    help="let mixsph write its particle snapshots (off by default: the FMU writes none)")
    args = ap.parse_args()
    os.environ["OMP_NUM_THREADS"] = "1"
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    build = pathlib.Path(args.build)
    mixsph, fmu = build / "mixsph", build / "LandslideWave.fmu"
    for p in (mixsph, fmu):
        if not p.is_file():
            sys.exit(f"bench_fmu: {p} not found (./tools/do build)")
    import fmpy  # noqa: F401  (imported before timing)

    print(f"Vajont case, dx = {args.dx} m, mu0 = {args.mu0} Pa s, t_end = {args.t_end} s, 1 thread; "
          f"FMU communication step {args.step} s; CPU time (user + sys), best of {args.repeat}")
    cli, fm = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(args.repeat):
            cli.append(run_cli(mixsph, args, pathlib.Path(tmp) / f"cli{k}"))
            fm.append(run_fmu(fmu, args))
            print(f"  repeat {k + 1}: mixsph {cli[-1][0]:.2f} s CPU ({cli[-1][1]:.2f} s wall), "
                  f"FMU {fm[-1][0]:.2f} s CPU ({fm[-1][1]:.2f} s wall, {fm[-1][4] - 1} doSteps)", flush=True)
    if f"{fm[0][2]:.9g}" != f"{cli[0][2]:.9g}" or fm[0][3] != cli[0][3]:
        print(f"bench_fmu: not the same run: mixsph max run-up {cli[0][2]} in {cli[0][3]} steps, "
              f"FMU {fm[0][2]} in {fm[0][3]} steps", file=sys.stderr)
        return 1
    best_cli, best_fmu = min(c[0] for c in cli), min(f[0] for f in fm)
    over = 100.0 * (best_fmu - best_cli) / best_cli
    print(f"same run: max run-up {fm[0][2]:.6f} m, {fm[0][3]} steps")
    print(f"mixsph {best_cli:.3f} s, FMU {best_fmu:.3f} s CPU: FMU overhead {over:+.2f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
