#!/usr/bin/env python3
"""Pressure noise of a water column at rest: the hydrostatic tank with and without density
diffusion.

    PYTHONPATH=$PWD python -m tools.hydrostatic_noise [--mixsph build/mixsph] [--out out/hydro_noise]
                                                      [--t-end 1.0] [--set KEY=VALUE]...

Runs cases/hydrostatic_tank.json (0.4 x 0.3 m of water, dx = 0.01, K = 6.25e5 Pa) with
numerics.density_diffusion = 0 (off), and 0.1 in its two forms ("hydrostatic": the density
difference less its hydrostatic part; "molteni": the whole difference), snapshots every 0.01 s,
one thread. For every snapshot after t = 0, over the water particles:

- the deviation of each particle's pressure from rho0 g (z_s - z), z_s the free surface (mean
  height of the top row of particles plus dx/2, as tests/test_hydrostatic.c measures it);
- its rms over the particles and all snapshots ("rms dev"), and the same with the mean deviation
  of each layer of height dx removed ("rms noise": what is left once the steady profile, e.g. the
  kernel's lattice bias, is taken out: particle-to-particle scatter and its oscillation);
- the largest particle speed and the surface height at the end.

Prints one table row per run. Exit status 0, or 1 when a run fails.
"""

import argparse
import os
import subprocess
import sys

import numpy as np

from tools.mixsph_tools.readers import list_snapshots, read_snapshot

RHO0, G, DX = 1000.0, 9.81, 0.01
RUNS = (("off", ["numerics.density_diffusion=0"]),
        ("hydrostatic 0.1", ["numerics.density_diffusion=0.1", "numerics.density_diffusion_form=0"]),
        ("molteni 0.1", ["numerics.density_diffusion=0.1", "numerics.density_diffusion_form=1"]))


def measure(outdir, dx=DX):
    """(rms dev, rms noise, max speed, z_s at the end) over the snapshots after t = 0 of a run of
    water at rest at particle spacing dx (also used by tools/dambreak_lobovsky.py)."""
    dev2, noise2, count, vmax, zs = 0.0, 0.0, 0, 0.0, float("nan")
    for t, ref in list_snapshots(outdir):
        if t <= 0.0:
            continue
        _, c = read_snapshot(ref)
        water = c["state"] != 2  # not a wall
        z, p = c["z"][water], c["p"][water]
        top = z > z.max() - 0.5 * dx
        zs = z[top].mean() + 0.5 * dx
        d = p - RHO0 * G * (zs - z)
        layer = np.floor(z / dx).astype(int)
        mean = np.bincount(layer, weights=d) / np.maximum(np.bincount(layer), 1)
        dev2 += np.sum(d * d)
        noise2 += np.sum((d - mean[layer]) ** 2)
        count += d.size
        vmax = max(vmax, float(np.max(np.hypot(c["vx"][water], c["vz"][water]))))
    return np.sqrt(dev2 / count), np.sqrt(noise2 / count), vmax, zs


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mixsph", default="build/mixsph")
    ap.add_argument("--out", default="out/hydro_noise")
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--set", action="append", default=[])
    a = ap.parse_args()
    print(f"{'run':18s} {'rms dev [Pa]':>12s} {'rms noise [Pa]':>14s} {'max speed [m/s]':>15s} {'z_s end [m]':>11s}")
    status = 0
    for label, sets in RUNS:
        out = os.path.join(a.out, label.replace(" ", "_"))
        cmd = [a.mixsph, "run", "cases/hydrostatic_tank.json", "--threads", "1", "--quiet", "--out", out,
               "--set", f"numerics.t_end={a.t_end}", "--set", "output.snapshot_interval=0.01"]
        for s in sets + a.set:
            cmd += ["--set", s]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            print(f"{label:18s} failed (exit {r.returncode}): {r.stderr.strip()[-300:]}")
            status = 1
            continue
        dev, noise, vmax, zs = measure(out)
        print(f"{label:18s} {dev:12.2f} {noise:14.2f} {vmax:15.5f} {zs:11.5f}")
    return status


if __name__ == "__main__":
    sys.exit(main())
