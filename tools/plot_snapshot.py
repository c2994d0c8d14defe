#!/usr/bin/env python3
"""Plot particle snapshots of a mixsph run from its HDF5 file (run.h5), like the paper's
Figs 2, 6 and 10 (Manenti et al. 2018): the particles of one instant coloured by medium
(water, granular material; grains held fixed in a darker shade) or by velocity magnitude |u|,
the walls in grey; or an animation of all snapshots.

    .venv/bin/python tools/plot_snapshot.py RUN [--time T | --index K] [--color medium|speed]
        [--animate] [--fps F] [--vmax V] [--xlim X0 X1] [--zlim Z0 Z1] [--no-walls] [-o FILE]
        [--view side|plan] [--y-band Y0 Y1]

A 3D run ("dimensions": 3) is drawn as a vertical slice, the side view x-z of the particles whose
y lies in a band (--y-band; by default 2 dx wide about the middle of the particles' y range at
t = 0), or with --view plan as a plan view x-y from above (every particle, the highest drawn
last, so the colours are those of the top; --zlim then bounds y).

RUN is an output folder (holding run.h5) or the run.h5 file itself. Without --time/--index the
last snapshot is drawn. -o defaults to RUN/snapshot_<index>_<color>.png, or for --animate to
RUN/run_<color>.mp4 when ffmpeg is on the PATH and RUN/run_<color>.gif otherwise (the format
follows the extension of -o: .gif with pillow, .mp4 with ffmpeg). With --color speed the colour
scale is shared by all frames (0 to the largest |u| of the run, or --vmax).
Only complete snapshots are read (groups with their index attribute, written last), so a run
still going or killed mid-way can be plotted.
Exit codes: 0 ok, 2 bad arguments or no such file/snapshot.
"""
import argparse
import json
import os
import shutil
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib import animation  # noqa: E402
from matplotlib.colors import to_rgb  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

MOBILE, FIXED, WALL, LOST = 0, 1, 2, 3
# colours of media by kind: water-like media blue, granular media sand-brown (darker when fixed)
WATER_COLOURS = ["#2b7bba", "#6baed6", "#08519c"]
GRAIN_COLOURS = ["#b5835a", "#8c6d46", "#d9b38c"]
WALL_COLOUR = "#9a9a9a"


class Run:
    """The complete snapshots of a run.h5 and its metadata."""

    def __init__(self, path):
        if os.path.isdir(path):
            path = os.path.join(path, "run.h5")
        if not os.path.isfile(path):
            raise SystemExit(f"plot_snapshot: {path}: no such file (run mixsph with an output folder)")
        self.path = path
        self.folder = os.path.dirname(os.path.abspath(path))
        self.f = h5py.File(path, "r")
        if self.f.attrs.get("format") != "mixsph-run":
            raise SystemExit(f"plot_snapshot: {path}: not a mixsph run file")
        meta = self.f["metadata"]
        self.case = str(self.f.attrs.get("case_name", ""))
        self.media = [str(m) for m in meta.attrs["media"]]
        self.dx = float(meta.attrs["dx"])
        # complete snapshots: groups with their index attribute (written last), by index (a run
        # restarted into a new folder starts at the checkpoint's index)
        snaps = self.f["snapshots"]
        self.groups = [snaps[name] for name in sorted(snaps) if "index" in snaps[name].attrs]
        self.times = np.array([g.attrs["time"] for g in self.groups])
        if not self.groups:
            raise SystemExit(f"plot_snapshot: {path}: no snapshot yet")
        # granular media: those whose particles are ever fixed, or named so in the case
        case = json.loads(self.f["metadata/case_json"][()])
        kinds = {name: m.get("type", "fluid") for name, m in case.get("media", {}).items()}
        self.granular = [kinds.get(m, "fluid") == "granular" for m in self.media]

        self.dim = self.groups[0]["position"].shape[1]
        self.view, self.y_band = "side", None

    def set_view(self, view, y_band):
        """What snapshot() returns of a 3D run: the side view of the particles in the y band (the
        default band: 2 dx about the middle of the y range at t = 0), or the plan view."""
        if self.dim == 2 and (view != "side" or y_band):
            raise SystemExit("plot_snapshot: --view plan and --y-band are for a 3D run; this run is 2D")
        self.view = view
        if self.dim == 3 and view == "side":
            y = self.groups[0]["position"][()][:, 1]
            mid = 0.5 * (y.min() + y.max())
            self.y_band = tuple(y_band) if y_band else (mid - self.dx, mid + self.dx)

    def snapshot(self, k):
        """Snapshot k: positions in the plotted plane (x and the vertical, last, component; of a
        3D run the particles in the y band, or x and y in the plan view, the highest last),
        speeds |u|, media, states, time."""
        g = self.groups[k]
        pos = g["position"][()]
        out = {name: g[name][()] for name in ("medium", "state")} | {
            "speed": np.linalg.norm(g["velocity"][()], axis=1), "time": float(g.attrs["time"]), "index": k}
        if self.dim == 3 and self.view == "plan":
            keep = np.argsort(pos[:, 2], kind="stable")
            axes = [0, 1]
        elif self.dim == 3:
            keep = np.nonzero((pos[:, 1] >= self.y_band[0]) & (pos[:, 1] < self.y_band[1]))[0]
            axes = [0, 2]
        else:
            keep = slice(None)
            axes = [0, pos.shape[1] - 1]
        out = {name: v[keep] if isinstance(v, np.ndarray) else v for name, v in out.items()}
        out["position"] = pos[keep][:, axes]
        return out

    def max_speed(self):
        v = 0.0
        for k in range(len(self.groups)):
            s = self.snapshot(k)
            moving = s["state"] <= FIXED
            if moving.any():
                v = max(v, float(s["speed"][moving].max()))
        return v


def medium_colours(run):
    """RGB of each medium (mobile) and of its fixed particles."""
    cols, fixed = [], []
    w = g = 0
    for k, _ in enumerate(run.media):
        if run.granular[k]:
            c = to_rgb(GRAIN_COLOURS[g % len(GRAIN_COLOURS)])
            g += 1
        else:
            c = to_rgb(WATER_COLOURS[w % len(WATER_COLOURS)])
            w += 1
        cols.append(c)
        fixed.append(tuple(0.6 * x for x in c))
    return np.array(cols), np.array(fixed)


class Drawer:
    """One axes that redraws a snapshot (for a still image or for animation frames)."""

    def __init__(self, run, args):
        self.run, self.args = run, args
        s0 = run.snapshot(0)
        pos = s0["position"]
        x0, x1 = args.xlim if args.xlim else (pos[:, 0].min() - run.dx, pos[:, 0].max() + run.dx)
        z0, z1 = args.zlim if args.zlim else (pos[:, 1].min() - run.dx, pos[:, 1].max() + run.dx)
        # a figure of about the data's aspect (plus room for labels and the colour bar)
        height = min(max(args.width * 0.8 * (z1 - z0) / max(x1 - x0, 1e-12) + 1.0, 2.5), 2.0 * args.width)
        self.fig, self.ax = plt.subplots(figsize=(args.width, height), dpi=args.dpi)
        self.ax.set_xlim(x0, x1)
        self.ax.set_ylim(z0, z1)
        self.ax.set_aspect("equal")
        self.ax.set_xlabel("x [m]")
        self.ax.set_ylabel("y [m]" if run.view == "plan" else "z [m]")
        self.cols, self.fixed_cols = medium_colours(run)
        self.walls = self.ax.scatter([], [], c=WALL_COLOUR, marker="s", linewidths=0)
        if args.color == "speed":
            self.vmax = args.vmax if args.vmax else max(run.max_speed(), 1e-12)
            self.pts = self.ax.scatter([], [], c=[], cmap="jet", vmin=0.0, vmax=self.vmax, marker="o", linewidths=0)
            cb = self.fig.colorbar(self.pts, ax=self.ax, fraction=0.04, pad=0.02)
            cb.set_label("|u| [m/s]")
        else:
            self.pts = self.ax.scatter([], [], marker="o", linewidths=0)
            handles = [Line2D([], [], marker="o", ls="", color=self.cols[k], label=m) for k, m in enumerate(run.media)]
            if any(run.granular):
                handles.append(Line2D([], [], marker="o", ls="", color=self.fixed_cols[run.granular.index(True)],
                                      label="fixed grains"))
            if not args.no_walls:
                handles.append(Line2D([], [], marker="s", ls="", color=WALL_COLOUR, label="walls"))
            self.ax.legend(handles=handles, loc="best", fontsize=8, markerscale=1.5)
        self.title = self.ax.set_title(" ")
        self.fig.tight_layout()
        # marker area so that particles of spacing dx about tile the plane (once the layout and
        # the equal aspect are applied)
        self.fig.canvas.draw()
        px_per_m = self.ax.transData.transform((1.0, 0.0))[0] - self.ax.transData.transform((0.0, 0.0))[0]
        size = max(0.3, (0.95 * run.dx * px_per_m * 72.0 / self.fig.dpi) ** 2)
        self.walls.set_sizes([size])
        self.pts.set_sizes([size])

    def draw(self, k):
        s = self.run.snapshot(k)
        pos, st = s["position"], s["state"]
        wall = st == WALL
        part = st <= FIXED
        self.walls.set_offsets(pos[wall] if not self.args.no_walls else np.empty((0, 2)))
        self.pts.set_offsets(pos[part])
        if self.args.color == "speed":
            self.pts.set_array(s["speed"][part])
        else:
            med = s["medium"][part]
            colours = np.where((st[part] == FIXED)[:, None], self.fixed_cols[med], self.cols[med])
            self.pts.set_facecolors(colours)
        what = "|u|" if self.args.color == "speed" else "medium"
        where = ""
        if self.run.dim == 3:
            where = ", plan view" if self.run.view == "plan" else \
                f", {self.run.y_band[0]:.3g} <= y < {self.run.y_band[1]:.3g} m"
        self.title.set_text(f"{self.run.case}: t = {s['time']:.3f} s ({what}, snapshot {k}{where})")
        return self.walls, self.pts, self.title


def pick(run, args):
    n = len(run.groups)
    if args.index is not None:
        if not -n <= args.index < n:
            raise SystemExit(f"plot_snapshot: --index {args.index}: the run has snapshots 0..{n - 1}")
        return args.index % n
    if args.time is not None:
        return int(np.argmin(np.abs(run.times - args.time)))
    return n - 1


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", help="output folder of a mixsph run, or its run.h5")
    ap.add_argument("--time", type=float, help="draw the snapshot nearest this time [s]")
    ap.add_argument("--index", type=int, help="draw snapshot K (negative: from the end)")
    ap.add_argument("--color", choices=["medium", "speed"], default="medium",
                    help="colour by medium (default) or by velocity magnitude |u|")
    ap.add_argument("--animate", action="store_true", help="all snapshots as a GIF or MP4")
    ap.add_argument("--fps", type=float, default=5.0, help="frames per second of the animation (5)")
    ap.add_argument("--vmax", type=float, help="top of the |u| colour scale [m/s]")
    ap.add_argument("--xlim", type=float, nargs=2, metavar=("X0", "X1"))
    ap.add_argument("--zlim", type=float, nargs=2, metavar=("Z0", "Z1"))
    ap.add_argument("--no-walls", action="store_true", help="do not draw the wall particles")
    ap.add_argument("--view", choices=["side", "plan"], default="side",
                    help="3D run: a vertical slice x-z (side, default) or the plan view x-y")
    ap.add_argument("--y-band", type=float, nargs=2, metavar=("Y0", "Y1"),
                    help="3D run, side view: the slice Y0 <= y < Y1 [m] (default: 2 dx about the middle)")
    ap.add_argument("--width", type=float, default=9.0, help="figure width [in] (9)")
    ap.add_argument("--dpi", type=float, default=110.0)
    ap.add_argument("-o", "--output", help="output file (.png, .pdf, .svg; .gif or .mp4 with --animate)")
    args = ap.parse_args(argv)
    if args.animate and (args.time is not None or args.index is not None):
        ap.error("--animate draws every snapshot: no --time or --index")
    run = Run(args.run)
    run.set_view(args.view, args.y_band)
    drawer = Drawer(run, args)
    if not args.animate:
        k = pick(run, args)
        view = f"_{args.view}" if run.dim == 3 else ""
        out = args.output or os.path.join(run.folder, f"snapshot_{k:04d}_{args.color}{view}.png")
        drawer.draw(k)
        drawer.fig.savefig(out)
        print(f"plot_snapshot: {out} (snapshot {k}, t = {run.times[k]:.4f} s)")
        return 0
    have_ffmpeg = shutil.which("ffmpeg") is not None
    out = args.output or os.path.join(run.folder, f"run_{args.color}.{'mp4' if have_ffmpeg else 'gif'}")
    ext = os.path.splitext(out)[1].lower()
    if ext == ".mp4":
        if not have_ffmpeg:
            raise SystemExit("plot_snapshot: MP4 needs ffmpeg on the PATH (apt-get install ffmpeg); use a .gif name")
        writer = animation.FFMpegWriter(fps=args.fps)
    elif ext == ".gif":
        writer = animation.PillowWriter(fps=args.fps)
    else:
        raise SystemExit(f"plot_snapshot: {out}: an animation is written as .gif or .mp4")
    anim = animation.FuncAnimation(drawer.fig, drawer.draw, frames=len(run.groups), blit=False)
    anim.save(out, writer=writer)
    print(f"plot_snapshot: {out} ({len(run.groups)} frames, t = {run.times[0]:.3f} .. {run.times[-1]:.3f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
