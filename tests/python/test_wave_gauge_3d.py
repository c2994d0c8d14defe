"""A 3D wave gauge reads the water column at its station (x, y), within `window` of x and of y
(docs/cases.md, monitors: wave_gauge). Reference: the pool's surface at t = 0, H = 0.24 m: the
gauge over the pool reads H - still to within one spacing's rounding; the one at the same x over
the dry half of the tank reads nothing (NaN), as a gauge over a dry bed should; a 3D gauge without
y is refused by name."""
import csv
import json
import math
import os
import subprocess

from tool_helpers import ROOT, built


def run_tank(tmp_path, gauges):
    case = json.load(open(os.path.join(ROOT, "cases", "hydrostatic_tank_3d.json")))
    case["walls"]["tank"]["box_max"][1] = 0.24          # a tank twice as wide as the pool
    case["domain"]["y_max"] = 0.34
    case["numerics"]["t_end"] = 0.004
    case["monitors"] = gauges
    path = tmp_path / "case.json"
    path.write_text(json.dumps(case))
    out = tmp_path / "out"
    run = subprocess.run([built("mixsph"), "run", str(path), "--out", str(out), "--no-csv"],
                         capture_output=True, text=True, timeout=120)
    return run, out


def test_gauge_reads_its_own_column(tmp_path):
    still = 0.20
    run, out = run_tank(tmp_path, {
        "wet": {"type": "wave_gauge", "medium": "water", "x": 0.1, "y": 0.06, "still": still},
        "dry": {"type": "wave_gauge", "medium": "water", "x": 0.1, "y": 0.20, "still": still}})
    assert run.returncode == 0, run.stderr
    rows = list(csv.DictReader(open(out / "monitors.csv")))
    first = rows[0]
    # the pool's top layer centre at 0.23 m, its top 0.24 m: eta = 0.24 - still, to 1 mm
    assert abs(float(first["wet"]) - (0.24 - still)) < 1e-3
    assert math.isnan(float(first["dry"]))   # no water within 2 dx of y = 0.20 m


def test_gauge_without_y_is_refused(tmp_path):
    run, _ = run_tank(tmp_path, {"g": {"type": "wave_gauge", "medium": "water", "x": 0.1, "still": 0.2}})
    assert run.returncode != 0
    assert "monitors.g.y: missing" in run.stderr
