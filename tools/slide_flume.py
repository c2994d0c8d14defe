#!/usr/bin/env python3
"""The slide-into-a-flume case (cases/slide_flume.json): run it for a speed and a thickness, and
report what a violent impact does to the run.

    PYTHONPATH=$PWD python -m tools.slide_flume [--speed 2.5] [--thickness 0.08] [--dx 0.01]
        [--t-end 1.6] [--threads 2] [--mixsph build/mixsph] [--out out/slide_flume/NAME]
        [--reuse] [--set KEY=VALUE]...

--speed sets parameters.slide_speed and parameters.push_duration = 0.4 / speed (the plate's
stroke stays 0.4 m: it stops where the slab's front started); --thickness T [m] (normal to the
ramp) moves the slab's two top corners to the bottom ones plus T (1, 1) / sqrt(2). --reuse
reads an existing output folder instead of running.

Printed: how the run ended (exit status and message); per medium the smallest and largest
density over the snapshots, relative to its rho0; the mechanical energy of water and grains
(kinetic + potential, from the run.h5 snapshots, per unit depth) at the snapshots, against its
initial value; the grains' deposit at the last snapshot: median height above the flume floor and
the 50 / 95 / 99 % quantiles of x, and how many grains are higher than 0.05 m above the floor
(still suspended) beyond the ramp's toe; the largest water elevation at x >= 1 m (monitor
run_up). The energy budget: E(t) - E(0) against the work W(t) the plate has done on the water and
the grains (monitor plate_work, interpolated to the snapshot's time): E(t) - E(0) - W(t) is what
the run has dissipated, never above 0 in a sound run. E counts what particles excluded for a
density beyond numerics.density_bound took away (monitors excluded_mass, excluded_energy), and
their number is printed.

Exit status: 0 the run finished; 1 it did not (its numbers up to the failure are still printed);
2 bad usage.
"""

import argparse
import json
import math
import os
import subprocess
import sys

import numpy as np

from tools.mixsph_tools.readers import _h5_snapshots, read_monitors, read_snapshot

CASE = "cases/slide_flume.json"
STROKE = 0.4                       # the plate's stroke [m] at push_duration = 0.4 / speed
BACK = (-0.282843, 0.282843)       # the slab's bottom corners on the ramp x + z = 0
FLOOR_Z, TOE_X = -0.45, 0.45       # the flume's floor and the ramp's toe [m]
G = 9.81


def run(a, out):
    r = 1.0 / math.sqrt(2.0)
    t = a.thickness
    sets = [f"parameters.slide_speed={a.speed}", f"parameters.push_duration={STROKE / a.speed}",
            f"numerics.dx={a.dx}", f"numerics.t_end={a.t_end}",
            f"bodies.slide.polygon.2.0={t * r}", f"bodies.slide.polygon.2.1={t * r}",
            f"bodies.slide.polygon.3.0={BACK[0] + t * r}", f"bodies.slide.polygon.3.1={BACK[1] + t * r}"]
    cmd = [a.mixsph, "run", CASE, "--threads", str(a.threads), "--quiet", "--out", out]
    for s in sets + a.set:
        cmd += ["--set", s]
    print("$", " ".join(cmd))
    r = subprocess.run(cmd, capture_output=True, text=True)
    with open(os.path.join(out, "run.log"), "w") as f:
        f.write(r.stdout + r.stderr)
    return r.returncode


def media(case_path):
    """[(name, rho0)] of the case's media in index order (granular: the mixture density)."""
    with open(case_path) as f:
        c = json.load(f)
    out = []
    for name, m in c["media"].items():
        rho = float(m["rho"])
        if m["type"] == "granular":
            rho *= 1.0 - float(m["porosity"])  # dry: the grains' bulk density
        out.append((name, rho))
    return out


def report(out, case_path):
    meds = media(case_path)
    h5 = os.path.join(out, "run.h5")
    snaps = _h5_snapshots(h5) if os.path.isfile(h5) else []  # run.h5's snapshots hold the masses
    lo = {k: math.inf for k in range(len(meds))}
    hi = {k: -math.inf for k in range(len(meds))}
    energy = []
    last = None
    for t, ref in snaps:
        _, c = read_snapshot(ref)
        live = c["state"] < 2
        med = c["medium"].astype(int)
        for k in range(len(meds)):
            sel = live & (med == k)
            if sel.any():
                lo[k] = min(lo[k], float(c["rho"][sel].min()))
                hi[k] = max(hi[k], float(c["rho"][sel].max()))
        m = c["m"][live]
        ke = 0.5 * np.sum(m * (c["vx"][live] ** 2 + c["vz"][live] ** 2))
        pe = G * np.sum(m * (c["z"][live] - FLOOR_Z))
        energy.append((t, ke, pe))
        last = c
    for k, (name, rho0) in enumerate(meds):
        if math.isfinite(lo[k]):
            print(f"  {name:8s} density {lo[k]:8.1f} .. {hi[k]:8.1f} kg/m3 = rho0 x ({lo[k] / rho0:.3f} .. "
                  f"{hi[k] / rho0:.3f}) over {len(snaps)} snapshots")
    mon = os.path.join(out, "monitors.csv")
    cols = read_monitors(mon) if os.path.isfile(mon) else {}
    def at(name, t):  # a monitor column at time t, interpolated (0 without the column)
        return float(np.interp(t, cols["t"], cols[name])) if name in cols else 0.0

    def so_far(name, t):  # a running count or sum: its last sample at or before t (0 without the column)
        if name not in cols:
            return 0.0
        k = int(np.searchsorted(np.asarray(cols["t"], dtype=float), t + 1e-9, side="right")) - 1
        return float(cols[name][max(k, 0)])

    if cols and "excluded_particles" in cols:
        t_end = cols["t"][-1]
        print(f"  excluded (density beyond numerics.density_bound): {int(so_far('excluded_particles', t_end))} "
              f"particles, {so_far('excluded_mass', t_end):.4f} kg/m of {cols['mass'][0]:.4f}; floored grains at the "
              f"end: {int(so_far('floored_particles', t_end))}")
    if energy:
        e0 = energy[0][1] + energy[0][2]
        work = (lambda t: at("plate_work", t)) if "plate_work" in cols else None
        print("  E: kinetic + potential of the particles in the run plus what the excluded took away (potential from "
              "the floor)")
        print("  t [s]   kinetic [J/m]  potential [J/m]  excluded [J/m]  E - E(0) [J/m]  plate work W [J/m]  "
              "E - E(0) - W [J/m]")
        for t, ke, pe in energy:
            w = work(t) if work else math.nan
            ex = so_far("excluded_energy", t) - G * FLOOR_Z * so_far("excluded_mass", t)
            e = ke + pe + ex
            print(f"  {t:5.2f}  {ke:13.2f}  {pe:15.2f}  {ex:14.2f}  {e - e0:+14.2f}  {w:18.2f}  {e - e0 - w:+18.2f}")
    if last is not None:
        live = last["state"] < 2
        g = live & (last["medium"].astype(int) == 1)
        x, z = last["x"][g], last["z"][g] - FLOOR_Z
        beyond = x > TOE_X
        print(f"  grains at t = {energy[-1][0]:.2f} s: median height above the floor {np.median(z):.3f} m; "
              f"x quantiles 50 % {np.quantile(x, 0.5):.3f}, 95 % {np.quantile(x, 0.95):.3f}, "
              f"99 % {np.quantile(x, 0.99):.3f} m; {int(np.sum(beyond & (z > 0.05)))} of {int(np.sum(beyond))} "
              f"beyond the toe higher than 0.05 m")
        v = np.hypot(last["vx"][g], last["vz"][g])
        x99 = np.quantile(x, 0.99)
        far = x >= x99
        bed = beyond & (z <= 0.05)
        span = f"x {x[bed].min():.3f} .. {x[bed].max():.3f} m" if bed.any() else "none"
        print(f"  on the floor (within 0.05 m, beyond the toe): {int(np.sum(bed))} grains, {span}; the farthest 1 % "
              f"(x >= {x99:.3f} m): {int(np.sum(far))} grains {np.min(z[far]):.3f} .. {np.max(z[far]):.3f} m above "
              f"the floor; grain speed largest {np.max(v):.3f} m/s, 99 % {np.quantile(v, 0.99):.3f} m/s")
    if cols:
        if "run_up" in cols and len(cols["run_up"]):
            w = np.asarray(cols["run_up"], dtype=float)
            t = np.asarray(cols["t"], dtype=float)
            k = int(np.nanargmax(w))
            print(f"  run_up (largest water elevation at x >= 1 m): {w[k] - (FLOOR_Z + 0.3):+.3f} m above still water at t = {t[k]:.3f} s; "
                  f"monitors to t = {t[-1]:.3f} s")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--speed", type=float, default=2.5, help="the plate's speed [m/s] (default 2.5; its stroke "
                    "stays 0.4 m)")
    ap.add_argument("--thickness", type=float, default=0.08, help="the slab's thickness normal to the ramp [m] "
                    "(default 0.08)")
    ap.add_argument("--dx", type=float, default=0.01, help="particle spacing [m] (default 0.01)")
    ap.add_argument("--t-end", type=float, default=1.6, help="end time [s] (default 1.6)")
    ap.add_argument("--threads", type=int, default=2, help="threads of the run (default 2)")
    ap.add_argument("--mixsph", default="build/mixsph", help="the executable (default build/mixsph)")
    ap.add_argument("--out", help="output folder (default out/slide_flume/v<speed>_t<thickness>_dx<dx>)")
    ap.add_argument("--reuse", action="store_true", help="read an existing output folder instead of running")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="an override passed to the run (repeatable), e.g. numerics.density_diffusion=0")
    a = ap.parse_args()
    if not (a.speed > 0 and 0 < a.thickness <= 0.15 and a.dx > 0):
        print("slide_flume: --speed > 0, 0 < --thickness <= 0.15 (the plate's height), --dx > 0", file=sys.stderr)
        return 2
    out = a.out or f"out/slide_flume/v{a.speed:g}_t{a.thickness:g}_dx{a.dx:g}"
    status = 0
    if not a.reuse:
        os.makedirs(out, exist_ok=True)
        status = run(a, out)
    log = os.path.join(out, "run.log")
    tail = open(log).read().strip().splitlines()[-1:] if os.path.isfile(log) else []
    print(f"{out}: exit {status}" + (f" ({tail[0]})" if tail else ""))
    report(out, CASE)
    return 0 if status == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
