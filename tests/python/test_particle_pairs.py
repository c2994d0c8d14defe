"""tools/particle_pairs.py on snapshots written by hand (the CSV format of cli/main.c): the pairs
closer than a fraction of dx, those of two medium-0 particles, and the smallest distance, with
wall particles left out."""

import os
import subprocess
import sys


ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "tools", "particle_pairs.py")
DX = 0.01


def write_snapshot(folder, index, t, rows):
    with open(os.path.join(folder, f"snap_{index:04d}.csv"), "w") as f:
        f.write(f"# t = {t} s\n")
        f.write("id,x,z,vx,vz,rho,p,mu,medium,state\n")
        for k, (x, z, medium, state) in enumerate(rows):
            f.write(f"{k},{x},{z},0,0,1000,0,0.001,{medium},{state}\n")


def lattice():
    """A 10 x 10 lattice at spacing DX, water (medium 0) on the left half, grains (2) on the right."""
    return [[(i + 0.5) * DX, (k + 0.5) * DX, 0 if i < 5 else 2, 0] for i in range(10) for k in range(10)]


def run(folder, *args):
    out = subprocess.run([sys.executable, SCRIPT, folder, "--dx", str(DX), *args], capture_output=True, text=True)
    return out.returncode, out.stdout, out.stderr


def test_counts_close_pairs_by_medium_and_skips_walls(tmp_path):
    rows = lattice()
    write_snapshot(tmp_path, 0, 0.0, rows)
    moved = [list(r) for r in rows]
    moved[0][0] += 0.9 * DX       # water particle 0 to 0.1 dx from the water particle at (1.5 dx, 0.5 dx)
    moved[99][1] -= 0.8 * DX      # the last grain to 0.2 dx from its neighbour below
    moved.append([moved[50][0], moved[50][1], 0, 2])   # a wall particle on top of a grain: not counted
    write_snapshot(tmp_path, 1, 0.1, moved)
    code, out, err = run(str(tmp_path))
    assert code == 0, err
    lines = [line for line in out.splitlines() if not line.startswith("#")]
    assert lines[0] == "t_s,pairs,pairs_medium0,min_distance_over_dx"
    # reference: the construction; a lattice has no pair closer than dx, the moved one two
    _, n0, w0, d0 = lines[1].split(",")
    assert (int(n0), int(w0)) == (0, 0) and abs(float(d0) - 1.0) < 1e-3
    _, n1, w1, d1 = lines[2].split(",")
    assert (int(n1), int(w1)) == (2, 1)
    assert abs(float(d1) - 0.1) < 1e-3
    # a looser fraction (0.5 dx) counts the same two; --every 0.1 keeps both instants
    code, out, _ = run(str(tmp_path), "--fraction", "0.5", "--every", "0.1")
    assert code == 0 and out.splitlines()[-1].split(",")[1] == "2"


def test_refuses_bad_arguments_and_empty_folders(tmp_path):
    code, _, err = run(str(tmp_path))
    assert code == 2 and "no snapshots" in err
    code, _, err = run(str(tmp_path), "--fraction", "1.5")
    assert code == 2 and "--fraction" in err
    no_dx = subprocess.run([sys.executable, SCRIPT, str(tmp_path)], capture_output=True, text=True)
    assert no_dx.returncode == 2 and "--dx" in no_dx.stderr   # no --dx and no vajont_run.json
