"""Benchmark: scenarios per hour of a sweep on this machine at the default coarse resolution.

    python -m tools.dss.bench [--n 8] [--workers N] [--dx 0.03] [--stop-time T] [--fmu PATH]
                              [--out out/dss_bench]

Runs a fresh Latin-hypercube sweep (reservoir_level 0.40-0.50 m, phi 28-40 deg, the case's
other parameters) through the same command as users (python -m tools.dss sweep) on a local
cluster, and prints:
  - scenarios/hour over the whole command (cluster start-up included) and over the sweep
    itself (first submission to last result);
  - the mean wall and CPU time of one scenario, and the scenarios/hour the CPU time alone would
    allow on all workers (what an otherwise idle machine gives);
  - the load average before and after (other jobs on the machine slow everything down).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import time

import pandas as pd

from . import cli
from .store import ResultStore


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m tools.dss.bench", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=8, help="scenarios (default 8)")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--dx", type=float, default=cli.DEFAULT_DX)
    ap.add_argument("--stop-time", type=float, help="default: the FMU's (1.6 s for Vajont)")
    ap.add_argument("--fmu", default=None)
    ap.add_argument("--out", default=os.path.join(cli.ROOT, "out", "dss_bench"))
    a = ap.parse_args(argv)
    fmu = a.fmu or cli.default_fmu()
    shutil.rmtree(a.out, ignore_errors=True)
    cmd = [sys.executable, "-m", "tools.dss", "sweep", a.out, "--fmu", fmu,
           "--dist", "reservoir_level=uniform:0.40:0.50", "--dist", "phi=uniform:28:40",
           "-n", str(a.n), "--seed", "1", "--dx", str(a.dx), "--workers", str(a.workers),
           "--no-report"]
    if a.stop_time:
        cmd += ["--stop-time", str(a.stop_time)]
    load0 = os.getloadavg()
    t0 = time.monotonic()
    p = subprocess.run(cmd, cwd=cli.ROOT)
    total = time.monotonic() - t0
    load1 = os.getloadavg()
    if p.returncode != 0:
        print(f"bench: the sweep failed (exit {p.returncode})", file=sys.stderr)
        return 1
    df = ResultStore(a.out).latest()
    ok = df[df["status"] == "ok"]
    sub = pd.to_datetime(df["submitted_at"]).min()
    fin = pd.to_datetime(df["finished_at"]).max()
    sweep = (fin - sub).total_seconds()
    n = len(ok)
    print(f"\nbench: {n} of {len(df)} scenarios ok, dx = {a.dx} m, stop time "
          f"{ok['stop_time'].iloc[0] if n else '?'} s, {a.workers} workers x 1 thread")
    print(f"  whole command     : {total:8.1f} s  -> {n / total * 3600:7.0f} scenarios/h")
    print(f"  sweep (submit-last): {sweep:8.1f} s  -> {n / sweep * 3600:7.0f} scenarios/h")
    if n:
        w, c = ok["wall_time_s"].mean(), ok["cpu_time_s"].mean()
        print(f"  one scenario      : wall {w:.1f} s, CPU {c:.1f} s (mean); steps {ok['steps'].mean():.0f}")
        print(f"  CPU-bound estimate: {a.workers * 3600 / c:7.0f} scenarios/h on {a.workers} idle cores")
    print(f"  load average      : {load0[0]:.2f} before, {load1[0]:.2f} after "
          f"({os.cpu_count()} cores)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
