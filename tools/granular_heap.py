#!/usr/bin/env python3
"""Heaps of dry grains: one 3 degrees below its friction angle must stay, a steeper one must fail
and come to rest near its friction angle.

    python tools/granular_heap.py [--phi 32] [--dx 0.01] [--refine] [--t-end 3] [--threads 2]
        [--mixsph build/mixsph] [--out out/granular_heap] [--reuse] [--check] [--doc FILE]
        [--diagnose [--floor-friction DEG]]
    mixsph-validate heap ...      (the same, installed by ./tools/do setup)

The case (cases/granular_heap.json, the elastic-plastic law with its wall friction delta = phi,
the angle --phi): a symmetric heap of base 0.4 m on a no-slip floor (lengthened to x in
[-0.4, 0.8] m so that a failed heap stays on it), its apex at 0.2 tan(slope), for two slopes:
    stable  phi - 3 degrees: every grain within 0.1 dx of its start over 2 s;
    steep   45 degrees: it fails; at t_end its flanks within 3 degrees of phi.
Measured from the run.h5 snapshots (every 0.1 s): the largest displacement of a grain from its
place at t = 0 over the snapshots to 2 s; the flank angle at t_end: the top grain of every column
dx wide and a least-squares line through the tops between 20 % and 80 % of the heap's height on
each side of its highest column, the mean of the two sides (the measure of test_elastic_plastic's
repose test); the share of grains faster than 1 mm/s at t_end. --refine runs each heap at dx and
dx / 2 and gives the change.

--diagnose runs the steep heap only (at dx, and dx / 2 with --refine) and tells what sets its
final angle: per snapshot time the flank angle by the measure above and by variants of it (columns
2 dx wide; the tops between 10-90 %, 30-70 %, 20-50 % and 50-80 % of the height), the heap's
height, the toe's run-out beyond the initial base, the share of grains above 1 mm/s and their mean
speed, the slip along the floor of the grains of the first row; and the peak kinetic energy per
unit mass. --floor-friction sets the floor's friction angle delta (default: the grains' phi; 90:
no Coulomb contact, the law's own no-slip shear). Written: OUT/heap_diagnosis.md.

Written: OUT/granular_heap.md (the table and the command) and, with --doc FILE, the same there.
Exit status: 0 ok; 1 a run failed (or, with --check, a criterion failed); 2 bad usage.
"""

import argparse
import json
import math
import os
import shlex
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mixsph_tools.readers import list_snapshots, read_snapshot  # noqa: E402
from mixsph_tools.report import write_report  # noqa: E402
from mixsph_tools.runs import with_law  # noqa: E402

PROG = "tools/granular_heap.py"
CASE = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "cases", "granular_heap.json")
HALF_BASE = 0.2          # [m]
CENTRE = 0.2             # [m] the apex's x
STILL_OVER = 2.0         # [s] the stable heap's grains stay put this long
STILL_TOL = 0.1          # [dx] ... within this
ANGLE_TOL = 3.0          # [deg] the failed heap's flanks within this of phi
STEEP = 45.0             # [deg]
BELOW = 3.0              # [deg] the stable heap's slope below phi
STOP_SPEED = 1e-3        # [m/s]


def heap_case(base, phi, slope, t_end):
    c = with_law(base, "elastic_plastic", CASE)
    sand = c["media"]["sand"]
    sand["phi"] = phi
    c["bodies"]["heap"]["polygon"] = [[CENTRE - HALF_BASE, 0.0], [CENTRE + HALF_BASE, 0.0],
                                      [CENTRE, HALF_BASE * math.tan(math.radians(slope))]]
    c["walls"]["floor"]["polyline"] = [[-0.4, 0.0], [0.8, 0.0]]
    c["domain"] = {"x_min": -0.45, "x_max": 0.85, "z_min": -0.05, "z_max": 0.3}
    c["numerics"]["t_end"] = t_end
    c["monitors"] = {"speed_max": {"type": "speed", "medium": "sand"}}
    c["output"] = {"monitor_interval": 0.01, "snapshot_interval": 0.1}
    return c


def column_tops(x, z, width):
    """(x of the first column's left edge, the top z of every column `width` wide)."""
    # columns with edges at multiples of the width, so the lattice's sites x = (i + 1/2) dx are at
    # their centres: columns placed from the leftmost grain had every site on an edge, where a motion
    # of 0.01 dx moved whole columns of tops across (4 degrees on a heap that had not moved)
    x0 = (math.floor(x.min() / width) - 1) * width
    b = np.floor((x - x0) / width).astype(int)
    top = np.full(b.max() + 1, -np.inf)
    np.maximum.at(top, b, z)
    return x0, top


def flank_angle(x, z, dx, lo=0.2, hi=0.8):
    """The mean slope [deg] of the two flanks (module docstring): columns dx wide, the tops between
    lo and hi times the height; NaN when a side has < 2 columns."""
    x0, top = column_tops(x, z, dx)
    apex = int(np.argmax(top))
    H = top[apex]
    angles = []
    for side in (-1, 1):
        k = np.arange(top.size)
        sel = ((k - apex) * side > 0) & (top > lo * H) & (top < hi * H)
        if sel.sum() < 2:
            return math.nan
        slope = np.polyfit(x0 + (k[sel] + 0.5) * dx, top[sel], 1)[0]
        angles.append(math.degrees(math.atan(abs(slope))))
    return float(np.mean(angles))


# --diagnose: the variants of the flank angle (label, column width in dx, lo, hi)
ANGLE_VARIANTS = (("20-80 %", 1, 0.2, 0.8), ("2 dx columns", 2, 0.2, 0.8), ("10-90 %", 1, 0.1, 0.9),
                  ("30-70 %", 1, 0.3, 0.7), ("20-50 %", 1, 0.2, 0.5), ("50-80 %", 1, 0.5, 0.8))
DIAGNOSE_TIMES = (0.2, 0.4, 0.6, 0.8, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0)   # [s]


def heap_state(x, z, speed, dx):
    """What --diagnose reads at one time: the flank angle's variants [deg], the height [m], the toe's
    distance from the apex column [m], the share of grains above STOP_SPEED and their mean speed [m/s]."""
    x0, top = column_tops(x, z, dx)
    apex = int(np.argmax(top))
    xa = x0 + (apex + 0.5) * dx
    return {"angles": [flank_angle(x, z, w * dx, lo, hi) for _, w, lo, hi in ANGLE_VARIANTS],
            "height": float(top[apex]), "toe": float(max(x.max() - xa, xa - x.min())),
            "moving": float(np.mean(speed > STOP_SPEED)), "mean_speed": float(np.mean(speed))}


def diagnose_one(a, dx):
    """The --diagnose rows of the steep heap at dx (its run made or reused by run_one)."""
    res = run_one(a, "steep", dx)
    out = os.path.join(a.out, f"steep_dx{dx:g}")
    lines = [f"steep heap, dx = {dx:g} m ({res['status']}); floor friction "
             f"{'phi' if a.floor_friction is None else f'{a.floor_friction:g} deg'}", "",
             "| t [s] | " + " | ".join(f"angle {v[0]} [deg]" for v in ANGLE_VARIANTS) +
             " | height [m] | toe beyond the base [m] | grains > 1 mm/s | mean speed [mm/s] | "
             "first row's slip, mean / max [mm] |", "|" + " --- |" * (len(ANGLE_VARIANTS) + 6)]
    if res["status"] != "ok":
        return lines, res
    snaps = list_snapshots(out)
    _, c0 = read_snapshot(snaps[0][1])
    g0 = c0["state"] <= 1
    order0 = np.argsort(c0["id"][g0])
    ids0, x0, z0 = c0["id"][g0][order0], c0["x"][g0][order0], c0["z"][g0][order0]
    first_row = z0 < dx   # the grains on the floor at t = 0
    for t, ref in snaps:
        if min(abs(t - w) for w in DIAGNOSE_TIMES) > 0.02:
            continue
        _, c = read_snapshot(ref)
        g = c["state"] <= 1
        st = heap_state(c["x"][g], c["z"][g], np.hypot(c["vx"][g], c["vz"][g]), dx)
        o = np.argsort(c["id"][g])
        slip = "n/a"
        if np.array_equal(c["id"][g][o], ids0):
            d = np.abs(c["x"][g][o][first_row] - x0[first_row])
            slip = f"{1e3 * d.mean():.2f} / {1e3 * d.max():.1f}"
        lines.append(f"| {t:.1f} | " + " | ".join(f(v, ".1f") for v in st["angles"]) +
                     f" | {st['height']:.4f} | {st['toe'] - HALF_BASE:.3f} | {100 * st['moving']:.1f} % | "
                     f"{1e3 * st['mean_speed']:.2f} | {slip} |")
    mon = np.genfromtxt(os.path.join(out, "monitors.csv"), delimiter=",", names=True)
    k = int(np.argmax(mon["kinetic_energy"]))
    lines += ["", f"peak kinetic energy {mon['kinetic_energy'][k]:.4g} J/m at t = {mon['t'][k]:.2f} s: "
              f"{mon['kinetic_energy'][k] / mon['mass'][k]:.3g} J/kg", ""]
    return lines, res


def run_one(a, kind, dx):
    slope = a.phi - BELOW if kind == "stable" else STEEP
    out = os.path.join(a.out, f"{kind}_dx{dx:g}")
    os.makedirs(out, exist_ok=True)
    with open(CASE) as f:
        base = json.load(f)
    case = os.path.join(out, "case.json")
    t_end = STILL_OVER if kind == "stable" else a.t_end
    c = heap_case(base, a.phi, slope, t_end)
    if a.floor_friction is not None:
        c["walls"]["floor"]["friction"] = a.floor_friction
    with open(case, "w") as f:
        json.dump(c, f, indent=1)
    res = {"kind": kind, "slope": slope, "dx": dx, "status": "ok", "t_end": t_end}
    if not (a.reuse and os.path.isfile(os.path.join(out, "summary.json"))):
        for name in os.listdir(out):
            if name.startswith("snap_") or name in ("run.h5", "run.xdmf", "summary.json", "monitors.csv"):
                os.remove(os.path.join(out, name))
        cmd = [a.mixsph, "run", case, "--out", out, "--set", f"numerics.dx={dx:g}", "--threads", str(a.threads),
               "--quiet"] + [w for kv in a.set for w in ("--set", kv)]
        print("$", shlex.join(cmd), flush=True)
        r = subprocess.run(cmd, capture_output=True, text=True)
        with open(os.path.join(out, "mixsph.log"), "w") as f:
            f.write(r.stdout + r.stderr)
        if r.returncode != 0:
            res["status"] = f"FAILED ({r.returncode})"
            return res
    with open(os.path.join(out, "summary.json")) as f:
        res["wall"] = float(json.load(f).get("wall_time_s", math.nan))
    snaps = list_snapshots(out)
    if not snaps:
        res["status"] = "no snapshots"
        return res
    _, c0 = read_snapshot(snaps[0][1])
    g0 = c0["state"] <= 1
    ids0 = c0["id"][g0]
    order0 = np.argsort(ids0)
    x0, z0 = c0["x"][g0][order0], c0["z"][g0][order0]
    res["angle0"] = flank_angle(x0, z0, dx)
    moved = 0.0
    last = None
    for t, ref in snaps:
        _, c = read_snapshot(ref)
        g = c["state"] <= 1
        ids = c["id"][g]
        o = np.argsort(ids)
        if t <= STILL_OVER + 1e-9 and np.array_equal(ids[o], ids0[order0]):
            moved = max(moved, float(np.max(np.hypot(c["x"][g][o] - x0, c["z"][g][o] - z0))))
        last = (t, c, g)
    t, c, g = last
    res["moved_dx"] = moved / dx
    res["angle"] = flank_angle(c["x"][g], c["z"][g], dx)
    res["t_last"] = t
    res["moving"] = float(np.mean(np.hypot(c["vx"][g], c["vz"][g]) > STOP_SPEED))
    return res


def f(v, spec):
    return format(v, spec) if isinstance(v, (int, float)) and math.isfinite(v) else "n/a"


def main(argv=None, prog=PROG):
    ap = argparse.ArgumentParser(prog=prog, description="A heap below phi stays; a steeper one fails and rests "
                                 "near phi.")
    ap.add_argument("--phi", type=float, default=32.0, help="the grains' friction angle [deg] (default 32)")
    ap.add_argument("--dx", type=float, default=0.01, help="particle spacing [m] (default 0.01)")
    ap.add_argument("--refine", action="store_true", help="also run at dx / 2 and give the change")
    ap.add_argument("--t-end", type=float, default=3.0, help="end of the steep heap's run [s] (default 3)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--mixsph", default="build/mixsph")
    ap.add_argument("--out", default="out/granular_heap")
    ap.add_argument("--reuse", action="store_true", help="read finished runs instead of running them again")
    ap.add_argument("--check", action="store_true", help="exit status 1 when a criterion fails")
    ap.add_argument("--doc", help="also write the table (with the command) to this file")
    ap.add_argument("--diagnose", action="store_true", help="the steep heap's angle over time, by variants of "
                    "the measure, its toe, speeds and floor slip (module docstring)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a case override passed to every run (mixsph run --set), e.g. media.sand.rate_dependent=1")
    ap.add_argument("--floor-friction", type=float, help="the floor's friction angle delta [deg] (default: phi)")
    a = ap.parse_args(argv)
    if not (5 < a.phi < 42 and a.dx > 0 and a.t_end > 0 and a.threads >= 1):
        ap.error("--phi between 5 and 42 degrees, --dx and --t-end positive, --threads at least 1")
    if not os.access(a.mixsph, os.X_OK):
        ap.error(f"{a.mixsph}: no mixsph executable there (build it: ./tools/do build)")
    a.mixsph = os.path.abspath(a.mixsph)
    if a.floor_friction is not None and not (0.0 <= a.floor_friction <= 90.0 and a.diagnose):
        ap.error("--floor-friction: with --diagnose, between 0 and 90 degrees")
    spacings = [a.dx, a.dx / 2] if a.refine else [a.dx]
    if a.diagnose:
        lines = []
        for dx in spacings:
            lines += diagnose_one(a, dx)[0]
        write_report(lines, PROG, list(argv) if argv is not None else sys.argv[1:], a.out, "heap_diagnosis.md")
        return
    rows = [run_one(a, kind, dx) for kind in ("stable", "steep") for dx in spacings]
    head = ("| heap | slope [deg] | dx [m] | status | wall [s] | t [s] | largest displacement to 2 s [dx] | "
            "flank angle at 0 [deg] | at t [deg] | vs 2 dx [deg] | grains > 1 mm/s at t | criterion | met |")
    lines = [head, "|" + " --- |" * (head.count("|") - 1)]
    ok_all = True
    for r in rows:
        c = next((q for q in rows if q["kind"] == r["kind"] and abs(q["dx"] - 2 * r["dx"]) < 1e-12), None)
        d = r.get("angle", math.nan) - c.get("angle", math.nan) if c else math.nan
        if r["kind"] == "stable":
            crit = f"every grain within {STILL_TOL:g} dx over {STILL_OVER:g} s"
            met = r.get("moved_dx", math.inf) <= STILL_TOL
        else:
            crit = f"flanks within {ANGLE_TOL:g} deg of phi = {a.phi:g}"
            met = abs(r.get("angle", math.nan) - a.phi) <= ANGLE_TOL
        ok_all &= met and r["status"] == "ok"
        lines.append(f"| {r['kind']} | {r['slope']:g} | {r['dx']:g} | {r['status']} | {f(r.get('wall'), '.0f')} | "
                     f"{f(r.get('t_last'), '.1f')} | {f(r.get('moved_dx'), '.3g')} | {f(r.get('angle0'), '.1f')} | "
                     f"{f(r.get('angle'), '.1f')} | "
                     f"{f(d, '+.1f')} | {f(100 * r.get('moving', math.nan), '.1f')} % | {crit} | "
                     f"{'yes' if met else '**no**'} |")
    write_report(lines, PROG, list(argv) if argv is not None else sys.argv[1:], a.out, "granular_heap.md", a.doc)
    if any(r["status"] != "ok" for r in rows):
        raise SystemExit(1)
    if a.check and not ok_all:
        print(f"{prog}: a criterion is not met (table above)", file=sys.stderr)
        raise SystemExit(1)


if __name__ == "__main__":
    main()
