#!/usr/bin/env python3
"""How the Vajont slide moves in a run of cases/vajont_padua.json: the plate's push against the
grains' motion, the slide's shape and how much of it enters the water, from the run's snapshots
(docs/validation/vajont_elastic_plastic.md uses it to compare the granular laws).

    PYTHONPATH=$PWD python -m tools.vajont_slide RUN_DIR [RUN_DIR...] [--times 0.2,0.4,0.6,0.8,1.0]
        [--level 0.46] [--markdown] [--plot FILE.png] [--plot-times 0.4,0.8,1.1] [--labels A,B]

RUN_DIR is the output folder of one run (e.g. out/ep/v1_dx0.01/V1_dx0.01, as
tools/vajont_validate.py writes it). At each snapshot nearest to the requested times (snapshots
come every output.snapshot_interval, 0.1 s in the case), per run:

- ``plate``: the plate's stroke [m] (mean x of its wall particles, wall index 1 of the case,
  against the first snapshot) and its speed u_p [m/s] (their mean vx);
- ``grains``: the displacement of the grains' centroid [m] and their mean speed along x [m/s], as
  a fraction of the plate's speed while it moves (1: the slide moves as a block with the plate);
  the 10th and 90th percentiles of the grains' vx [m/s] (their spread: 0 for a rigid translation);
- ``entered``: the grains' area below the still water level z = --level and outside the slide's
  initial polygon (the case's body slide_above / slide_below), i.e. where water stood at t = 0
  [m^2 per m depth]: each grain stands for dx^2 of the lattice, which its density changes by
  less than 2 % here; the water the slide has pushed out of the reservoir's cross-section;
- ``front``: the 99.5th percentile of the grains' x [m] (the toe, without the odd grain that
  splashes ahead), and ``top``: the grains' highest z [m].

--plot draws, per run (rows) and per --plot-times (columns), the grains (brown; darker the faster) and
the water (blue) of the nearest snapshot over the bed, with the experiment's maximum run-up line;
--labels names the runs in the table and the plot (default: the folders' names).

A grain is a particle of the case's granular media (slide, slide_wet: media 1 and 2), the water
medium 0; wall particles carry their wall's index (0 bed, 1 plate) in the medium column.

Exit status: 0 ok; 2 a folder without snapshots or a snapshot that cannot be read.
"""

import argparse
import json
import os
import sys

import numpy as np
from matplotlib.path import Path

from tools.mixsph_tools.readers import (STATE_LOST, STATE_WALL, ToolError, list_snapshots,
                                        read_snapshot)

GRAIN_MEDIA = (1.0, 2.0)   # slide, slide_wet in cases/vajont_padua.json
PLATE_WALL = 1.0           # the wall index of "plate" (walls: bed, plate)
BED = [(0.0, 0.28), (0.66, 0.22), (0.72, 0.0), (0.75, 0.0), (1.02, 0.46), (1.81, 0.878)]  # the case's bed wall
EXP_RUN_UP = 0.712         # the experiment's maximum run-up [m]
STILL_LEVEL = 0.46         # the case's parameters.reservoir_level [m]
SLIDE_POLYGON = Path([(0.0, 0.73), (0.434, 0.46), (0.627, 0.34), (0.66, 0.22), (0.0, 0.28)])  # the case's bodies


def run_dx(run_dir):
    """The run's particle spacing [m] from its summary.json."""
    path = os.path.join(run_dir, "summary.json")
    try:
        with open(path) as f:
            return float(json.load(f)["numerics"]["dx"])
    except (OSError, KeyError, ValueError, TypeError) as e:
        raise ToolError(f"{path}: no numerics.dx ({e})") from None


def slide_state(snap, dx, level):
    """The measures of the module docstring for one snapshot (a dict)."""
    state, medium = snap["state"], snap["medium"]
    plate = (state == STATE_WALL) & (medium == PLATE_WALL)
    grains = (state != STATE_WALL) & (state != STATE_LOST) & np.isin(medium, GRAIN_MEDIA)
    gx, gz, gvx = snap["x"][grains], snap["z"][grains], snap["vx"][grains]
    return {
        "plate_x": float(np.mean(snap["x"][plate])),
        "plate_u": float(np.mean(snap["vx"][plate])),
        "grain_x": float(np.mean(gx)),
        "grain_u": float(np.mean(gvx)),
        "u10": float(np.percentile(gvx, 10)),
        "u90": float(np.percentile(gvx, 90)),
        "entered": float(np.count_nonzero((gz < level) & ~SLIDE_POLYGON.contains_points(np.column_stack((gx, gz)))))
                   * dx * dx,
        "front": float(np.percentile(gx, 99.5)),
        "top": float(np.max(gz)),
    }


def report(run_dir, times, level):
    """[(t, measures)] at the snapshots nearest to `times`, with the displacements against the
    first snapshot."""
    snaps = list_snapshots(run_dir)
    if not snaps:
        raise ToolError(f"{run_dir}: no snapshots")
    dx = run_dx(run_dir)
    t0, s0 = read_snapshot(snaps[0][1])
    first = slide_state(s0, dx, level)
    rows = []
    for t in times:
        ts, ref = min(snaps, key=lambda s: abs(s[0] - t))
        _, snap = read_snapshot(ref)
        m = slide_state(snap, dx, level)
        m["stroke"] = m["plate_x"] - first["plate_x"]
        m["moved"] = m["grain_x"] - first["grain_x"]
        rows.append((ts, m))
    return rows


def plot(path, runs, labels, times):
    """The grains and the water of each run at the snapshots nearest to `times` (module docstring)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(runs), len(times), figsize=(4.2 * len(times), 2.3 * len(runs)), squeeze=False,
                             sharex=True, sharey=True)
    for r, (run_dir, label) in enumerate(zip(runs, labels)):
        snaps = list_snapshots(run_dir)
        if not snaps:
            raise ToolError(f"{run_dir}: no snapshots")
        for c, t in enumerate(times):
            ts, ref = min(snaps, key=lambda s: abs(s[0] - t))
            _, snap = read_snapshot(ref)
            ax = axes[r][c]
            live = (snap["state"] != STATE_WALL) & (snap["state"] != STATE_LOST)
            water = live & (snap["medium"] == 0.0)
            grains = live & np.isin(snap["medium"], GRAIN_MEDIA)
            speed = np.hypot(snap["vx"][grains], snap["vz"][grains])
            ax.scatter(snap["x"][water], snap["z"][water], s=0.3, c="tab:blue", lw=0)
            ax.scatter(snap["x"][grains], snap["z"][grains], s=0.3, c=speed, cmap="copper_r", vmin=0.0, vmax=0.8, lw=0)
            ax.plot(*zip(*BED), "k-", lw=0.8)
            ax.axhline(EXP_RUN_UP, color="r", lw=0.6, ls="--")
            ax.set_aspect("equal")
            ax.set_xlim(-0.05, 1.55)
            ax.set_ylim(-0.02, 0.85)
            ax.set_title(f"{label}, t = {ts:.2f} s", fontsize=8)
            ax.tick_params(labelsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs", nargs="+", help="output folders of runs of cases/vajont_padua.json")
    ap.add_argument("--times", default="0.2,0.4,0.6,0.8,1.0,1.2", help="times [s], comma-separated")
    ap.add_argument("--level", type=float, default=STILL_LEVEL, help="the still water level [m]")
    ap.add_argument("--markdown", action="store_true", help="print Markdown table rows")
    ap.add_argument("--plot", metavar="FILE", help="draw the grains and the water at --plot-times into FILE (PNG)")
    ap.add_argument("--plot-times", default="0.4,0.8,1.1", help="times [s] of --plot, comma-separated")
    ap.add_argument("--labels", help="names of the runs, comma-separated (default: the folders')")
    a = ap.parse_args(argv)
    try:
        times = [float(v) for v in a.times.split(",")]
        plot_times = [float(v) for v in a.plot_times.split(",")]
    except ValueError:
        print(f"--times {a.times}, --plot-times {a.plot_times}: expected numbers separated by commas", file=sys.stderr)
        return 2
    labels = a.labels.split(",") if a.labels else [os.path.basename(os.path.normpath(r)) for r in a.runs]
    if len(labels) != len(a.runs):
        print(f"--labels: {len(labels)} names for {len(a.runs)} runs", file=sys.stderr)
        return 2
    head = ("run", "t [s]", "stroke [m]", "u_p [m/s]", "grains moved [m]", "u_g [m/s]", "u_g/u_p",
            "vx p10 [m/s]", "vx p90 [m/s]", "entered [m2/m]", "front [m]", "top [m]")
    if a.markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + " --- |" * len(head))
    else:
        print("  ".join(head))
    try:
        for run_dir, label in zip(a.runs, labels):
            for t, m in report(run_dir, times, a.level):
                ratio = m["grain_u"] / m["plate_u"] if abs(m["plate_u"]) > 1e-3 else float("nan")
                cells = (label, f"{t:.2f}",
                         f"{m['stroke']:.3f}", f"{m['plate_u']:.3f}", f"{m['moved']:.3f}", f"{m['grain_u']:.3f}",
                         "-" if ratio != ratio else f"{ratio:.2f}", f"{m['u10']:.3f}", f"{m['u90']:.3f}",
                         f"{m['entered']:.4f}", f"{m['front']:.3f}", f"{m['top']:.3f}")
                print(("| " + " | ".join(cells) + " |") if a.markdown else "  ".join(cells))
        if a.plot:
            plot(a.plot, a.runs, labels, plot_times)
            print(f"plot: {a.plot}")
    except ToolError as e:
        print(f"vajont_slide: {e}", file=sys.stderr)
        return e.code
    return 0


if __name__ == "__main__":
    sys.exit(main())
