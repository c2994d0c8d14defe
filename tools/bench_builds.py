#!/usr/bin/env python3
"""Two builds of mixsph against each other on the same runs, interleaved in one sitting.

    .venv/bin/python tools/bench_builds.py --ref REF_BUILD [--new build] [--pairs 5]
                                           [--threads 1,2] [--runs dambreak20k,vajont_v1]

For each run and thread count it takes one warm-up of each build, then `--pairs` pairs, the order
within a pair alternating (new, ref / ref, new) so that a drift of the machine's speed favours
neither, and prints each build's median wall and CPU seconds of the whole process (the kernel's
accounting of the finished child) and the median of the pairs' ratios new/ref with their range.
The runs:
  dambreak20k  build/bench_dambreak --dx 0.0025 --steps 1500 (20,000 water particles, timed steps);
  vajont_v1    mixsph run cases/vajont_padua.json (V1) at dx = 0.01, explicit, to t = 0.1 s, --no-csv.
A benchmark (docs/performance.md), not a test: it asserts nothing; quote it with the machine's load.
"""
import argparse
import os
import pathlib
import resource
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]


def command(build, run, threads, out):
    if run == "dambreak20k":
        return [str(build / "bench_dambreak"), "--dx", "0.0025", "--steps", "1500", "--threads", str(threads)]
    if run == "vajont_v1":
        return [str(build / "mixsph"), "run", str(ROOT / "cases" / "vajont_padua.json"), "--set", "numerics.dx=0.01",
                "--set", "numerics.t_end=0.1", "--threads", str(threads), "--fixed-threads", "--no-csv", "--quiet",
                "--out", out]
    raise SystemExit(f"unknown run {run!r} (dambreak20k, vajont_v1)")


def timed(cmd):
    """(wall, cpu) seconds of one run of cmd as a child process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    rc = subprocess.call(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.monotonic() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if rc != 0:
        raise SystemExit(f"{' '.join(cmd)}: exit {rc}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ref", required=True, type=pathlib.Path, help="the reference build folder")
    ap.add_argument("--new", default=ROOT / "build", type=pathlib.Path, help="the build measured (default build/)")
    ap.add_argument("--pairs", type=int, default=5)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--runs", default="dambreak20k,vajont_v1")
    a = ap.parse_args(argv)
    print(f"load average before: {os.getloadavg()[0]:.2f}; {a.pairs} pairs after a warm-up each")
    print(f"{'run':<12} {'threads':>7} {'new wall':>9} {'ref wall':>9} {'new/ref wall':>22} {'new/ref cpu':>22}")
    with tempfile.TemporaryDirectory() as tmp:
        for run in a.runs.split(","):
            for threads in (int(t) for t in a.threads.split(",")):
                cmds = {k: command(b.resolve(), run, threads, os.path.join(tmp, k)) for k, b in (("new", a.new), ("ref", a.ref))}
                for k in ("new", "ref"):
                    timed(cmds[k])
                res = {"new": [], "ref": []}
                for p in range(a.pairs):
                    for k in (("new", "ref") if p % 2 == 0 else ("ref", "new")):
                        res[k].append(timed(cmds[k]))
                rw = [n[0] / r[0] for n, r in zip(res["new"], res["ref"])]
                rc = [n[1] / r[1] for n, r in zip(res["new"], res["ref"])]
                med = lambda xs: statistics.median(xs)
                print(f"{run:<12} {threads:>7} {med([x[0] for x in res['new']]):>9.3f} {med([x[0] for x in res['ref']]):>9.3f} "
                      f"{med(rw):>8.4f} ({min(rw):.3f}-{max(rw):.3f}) {med(rc):>8.4f} ({min(rc):.3f}-{max(rc):.3f})")
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
