"""The granular validation scripts of issue 59 (tools/column_runout.py's threshold measures,
tools/granular_heap.py, tools/impulse_waves.py): their formulas against hand computations and the
cases they write. No run: the runs are the validation suite's (docs/validation/granular_thresholds.md)."""

import json
import math
import os

import numpy as np
import pytest

from tool_helpers import ROOT
import column_runout as cr  # noqa: E402  (tools/ is on the path through tool_helpers)
import granular_heap as gh  # noqa: E402
import impulse_waves as iw  # noqa: E402


def load(name):
    with open(os.path.join(ROOT, "cases", name)) as f:
        return json.load(f)


def test_impulse_product():
    # Heller & Hager (2010): P = F S^(1/2) M^(1/4) cos(6 alpha / 7)^(1/2). V_s = 2 sqrt(g h) (F = 2),
    # s = h / 4 (S^(1/2) = 1/2), m = 16 rho_w h^2 (M^(1/4) = 2): P = 2 cos(6 pi / 28)^(1/2).
    h = 0.3
    p = iw.impulse_product(2 * math.sqrt(iw.G * h), h / 4, 16 * iw.RHO_W * h * h, h)
    assert p == pytest.approx(2 * math.sqrt(math.cos(math.radians(6 * 45 / 7))), rel=1e-12)


def test_exponent_fit():
    # points on a_M / h = 0.3 P^0.7 give back 0.7; fewer than two points give NaN
    rows = [{"P": p, "a_rel": 0.3 * p ** 0.7} for p in (0.3, 1.0, 2.5)]
    assert iw.fit_exponent(rows) == pytest.approx(0.7, rel=1e-9)
    assert math.isnan(iw.fit_exponent(rows[:1]))


def test_scenario_case_geometry():
    # depth 0.45: the floor at -0.15 - 0.45 = -0.6, the ramp x + z = 0 meets it at x = 0.6; the
    # gauges at k h / 2 from the still shoreline x = 0.15; the slab's top corners T (1, 1) / sqrt 2
    # above its bottom ones; the plate's stroke kept (push_duration = 0.4 / speed)
    c = iw.scenario_case(load("slide_flume.json"), 2.0, 0.1, 0.45, 1.0)
    assert c["walls"]["bed"]["polyline"][1] == pytest.approx([0.6, -0.6])
    assert c["bodies"]["flume"]["polygon"][0] == pytest.approx([0.15, -0.15])
    assert c["parameters"]["push_duration"] == pytest.approx(0.2)
    assert c["bodies"]["slide"]["polygon"][2] == pytest.approx([0.1 / math.sqrt(2)] * 2)
    gauges = sorted(m["x"] for m in c["monitors"].values() if m["type"] == "wave_gauge")
    assert gauges == pytest.approx([0.15 + 0.225 * k for k in range(2, 9)])
    assert c["monitors"]["impact"]["x_max"] == pytest.approx(0.6)
    assert c["media"]["gravel"]["law"] == 1   # elastic_plastic


def test_column_threshold_criteria():
    # the distance from a fit or a band (0 inside it), and the three criteria of a result
    assert cr.within_fit(1.2, 1.2, 1.2) == 0.0
    assert cr.within_fit(1.02, 1.2, 1.2) == pytest.approx(-0.15)
    assert cr.within_fit(2.7, 2.4, 3.0) == 0.0 and cr.within_fit(3.3, 2.4, 3.0) == pytest.approx(0.1)
    r = cr.Result(None, 0.01, "", "", aspect=1.0, runout_thr=1.05, height_thr=0.86, speed_p99=5e-4)
    assert cr.criteria(r) == (True, True, True)
    r.runout_thr, r.speed_p99 = 1.0, 2e-3
    assert cr.criteria(r) == (False, True, False)
    case = cr.with_threshold_monitors(load("column_collapse.json"), 0.02)
    assert case["monitors"]["deposit"]["threshold"] == 0.02 and case["monitors"]["speed_p99"]["quantile"] == 0.99


def test_column_thresholds_in_metres_or_spacings():
    # "0.02": 0.02 m at every spacing; "1.5dx": 1.5 spacings at each; one runout monitor per
    # threshold, the criterion's first; anything else refused, naming the option
    assert cr.parse_threshold("0.02").at(0.005) == 0.02
    assert cr.parse_threshold("1.5dx").at(0.005) == pytest.approx(0.0075)
    assert str(cr.parse_threshold("2dx")) == "2 dx"
    for bad in ("", "dx", "-1dx", "0", "2 mm", "nan"):
        with pytest.raises(cr.mt.ToolError, match="--threshold"):
            cr.parse_threshold(bad)
    case = cr.with_threshold_monitors(load("column_collapse.json"), [0.015, 0.02])
    mons = case["monitors"]
    assert mons["deposit"]["threshold"] == 0.015 and mons[cr.deposit_monitor(1)]["threshold"] == 0.02


def test_flank_angle_of_a_lattice_heap():
    # the tops of a 30-degree heap on a lattice of dx = 0.005: within 1.5 degrees (the lattice's
    # staircase), both sides
    dx = 0.005
    pts = [((i + 0.5) * dx, (k + 0.5) * dx) for i in range(-60, 60) for k in range(60)]
    pts = [(x, z) for x, z in pts if z <= (0.3 - abs(x)) * math.tan(math.radians(30))]
    x, z = np.array(pts).T
    assert gh.flank_angle(x, z, dx) == pytest.approx(30.0, abs=1.5)


def test_heap_state_of_a_lattice_heap():
    # the 30-degree lattice heap by every variant of the measure (--diagnose): within 1.5 degrees but
    # the 2 dx columns (their tops are a staircase of two sites: 2 degrees); its height and toe
    dx = 0.005
    pts = [((i + 0.5) * dx, (k + 0.5) * dx) for i in range(-60, 60) for k in range(60)]
    pts = [(x, z) for x, z in pts if z <= (0.3 - abs(x)) * math.tan(math.radians(30))]
    x, z = np.array(pts).T
    speed = np.where(z > 0.1, 2e-3, 0.0)
    st = gh.heap_state(x, z, speed, dx)
    for (label, width, _, _), angle in zip(gh.ANGLE_VARIANTS, st["angles"]):
        assert angle == pytest.approx(30.0, abs=2.0 if width == 2 else 1.5), label
    assert st["height"] == pytest.approx(z.max())
    assert st["toe"] == pytest.approx(0.3 - dx / 2, abs=dx)
    assert st["moving"] == pytest.approx(np.mean(z > 0.1))


def test_reproduce_command_drops_where_things_go():
    # --mixsph, --doc and --out (with their values, in either form) do not change the numbers: left out
    import mixsph_tools as mt
    cmd = mt.reproduce_command("tools/x.py", ["--dx", "0.01", "--mixsph", "/a/b/mixsph", "--doc=d.md", "--out", "o", "--check"])
    assert cmd == "PYTHONPATH=$PWD .venv/bin/python tools/x.py --dx 0.01 --check"


def test_deposit_motion_tells_creep_from_ringing(tmp_path):
    # two grains, snapshots every 5 ms over 0.2 s: grain 1 creeps at 2 mm/s along x, grain 2
    # oscillates in place (amplitude 1e-5 m, period 0.01 s, so it is back at its place every
    # 5 ms while its speed is 2 pi 1e-5 / 0.01 = 6.3 mm/s at the samples). With the quantile 1
    # (the largest): the speed is the ringing grain's, the drift over every window the creeping
    # one's, and the ringing (speed less the net motion over 5 ms) the ringing grain's.
    import deposit_motion as dm
    dx = 0.01
    with open(tmp_path / "summary.json", "w") as f:
        json.dump({"numerics": {"dx": dx}}, f)
    for k in range(41):
        t = 0.005 * k
        x1, x2 = 0.1 + 2e-3 * t, 0.2 + 1e-5 * math.sin(2 * math.pi * t / 0.01)
        v2 = 2 * math.pi * 1e-5 / 0.01 * math.cos(2 * math.pi * t / 0.01)
        with open(tmp_path / f"snap_{k:04d}.csv", "w") as f:
            f.write(f"# t = {t:.9g} s\nid,x,z,vx,vz,rho,p,mu,medium,state\n")
            f.write(f"0,{x1!r},0.005,0.002,0,1700,0,0,0,0\n1,{x2!r},0.005,{v2!r},0,1700,0,0,0,0\n")
            f.write("2,0,-0.005,0,0,1700,0,0,0,2\n")   # a wall particle: not a grain
    m = dm.motion(str(tmp_path), 0, None, [0.005, 0.05, 0.2], 1.0)
    assert m["n"] == 2 and m["t"] == pytest.approx(0.2)
    assert m["speed"] == pytest.approx(2 * math.pi * 1e-3, rel=1e-6)   # the ringing grain's
    assert m["drift"] == pytest.approx([2e-3] * 3, rel=1e-3)           # the creeping grain's
    assert m["ringing"] == pytest.approx(2 * math.pi * 1e-3, rel=1e-3)
    assert m["largest"] / dx == pytest.approx(2e-3 * 0.2 / dx, rel=1e-3)
