#!/usr/bin/env python3
"""Impulse waves of granular slides against the relation of Heller & Hager (2010).

    python tools/impulse_waves.py [--scenarios all|S1,S3] [--dx 0.02] [--refine] [--t-end 1.2]
        [--threads 2] [--mixsph build/mixsph] [--out out/impulse_waves] [--reuse] [--check]
        [--doc FILE]
    mixsph-validate impulse ...      (the same, installed by ./tools/do setup)

The set-up (cases/slide_flume.json, Fritz 2002 / Heller & Hager 2010 style): a dry gravel slab
(bulk density 1590 kg/m3, phi 35, under the elastic-plastic law with its wall friction delta =
phi) on a 45-degree ramp, pushed by a plate (the launcher) at `speed` over 0.4 m, then released to
slide freely down the ramp into still water `depth` deep; the flume beyond the ramp's toe is flat.
Each scenario is the case with its own speed, slab thickness T (normal to the ramp) and water
depth h (the floor lowered, the still level kept at z = -0.15 m), written by this script as
OUT/<scenario>/case.json with its monitors:
    impact   a slide_impact monitor on the slide (still level, ramp angle 45, the ramp x <= its toe);
    g<k>     wave_gauge monitors at x - x_s = k h / 2, k = 2..8 (1 to 4 depths from the still
             shoreline x_s).
From the run's own impact the impulse product (Heller & Hager 2010, eq. for P; 2D: per unit width)
    P = F S^(1/2) M^(1/4) cos(6 alpha / 7)^(1/2),   F = V_s / sqrt(g h), S = s / h,
    M = m_s / (rho_w b h^2)
and the largest amplitude a_M = the largest eta over the gauges and the run, against
a_M / h = (4/9) P^0.8. Criteria (issue 59): each scenario's a_M within +-30 % of the relation
(the data's scatter), and the exponent of a least-squares fit of log(a_M / h) on log P within 0.6
to 1.0. --refine runs each scenario at dx and dx / 2; the table gives both and the change.

Written: OUT/impulse_waves.md (the table and the command) and, with --doc FILE, the same there.
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
from mixsph_tools.readers import read_monitors  # noqa: E402
from mixsph_tools.report import write_report  # noqa: E402
from mixsph_tools.runs import with_law  # noqa: E402

PROG = "tools/impulse_waves.py"
CASE = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "cases", "slide_flume.json")
G = 9.81
RHO_W = 1000.0                 # [kg/m3] the water's (the case's)
ALPHA = 45.0                   # [deg] the ramp
STILL_Z = -0.15                # [m] the still level of the case (the ramp is x + z = 0)
STROKE = 0.4                   # [m] the plate's stroke
BACK = (-0.282843, 0.282843)   # the slab's back bottom corner on the ramp
FLUME_END = 2.95               # [m] the flume's end wall (shorter than the case's 3.45: cost)
GAUGE_STEPS = range(2, 9)      # gauges at k h / 2 from the still shoreline
CRITERION = 0.30               # a_M within +-30 % of (4/9) P^0.8 h
EXPONENT = (0.6, 1.0)          # the fitted exponent of a_M on P

# name: (plate speed [m/s], slab thickness T [m], water depth h [m])
SCENARIOS = {
    "S1": (1.5, 0.04, 0.45),
    "S2": (1.5, 0.04, 0.30),
    "S3": (2.5, 0.08, 0.30),
    "S4": (4.0, 0.12, 0.30),
    "S5": (5.0, 0.12, 0.30),
}


def scenario_case(base, speed, thickness, depth, t_end):
    """The case of one scenario (a dict): the elastic-plastic law, the slab of thickness T, the plate
    at `speed` over the stroke, the floor at STILL_Z - depth, the flume to FLUME_END, its monitors."""
    c = with_law(base, "elastic_plastic", CASE)
    c["parameters"]["slide_speed"] = speed
    c["parameters"]["push_duration"] = STROKE / speed
    r = 1.0 / math.sqrt(2.0)
    poly = c["bodies"]["slide"]["polygon"]
    poly[2] = [thickness * r, thickness * r]
    poly[3] = [BACK[0] + thickness * r, BACK[1] + thickness * r]
    floor = STILL_Z - depth
    toe = -floor                                    # where the ramp x + z = 0 meets the floor
    c["bodies"]["flume"]["polygon"] = [[-STILL_Z, STILL_Z], [toe, floor], [FLUME_END, floor], [FLUME_END, STILL_Z]]
    c["walls"]["bed"]["polyline"] = [[-0.45, 0.45], [toe, floor], [FLUME_END, floor], [FLUME_END, 0.15]]
    c["domain"] = {"x_min": -0.5, "x_max": FLUME_END + 0.05, "z_min": floor - 0.05, "z_max": 0.8}
    c["numerics"]["t_end"] = t_end
    shore = -STILL_Z
    mons = {"impact": {"type": "slide_impact", "medium": "gravel", "still": STILL_Z, "angle": ALPHA,
                       "x_max": toe}}
    for k in GAUGE_STEPS:
        mons[f"g{k}"] = {"type": "wave_gauge", "medium": "water", "x": shore + 0.5 * k * depth, "still": STILL_Z}
    c["monitors"] = mons
    c["output"] = {"monitor_interval": 0.002}
    return c


def impulse_product(v_s, s, m, h, alpha=ALPHA):
    """P of Heller & Hager (2010): m the slide's mass per unit width, alpha its slope [deg]."""
    F = v_s / math.sqrt(G * h)
    S = s / h
    M = m / (RHO_W * h * h)
    return F * math.sqrt(S) * M ** 0.25 * math.sqrt(math.cos(math.radians(6.0 * alpha / 7.0)))


def run_one(a, name, dx):
    """Run (or with --reuse read) one scenario at dx; returns a dict of its results."""
    speed, thickness, depth = SCENARIOS[name]
    out = os.path.join(a.out, f"{name}_dx{dx:g}")
    os.makedirs(out, exist_ok=True)
    with open(CASE) as f:
        base = json.load(f)
    case = os.path.join(out, "case.json")
    with open(case, "w") as f:
        json.dump(scenario_case(base, speed, thickness, depth, a.t_end), f, indent=1)
    res = {"name": name, "dx": dx, "speed": speed, "T": thickness, "h": depth, "status": "ok", "wall": math.nan}
    mon = os.path.join(out, "monitors.csv")
    summary = os.path.join(out, "summary.json")
    if not (a.reuse and os.path.isfile(summary)):
        cmd = [a.mixsph, "run", case, "--out", out, "--set", f"numerics.dx={dx:g}", "--threads", str(a.threads),
               "--quiet"] + [w for kv in a.set for w in ("--set", kv)]
        print("$", shlex.join(cmd), flush=True)
        r = subprocess.run(cmd, capture_output=True, text=True)
        with open(os.path.join(out, "mixsph.log"), "w") as f:
            f.write(r.stdout + r.stderr)
        if r.returncode != 0:
            res["status"] = f"FAILED ({r.returncode})"
    if os.path.isfile(summary):
        with open(summary) as f:
            sm = json.load(f)
        res["wall"] = float(sm.get("wall_time_s", sm.get("wall_s", math.nan)) or math.nan)
    if not os.path.isfile(mon):
        res["status"] = "no monitors"
        return res
    cols = read_monitors(mon)
    last = lambda k: float(np.asarray(cols[k], float)[-1])  # noqa: E731 (the impact's values, kept once taken)
    v_s, s, m = last("impact_speed"), last("impact_thickness"), last("impact_mass")
    res.update(t_impact=last("impact"), v_s=v_s, s=s, m=m)
    res["P"] = impulse_product(v_s, s, m, depth) if math.isfinite(v_s) else math.nan
    etas = {k: np.nanmax(np.asarray(cols[f"g{k}"], float)) for k in GAUGE_STEPS}
    kmax = max(etas, key=lambda k: etas[k])
    res["a_M"], res["at"] = float(etas[kmax]), 0.5 * kmax
    res["a_rel"] = res["a_M"] / depth
    res["law"] = 4.0 / 9.0 * res["P"] ** 0.8
    res["off"] = res["a_rel"] / res["law"] - 1.0
    res["excluded"] = last("excluded_mass") / float(np.asarray(cols["mass"], float)[0])
    return res


def fit_exponent(rows):
    """The exponent b of a least-squares fit a_M / h = c P^b over rows (NaN for fewer than 2)."""
    pts = [(math.log(r["P"]), math.log(r["a_rel"])) for r in rows
           if math.isfinite(r.get("P", math.nan)) and r.get("a_rel", 0) > 0]
    if len(pts) < 2:
        return math.nan
    x, y = np.array(pts).T
    return float(np.polyfit(x, y, 1)[0])


def f(v, spec):
    return format(v, spec) if isinstance(v, (int, float)) and math.isfinite(v) else "n/a"


def table(rows, coarse_of):
    head = ("| scenario | dx [m] | status | wall [s] | plate [m/s] | T [m] | h [m] | V_s [m/s] | s [m] | m_s [kg/m] "
            "| P | a_M [m] | at x/h | a_M/h | (4/9) P^0.8 | off | within 30 % | P vs 2 dx | a_M vs 2 dx |")
    lines = [head, "|" + " --- |" * (head.count("|") - 1)]
    for r in rows:
        c = coarse_of(r)
        d_p = 100 * (r["P"] / c["P"] - 1) if c and math.isfinite(c.get("P", math.nan)) else math.nan
        d_a = 100 * (r["a_M"] / c["a_M"] - 1) if c and math.isfinite(c.get("a_M", math.nan)) else math.nan
        ok = abs(r.get("off", math.nan)) <= CRITERION
        lines.append(f"| {r['name']} | {r['dx']:g} | {r['status']} | {f(r['wall'], '.0f')} | {r['speed']:g} | "
                     f"{r['T']:g} | {r['h']:g} | {f(r.get('v_s'), '.2f')} | {f(r.get('s'), '.3f')} | "
                     f"{f(r.get('m'), '.1f')} | {f(r.get('P'), '.2f')} | {f(r.get('a_M'), '.3f')} | "
                     f"{f(r.get('at'), '.1f')} | {f(r.get('a_rel'), '.3f')} | {f(r.get('law'), '.3f')} | "
                     f"{f(100 * r.get('off', math.nan), '+.0f')} % | {'yes' if ok else '**no**'} | "
                     f"{f(d_p, '+.0f')} % | {f(d_a, '+.0f')} % |")
    return lines


def main(argv=None, prog=PROG):
    ap = argparse.ArgumentParser(prog=prog, description="Impulse waves of granular slides against Heller & Hager "
                                 "(2010): a_M / h = (4/9) P^0.8.")
    ap.add_argument("--scenarios", default="all", help=f"all or some of {','.join(SCENARIOS)}")
    ap.add_argument("--dx", type=float, default=0.02, help="particle spacing [m] (default 0.02)")
    ap.add_argument("--refine", action="store_true", help="also run at dx / 2 and give the change")
    ap.add_argument("--t-end", type=float, default=1.2, help="end time [s] (default 1.2)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--mixsph", default="build/mixsph")
    ap.add_argument("--out", default="out/impulse_waves")
    ap.add_argument("--reuse", action="store_true", help="read finished runs instead of running them again")
    ap.add_argument("--check", action="store_true", help="exit status 1 when a criterion fails")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a case override passed to every run (mixsph run --set), e.g. media.sand.rate_dependent=1")
    ap.add_argument("--doc", help="also write the table (with the command) to this file")
    a = ap.parse_args(argv)
    names = list(SCENARIOS) if a.scenarios == "all" else [x for x in a.scenarios.split(",") if x]
    bad = [x for x in names if x not in SCENARIOS]
    if bad or not names:
        ap.error(f"--scenarios {a.scenarios}: expected all or some of {','.join(SCENARIOS)}")
    if not (a.dx > 0 and a.t_end > 0 and a.threads >= 1):
        ap.error("--dx and --t-end must be positive, --threads at least 1")
    if not os.access(a.mixsph, os.X_OK):
        ap.error(f"{a.mixsph}: no mixsph executable there (build it: ./tools/do build)")
    a.mixsph = os.path.abspath(a.mixsph)
    spacings = [a.dx, a.dx / 2] if a.refine else [a.dx]
    rows = [run_one(a, n, dx) for n in names for dx in spacings]

    def coarse_of(r):
        return next((c for c in rows if c["name"] == r["name"] and abs(c["dx"] - 2 * r["dx"]) < 1e-12), None)

    lines = table(rows, coarse_of)
    fits = {dx: fit_exponent([r for r in rows if r["dx"] == dx]) for dx in spacings}
    ex_ok = {dx: EXPONENT[0] <= b <= EXPONENT[1] for dx, b in fits.items()}
    lines.append("")
    for dx, b in fits.items():
        lines.append(f"Fitted exponent of a_M/h on P at dx = {dx:g} m: {f(b, '.2f')} (criterion {EXPONENT[0]:g}-"
                     f"{EXPONENT[1]:g}: {'met' if ex_ok[dx] else '**not met**'}).")
    worst = max((r.get("excluded", 0.0) for r in rows), default=0.0)
    lines.append(f"Largest excluded mass: {100 * worst:.3f} % of the total.")
    write_report(lines, PROG, list(argv) if argv is not None else sys.argv[1:], a.out, "impulse_waves.md", a.doc)
    failed = [r for r in rows if r["status"] != "ok"]
    if failed:
        print(f"{prog}: failed runs: {', '.join(r['name'] + ' dx ' + format(r['dx'], 'g') for r in failed)}",
              file=sys.stderr)
        raise SystemExit(1)
    if a.check and not (all(abs(r["off"]) <= CRITERION for r in rows) and all(ex_ok.values())):
        print(f"{prog}: a criterion is not met (table above)", file=sys.stderr)
        raise SystemExit(1)


if __name__ == "__main__":
    main()
