#!/usr/bin/env python3
"""A 2D case as a 3D flume: extrude its section across a width of a few dx between mirror side
walls, run both at the same dx, and compare their monitors (docs/validation/three_d.md).

    python tools/flume_3d.py CASE [--cells N] [--dx DX] [--t-end T] [--set KEY=VALUE]...
                             [--compare MONITOR:series|max]... [--tol REL] [--check]
                             [--threads N] [--mixsph build/mixsph] [--out DIR]
                             [--write-case PATH] [--doc FILE] [--lanes]
                             [--side-walls mirror|free-slip]

The flume (``extrude``): ``"dimensions": 3``; every polygon body and every polyline wall spans
y in [0, W], W = N dx (N = --cells, default 4; the lattice puts N particles across it); the first
fixed polyline wall (no motion) gets ``"side_walls": "mirror"`` (--side-walls; default), the
planes y = 0 and y = W as planes of symmetry without wall particles, every particle within 2h of
one imaged across it (docs/cases.md), so that nothing in the flow depends on y by construction;
``--side-walls free-slip`` gives them free-slip wall particles instead, up to the wall's highest
point, as before 2026-12-08; a domain gets y in
[-(wall_layers + 2) dx, W + (wall_layers + 2) dx]; a pressure probe sits at y = W / 2; the 2D-only
monitors (``profile``, ``wall_pressure``) are left out. Everything else (media, motions, numerics,
parameters) is the 2D case's. ``--write-case PATH`` only writes the flume (at the case's own dx,
or --dx) and exits.

Comparison: each ``--compare MONITOR:series`` takes the largest relative difference
|m3 - m2| / |m2| over the monitor times at which both runs have a value (nan rows skipped);
``MONITOR:max`` the relative difference of the maxima over the run (summary.json). ``--check``
exits 1 unless every difference is within --tol (default 0.02); with ``--known-band LO HI`` (a
known failure, tests/known_failure.h's rule) unless every difference is beyond --tol and within
[LO, HI], so that it fails on a regression and the day the criterion is met. Runs: ``mixsph run CASE --set
numerics.dx=DX [--set numerics.t_end=T] [--set ...] --threads N --quiet --out OUT/{2d,3d}``,
the CPU lock of a shared machine is the caller's business.

``--lanes`` (give the runs CSV snapshots, e.g. ``--set output.snapshot_interval=0.02``) prints, at
each snapshot, the 2D front and the front of each lane of the 3D flume: the largest x of the mobile
particles whose y lies in [k dx, (k + 1) dx), k = 0 .. N - 1. The ``front`` monitor of the 3D run is
the largest of these; in a flume whose flow does not depend on y they are all the 2D front
(docs/validation/three_d.md, "Where the 3D front's lead comes from").
"""

import argparse
import copy
import json
import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mixsph_tools import readers  # noqa: E402

TWO_D_ONLY_MONITORS = ("profile", "wall_pressure")


def extrude(case, dx, cells, side_walls="mirror"):
    """The 3D flume of the 2D case (a dict; not modified): see the module's docstring."""
    if case.get("dimensions", 2) != 2:
        raise readers.ToolError(f"case {case.get('name')}: not a 2D case")
    width = cells * dx
    c = copy.deepcopy(case)
    c["dimensions"] = 3
    c["name"] = f"{case['name']}_flume_3d"
    c["description"] = (f"The 2D case {case['name']} extruded by tools/flume_3d.py into a 3D flume {cells} dx wide "
                        f"(dx = {dx:g} m, W = {width:g} m) with {side_walls} side walls; its monitors must match the "
                        f"2D run's (docs/validation/three_d.md). The 2D case: " + case.get("description", ""))
    numerics = c.setdefault("numerics", {})
    numerics["dx"] = dx
    layers = numerics.get("wall_layers", 3)
    if "domain" in c:
        margin = (layers + 2) * dx
        c["domain"] = {"x_min": c["domain"]["x_min"], "x_max": c["domain"]["x_max"], "y_min": -margin,
                       "y_max": width + margin, "z_min": c["domain"]["z_min"], "z_max": c["domain"]["z_max"]}
    for name, body in c.get("bodies", {}).items():
        if "polygon" not in body:
            raise readers.ToolError(f"bodies.{name}: only polygon bodies are extruded")
        body["y_min"], body["y_max"] = 0.0, width
    sides = None
    for name, wall in c.get("walls", {}).items():
        if "polyline" not in wall:
            raise readers.ToolError(f"walls.{name}: only polyline walls are extruded")
        wall["y_min"], wall["y_max"] = 0.0, width
        if sides is None and "motion" not in wall:
            wall["side_walls"] = side_walls
            sides = name
    if sides is None:
        raise readers.ToolError(f"case {case['name']}: no fixed polyline wall to carry the side walls")
    monitors = {}
    for name, m in c.get("monitors", {}).items():
        if m.get("type") in TWO_D_ONLY_MONITORS:
            continue
        if m.get("type") == "pressure_probe":
            m["y"] = 0.5 * width
        monitors[name] = m
    c["monitors"] = monitors
    return c


def lane_fronts(snap, dx, cells):
    """The front (largest x) of the mobile particles of each lane k = 0 .. cells - 1 of a 3D flume's
    snapshot (a read_snapshot dict), the lane of a particle being floor(y / dx) clipped to the
    flume; nan for a lane with no particle."""
    mobile = snap["state"] == 0
    x, lane = snap["x"][mobile], np.clip(np.floor(snap["y"][mobile] / dx), 0, cells - 1).astype(int)
    return np.array([x[lane == k].max() if (lane == k).any() else np.nan for k in range(cells)])


def lane_table(out2, out3, dx, cells):
    """Markdown rows: at each snapshot (the 2D run's time), the 2D front and each 3D lane's front
    relative to it [%] (mobile particles, no spray filter: the front monitor's min_neighbours
    is not in the snapshots)."""
    lines = ["| t [s] | 2D front [m] | " + " | ".join(f"lane {k} [%]" for k in range(cells)) + " |",
             "|---" * (cells + 2) + "|"]
    # the two runs take their snapshots at the first step ends past the same times: pair them in order
    for (t, path2), (_, path3) in zip(readers.list_snapshots(out2)[1:], readers.list_snapshots(out3)[1:]):
        _, s2 = readers.read_snapshot(path2)
        _, s3 = readers.read_snapshot(path3)
        x2 = s2["x"][s2["state"] == 0].max()
        rel = 100 * (lane_fronts(s3, dx, cells) - x2) / x2
        lines.append(f"| {t:.3f} | {x2:.4f} | " + " | ".join(f"{r:+.2f}" for r in rel) + " |")
    return lines


def run(mixsph, case_path, outdir, sets, threads):
    cmd = [mixsph, "run", case_path, "--out", outdir, "--quiet", "--threads", str(threads)]
    for s in sets:
        cmd += ["--set", s]
    os.makedirs(outdir, exist_ok=True)
    t0 = time.time()
    with open(os.path.join(outdir, "mixsph.log"), "w") as log:
        rc = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT).returncode
    if rc != 0:
        raise readers.ToolError(f"{' '.join(cmd)} failed ({rc}):\n{readers.tail(os.path.join(outdir, 'mixsph.log'))}", 1)
    summary = readers.read_summary(os.path.join(outdir, "summary.json"))
    return summary, readers.read_monitors(os.path.join(outdir, "monitors.csv")), time.time() - t0


def difference(what, mon2, mon3, sum2, sum3):
    name, _, kind = what.partition(":")
    if kind == "max":
        a = readers.summary_value(sum2, name, "max")
        b = readers.summary_value(sum3, name, "max")
        return a, b, abs(b - a) / abs(a)
    if kind != "series":
        raise readers.ToolError(f"--compare {what}: give MONITOR:series or MONITOR:max")
    for m in (mon2, mon3):
        if name not in m:
            raise readers.ToolError(f"--compare {what}: no monitor {name}")
    n = min(len(mon2["t"]), len(mon3["t"]))
    a, b = mon2[name][:n], mon3[name][:n]
    ok = np.isfinite(a) & np.isfinite(b) & (a != 0)
    if not ok.any():
        raise readers.ToolError(f"--compare {what}: no time at which both runs have a value")
    rel = np.abs(b[ok] - a[ok]) / np.abs(a[ok])
    k = int(np.argmax(rel))
    return a[ok][k], b[ok][k], float(rel[k])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("case")
    ap.add_argument("--cells", type=int, default=4, help="particles across the flume (default 4)")
    ap.add_argument("--dx", type=float, help="spacing of both runs (default: the case's)")
    ap.add_argument("--t-end", type=float)
    ap.add_argument("--set", action="append", default=[], help="KEY=VALUE for both runs")
    ap.add_argument("--compare", action="append", default=[], help="MONITOR:series or MONITOR:max")
    ap.add_argument("--tol", type=float, default=0.02)
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--known-band", type=float, nargs=2, metavar=("LO", "HI"),
                    help="known failure: --check passes only while every difference is beyond --tol and in [LO, HI]")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--mixsph", default="build/mixsph")
    ap.add_argument("--out", default="out/flume_3d")
    ap.add_argument("--write-case")
    ap.add_argument("--doc", help="append the table and the command to this markdown file")
    ap.add_argument("--side-walls", choices=("mirror", "free-slip"), default="mirror",
                    help="the side walls: mirror planes (images, no particles; default) or free-slip wall particles")
    ap.add_argument("--lanes", action="store_true", help="print the 3D front of each lane beside the 2D front")
    args = ap.parse_args(argv)
    try:
        with open(args.case) as f:
            case = json.load(f)
        dx = args.dx if args.dx else case["numerics"]["dx"]
        flume = extrude(case, dx, args.cells, args.side_walls)
        if args.write_case:
            with open(args.write_case, "w") as f:
                json.dump(flume, f, indent=2)
                f.write("\n")
            return 0
        os.makedirs(args.out, exist_ok=True)
        flume_path = os.path.join(args.out, f"{flume['name']}.json")
        with open(flume_path, "w") as f:
            json.dump(flume, f, indent=2)
        sets = [f"numerics.dx={dx!r}"] + ([f"numerics.t_end={args.t_end!r}"] if args.t_end else []) + args.set
        sum2, mon2, w2 = run(args.mixsph, args.case, os.path.join(args.out, "2d"), sets, args.threads)
        sum3, mon3, w3 = run(args.mixsph, flume_path, os.path.join(args.out, "3d"), sets, args.threads)
        load = os.getloadavg()[0]
        lines = [f"| run | particles | steps | wall time [s] |", "| --- | --- | --- | --- |"]
        for label, s, w in (("2D", sum2, w2), (f"3D, {args.cells} dx wide", sum3, w3)):
            lines.append(f"| {label} | {s.get('particles', 'n/a')} | {s.get('steps', 'n/a')} | {w:.1f} |")
        lines += ["", "| monitor | 2D | 3D flume | difference | tolerance |", "| --- | --- | --- | --- | --- |"]
        failed = []
        for what in args.compare:
            a, b, rel = difference(what, mon2, mon3, sum2, sum3)
            lines.append(f"| {what} (largest) | {a:.4f} | {b:.4f} | {100 * rel:.2f} % | {100 * args.tol:g} % |")
            if args.known_band:  # a known failure: beyond the tolerance, inside today's band
                if not (rel > args.tol and args.known_band[0] <= rel <= args.known_band[1]):
                    failed.append(what)
            elif not rel <= args.tol:
                failed.append(what)
        if args.lanes:
            lines += [""] + lane_table(os.path.join(args.out, "2d"), os.path.join(args.out, "3d"), dx, args.cells)
        given = list(argv if argv is not None else sys.argv[1:])
        kept = [a for k, a in enumerate(given) if a not in ("--mixsph", "--doc", "--out")
                and (k == 0 or given[k - 1] not in ("--mixsph", "--doc", "--out"))]
        command = "python tools/flume_3d.py " + " ".join(kept)
        text = "\n".join(lines) + f"\n\nCommand: `{command}` (load average {load:.2f} at the end)\n"
        print(text)
        if args.doc:
            with open(args.doc, "a") as f:
                f.write("\n" + text)
        if args.check and failed:
            band = f" or outside the known band {args.known_band}" if args.known_band else ""
            print(f"FAIL: {', '.join(failed)} beyond {100 * args.tol:g} %{band}")
            return 1
        return 0
    except readers.ToolError as e:
        print(f"flume_3d.py: {e}", file=sys.stderr)
        return e.code


if __name__ == "__main__":
    sys.exit(main())
