#!/usr/bin/env python3
"""SPHERIC benchmark test 2 (cases/spheric_test2.json) against the MARIN experiment of Kleefsman
et al. (2005): the water heights at the gauges H1-H4 and the pressures on the box's front, the
runs' time series beside the measured ones, and the differences.

    .venv/bin/python tools/spheric_test2.py RUN [RUN...] [--exp FILE] [--every 0.5] [-o FIG.png]
        [--check]
    .venv/bin/python tools/spheric_test2.py --check-data FILE

RUN is the output folder of `mixsph run cases/spheric_test2.json` (several: e.g. two spacings).
FILE is the measured series (default data/spheric_test2/kleefsman_marin.csv; columns Time [s],
P1.. [Pa], H1..H4 [m]; its README says where it comes from).

What the runs read (the case's description): a gauge's water height is its max_elevation monitor
(the highest water particle centre over a square 2 dx wide about the gauge) plus dx/2, the water's
top above that centre; a dry square reads 0. A pressure sensor is read two ways: Pk, a probe in the
flow 1.5 h in front of the face, and Pk_wall (when the case has it), the highest pressure of the
box's first layer of wall particles within dx/2 of the sensor's height and within dx of its y (the
fluid's pressure extrapolated onto the face).

The differences, each computed the same way on the run and on the experiment:

- arrival at H1-H3: the first time the height reaches ARRIVAL_H; H4 (in the reservoir): the first
  time it falls below DRAIN_H, half the column's depth;
- the first impact at each sensor: its onset, the first time it exceeds PEAK_ONSET, and the
  largest pressure within PEAK_WINDOW s after it, and its time (first_peak);
- the rms of the height difference run - experiment over the experiment's 10 ms grid (the impact
  window's extra rows left out, so that each time counts alike), from 0 s to the end of the run
  (6 s for a run that reached it); also for the pressures, over 1-6 s (after the impact, the
  quasi-static load) and over the whole span.

--check tests a run against tolerances stated and argued in CHECKS (exit 1 when one fails; a run
that stopped before 6 s fails). --check-data checks the measured file alone (time strictly
increasing, the 10 ms grid complete from 0 to 6 s, H4 starting near 0.55 m, values in range) and
prints what it finds. Writes RUN/spheric_test2.png for one run, or -o. Exit codes: 0 ok, 1 a check
failed, 2 missing or bad files.
"""
import argparse
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mixsph_tools.readers import ToolError, read_monitors  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXP_DEFAULT = os.path.join(ROOT, "data", "spheric_test2", "kleefsman_marin.csv")
GAUGES = ("H1", "H2", "H3", "H4")
GAUGE_X = {"H1": 0.496, "H2": 0.992, "H3": 1.488, "H4": 2.638}  # m, the case's gauges (y = 0.5 m)
PROBES = ("P1", "P2", "P3", "P4")
T_END = 6.0          # s: the benchmark's span
DEPTH = 0.55         # m: the column's depth (H4 at t = 0)
ARRIVAL_H = 0.05     # m: a gauge counts as reached (above the experiment's dry noise and the run's
                     # thinnest reading, one particle on the floor: dx = 0.04-0.05 m)
DRAIN_H = 0.5 * DEPTH  # m: H4's "arrival" is the reservoir falling below half its depth
PEAK_ONSET = 1000.0  # Pa: a pressure sensor counts as wet
PEAK_WINDOW = 0.3    # s after the onset in which the first impact peak is sought
GRID = 0.01          # s: the experiment file's regular grid
SLOT_TOL = 0.5e-3    # s: a row within half the 1 kHz sampling period of a grid time is its row
QUASI_STATIC = (1.0, 6.0)  # s: the pressures' comparison after the first impact

# The measured file's column at each of the case's gauges. Its H1 and H3 are the gauges at
# x = 1.488 and 0.496 m, the reverse of the case's labels: the file's H1 is wet at 0.25 s, when no
# water can have reached x = 0.496 m (1.5 m from the column's face, behind the box: Ritter's front,
# 2 sqrt(g 0.55) = 4.6 m/s, an upper bound, is at most 1.16 m out), and its H3 last, at 0.94 s;
# the arrival order of the file's H1, H2, H3 is that of x = 1.488, 0.992, 0.496 m.
EXP_GAUGE = {"H1": "H3", "H2": "H2", "H3": "H1", "H4": "H4"}

# --check: (metric, gauge, tolerance, why). A metric beyond its tolerance fails the check.
CHECKS = (
    ("rms_h", "H2", "dx", "the gauge reads the top particle centre + dx/2, so a resolved surface is "
                          "known to about dx/2; dx allows as much again for the splash"),
    ("rms_h", "H3", "dx", "as H2"),
    ("rms_h", "H4", "dx", "as H2 (the reservoir: a deep, resolved column)"),
    ("arrival", "H2", 0.05, "s; the front at 4-5 m/s crosses the gauge's 2 dx square and a "
                            "PEAK_ONSET-like threshold in about 0.02 s at dx = 0.05; 0.05 s is that "
                            "twice with the 5 ms sampling"),
    ("arrival", "H3", 0.05, "s; as H2"),
    ("drain", "H4", 0.1, "s; the reservoir falls at about 0.3 m/s through DRAIN_H: 0.1 s is "
                         "0.03 m, less than one particle"),
)


def heights(mon, dx):
    """{gauge: water height [m]}: the top particle centre + dx/2, 0 where the square is dry."""
    return {g: np.where(np.isfinite(mon[g]), mon[g] + 0.5 * dx, 0.0) for g in GAUGES if g in mon}


def first_peak(t, p, onset=PEAK_ONSET, window=PEAK_WINDOW):
    """(time, value) of the largest p within `window` s after p first exceeds `onset`."""
    k = np.flatnonzero(p > onset)
    if len(k) == 0:
        return float("nan"), float("nan")
    sel = (t >= t[k[0]]) & (t <= t[k[0]] + window)
    j = np.flatnonzero(sel)[np.argmax(p[sel])]
    return float(t[j]), float(p[j])


def first_time_at_least(t, v, level):
    """First t at which v >= level (nan values never count), nan if never."""
    k = np.flatnonzero(np.isfinite(v) & (v >= level))
    return float(t[k[0]]) if k.size else math.nan


def first_time_below(t, v, level):
    """First t at which v < level (nan values never count), nan if never."""
    k = np.flatnonzero(np.isfinite(v) & (v < level))
    return float(t[k[0]]) if k.size else math.nan


def arrival(t, h, gauge):
    """The gauge's arrival time [s]: H1-H3 the first time the water reaches ARRIVAL_H; H4, in the
    reservoir, the first time it falls below DRAIN_H."""
    return first_time_below(t, h, DRAIN_H) if gauge == "H4" else first_time_at_least(t, h, ARRIVAL_H)


def read_experiment(path):
    """The measured series as {"t": array, "P1": array, ..., "H4": array}: the columns Time and
    any of P1-P8, H1-H4 of a CSV file (a header line, then numbers)."""
    if not os.path.isfile(path):
        raise ToolError(f"{path} not found (the measured series: data/spheric_test2/README.md)")
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    if not rows:
        raise ToolError(f"{path}: empty")
    header = [h.strip() for h in rows[0]]
    if "Time" not in header:
        raise ToolError(f"{path}: no column 'Time' (header: {','.join(header)})")
    wanted = ["Time"] + [f"P{k}" for k in range(1, 9)] + list(GAUGES)
    cols = {name: header.index(name) for name in wanted if name in header}
    data = {name: [] for name in cols}
    for lineno, r in enumerate(rows[1:], start=2):
        if len(r) != len(header):
            raise ToolError(f"{path}:{lineno}: {len(r)} fields but {len(header)} names in the header")
        for name, k in cols.items():
            try:
                data[name].append(float(r[k]))
            except ValueError:
                raise ToolError(f"{path}:{lineno}: {name}: not a number: {r[k]!r}") from None
    out = {("t" if name == "Time" else name): np.array(v) for name, v in data.items()}
    if not out["t"].size:
        raise ToolError(f"{path}: no rows")
    return out


def grid_rows(t_exp, grid=GRID, t_end=None):
    """{k: index of the row nearest to k grid} for every multiple k grid (0 <= k grid <= t_end,
    default the last time) that has a row within SLOT_TOL of it: the experiment's regular grid,
    the impact window's extra rows left out."""
    t_end = t_exp[-1] if t_end is None else t_end
    slots = {}
    for i, ti in enumerate(t_exp):
        k = int(round(ti / grid))
        off = abs(ti - k * grid)
        if off <= SLOT_TOL and k * grid <= t_end + SLOT_TOL and (k not in slots or off < abs(t_exp[slots[k]] - k * grid)):
            slots[k] = i
    return slots


def data_findings(exp, grid=GRID, t_end=T_END):
    """What is wrong or notable in the measured series, as (ok, message) pairs: time strictly
    increasing; a row within SLOT_TOL of every multiple of `grid` from 0 to t_end; H4 starting
    within 0.02 m of DEPTH; heights in [-0.05, 1] m (the tank is 1 m deep); pressures in
    [-5, 100] kPa (a negative reading is the sensors' offset or a cavity; beyond 100 kPa is no
    impact of a 0.55 m column at 4-5 m/s, rho u^2 = 25 kPa)."""
    t = exp["t"]
    found = []
    dt = np.diff(t)
    bad = np.flatnonzero(~(dt > 0.0))
    found.append((bad.size == 0, "time strictly increasing" if bad.size == 0 else
                  f"time not increasing at {bad.size} rows, the first at t = {t[bad[0]]:.4f} -> {t[bad[0] + 1]:.4f} s"))
    n = int(round(t_end / grid))
    slots = grid_rows(t, grid)
    missing = [k for k in range(n + 1) if k not in slots]
    if missing:
        show = ", ".join(f"{k * grid:.2f}" for k in missing[:10]) + (" ..." if len(missing) > 10 else "")
        found.append((False, f"the {grid * 1e3:.0f} ms grid 0-{t_end:g} s misses {len(missing)} of {n + 1} times: {show}"))
    else:
        worst = max(abs(t[i] - k * grid) for k, i in slots.items() if k <= n)
        found.append((True, f"the {grid * 1e3:.0f} ms grid 0-{t_end:g} s complete ({n + 1} times, each row within "
                            f"{worst * 1e3:.2f} ms of its time)"))
    beyond = [k for k in slots if k > n]
    if beyond:
        found.append((True, f"{len(beyond)} grid times beyond {t_end:g} s, to {t[-1]:.3f} s"))
    extra = np.setdiff1d(np.arange(t.size), list(slots.values()))
    if extra.size:
        found.append((True, f"{extra.size} rows off the grid, from {t[extra].min():.3f} to {t[extra].max():.3f} s "
                            f"(median step {np.median(np.diff(t[extra])) * 1e3:.2f} ms)"))
    if "H4" in exp:
        h40 = float(exp["H4"][0])
        found.append((abs(h40 - DEPTH) <= 0.02, f"H4 at t = {t[0]:g} s: {h40:.4f} m (column depth {DEPTH} m)"))
    for g in GAUGES:
        if g in exp:
            v = exp[g]
            ok = bool(np.all(np.isfinite(v)) and v.min() >= -0.05 and v.max() <= 1.0)
            found.append((ok, f"{g}: {v.min():.4f} to {v.max():.4f} m" + ("" if ok else " (out of [-0.05, 1] m or not finite)")))
    for p in [k for k in exp if k.startswith("P")]:
        v = exp[p]
        ok = bool(np.all(np.isfinite(v)) and v.min() >= -5e3 and v.max() <= 1e5)
        found.append((ok, f"{p}: {v.min() / 1e3:.2f} to {v.max() / 1e3:.2f} kPa" + ("" if ok else " (out of [-5, 100] kPa or not finite)")))
    return found


def rms_difference(t_run, v_run, t_exp, v_exp, t0=0.0, t1=T_END):
    """(rms of v_run - v_exp [units of v], the span compared [s, s]) over the experiment's grid
    rows in [t0, min(t1, the run's last time)], the run interpolated linearly onto them."""
    k = np.array(sorted(grid_rows(t_exp).values()), dtype=int)
    k = k[(t_exp[k] >= t0 - SLOT_TOL) & (t_exp[k] <= min(t1, t_run[-1]) + SLOT_TOL)]
    if k.size == 0:
        return math.nan, (t0, t0)
    v = np.interp(t_exp[k], t_run, v_run)
    return float(np.sqrt(np.mean((v - v_exp[k]) ** 2))), (float(t_exp[k[0]]), float(t_exp[k[-1]]))


def compare(mon, dx, exp):
    """The run's differences from the experiment: {key: {metric: value}} for every gauge and the
    sensors both have (module doc)."""
    t = mon["t"]
    h = heights(mon, dx)
    out = {}
    for g in GAUGES:
        e = EXP_GAUGE[g]
        if g not in h or e not in exp:
            continue
        rms, span = rms_difference(t, h[g], exp["t"], exp[e])
        ta_r, ta_e = arrival(t, h[g], g), arrival(exp["t"], exp[e], g)
        out[g] = {"arrival_run": ta_r, "arrival_exp": ta_e, "arrival_diff": ta_r - ta_e, "rms_h": rms,
                  "span": span, "max_run": float(np.max(h[g])), "max_exp": float(np.max(exp[e]))}
    for p in PROBES:
        if p not in exp:
            continue
        for name in (p, p + "_wall"):
            if name not in mon:
                continue
            v = np.nan_to_num(mon[name], nan=0.0)
            tp_r, vp_r = first_peak(t, v)
            tp_e, vp_e = first_peak(exp["t"], exp[p])
            rms_qs, _ = rms_difference(t, v, exp["t"], exp[p], *QUASI_STATIC)
            rms_all, span = rms_difference(t, v, exp["t"], exp[p])
            qs = (exp["t"] >= QUASI_STATIC[0]) & (exp["t"] <= QUASI_STATIC[1])
            qr = (t >= QUASI_STATIC[0]) & (t <= QUASI_STATIC[1])
            out[name] = {"onset_run": first_time_at_least(t, v, PEAK_ONSET),
                         "onset_exp": first_time_at_least(exp["t"], exp[p], PEAK_ONSET),
                         "peak_run": vp_r, "t_peak_run": tp_r, "peak_exp": vp_e, "t_peak_exp": tp_e,
                         "rms_p_qs": rms_qs, "rms_p": rms_all, "span": span,
                         "mean_qs_run": float(np.mean(v[qr])) if qr.any() else math.nan,
                         "mean_qs_exp": float(np.mean(exp[p][qs]))}
    return out


def check(cmp, dx, t_last):
    """[(ok, message)] of CHECKS on one run's comparison; a run short of T_END fails."""
    res = [(t_last >= T_END - 1e-6, f"run reached t = {t_last:.3f} s (the benchmark's {T_END:g} s)")]
    for metric, g, tol, _ in CHECKS:
        tol_v = dx if tol == "dx" else tol
        c = cmp.get(g)
        if c is None:
            res.append((False, f"{g}: missing in the run or the experiment"))
            continue
        if metric == "rms_h":
            v = c["rms_h"]
            res.append((bool(v <= tol_v), f"{g}: rms height difference {v:.4f} m <= {tol_v:g} m"))
        else:
            v = abs(c["arrival_diff"])
            what = "drain (H4 < DRAIN_H)" if metric == "drain" else "arrival"
            res.append((bool(v <= tol_v), f"{g}: {what} {c['arrival_run']:.3f} s vs {c['arrival_exp']:.3f} s, "
                                          f"|diff| {v:.3f} s <= {tol_v:g} s"))
    return res


def run_table(mon, dx, every):
    """The sampled heights and pressures of a run, as printed lines."""
    t = mon["t"]
    h = heights(mon, dx)
    names = [p for p in PROBES if p in mon] + [p + "_wall" for p in PROBES if p + "_wall" in mon]
    lines = [f"{'t [s]':>6} " + " ".join(f"{g + ' [m]':>8}" for g in h) + " " +
             " ".join(f"{p + ' [kPa]':>12}" for p in names)]
    for ts in np.arange(0.0, t[-1] + 1e-9, every):
        k = int(np.argmin(np.abs(t - ts)))
        lines.append(f"{t[k]:>6.2f} " + " ".join(f"{h[g][k]:>8.3f}" for g in h) + " " +
                     " ".join(f"{mon[p][k] / 1e3:>12.2f}" for p in names))
    for g in h:
        k = int(np.argmax(h[g]))
        lines.append(f"{g}: highest {h[g][k]:.3f} m at t = {t[k]:.3f} s")
    for p in names:
        v = np.nan_to_num(mon[p], nan=0.0)
        k = int(np.argmax(v))
        tp, vp = first_peak(t, v)
        lines.append(f"{p}: largest {v[k] / 1e3:.2f} kPa at t = {t[k]:.3f} s; first impact peak "
                     f"{vp / 1e3:.2f} kPa at t = {tp:.3f} s")
    return lines


def comparison_lines(label, cmp):
    """The comparison of one run as printed lines (markdown tables)."""
    lines = [f"\n{label}: heights against the experiment",
             "| gauge | arrival run [s] | arrival exp [s] | diff [s] | highest run [m] | highest exp [m] | rms diff [m] | span [s] |",
             "|---|---|---|---|---|---|---|---|"]
    for g in GAUGES:
        if g in cmp:
            c = cmp[g]
            lines.append(f"| {g} | {c['arrival_run']:.3f} | {c['arrival_exp']:.3f} | {c['arrival_diff']:+.3f} | "
                         f"{c['max_run']:.3f} | {c['max_exp']:.3f} | {c['rms_h']:.3f} | {c['span'][0]:.2f}-{c['span'][1]:.2f} |")
    lines += [f"\n{label}: pressures against the experiment",
              "| sensor | onset run [s] | onset exp [s] | first peak run [kPa] | at [s] | first peak exp [kPa] | at [s] | "
              "mean 1-6 s run [kPa] | mean 1-6 s exp [kPa] | rms diff 1-6 s [kPa] | rms diff all [kPa] |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, c in cmp.items():
        if not name.startswith("P"):
            continue
        lines.append(f"| {name} | {c['onset_run']:.3f} | {c['onset_exp']:.3f} | {c['peak_run'] / 1e3:.2f} | "
                     f"{c['t_peak_run']:.3f} | {c['peak_exp'] / 1e3:.2f} | "
                     f"{c['t_peak_exp']:.3f} | {c['mean_qs_run'] / 1e3:.2f} | {c['mean_qs_exp'] / 1e3:.2f} | "
                     f"{c['rms_p_qs'] / 1e3:.2f} | {c['rms_p'] / 1e3:.2f} |")
    return lines


def plot(runs, exp, out):
    """H1-H4 and the pressures P1, P3 of every run beside the experiment."""
    fig, axes = plt.subplots(3, 2, figsize=(11, 9), sharex=True)
    panels = list(GAUGES) + ["P1", "P3"]
    for ax, key in zip(axes.flat, panels):
        col = EXP_GAUGE.get(key, key)
        if exp is not None and col in exp:
            scale = 1e-3 if key.startswith("P") else 1.0
            ax.plot(exp["t"], exp[col] * scale, color="k", lw=0.8,
                    label="experiment" + (f" (file's {col})" if col != key else ""))
        for k, (label, mon, dx) in enumerate(runs):
            color = f"C{k}"
            t = mon["t"]
            if key.startswith("H"):
                if key in mon:
                    ax.plot(t, heights(mon, dx)[key], color=color, lw=0.9, label=label)
            else:
                if key + "_wall" in mon:
                    ax.plot(t, mon[key + "_wall"] / 1e3, color=color, lw=0.9, label=f"{label} face")
                if key in mon:
                    ax.plot(t, mon[key] / 1e3, color=color, lw=0.7, ls=":", label=f"{label} probe 1.5 h")
        ax.set_title(key + (f" (x = {GAUGE_X[key]} m)" if key in GAUGE_X else ""), fontsize=9)
        ax.set_ylabel("height [m]" if key.startswith("H") else "pressure [kPa]")
        if key.startswith("P"):
            ax.set_ylim(-5, 25)
        ax.legend(fontsize=7)
        ax.set_xlim(0, T_END)
    for ax in axes[-1]:
        ax.set_xlabel("t [s]")
    fig.suptitle("SPHERIC test 2 (Kleefsman et al. 2005): runs and the MARIN experiment", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)


def load_run(run):
    """(label, monitors, dx, t_last, status) of a run folder."""
    mon = read_monitors(os.path.join(run, "monitors.csv"))
    try:
        with open(os.path.join(run, "summary.json")) as f:
            summ = json.load(f)
        dx = float(summ["numerics"]["dx"])
    except (OSError, KeyError, ValueError) as e:
        raise ToolError(f"{run}/summary.json: {e}") from None
    return f"dx = {dx:g}", mon, dx, float(mon["t"][-1]), summ.get("status", "?")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs", nargs="*")
    ap.add_argument("--exp", default=EXP_DEFAULT)
    ap.add_argument("--every", type=float, default=0.5)
    ap.add_argument("-o", default=None)
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--check-data", metavar="FILE")
    a = ap.parse_args(argv)
    try:
        if a.check_data:
            found = data_findings(read_experiment(a.check_data))
            for ok, msg in found:
                print(("ok   " if ok else "FAIL ") + msg)
            return 0 if all(ok for ok, _ in found) else 1
        if not a.runs:
            ap.error("give a run folder (or --check-data FILE)")
        exp = read_experiment(a.exp) if a.exp else None
        runs = [load_run(r) for r in a.runs]
    except ToolError as e:
        print(f"spheric_test2: {e}", file=sys.stderr)
        return 2
    failed = False
    for run, (label, mon, dx, t_last, status) in zip(a.runs, runs):
        print(f"run {run}: {label} m, t_end = {t_last:.3f} s, status {status}")
        print("\n".join(run_table(mon, dx, a.every)))
        cmp = compare(mon, dx, exp)
        print("\n".join(comparison_lines(label, cmp)))
        if a.check:
            print(f"\n{label}: checks")
            for ok, msg in check(cmp, dx, t_last):
                print(("ok   " if ok else "FAIL ") + msg)
                failed |= not ok
        print()
    out = a.o or os.path.join(a.runs[0], "spheric_test2.png")
    plot([(label, mon, dx) for label, mon, dx, _, _ in runs], exp, out)
    print(f"wrote {out}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
