#!/usr/bin/env python3
"""under_load.py - speed of `mixsph run` on an idle machine and beside one competing busy process.

    tests/bench/under_load.py [--bin 'LABEL=PATH [OPTION]...']... [--env LABEL=VAR=VALUE[,VAR=VALUE]]...
                              [--threads 1,2] [--schemes explicit,implicit] [--loads idle,yes]
                              [--dx 0.01] [--t-end 0.1] [--cap 60] [--repeat 1] [--csv FILE]

Runs the Vajont case (cases/vajont_padua.json, run V1) at --dx to --t-end of simulated time
with every combination of binary (--bin, default build/mixsph), environment variant (--env,
default none: the environment as it is), scheme (numerics.viscosity 0 / 1), thread count and
load. The load `yes` is one `yes > /dev/null` started before the run and stopped after it.
The binaries and environment variants are the innermost loop, so that the runs to compare
alternate in one sitting. A run still going after --cap seconds of wall time is stopped with
SIGTERM (mixsph then stops before its next step and writes summary.json): its rate covers the
simulated time it reached. Prints, per run, the simulated seconds per wall minute, particle-steps
per second, the wall time, the steps, the run's CPU time, the CPU that other processes used
meanwhile (in cores: a run beside others' jobs is not a measurement of an idle machine; the `yes`
is not counted) and the 1-minute load average before the run.

A benchmark, not a test. Run it under the CPU lock of shared machines:
    flock /tmp/mixsph-cpu.lock tests/bench/under_load.py --bin before=/tmp/a/mixsph --bin after=build/mixsph
"""
import argparse
import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def loadavg():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def hog_cpu_s(hog):
    """CPU seconds the competing process has used so far (0 without one)."""
    if not hog:
        return 0.0
    try:
        with open(f"/proc/{hog.pid}/stat") as f:
            v = f.read().rsplit(")", 1)[1].split()
        return (int(v[11]) + int(v[12])) / os.sysconf("SC_CLK_TCK")
    except OSError:
        return 0.0


def busy_cpu_s():
    """CPU seconds the whole machine has spent busy (all CPUs, /proc/stat)."""
    with open("/proc/stat") as f:
        v = [int(x) for x in f.readline().split()[1:]]
    idle = v[3] + (v[4] if len(v) > 4 else 0)
    return (sum(v[:8]) - idle) / os.sysconf("SC_CLK_TCK")


def run_one(binary, env_extra, case, dx, t_end, scheme, threads, cap, load):
    out = tempfile.mkdtemp(prefix="mixsph_load_")
    exe, extra = binary.split()[0], binary.split()[1:]
    cmd = [exe, "run", case] + extra + ["--set", f"numerics.dx={dx}", "--set", f"numerics.t_end={t_end}",
           "--set", f"numerics.viscosity={1 if scheme == 'implicit' else 0}",
           "--set", "output.snapshot_interval=0", "--threads", str(threads), "--out", out, "--quiet", "--no-csv"]
    env = dict(os.environ)
    env.update(env_extra)
    la = loadavg()
    hog = None
    if load == "yes":
        hog = subprocess.Popen(["yes"], stdout=subprocess.DEVNULL)
        time.sleep(0.5)
    errf = tempfile.TemporaryFile(mode="w+")
    t0, busy0 = time.monotonic(), busy_cpu_s()
    hog0 = hog_cpu_s(hog)
    try:
        p = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=errf)
        deadline = time.monotonic() + cap
        while True:
            pid, status, ru = os.wait4(p.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() > deadline:
                p.send_signal(signal.SIGTERM)
                pid, status, ru = os.wait4(p.pid, 0)
                break
            time.sleep(0.05)
        p.returncode = status
    finally:
        elapsed, busy = time.monotonic() - t0, busy_cpu_s() - busy0
        hog_used = hog_cpu_s(hog) - hog0
        if hog:
            hog.kill()
            hog.wait()
    errf.seek(0)
    err = errf.read()
    # CPU the machine spent on anything but this run and its own `yes`, in cores over the run
    others = max(0.0, busy - (ru.ru_utime + ru.ru_stime) - hog_used) / elapsed if elapsed > 0 else float("nan")
    try:
        with open(os.path.join(out, "summary.json")) as f:
            s = json.load(f)
    except (OSError, ValueError):
        sys.stderr.write(f"under_load: no summary.json from {' '.join(cmd)}: {err}\n")
        shutil.rmtree(out, ignore_errors=True)
        return None
    shutil.rmtree(out, ignore_errors=True)
    wall, sim_t = s["wall_time_s"], s["simulated_time_s"]
    return {"status": s["status"], "wall_s": wall, "simulated_s": sim_t, "steps": s["steps"],
            "sim_s_per_min": 60.0 * sim_t / wall if wall > 0 else float("nan"),
            "psteps_per_s": s["particle_steps_per_s"], "cpu_s": ru.ru_utime + ru.ru_stime, "others_cores": others,
            "load_before": la}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", action="append", default=[],
                    help="LABEL=PATH of a mixsph executable, optionally followed by options of `mixsph run`")
    ap.add_argument("--env", action="append", default=[], help="LABEL=VAR=VALUE[,VAR=VALUE]: an environment variant")
    ap.add_argument("--case", default=os.path.join(ROOT, "cases", "vajont_padua.json"))
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--schemes", default="explicit,implicit")
    ap.add_argument("--loads", default="idle,yes")
    ap.add_argument("--dx", type=float, default=0.01)
    ap.add_argument("--t-end", type=float, default=0.1)
    ap.add_argument("--cap", type=float, default=60.0, help="stop a run after this many wall seconds")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--csv", help="append the rows to this CSV file")
    a = ap.parse_args()
    bins = [b.split("=", 1) for b in a.bin] or [["build", os.path.join(ROOT, "build", "mixsph")]]
    envs = [["-", {}]]
    for e in a.env:
        label, spec = e.split("=", 1)
        envs.append([label, dict(kv.split("=", 1) for kv in spec.split(","))])
    print(f"# under_load: {os.uname().nodename}, {os.cpu_count()} CPUs, case {a.case}, dx {a.dx}, "
          f"t_end {a.t_end} s, cap {a.cap} s, {time.strftime('%Y-%m-%d %H:%M:%S %Z')}")
    hdr = ["load", "scheme", "threads", "binary", "env", "status", "sim_s_per_min", "psteps_per_s", "wall_s",
           "simulated_s", "steps", "cpu_s", "others_cores", "load_before"]
    print("  ".join(f"{h:>13}" for h in hdr), flush=True)
    rows = []
    for _ in range(a.repeat):
        for load in a.loads.split(","):
            for scheme in a.schemes.split(","):
                for th in [int(t) for t in a.threads.split(",")]:
                    for label, path in bins:
                        for elabel, env in envs:
                            r = run_one(path, env, a.case, a.dx, a.t_end, scheme, th, a.cap, load)
                            if r is None:
                                continue
                            row = {"load": load, "scheme": scheme, "threads": th, "binary": label, "env": elabel, **r}
                            rows.append(row)
                            vals = [row[h] for h in hdr]
                            print("  ".join(f"{v:>13.4g}" if isinstance(v, float) else f"{v!s:>13}" for v in vals),
                                  flush=True)
    if a.csv:
        new = not os.path.exists(a.csv)
        with open(a.csv, "a", newline="") as f:
            w = csv.DictWriter(f, fieldnames=hdr)
            if new:
                w.writeheader()
            for r in rows:
                w.writerow({h: r[h] for h in hdr})


if __name__ == "__main__":
    main()
