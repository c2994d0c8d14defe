#!/usr/bin/env python3
"""Is a granular deposit creeping, or only ringing? The grains' speeds against their net motion.

    PYTHONPATH=$PWD .venv/bin/python tools/deposit_motion.py OUTDIR [OUTDIR...] [--medium 0]
                                      [--at T] [--windows 0.01,0.05,0.2] [--quantile 0.99]

A weakly compressible elastic-plastic deposit carries elastic waves (the acoustic speed c_p is 25-50
times the flow's): a grain on such a wave has a speed but, averaged over many periods, no motion.
A creeping grain moves the same way step after step. The issue's criterion (99 % of the grains
below 1 mm/s) reads the instantaneous speed, which counts both. This script tells them apart
from the snapshots of a run (its CSV snapshots or run.h5) whose interval resolves the windows:
per grain (mobile or held particles of the medium, matched by id), at time --at (default: the
last snapshot),

    speed  |u(t)|                                       the criterion's quantity
    drift  |x(t) - x(t - w)| / w  for each window w     the net motion over w
    ringing |u(t) - (x(t) - x(t - w1)) / w1|            what of the speed is not net motion over
                                                        the shortest window w1 (waves, and the
                                                        change of u over w1)

and prints the --quantile of each over the grains. A drift that stays at the speed for every w
is creep (or flow); a drift that falls as 1/w while the speed stays is a grain oscillating in
place with an amplitude about drift * w / 2; the ringing bounds the speed of such waves. Also printed: the largest displacement of a grain
over the longest window, in particle spacings dx (the heap criterion's unit), when the run's
summary gives dx.
"""

import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mixsph_tools as mt  # noqa: E402


def grains(cols, medium_index):
    """The rows of the medium's mobile or held particles, by id: {id: row}."""
    keep = (cols["state"] <= 1) & (cols["medium"] == medium_index)
    return {int(i): k for k, i in enumerate(cols["id"]) if keep[k]}


def run_dx(outdir):
    """The run's particle spacing [m] (its summary.json)."""
    try:
        with open(os.path.join(outdir, "summary.json")) as f:
            return float(json.load(f)["numerics"]["dx"])
    except (OSError, KeyError, ValueError, TypeError) as e:
        raise mt.ToolError(f"{outdir}/summary.json: no numerics.dx ({e})") from None


def motion(outdir, medium, at, windows, quantile):
    """{"t": t, "speed": q, "drift": [q per window], "largest": largest displacement over the
    longest window [m], "n": grains} of one run."""
    snaps = mt.list_snapshots(outdir)
    if not snaps:
        raise mt.ToolError(f"{outdir}: no snapshots")
    times = np.array([t for t, _ in snaps])
    k_at = len(snaps) - 1 if at is None else int(np.argmin(np.abs(times - at)))
    t_at, cols = mt.read_snapshot(snaps[k_at][1])
    index = medium
    rows = grains(cols, index)
    ids = sorted(rows)
    r_at = np.array([rows[i] for i in ids])
    pos = np.column_stack([cols["x"][r_at], cols["z"][r_at]])
    speed = np.hypot(cols["vx"][r_at], cols["vz"][r_at])
    out = {"t": t_at, "speed": float(np.quantile(speed, quantile)), "drift": [], "ringing": math.nan,
           "largest": math.nan,
           "n": len(ids), "dx": run_dx(outdir)}
    for w in windows:
        k = int(np.argmin(np.abs(times - (t_at - w))))
        if abs(times[k] - (t_at - w)) > 0.25 * w or k == k_at:
            raise mt.ToolError(f"{outdir}: no snapshot near t = {t_at - w:g} s for the window {w:g} s "
                               f"(snapshots every {np.median(np.diff(times)):g} s)")
        _, before = mt.read_snapshot(snaps[k][1])
        rows_b = grains(before, index)
        common = [j for j, i in enumerate(ids) if i in rows_b]
        r_b = np.array([rows_b[ids[j]] for j in common])
        d = np.hypot(pos[common, 0] - before["x"][r_b], pos[common, 1] - before["z"][r_b])
        out["drift"].append(float(np.quantile(d / (t_at - times[k]), quantile)))
        if len(out["drift"]) == 1:
            vel = np.column_stack([cols["vx"][r_at], cols["vz"][r_at]])[common]
            net = (pos[common] - np.column_stack([before["x"][r_b], before["z"][r_b]])) / (t_at - times[k])
            out["ringing"] = float(np.quantile(np.hypot(*(vel - net).T), quantile))
        out["largest"] = float(d.max())
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[1], prog="tools/deposit_motion.py")
    ap.add_argument("outdirs", nargs="+", help="run output folders")
    ap.add_argument("--medium", type=int, default=0, help="the granular medium's index (its place in the case's "
                                                          "media, from 0; default 0)")
    ap.add_argument("--at", type=float, help="the time [s] (default: the last snapshot)")
    ap.add_argument("--windows", default="0.01,0.05,0.2", help="windows w [s], comma-separated")
    ap.add_argument("--quantile", type=float, default=0.99)
    a = ap.parse_args(argv)
    try:
        windows = [float(w) for w in a.windows.split(",") if w.strip()]
        if not windows or any(not (w > 0) for w in windows) or not (0 < a.quantile <= 1):
            ap.error("--windows: positive times; --quantile in (0, 1]")
        q = f"{100 * a.quantile:g} %"
        head = ["run", "t [s]", "grains", f"speed {q} [mm/s]"] + [f"drift {q} over {w:g} s [mm/s]" for w in windows]
        head += [f"ringing {q} [mm/s]", f"largest displacement over {windows[-1]:g} s [dx]"]
        rows = []
        for d in a.outdirs:
            m = motion(d, a.medium, a.at, windows, a.quantile)
            rows.append([d, f"{m['t']:.3f}", str(m["n"]), f"{1e3 * m['speed']:.3g}"]
                        + [f"{1e3 * v:.3g}" for v in m["drift"]]
                        + [f"{1e3 * m['ringing']:.2g}", f"{m['largest'] / m['dx']:.3g}"])
        print("| " + " | ".join(head) + " |")
        print("|" + " --- |" * len(head))
        for r in rows:
            print("| " + " | ".join(r) + " |")
    except mt.ToolError as e:
        print(f"tools/deposit_motion.py: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
