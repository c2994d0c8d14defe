"""tools/erosive_ensemble.py: the within / between / mean-profile errors on run folders written by
hand in the formats of cli/main.c and lib/src/io/monitors.c (no mixsph run needed)."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import erosive_ensemble as ee  # noqa: E402
import mixsph_tools as mt  # noqa: E402
from test_erosive_dambreak import DX, layered_tank, write_snapshot  # noqa: E402

CASE = os.path.join(ROOT, "cases", "erosive_dambreak.json")
BINS = (np.arange(50) + 0.5) * DX   # the 0.01 m bins of 0 <= x <= 0.5


def write_member(folder, top, bed_top=0.07, rise=0.25, steps=100):
    """A finished run folder: stamp, summary, interface profile (bin tops ``top``) and a snapshot
    of a flat bed at bed_top, all at t = 0.5 s."""
    os.makedirs(folder)
    with open(os.path.join(folder, "erosive_run.json"), "w") as f:
        json.dump({"run": 2, "dx": DX, "case": CASE}, f)
    with open(os.path.join(folder, "summary.json"), "w") as f:
        json.dump({"status": "ok", "steps": steps, "wall_time_s": 10.0,
                   "outputs": {"bedload_rise_left_wall": {"max": rise}}}, f)
    with open(os.path.join(folder, "profile_interface_0.csv"), "w") as f:
        f.write("# profile interface of sediment at t = 0.5 s (requested 0.5 s), bins of 0.01 m\nx,z_top\n")
        for x, z in zip(BINS, top):
            f.write(f"{x:.9g},{z:.9g}\n")
    write_snapshot(folder, 0.5, layered_tank(bed_top))
    return str(folder)


def test_within_between_and_mean_profiles(tmp_path):
    # reference: group A tops 0.10 and 0.11 m everywhere, group B 0.12 and 0.13 m. Within A (both
    # orders): |0.10 - 0.11| / 0.11 and / 0.10 -> mean (9.09 + 10) / 2 = 9.55 %, max 10 %;
    # B against A over the 4 pairs: (20 + 9.09 + 30 + 18.18) / 4 = 19.32 %; mean profiles
    # 0.125 against 0.105: 19.05 %. Exact arithmetic, tolerance 1e-9 %.
    a = [write_member(tmp_path / f"a{k}", np.full(50, z)) for k, z in enumerate((0.10, 0.11))]
    b = [write_member(tmp_path / f"b{k}", np.full(50, z), rise=r)
         for k, (z, r) in enumerate(((0.12, 0.2), (0.13, 0.3)))]
    groups = [("A", [ee.Member(d, 0.5) for d in a]), ("B", [ee.Member(d, 0.5) for d in b])]
    rows = ee.compare(groups)
    assert rows[0]["within_top_mean"] == pytest.approx((1 / 0.11 + 1 / 0.10) / 2, abs=1e-9)
    assert rows[0]["within_top_max"] == pytest.approx(10.0, abs=1e-9)
    assert np.isnan(rows[0]["between_top_mean"])
    assert rows[1]["between_top_mean"] == pytest.approx((20 + 100 / 11 + 30 + 200 / 11) / 4, abs=1e-9)
    assert rows[1]["means_top"] == pytest.approx(2 / 0.105, abs=1e-9)
    assert rows[1]["rise_mean"] == pytest.approx(0.25) and rows[1]["rise_min"] == 0.2
    # every member has the same flat bed at 0.07 m: the f = 0.5 measure finds no difference
    assert rows[1]["between_frac_mean"] == pytest.approx(0.0, abs=1e-9)
    png = tmp_path / "ensemble.png"
    ee.plot(str(png), groups, 0.5)
    assert png.stat().st_size > 0


def test_mean_profile_leaves_out_bins_a_member_lacks(tmp_path):
    top = np.full(50, 0.1)
    top[3] = np.nan
    a = ee.Member(write_member(tmp_path / "a", top), 0.5)
    b = ee.Member(write_member(tmp_path / "b", np.full(50, 0.2)), 0.5)
    m = ee.mean_profile([a.top, b.top])
    assert np.isnan(m.z[3]) and m.z[4] == pytest.approx(0.15)


def test_bad_input_is_refused(tmp_path):
    a = write_member(tmp_path / "a", np.full(50, 0.1))
    b = write_member(tmp_path / "b", np.full(50, 0.1))
    tool = [sys.executable, os.path.join(ROOT, "tools", "erosive_ensemble.py")]
    for opts, message in (
            (["--group", "A", a], "needs at least 2 run folders"),
            (["--group", "A", a, b, "--group", "A", a, b], "the same name"),
            (["--group", "A", a, str(tmp_path / "none")], "not a finished run")):
        r = subprocess.run(tool + opts + ["--out", str(tmp_path / "out")], capture_output=True, text=True)
        assert r.returncode == 2 and message in r.stderr, r.stderr
    with open(os.path.join(b, "summary.json"), "w") as f:
        json.dump({"status": "unstable", "outputs": {}}, f)
    with pytest.raises(mt.ToolError, match="not ok"):
        ee.Member(b, 0.5)
