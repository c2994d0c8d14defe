#!/usr/bin/env python3
"""SPHERIC benchmark test 2 (cases/spheric_test2.json): the water heights at the gauges H1-H4 and
the pressures P1-P4 on the box's front, as a table of sampled values and their extremes, and a
figure of the time series.

    .venv/bin/python tools/spheric_test2.py RUN [--every 0.5] [-o FIG.png]

RUN is the output folder of `mixsph run cases/spheric_test2.json`. A gauge's water height is its
max_elevation monitor (the highest water particle centre over a square 2 dx wide about the gauge)
plus dx/2, the water's top above that centre; an empty square (dry) reads 0. The pressure probes
read in the flow 1.5 h in front of the face (the case's description). Prints the heights and
pressures every --every seconds, then per probe its largest value and the time, and for P1 and P2
the first peak (the largest value within 0.3 s after the first time the probe reads more than
1 kPa: the water's first impact). The experiment's time series are not in the repository (the
SPHERIC site's files, not reachable here): no comparison is computed. Writes RUN/spheric_test2.png
(or -o). Exit codes: 0 ok, 2 missing files.
"""
import argparse
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mixsph_tools.readers import ToolError, read_monitors  # noqa: E402

GAUGES = ("H1", "H2", "H3", "H4")
PROBES = ("P1", "P2", "P3", "P4")


def heights(mon, dx):
    """{gauge: water height [m]}: the top particle centre + dx/2, 0 where the square is dry."""
    return {g: np.where(np.isfinite(mon[g]), mon[g] + 0.5 * dx, 0.0) for g in GAUGES if g in mon}


def first_peak(t, p, onset=1000.0, window=0.3):
    """(time, value) of the largest p within `window` s after p first exceeds `onset`."""
    k = np.flatnonzero(p > onset)
    if len(k) == 0:
        return float("nan"), float("nan")
    sel = (t >= t[k[0]]) & (t <= t[k[0]] + window)
    j = np.flatnonzero(sel)[np.argmax(p[sel])]
    return float(t[j]), float(p[j])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run")
    ap.add_argument("--every", type=float, default=0.5)
    ap.add_argument("-o", default=None)
    a = ap.parse_args(argv)
    try:
        mon = read_monitors(os.path.join(a.run, "monitors.csv"))
        with open(os.path.join(a.run, "summary.json")) as f:
            dx = float(json.load(f)["numerics"]["dx"])
    except (ToolError, OSError, KeyError) as e:
        print(f"spheric_test2: {e}", file=sys.stderr)
        return 2
    t = mon["t"]
    h = heights(mon, dx)
    print(f"run {a.run}: dx = {dx} m, t_end = {t[-1]:.3f} s")
    print(f"{'t [s]':>6} " + " ".join(f"{g + ' [m]':>8}" for g in h) + " " +
          " ".join(f"{p + ' [kPa]':>9}" for p in PROBES if p in mon))
    for ts in np.arange(0.0, t[-1] + 1e-9, a.every):
        k = int(np.argmin(np.abs(t - ts)))
        print(f"{t[k]:>6.2f} " + " ".join(f"{h[g][k]:>8.3f}" for g in h) + " " +
              " ".join(f"{mon[p][k] / 1e3:>9.2f}" for p in PROBES if p in mon))
    for g in h:
        k = int(np.argmax(h[g]))
        print(f"{g}: highest {h[g][k]:.3f} m at t = {t[k]:.3f} s")
    for p in PROBES:
        if p not in mon:
            continue
        k = int(np.nanargmax(mon[p]))
        line = f"{p}: largest {mon[p][k] / 1e3:.2f} kPa at t = {t[k]:.3f} s"
        if p in ("P1", "P2"):
            tp, vp = first_peak(t, mon[p])
            line += f"; first impact peak {vp / 1e3:.2f} kPa at t = {tp:.3f} s"
        print(line)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for g in h:
        ax1.plot(t, h[g], label=g)
    ax1.set_ylabel("water height [m]")
    ax1.legend(ncol=4, fontsize=8)
    for p in PROBES:
        if p in mon:
            ax2.plot(t, mon[p] / 1e3, label=p)
    ax2.set_ylabel("pressure [kPa]")
    ax2.set_xlabel("t [s]")
    ax2.legend(ncol=4, fontsize=8)
    ax1.set_title(f"SPHERIC test 2, dx = {dx} m")
    fig.tight_layout()
    out = a.o or os.path.join(a.run, "spheric_test2.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
