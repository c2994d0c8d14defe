"""tools/flume_3d.py: the 3D flume it builds from a 2D case (no run)."""

import json
import os

import pytest

from tool_helpers import ROOT
import flume_3d  # noqa: E402  (tools/ is on the path through tool_helpers)
from mixsph_tools import readers


def load(name):
    with open(os.path.join(ROOT, "cases", name)) as f:
        return json.load(f)


def test_the_bundled_dam_break_flume_is_the_tools_output():
    # cases/dambreak_flume_3d.json is written by the tool; it must not drift from the 2D case
    assert flume_3d.extrude(load("dambreak_water.json"), 0.02, 4) == load("dambreak_flume_3d.json")


def test_vajont_flume():
    case = load("vajont_padua.json")
    flume = flume_3d.extrude(case, 0.02, 4)
    assert flume["dimensions"] == 3
    for body in flume["bodies"].values():
        assert (body["y_min"], body["y_max"]) == (0.0, pytest.approx(0.08))
    # the side walls on the first fixed wall (the bed), not on the moving plate
    assert flume["walls"]["bed"]["side_walls"] == "mirror"
    assert flume_3d.extrude(case, 0.02, 4, "free-slip")["walls"]["bed"]["side_walls"] == "free-slip"
    assert "side_walls" not in flume["walls"]["plate"]
    # 2D-only monitors left out, the rest kept; the domain widened across y beyond the walls
    assert "water_surface" not in flume["monitors"] and "run_up" in flume["monitors"]
    assert flume["domain"]["y_min"] < -3 * 0.02 and flume["domain"]["y_max"] > 0.08 + 3 * 0.02
    assert "dimensions" not in case  # the 2D case is left alone


def test_refusals():
    with pytest.raises(readers.ToolError, match="not a 2D case"):
        flume_3d.extrude({"name": "x", "dimensions": 3}, 0.02, 4)
    case = load("dambreak_water.json")
    case["walls"]["tank"]["motion"] = "m"
    with pytest.raises(readers.ToolError, match="no fixed polyline wall"):
        flume_3d.extrude(case, 0.02, 4)


def test_lane_fronts_takes_each_lanes_largest_x_of_the_mobile_particles():
    import numpy as np
    # lanes of dx = 0.02: y = 0.01 (lane 0), 0.03 and 0.039 (lane 1), 0.07 (lane 3, beyond: clipped 0.085)
    snap = {"x": np.array([0.20, 0.30, 0.25, 0.90, 0.40, 0.35]),
            "y": np.array([0.01, 0.03, 0.039, 0.03, 0.07, 0.085]),
            "state": np.array([0, 0, 0, 2, 0, 0])}  # the wall particle at x = 0.9 is not water
    fronts = flume_3d.lane_fronts(snap, 0.02, 4)
    assert fronts[0] == 0.20 and fronts[1] == 0.30 and np.isnan(fronts[2]) and fronts[3] == 0.40
