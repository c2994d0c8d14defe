#!/usr/bin/env python3
"""The 3D slide into a basin (cases/basin_slide_3d.json): the largest wave amplitude at each
gauge against its radial distance from the impact point, the fitted decay exponent, and plan
views of the water surface's elevation.

    .venv/bin/python tools/basin_slide_3d.py RUN [--times 0.4,0.6,0.8,1.0] [-o FIG.png]

RUN is the output folder of `mixsph run cases/basin_slide_3d.json`. A gauge's amplitude is that
of the leading crest: the largest value its max_elevation monitor took after the impact until it
first falls back by a fifth of that rise (the crest has passed), minus its value at the impact (the
first sample at which the slide's front, `slide_front`, reaches the still water line x = -0.3464
m): the top particle centre of the water still at rest there, so the dx/2 between a centre and the
surface cancels, and the few millimetres the basin's water settles by before the impact (its
start from a lattice) do not count as a wave. A gauge whose rise has not fallen back by the run's
end is truncated (the crest not yet past): listed, marked, and left out of the fit. The
decay a = C r^(-n) is fitted by least squares on log a against log r, per ray (the slide's axis,
a0_*, and the ray 45 degrees off it, a45_*), over the gauges r >= --r-min (default 0.6 m: the far
field, beyond the slide's own width and run-out in the water, which disturb the near field). The plan
view: per square column 2 dx wide (one dx would leave columns that a lattice column has just
left), the highest water particle centre minus that of the first snapshot (t = 0, the still
water: the lattice's rounding cancels), over the basin (the half y >= 0 the case models,
mirrored to y < 0 for the picture), at each of --times (the nearest snapshots). Prints a table of r, amplitude and the time of the maximum, and
the exponents; writes RUN/basin_decay.png and RUN/basin_plan.png (or -o's stem + _decay/_plan).
Exit codes: 0 ok, 2 bad arguments or missing files.
"""
import argparse
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mixsph_tools.readers import (ToolError, list_snapshots, read_monitors, read_snapshot,  # noqa: E402
                                  nearest_snapshot)

IMPACT = (-0.3464, 0.0)  # the still water line on the slide's axis [m]
GAUGE = re.compile(r"^a(0|45)_r(\d\d)$")


def impact_index(mon):
    """The first sample at which the slide's front reaches the still water line."""
    k = np.flatnonzero(mon["slide_front"] >= IMPACT[0])
    if len(k) == 0:
        raise ToolError("the slide never reaches the water (slide_front < %g m)" % IMPACT[0])
    return int(k[0])


def amplitudes(mon):
    """{ray: [(r, amplitude, t_max)]} of the gauges of monitors.csv."""
    rays = {}
    k0 = impact_index(mon)
    for name, v in mon.items():
        m = GAUGE.match(name)
        if not m:
            continue
        if not np.isfinite(v[k0]) or not np.isfinite(v[k0:]).any():
            continue
        rise = v[k0:] - v[k0]
        best, kb, passed = 0.0, 0, False
        for j, e in enumerate(rise):
            if not np.isfinite(e):
                continue
            if e > best:
                best, kb = e, j
            elif best > 1e-3 and e < 0.8 * best:
                passed = True
                break
        rays.setdefault(int(m.group(1)), []).append((int(m.group(2)) / 10.0, best, mon["t"][k0 + kb], passed))
    return {a: sorted(g) for a, g in rays.items()}


def fit_decay(points, r_min):
    """(n, C) of a = C r^-n over the passed crests with r >= r_min and a > 0."""
    use = [p for p in points if p[0] >= r_min - 1e-9 and p[1] > 0 and p[3]]
    r = np.array([p[0] for p in use])
    a = np.array([p[1] for p in use])
    if len(r) < 2:
        return float("nan"), float("nan")
    slope, icpt = np.polyfit(np.log(r), np.log(a), 1)
    return -slope, float(np.exp(icpt))


def plan_top(cols, dx, x_range, y_range):
    """The highest water particle centre per dx x dx column (nan where there is none)."""
    water = (cols["state"] != 2) & (cols["medium"] == 0)
    x, y, z = cols["x"][water], cols["y"][water], cols["z"][water]
    nx = int(round((x_range[1] - x_range[0]) / dx))
    ny = int(round((y_range[1] - y_range[0]) / dx))
    grid = np.full((ny, nx), np.nan)
    ix = np.floor((x - x_range[0]) / dx).astype(int)
    iy = np.floor((y - y_range[0]) / dx).astype(int)
    ok = (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
    for i, j, h in zip(iy[ok], ix[ok], z[ok]):
        if not (grid[i, j] >= h):
            grid[i, j] = h
    return grid


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run")
    ap.add_argument("--times", default="0.4,0.6,0.8,1.0")
    ap.add_argument("--r-min", type=float, default=0.6)
    ap.add_argument("--dx", type=float, default=None, help="the run's dx (default: from RUN/summary.json)")
    ap.add_argument("-o", default=None)
    a = ap.parse_args(argv)
    try:
        mon = read_monitors(os.path.join(a.run, "monitors.csv"))
    except (ToolError, OSError) as e:
        print(f"basin_slide_3d: {e}", file=sys.stderr)
        return 2
    dx = a.dx
    if dx is None:
        import json
        with open(os.path.join(a.run, "summary.json")) as f:
            dx = float(json.load(f)["numerics"]["dx"])
    try:
        rays = amplitudes(mon)
    except ToolError as e:
        print(f"basin_slide_3d: {e}", file=sys.stderr)
        return 2
    print(f"impact (slide front at x = {IMPACT[0]} m): t = {mon['t'][impact_index(mon)]:.3f} s")
    if not rays:
        print("basin_slide_3d: no gauge a0_rNN / a45_rNN in monitors.csv", file=sys.stderr)
        return 2
    stem = os.path.splitext(a.o)[0] if a.o else os.path.join(a.run, "basin")
    print(f"run {a.run}: t_end {mon['t'][-1]:.3f} s, dx {dx}")
    print(f"{'ray':>4} {'r [m]':>6} {'a [mm]':>8} {'t_max [s]':>9}")
    print("(leading crest; * truncated: not yet past at the run's end, not fitted)")
    fig, ax = plt.subplots(figsize=(5, 4))
    for ray, pts in sorted(rays.items()):
        for r, amp, t, passed in pts:
            print(f"{ray:>4} {r:>6.2f} {1e3 * amp:>8.2f} {t:>9.3f}{'' if passed else ' *'}")
        n, c = fit_decay(pts, a.r_min)
        print(f"ray {ray} deg: a ~ r^-n, n = {n:.2f} (gauges r >= {a.r_min} m)")
        r = np.array([p[0] for p in pts])
        amp = np.array([p[1] for p in pts])
        passed = np.array([p[3] for p in pts])
        ax.loglog(r[passed], 1e3 * amp[passed], "o", label=f"{ray} deg: n = {n:.2f}")
        ax.loglog(r[~passed], 1e3 * amp[~passed], "x", color=ax.lines[-1].get_color())
        if np.isfinite(n):
            rr = np.linspace(a.r_min, r.max(), 20)
            ax.loglog(rr, 1e3 * c * rr ** -n, "-", color=ax.lines[-1].get_color())
    rr = np.linspace(0.4, 1.4, 20)
    a_ref = max(p[1] for pts in rays.values() for p in pts) * 1e3
    for n_ref, ls in ((0.5, ":"), (1.0, "--")):
        ax.loglog(rr, a_ref * (rr / 0.4) ** -n_ref, ls, color="grey", label=f"r^-{n_ref:g}")
    ax.set_xlabel("r from the impact point [m]")
    ax.set_ylabel("largest elevation a [mm]")
    ax.legend(fontsize=8)
    ax.set_title(f"basin_slide_3d, dx = {dx} m")
    fig.tight_layout()
    fig.savefig(stem + "_decay.png", dpi=120)
    print(f"wrote {stem}_decay.png")
    snaps = list_snapshots(a.run)
    times = [float(t) for t in a.times.split(",") if t]
    if snaps and times:
        fig, axes = plt.subplots(1, len(times), figsize=(3.2 * len(times), 3.6), squeeze=False)
        xr, yr = (-0.6, 1.6), (0.0, 1.2)
        base = plan_top(read_snapshot(snaps[0][1])[1], 2 * dx, xr, yr)
        for ax, t in zip(axes[0], times):
            ts, ref = nearest_snapshot(a.run, t)
            _, cols = read_snapshot(ref)
            g = plan_top(cols, 2 * dx, xr, yr) - base
            full = np.vstack([g[::-1], g])  # mirrored about the symmetry plane y = 0
            im = ax.imshow(1e3 * full, origin="lower", extent=(xr[0], xr[1], -yr[1], yr[1]), cmap="RdBu_r",
                           vmin=-30, vmax=30, aspect="equal")
            ax.plot(*IMPACT, "k+")
            ax.set_title(f"t = {ts:.2f} s")
            ax.set_xlabel("x [m]")
        axes[0][0].set_ylabel("y [m]")
        fig.colorbar(im, ax=axes[0].tolist(), label="surface elevation [mm]", shrink=0.8)
        fig.savefig(stem + "_plan.png", dpi=110)
        print(f"wrote {stem}_plan.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
