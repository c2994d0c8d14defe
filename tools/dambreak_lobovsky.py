#!/usr/bin/env python3
"""The water dam break against a wall of Lobovsky et al. (2014) (cases/dambreak_lobovsky.json):
the first pressure peak at the downstream wall's sensors, with and without density diffusion,
against the measured statistics; and the pressure noise of the column at rest.

    PYTHONPATH=$PWD python -m tools.dambreak_lobovsky [--H 0.3 0.6] [--dx 0.01] [--t-end 1.0]
        [--threads 2] [--mixsph build/mixsph] [--out out/dambreak_lobovsky] [--reuse]
        [--no-rest] [--rest-time 1.0] [--set KEY=VALUE]...

Reference: L. Lobovsky, E. Botia-Vera, F. Castellana, J. Mas-Soler, A. Souto-Iglesias (2014),
"Experimental investigation of dynamic pressure loads during dam break", J. Fluids Struct. 48,
407-434: a column 0.6 m wide, H = 0.3 or 0.6 m high, released in a tank 1.61 m long; pressure
sensors on the downstream wall at 3, 15, 30 and 80 mm above the floor; about 100 repetitions
per H, the peak pressure of each sensor given by its median and its 2.5 / 97.5 % percentiles.
The numbers below are those found in public transcriptions of the paper (REFERENCE; where each
comes from: docs/validation/dambreak_lobovsky.md); a sensor without one is compared with nothing.

For each H and each density diffusion (off: numerics.density_diffusion = 0; on: the case's
default) the case is run and each sensor is read, at every time step, by two monitors: the
pressure probe <s>_probe (the fluid's pressure interpolated by the kernel at the sensor's height,
1.5 h from the wall: docs/model.md section 9) and the wall monitor <s> (the highest pressure of
the wall's first layer of particles within 6 mm of the sensor's height). For each signal:

- arrival: the first sample above ARRIVAL x rho g H (the sensor is wet; before it, 0);
- first peak: the largest sample within PEAK_WINDOW s after the arrival, and its time; also the
  same on the signal averaged over SMOOTH s (a sensor of finite size and bandwidth does not see
  the single-sample spikes of a particle method);
- the largest sample of the whole run and its time;
- the mean pressure from AFTER[0] to AFTER[1] s after the first peak (the level the signal
  falls back to after the impact's spike) and the width of the spike at half its height.

--rest also runs the column at rest (a gate wall at x = 0.6 m added to the case) for --rest-time
seconds, both ways, and gives the rms deviation of the water's pressure from rho0 g (z_s - z)
over the snapshots (every 0.01 s) and the rms after removing each layer's mean (the noise), as
tools/hydrostatic_noise.py measures the hydrostatic tank: the pressure noise of the column before
it is released.

Prints the tables, writes OUT/dambreak_lobovsky_dx<dx>.csv (one row per H, diffusion,
sensor and monitor) and draws OUT/dambreak_lobovsky_dx<dx>.png (pressure at each sensor against time, the
measured median and band). --reuse reads existing output folders instead of running. Exit status 0; 1 when a run
failed (its numbers up to the failure are still given); 2 bad usage.
"""

import argparse
import csv
import json
import math
import os
import subprocess
import sys

import numpy as np

from tools.hydrostatic_noise import measure as rest_noise
from tools.mixsph_tools.readers import ToolError, read_monitors, read_summary, run_wall_time

CASE = "cases/dambreak_lobovsky.json"
RHO0, G = 1000.0, 9.81
SENSORS = ("P1", "P2", "P3", "P4")
# The monitors reading each sensor s: (label, column of monitors.csv)
MONITORS = (("probe", "{}_probe"), ("wall", "{}"))
HEIGHTS_MM = {"P1": 3.0, "P2": 15.0, "P3": 30.0, "P4": 80.0}
ARRIVAL = 0.05       # x rho g H: a sensor counts as wet above this pressure
PEAK_WINDOW = 0.02   # s after the arrival in which the first peak is sought (about 3 times the
                     # quoted median rise time of an impact, 7 ms)
SMOOTH = 0.001       # s: the averaging window of the smoothed signal
AFTER = (0.01, 0.05) # s after the first peak: the window of the level after the spike
GATE_X = 0.6         # the column's right side [m]

# Peak pressure [mbar] per sensor: (median, 2.5 %, 97.5 %) of about 100 repetitions; None where no
# number was found. H = 0.3: Lobovsky et al. (2014), Table 2, as transcribed in
# github.com/wi-re/warpSPH scripts/probe_acsphDambreakLobovsky.py; H = 0.6, P1: the median 185.69
# mbar as quoted in github.com/Marreonline0201/universe-status scripts/fluid-gates/s34-ref.mjs.
REFERENCE = {
    0.3: {"P1": (91.44, 75.06, 130.98), "P2": (57.49, 53.26, 63.31),
          "P3": (43.76, 39.79, 49.62), "P4": (30.15, 24.18, 36.32)},
    0.6: {"P1": (185.69, None, None)},
}
MBAR = 100.0  # Pa

DIFFUSION = (("off", ["numerics.density_diffusion=0"]), ("on", []))  # on: the case's default


def run(cmd, out):
    """Run cmd writing its output to out/run.log; its exit status."""
    os.makedirs(out, exist_ok=True)
    print("$", " ".join(cmd), flush=True)
    r = subprocess.run(cmd, capture_output=True, text=True)
    with open(os.path.join(out, "run.log"), "w") as f:
        f.write(r.stdout + r.stderr)
    if r.returncode != 0:
        print(f"  exit {r.returncode}: {(r.stdout + r.stderr).strip().splitlines()[-1:]}")
    return r.returncode


def case_sets(a, H, diffusion_sets):
    """The overrides of one run: the column's height, the spacing, the diffusion's, the user's."""
    return [f"parameters.H={H}", f"numerics.dx={a.dx}"] + diffusion_sets + a.set


def rest_case(path_out):
    """Write the case with a gate wall at x = GATE_X holding the column (so it stays at rest)."""
    with open(CASE) as f:
        c = json.load(f)
    top = c["walls"]["tank"]["polyline"][0][1]
    c["name"] = "dambreak_lobovsky_rest"
    c["walls"]["gate"] = {"polyline": [[GATE_X, 0.0], [GATE_X, top]], "fluid_side": "left", "slip": "free-slip"}
    with open(path_out, "w") as f:
        json.dump(c, f, indent=1)


def sensor_stats(t, p, H):
    """Arrival, first peak (raw and smoothed) and whole-run maximum of one sensor's signal."""
    nan = float("nan")
    s = {"t_arrival": nan, "peak": nan, "t_peak": nan, "peak_smooth": nan, "t_peak_smooth": nan,
         "max": nan, "t_max": nan, "width": nan, "mean_after": nan}
    ok = np.isfinite(p)
    if not ok.any():
        return s
    k = int(np.nanargmax(p))
    s["max"], s["t_max"] = float(p[k]), float(t[k])
    wet = np.nonzero(ok & (p > ARRIVAL * RHO0 * G * H))[0]
    if not wet.size:
        return s
    ta = float(t[wet[0]])
    s["t_arrival"] = ta
    win = (t >= ta) & (t <= ta + PEAK_WINDOW)
    j = np.nonzero(win)[0][int(np.nanargmax(p[win]))]
    s["peak"], s["t_peak"] = float(p[j]), float(t[j])
    half = 0.5 * p[j]
    lo, hi = j, j
    while lo > 0 and p[lo] > half:
        lo -= 1
    while hi < p.size - 1 and p[hi] > half:
        hi += 1
    s["width"] = float(t[hi] - t[lo])
    after = (t >= t[j] + AFTER[0]) & (t <= t[j] + AFTER[1]) & ok
    if after.any():
        s["mean_after"] = float(np.mean(p[after]))
    dt = float(np.median(np.diff(t))) if t.size > 1 else SMOOTH
    n = max(1, int(round(SMOOTH / dt)))
    ps = np.convolve(np.nan_to_num(p), np.ones(n) / n, mode="same")
    j = np.nonzero(win)[0][int(np.argmax(ps[win]))]
    s["peak_smooth"], s["t_peak_smooth"] = float(ps[j]), float(t[j])
    return s


def fmt(v, spec):
    return format(v, spec) if v is not None and math.isfinite(v) else "-"


def impact_runs(a, status):
    """{(H, label): (t, {sensor: p}, stats, info)} of the dam-break runs."""
    res = {}
    for H in a.H:
        for label, sets in DIFFUSION:
            out = os.path.join(a.out, f"H{H:g}_dx{a.dx:g}_{label}")
            if not a.reuse:
                cmd = [a.mixsph, "run", CASE, "--threads", str(a.threads), "--quiet", "--out", out,
                       "--set", f"numerics.t_end={a.t_end}"]
                for s in case_sets(a, H, sets):
                    cmd += ["--set", s]
                if run(cmd, out) != 0:
                    status[0] = 1
            try:
                mon = read_monitors(os.path.join(out, "monitors.csv"))
            except ToolError as e:
                print(f"H = {H:g}, diffusion {label}: {e}")
                status[0] = 1
                continue
            info = {"t_last": float(mon["t"][-1]), "wall_time": float("nan"), "steps": float("nan")}
            try:
                summ = read_summary(os.path.join(out, "summary.json"))
                info["wall_time"] = run_wall_time(summ)
                info["steps"] = float(summ.get("steps", float("nan")))
            except ToolError:
                pass
            sig = {(kind, s): mon[col.format(s)] for kind, col in MONITORS for s in SENSORS if col.format(s) in mon}
            stats = {k: sensor_stats(mon["t"], sig[k], H) for k in sig}
            res[(H, label)] = (mon["t"], sig, stats, info)
    return res


def in_band(peak, ref):
    """'yes' / 'no' whether a peak lies in the measured 2.5-97.5 % band, '-' without one."""
    if not ref or ref[1] is None or not math.isfinite(peak):
        return "-"
    return "yes" if ref[1] * MBAR <= peak <= ref[2] * MBAR else "no"


def print_impacts(res):
    print("\nFirst pressure peak at the downstream wall's sensors (Pa; times from the release, s)")
    print(f"{'H [m]':>5s} {'diff':>4s} {'sensor':>6s} {'monitor':>7s} {'arrival':>8s} {'first peak':>10s} {'at t':>7s} "
          f"{'1 ms mean':>9s} {'width ms':>8s} {'after':>7s} {'max run':>9s} {'at t':>7s} {'exp. median':>11s} {'exp. 2.5-97.5 %':>16s} "
          f"{'peak/median':>11s} {'in band':>7s}")
    rows = []
    for (H, label), (_, _, stats, info) in sorted(res.items()):
        for (kind, s), st in sorted(stats.items(), key=lambda kv: (kv[0][1], kv[0][0])):
            ref = REFERENCE.get(H, {}).get(s)
            med = ref[0] * MBAR if ref else None
            band = f"{ref[1] * MBAR:.0f}-{ref[2] * MBAR:.0f}" if ref and ref[1] is not None else "-"
            ratio = st["peak"] / med if med else None
            print(f"{H:5g} {label:>4s} {s:>6s} {kind:>7s} {fmt(st['t_arrival'], '8.4f')} {fmt(st['peak'], '10.0f')} "
                  f"{fmt(st['t_peak'], '7.4f')} {fmt(st['peak_smooth'], '9.0f')} {fmt(1e3 * st['width'], '8.1f')} "
                  f"{fmt(st['mean_after'], '7.0f')} {fmt(st['max'], '9.0f')} "
                  f"{fmt(st['t_max'], '7.4f')} {fmt(med, '11.0f')} {band:>16s} {fmt(ratio, '11.2f')} "
                  f"{in_band(st['peak'], ref):>7s}")
            rows.append({"H": H, "diffusion": label, "sensor": s, "monitor": kind, "z_mm": HEIGHTS_MM[s], **st,
                         "exp_median": med, "exp_p2_5": ref[1] * MBAR if ref and ref[1] is not None else None,
                         "exp_p97_5": ref[2] * MBAR if ref and ref[2] is not None else None,
                         "in_band": in_band(st["peak"], ref)})
        print(f"{'':5s} {'':4s} run to t = {info['t_last']:.4f} s, {info['steps']:.0f} steps, "
              f"{info['wall_time']:.1f} s wall time")
    return rows


def rest_runs(a, status):
    """{(H, label): (rms dev, rms noise, max speed, z_s)} of the column held at rest by a gate."""
    res = {}
    case = os.path.join(a.out, "dambreak_lobovsky_rest.json")
    if not a.reuse:
        os.makedirs(a.out, exist_ok=True)
        rest_case(case)
    for H in a.H:
        for label, sets in DIFFUSION:
            out = os.path.join(a.out, f"rest_H{H:g}_dx{a.dx:g}_{label}")
            if not a.reuse:
                cmd = [a.mixsph, "run", case, "--threads", str(a.threads), "--quiet", "--out", out,
                       "--set", f"numerics.t_end={a.rest_time}", "--set", "output.snapshot_interval=0.01",
                       "--set", "output.monitor_interval=0.01"]
                for s in case_sets(a, H, sets):
                    cmd += ["--set", s]
                if run(cmd, out) != 0:
                    status[0] = 1
                    continue
            try:
                res[(H, label)] = rest_noise(out, a.dx)
            except (ToolError, ValueError, ZeroDivisionError) as e:
                print(f"rest H = {H:g}, diffusion {label}: {e}")
                status[0] = 1
    print(f"\nThe column at rest behind a gate for {a.rest_time:g} s: pressure - rho0 g (z_s - z) over the "
          "snapshots (every 0.01 s)")
    print(f"{'H [m]':>5s} {'diff':>4s} {'rms dev [Pa]':>12s} {'rms noise [Pa]':>14s} {'max speed [m/s]':>15s} "
          f"{'z_s end [m]':>11s} {'rms dev / rho g H':>17s}")
    for (H, label), (dev, noise, vmax, zs) in sorted(res.items()):
        print(f"{H:5g} {label:>4s} {dev:12.2f} {noise:14.2f} {vmax:15.5f} {zs:11.5f} {dev / (RHO0 * G * H):17.2e}")
    return res


def plot(res, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    Hs = sorted({H for H, _ in res})
    if not Hs:
        return
    fig, axes = plt.subplots(len(Hs), len(SENSORS), figsize=(4 * len(SENSORS), 3.2 * len(Hs)), squeeze=False)
    colours = {"off": "tab:red", "on": "tab:blue"}
    for r, H in enumerate(Hs):
        for c, s in enumerate(SENSORS):
            ax = axes[r][c]
            ref = REFERENCE.get(H, {}).get(s)
            if ref:
                if ref[1] is not None:
                    ax.axhspan(ref[1] * MBAR, ref[2] * MBAR, color="0.85", label="exp. 2.5-97.5 %")
                ax.axhline(ref[0] * MBAR, color="0.3", ls="--", lw=1, label="exp. median")
            for label in ("off", "on"):
                if (H, label) not in res:
                    continue
                t, sig, stats, _ = res[(H, label)]
                for kind, style in (("wall", dict(lw=0.4, alpha=0.45, ls=":")), ("probe", dict(lw=0.7))):
                    if (kind, s) not in sig:
                        continue
                    ax.plot(t, sig[(kind, s)], color=colours[label], label=f"{kind}, diffusion {label}", **style)
                    st = stats[(kind, s)]
                    if kind == "probe" and math.isfinite(st["peak"]):
                        ax.plot(st["t_peak"], st["peak"], "o", ms=4, color=colours[label])
            arrivals = [res[k][2][("probe", s)]["t_arrival"] for k in res if k[0] == H and ("probe", s) in res[k][2]]
            arrivals = [x for x in arrivals if math.isfinite(x)]
            if arrivals:
                ax.set_xlim(min(arrivals) - 0.05, min(arrivals) + 0.35)
            # the scale of the probes and the measured band (the wall monitor's spikes run off it)
            tops = [res[k][2][("probe", s)]["max"] for k in res if k[0] == H and ("probe", s) in res[k][2]]
            tops = [x for x in tops if math.isfinite(x)] + ([ref[2] * MBAR] if ref and ref[1] is not None else [])
            if tops:
                ax.set_ylim(-0.1 * max(tops), 1.3 * max(tops))
            ax.set_title(f"H = {H:g} m, {s} (z = {HEIGHTS_MM[s]:g} mm)", fontsize=9)
            ax.set_xlabel("t [s]")
            ax.set_ylabel("p [Pa]")
            ax.grid(alpha=0.3)
            if r == 0 and c == 0:
                ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--H", type=float, nargs="+", default=[0.3, 0.6], help="column heights [m] (default 0.3 0.6)")
    ap.add_argument("--dx", type=float, default=0.01, help="particle spacing [m] (default 0.01)")
    ap.add_argument("--t-end", type=float, default=1.0, help="end time of the dam-break runs [s] (default 1.0)")
    ap.add_argument("--threads", type=int, default=2, help="threads of each run (default 2)")
    ap.add_argument("--mixsph", default="build/mixsph", help="the executable (default build/mixsph)")
    ap.add_argument("--out", default="out/dambreak_lobovsky", help="output folder (default out/dambreak_lobovsky)")
    ap.add_argument("--reuse", action="store_true", help="read existing output folders instead of running")
    ap.add_argument("--no-rest", dest="rest", action="store_false", help="skip the runs of the column at rest")
    ap.add_argument("--rest-time", type=float, default=1.0, help="duration of the runs at rest [s] (default 1.0)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="an override passed to every run (repeatable)")
    a = ap.parse_args()
    if not (a.dx > 0 and a.t_end > 0 and a.rest_time > 0 and all(0 < H <= 1.0 for H in a.H)):
        print("dambreak_lobovsky: --dx, --t-end, --rest-time > 0 and 0 < --H <= 1", file=sys.stderr)
        return 2
    status = [0]
    res = impact_runs(a, status)
    rows = print_impacts(res)
    if rows:
        os.makedirs(a.out, exist_ok=True)
        base = os.path.join(a.out, f"dambreak_lobovsky_dx{a.dx:g}")
        with open(base + ".csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        plot(res, base + ".png")
        print(f"\nwrote {base}.csv and {base}.png")
    if a.rest:
        rest_runs(a, status)
    return status[0]


if __name__ == "__main__":
    sys.exit(main())
