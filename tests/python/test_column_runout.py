"""tools/column_runout.py: the experimental laws it compares with, the geometry it gives each
aspect ratio, its refusals, and one tiny run through build/mixsph."""

import csv
import os
import subprocess

import pytest

from tool_helpers import ENV, ROOT, assert_refused, script_command
import column_runout as cr  # noqa: E402  (tools/ is on the path through tool_helpers)

COLUMN = os.path.join(ROOT, "cases", "column_collapse.json")


def test_lube_laws():
    # Lube et al. (2005): 1.2 a below 1.8, 1.9 a^(2/3) above 2.8, both fits in between; the final
    # height a below 1.15, a^(2/5) above.
    assert cr.lube_runout(1.0) == (1.2, 1.2)
    assert cr.lube_runout(8.0) == pytest.approx((7.6, 7.6))      # 1.9 * 8^(2/3) = 1.9 * 4
    lo, hi = cr.lube_runout(2.0)
    assert (lo, hi) == pytest.approx((2.4, 1.9 * 2 ** (2 / 3)))   # 1.2 a = 2.4 < 3.016: sorted
    assert cr.lube_height(0.5) == 0.5
    assert cr.lube_height(32.0) == pytest.approx(4.0)              # 32^(2/5)


def test_geometry_holds_the_deposit():
    # a = 2, L0 = 0.2: H0 = 0.4, the floor reaches L0 (2 + 2 x 3.016) = 1.61 m, past the longest
    # run-out of the laws (L0 (1 + 3.016) = 0.80 m) with room to spare.
    g = cr.geometry(2.0, 0.2)
    assert g["parameters.H0"] == pytest.approx(0.4)
    assert g["parameters.wall_top"] > g["parameters.H0"] and g["parameters.z_max"] > g["parameters.wall_top"]
    assert g["parameters.floor_end"] == pytest.approx(0.2 * (2 + 2 * 1.9 * 2 ** (2 / 3)))
    assert g["parameters.x_max"] > g["parameters.floor_end"]


def test_refused(tmp_path):
    tool = script_command("column_runout.py", "--case", COLUMN)
    assert_refused(tool, [
        (["--aspects", "0.5,x"], "--aspects 0.5,x: expected numbers"),
        (["--aspects", "0.5,0.5"], "distinct aspect ratios"),
        (["--aspects", "4", "--t-end", "0.5"], "shorter than 5 sqrt(H0/g) of a = 4"),
    ], tmp_path / "out")


def test_tiny_run(tmp_path):
    # a = 0.5 at dx = 0.04 (a few grains): the run reaches 5 T = 5 sqrt(0.1 / 9.81) = 0.505 s and
    # the table has its row; the numbers at this spacing mean nothing and are not asserted.
    out = tmp_path / "runout"
    cmd = script_command("column_runout.py", "--case", COLUMN, "--dx", "0.04", "--aspects", "0.5", "--t-end", "0.6",
                         "--threads", "1", "--out", str(out))
    r = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    with open(out / "column_runout.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 1 and rows[0]["a"] == "0.5" and rows[0]["status"] == "ok"
    assert rows[0]["5T s"] == "0.505"
    assert rows[0]["at 5T at rest"] in ("yes", "no")
    assert (out / "column_runout.png").stat().st_size > 0


def test_law_option_runs_the_case_with_that_law(tmp_path):
    # --law elastic_plastic: the run's case is OUT/case_elastic_plastic.json, the column's sand with
    # that law by its number (1), which lets it keep the paper law's keys (mu_thr, mu0) unused.
    # A case with no granular medium is refused.
    import json
    import mixsph_tools as mt
    with open(COLUMN) as f:
        case = json.load(f)
    ep = mt.with_law(case, "elastic_plastic", "column")
    sand = ep["media"]["sand"]
    assert sand["law"] == 1 and sand["mu_thr"] == case["media"]["sand"]["mu_thr"]
    assert "law" not in case["media"]["sand"]   # a copy
    assert mt.with_law(ep, "paper", "column")["media"]["sand"]["law"] == 0
    with open(os.path.join(ROOT, "cases", "dambreak_water.json")) as f:
        water = json.load(f)
    with pytest.raises(mt.ToolError, match="no granular medium"):
        mt.with_law(water, "elastic_plastic", "dambreak")
    out = tmp_path / "runout"
    cmd = script_command("column_runout.py", "--case", COLUMN, "--law", "elastic_plastic", "--dx", "0.04",
                         "--aspects", "0.5", "--t-end", "0.6", "--threads", "1", "--out", str(out))
    r = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    with open(out / "case_elastic_plastic.json") as f:
        assert json.load(f)["media"]["sand"]["law"] == 1
    with open(out / "column_runout.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 1 and rows[0]["status"] == "ok"
