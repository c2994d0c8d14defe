"""tools/step_independence.py: the agreement criterion on results written by hand, the refusals,
and one tiny campaign of the column collapse through build/mixsph."""

import csv
import os
import subprocess

import pytest

from tool_helpers import ENV, ROOT, assert_refused, script_command
import step_independence as si  # noqa: E402  (tools/ is on the path through tool_helpers)

COLUMN = os.path.join(ROOT, "cases", "column_collapse.json")


def test_agreement_against_the_twins_spread():
    # reference twins 1.000 and 1.002 (spread 0.002). A setting whose mean is 0.00025 away with a
    # spread of 0.0005 agrees (0.00025 <= max(0.002, 0.0005)); one 0.0095 away does not.
    m = ("front", "final")
    ref = si.Setting(1.0, values={m: [1.000, 1.002]}, steps=[100, 100], wall=[1.0, 1.0])
    close = si.Setting(0.5, values={m: [1.001, 1.0015]}, steps=[200, 200], wall=[2.0, 2.0])
    far = si.Setting(0.25, values={m: [1.010, 1.011]}, steps=[400, 400], wall=[4.0, 4.0])
    columns, rows = si.table([ref, close, far], [m])
    agrees = [h for h in columns].index(("front:final", "agrees", ">"))
    assert [r[agrees] for r in rows] == ["-", "yes", "NO"]
    diff = columns.index(("front:final", "diff", ">"))
    assert float(rows[1][diff]) == pytest.approx(0.00025, rel=1e-2)


def test_default_measures_follow_the_monitors():
    case = {"media": {"water": {"type": "fluid"}, "sand": {"type": "granular"}},
            "monitors": {"run_up": {"type": "max_elevation", "medium": "water"},
                         "height": {"type": "max_elevation", "medium": "sand"},
                         "front": {"type": "front", "medium": "sand"},
                         "ke": {"type": "kinetic_energy", "medium": "water"}}}
    assert si.default_measures(case) == [("run_up", "max"), ("height", "final"), ("front", "final")]


def test_refused(tmp_path):
    tool = script_command("step_independence.py", "--case", COLUMN)
    assert_refused(tool, [
        (["--factors", "1,2"], "--factors 1,2: distinct numbers in (0, 1]"),
        (["--factors", "a"], "--factors a: expected numbers"),
        (["--twins", "1"], "--twins must be at least 2"),
        (["--measure", "front:mean"], "--measure front:mean: expected OUTPUT:final"),
        (["--twin-rel", "0.01"], "--twin-rel: a relative change of gravity"),
    ], tmp_path / "out")


def test_tiny_campaign(tmp_path):
    # the column at dx = 0.04 to 0.05 s, factors 1 and 0.5, 2 twins: the probe reads the case's
    # cfl (the default 0.1: the case does not set it); halving both coefficients about doubles the
    # steps (criterion (4) sets dt: 2 +- 10 %, the last step and dt's drift aside); twins differ.
    out = tmp_path / "step"
    cmd = script_command("step_independence.py", "--case", COLUMN, "--dx", "0.04", "--t-end", "0.05",
                         "--factors", "1,0.5", "--twins", "2", "--jobs", "2", "--threads", "1", "--out", str(out))
    r = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    md = (out / "step_independence.md").read_text()
    assert "cfl = 0.1 and cfl_visc = 0.05 at factor 1" in md
    with open(out / "step_independence.csv") as f:
        rows = list(csv.DictReader(f))
    assert [row["factor"] for row in rows] == ["1", "0.5"]
    assert all(row["runs ok"] == "2" for row in rows)
    assert float(rows[1]["steps"]) / float(rows[0]["steps"]) == pytest.approx(2.0, rel=0.1)
