#!/usr/bin/env python3
"""Count particles that have clumped into pairs, per snapshot of a mixsph run: the pairs of
non-wall particles closer than a fraction of the spacing dx (default dx / 4). On a healthy run
the particles keep about dx apart; pairs far closer than that show where particles are pressed
together, on Vajont where walls clip them (the diagnosis of docs/validation/vajont.md).

    .venv/bin/python tools/particle_pairs.py RUN [--dx D] [--fraction F] [--every T]

RUN is an output folder (its run.h5 or snap_*.csv snapshots). --dx defaults to the dx recorded in
RUN/vajont_run.json (a run of tools/vajont_validate.py). Prints one line per snapshot: the time,
the pairs closer than F dx, how many of them join two particles of medium 0 (the water of the
Vajont case) and the smallest distance in units of dx; --every T keeps the snapshots at multiples
of T seconds only. Exit codes: 0 ok, 2 bad arguments or no snapshots.
"""
import argparse
import json
import os
import sys

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mixsph_tools.readers import STATE_WALL, ToolError, list_snapshots, read_snapshot  # noqa: E402


def close_pairs(cols, distance):
    """(pairs closer than distance, of them medium 0 with medium 0, smallest distance) among the
    non-wall particles of one snapshot."""
    keep = cols["state"] != STATE_WALL
    xz = np.column_stack([cols["x"][keep], cols["z"][keep]])
    medium = cols["medium"][keep]
    tree = cKDTree(xz)
    pairs = tree.query_pairs(distance, output_type="ndarray")
    nearest, _ = tree.query(xz, k=2)
    both_medium0 = int(np.count_nonzero((medium[pairs[:, 0]] == 0) & (medium[pairs[:, 1]] == 0))) if len(pairs) else 0
    return len(pairs), both_medium0, float(nearest[:, 1].min())


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", help="output folder of a run")
    ap.add_argument("--dx", type=float, help="particle spacing [m] (default: RUN/vajont_run.json's)")
    ap.add_argument("--fraction", type=float, default=0.25, help="count pairs closer than this times dx (0.25)")
    ap.add_argument("--every", type=float, default=0.0, help="only snapshots at multiples of this [s]")
    args = ap.parse_args(argv)
    dx = args.dx
    if dx is None:
        stamp = os.path.join(args.run, "vajont_run.json")
        try:
            with open(stamp) as f:
                dx = float(json.load(f)["dx"])
        except (OSError, KeyError, ValueError) as e:
            ap.error(f"--dx not given and {stamp} has no dx ({e})")
    if not dx > 0 or not 0 < args.fraction < 1:
        ap.error("--dx must be > 0 and --fraction in (0, 1)")
    try:
        snaps = list_snapshots(args.run)
        if not snaps:
            raise ToolError(f"{args.run}: no snapshots")
        print(f"# pairs of non-wall particles closer than {args.fraction:g} dx = {args.fraction * dx:.4g} m")
        print("t_s,pairs,pairs_medium0,min_distance_over_dx")
        for t, path in snaps:
            if args.every > 0 and abs(t / args.every - round(t / args.every)) > 1e-6:
                continue
            _, cols = read_snapshot(path)
            n, n0, dmin = close_pairs(cols, args.fraction * dx)
            print(f"{t:.4f},{n},{n0},{dmin / dx:.3f}")
    except ToolError as e:
        print(f"particle_pairs: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
