#!/usr/bin/env python3
"""Compare a mixsph water dam-break run with Martin & Moyce (1952).

    python tools/plot_dambreak.py OUTDIR [--a 0.25] [--g 9.81] [--shift 0.175]

Reads OUTDIR/monitors.csv (the ``front`` monitor: largest x of the water [m]) and the particle
snapshots OUTDIR/snap_NNNN.csv written by ``mixsph run cases/dambreak_water.json``.

Reference: J. C. Martin and W. J. Moyce (1952), "An experimental study of the collapse of liquid
columns on a rigid horizontal plane", Phil. Trans. R. Soc. A 244, 312-324; the column of width
a and height n^2 a / 2 with n^2 = 2 (height 2a). Dimensionless front Z = x_front / a versus
T = t sqrt(2 g / a).

The experiment's gate takes a moment to open, so the measured surge lags an instantaneous
release; as the Lethe dam-break benchmark does, the simulation is also compared at T - 0.175
(``--shift``). The table gives both the shifted and the unshifted comparison.

Prints the comparison table, writes it to OUTDIR/dambreak_comparison.csv and draws
OUTDIR/dambreak.png: (left) Z versus T, (right) snapshots coloured by velocity magnitude.
"""

import argparse
import glob
import os
import re
import sys

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after choosing the backend)

# Martin & Moyce (1952), n^2 = 2: surge front Z = x / a at T = t sqrt(2 g / a).
MM_T = np.array([0.41, 0.84, 1.19, 1.43, 1.63, 1.82, 1.97, 2.2, 2.32, 2.5, 2.64, 2.82, 2.96])
MM_Z = np.array([1.11, 1.23, 1.44, 1.67, 1.89, 2.11, 2.33, 2.56, 2.78, 3.0, 3.22, 3.44, 3.67])

STATE_WALL = 2
STATE_LOST = 3

PROG = "plot_dambreak.py"


def fail(msg):
    print(f"{PROG}: error: {msg}", file=sys.stderr)
    sys.exit(2)


def read_monitors(path):
    """Columns of monitors.csv as a dict of float arrays."""
    if not os.path.isfile(path):
        fail(f"{path} not found (run: build/mixsph run cases/dambreak_water.json --out {os.path.dirname(path) or '.'})")
    with open(path) as f:
        header = f.readline().strip().split(",")
    try:
        data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except ValueError as e:
        fail(f"{path}: cannot read: {e}")
    if data.shape[0] == 0:
        fail(f"{path}: no rows")
    if data.shape[1] != len(header):
        fail(f"{path}: {data.shape[1]} columns but {len(header)} names in the header")
    cols = {name: data[:, k] for k, name in enumerate(header)}
    for need in ("t", "front"):
        if need not in cols:
            fail(f"{path}: no column '{need}' (header: {','.join(header)})")
    return cols


def read_snapshot(path):
    """(time [s], dict of columns) of one snap_NNNN.csv."""
    with open(path) as f:
        first = f.readline()
        header = f.readline().strip().split(",")
    m = re.match(r"#\s*t\s*=\s*([-+0-9.eE]+)", first)
    if not m:
        fail(f"{path}: first line '{first.strip()}' is not '# t = <time> s'")
    try:
        data = np.loadtxt(path, delimiter=",", skiprows=2, ndmin=2)
    except ValueError as e:
        fail(f"{path}: cannot read: {e}")
    for need in ("x", "z", "vx", "vz", "state"):
        if need not in header:
            fail(f"{path}: no column '{need}' (header: {','.join(header)})")
    return float(m.group(1)), {name: data[:, k] for k, name in enumerate(header)}


def sim_z_at(T_sim, Z_sim, T):
    """Simulated Z at dimensionless times T (NaN outside the simulated range)."""
    if T_sim.size == 0:
        return np.full_like(T, np.nan)
    z = np.interp(T, T_sim, Z_sim)
    z[(T < T_sim[0]) | (T > T_sim[-1])] = np.nan
    return z


def fmt(v, spec):
    return format(v, spec) if np.isfinite(v) else "n/a".rjust(len(format(0.0, spec)))


def main():
    ap = argparse.ArgumentParser(description="Dam break: mixsph versus Martin & Moyce (1952).")
    ap.add_argument("outdir", help="output folder of 'mixsph run cases/dambreak_water.json'")
    ap.add_argument("--a", type=float, default=0.25, help="initial column width a [m] (default 0.25)")
    ap.add_argument("--g", type=float, default=9.81, help="gravity [m/s2] (default 9.81)")
    ap.add_argument("--shift", type=float, default=0.175,
                    help="gate-release shift in T applied to the simulation (default 0.175)")
    ap.add_argument("--png", help="plot file (default OUTDIR/dambreak.png)")
    args = ap.parse_args()
    if not os.path.isdir(args.outdir):
        fail(f"{args.outdir}: no such folder (run ./tools/do main first)")
    if args.a <= 0 or args.g <= 0:
        fail("--a and --g must be positive")

    mon = read_monitors(os.path.join(args.outdir, "monitors.csv"))
    tscale = np.sqrt(2.0 * args.g / args.a)  # T = t * tscale
    ok = np.isfinite(mon["front"])
    T_sim = mon["t"][ok] * tscale
    Z_sim = mon["front"][ok] / args.a
    if T_sim.size == 0:
        fail("monitors.csv: the 'front' monitor has no finite value")

    z_shift = sim_z_at(T_sim, Z_sim, MM_T - args.shift)
    z_plain = sim_z_at(T_sim, Z_sim, MM_T)
    err_shift = 100.0 * (z_shift - MM_Z) / MM_Z
    err_plain = 100.0 * (z_plain - MM_Z) / MM_Z

    # ---- table ----
    print(f"Dam break, surge front versus Martin & Moyce (1952), n^2 = 2, a = {args.a:g} m, g = {args.g:g} m/s2")
    print(f"T = t sqrt(2g/a), Z = x_front / a; shifted: simulation at T - {args.shift:g} (gate release)")
    print()
    print(f"{'T':>6} {'t [s]':>7} {'Z_exp':>7} | {'Z_sim(T-' + format(args.shift, 'g') + ')':>15} {'err %':>7}"
          f" | {'Z_sim(T)':>9} {'err %':>7}")
    print("-" * 72)
    for k in range(MM_T.size):
        print(f"{MM_T[k]:6.2f} {MM_T[k] / tscale:7.4f} {MM_Z[k]:7.2f} | {fmt(z_shift[k], '15.3f')} "
              f"{fmt(err_shift[k], '+7.1f')} | {fmt(z_plain[k], '9.3f')} {fmt(err_plain[k], '+7.1f')}")
    print("-" * 72)
    for label, err in (("shifted", err_shift), ("unshifted", err_plain)):
        e = err[np.isfinite(err)]
        if e.size:
            print(f"{label:>9}: mean |error| {np.mean(np.abs(e)):5.1f} %, max |error| {np.max(np.abs(e)):5.1f} %"
                  f" over {e.size} of {MM_T.size} points")
        else:
            print(f"{label:>9}: no point inside the simulated time range")

    table_path = os.path.join(args.outdir, "dambreak_comparison.csv")
    with open(table_path, "w") as f:
        f.write("T,t,Z_exp,Z_sim_shifted,err_shifted_percent,Z_sim,err_percent\n")
        for k in range(MM_T.size):
            row = (MM_T[k], MM_T[k] / tscale, MM_Z[k], z_shift[k], err_shift[k], z_plain[k], err_plain[k])
            f.write(",".join("nan" if not np.isfinite(v) else f"{v:.6g}" for v in row) + "\n")

    # ---- figure ----
    snaps = sorted(glob.glob(os.path.join(args.outdir, "snap_[0-9]*.csv")))
    if not snaps:
        print(f"{PROG}: warning: no snapshots (snap_NNNN.csv) in {args.outdir}: plotting the front only",
              file=sys.stderr)
    # up to 4 snapshots spread over the run
    pick = [snaps[i] for i in sorted(set(np.linspace(0, len(snaps) - 1, min(4, len(snaps))).round().astype(int)))] \
        if snaps else []
    shots = [read_snapshot(p) for p in pick]

    fig = plt.figure(figsize=(14, 6.5), constrained_layout=True)
    gs = fig.add_gridspec(2, 3, width_ratios=[1.15, 1, 1])
    ax = fig.add_subplot(gs[:, 0])
    ax.plot(T_sim + args.shift, Z_sim, "-", color="C0", lw=2, label=f"mixsph, shifted by +{args.shift:g} in T")
    ax.plot(T_sim, Z_sim, "--", color="C0", lw=1, alpha=0.6, label="mixsph, unshifted")
    ax.plot(MM_T, MM_Z, "o", color="k", mfc="none", ms=7, label="Martin & Moyce (1952), $n^2=2$")
    ax.set_xlabel(r"$T = t\,\sqrt{2g/a}$")
    ax.set_ylabel(r"$Z = x_{front}/a$")
    ax.set_title("Surge front")
    ax.set_xlim(0, max(3.2, MM_T[-1] + 0.2))
    ax.set_ylim(0.9, max(4.0, np.nanmax(Z_sim[T_sim <= 3.2]) + 0.1 if np.any(T_sim <= 3.2) else 4.0))
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left")

    if shots:
        speeds = []
        for _, c in shots:
            mobile = (c["state"] != STATE_WALL) & (c["state"] != STATE_LOST)
            speeds.append(np.hypot(c["vx"][mobile], c["vz"][mobile]))
        # colour scale: 99.5th percentile, so a few fast spray particles do not wash it out
        allspd = np.concatenate(speeds)
        vmax = max(float(np.percentile(allspd, 99.5)) if allspd.size else 0.0, 1e-9)
        xs = np.concatenate([c["x"] for _, c in shots])
        zs = np.concatenate([c["z"] for _, c in shots])
        mob_z = np.concatenate([c["z"][(c["state"] != STATE_WALL)] for _, c in shots])
        xlim = (xs.min() - 0.01, xs.max() + 0.01)
        zlim = (zs.min() - 0.01, min(zs.max(), mob_z.max() + 0.1 if mob_z.size else zs.max()) + 0.01)
        sc = None
        for k, ((t, c), spd) in enumerate(zip(shots, speeds)):
            a2 = fig.add_subplot(gs[k // 2, 1 + k % 2])
            wall = c["state"] == STATE_WALL
            mobile = (c["state"] != STATE_WALL) & (c["state"] != STATE_LOST)
            a2.scatter(c["x"][wall], c["z"][wall], s=0.6, c="0.6", marker="s", linewidths=0, rasterized=True)
            sc = a2.scatter(c["x"][mobile], c["z"][mobile], s=0.8, c=spd, cmap="viridis", vmin=0.0, vmax=vmax,
                            linewidths=0, rasterized=True)
            a2.set_xlim(*xlim)
            a2.set_ylim(*zlim)
            a2.set_aspect("equal")
            a2.set_title(f"t = {t:.3f} s  (T = {t * tscale:.2f})")
            a2.set_xlabel("x [m]")
            a2.set_ylabel("z [m]")
        fig.colorbar(sc, ax=fig.axes[1:], shrink=0.8, extend="max", label="|v| [m/s]")
    fig.suptitle(f"mixsph water dam break (a = {args.a:g} m) - {os.path.basename(os.path.normpath(args.outdir))}")
    png = args.png or os.path.join(args.outdir, "dambreak.png")
    fig.savefig(png, dpi=110)
    print()
    print(f"table: {table_path}")
    print(f"plot:  {png}")


if __name__ == "__main__":
    main()
