"""tools/mixsph_tools/campaign.py, the runner under both validation scripts, with a stand-in for
mixsph (a Python script that writes a summary.json and exits with the status a --set asks for):
runs at once, a bad-input failure stopping the runs not started, --reuse keeping finished runs,
SIGTERM stopping the running mixsph, the tables of tools/mixsph_tools/report.py."""

import json
import os
import stat
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import mixsph_tools as mt  # noqa: E402
from mixsph_tools import campaign  # noqa: E402

FAKE_MIXSPH = """#!{python}
# mixsph run CASE --out DIR --set KEY=VALUE...: exits with --set fake.rc (0: writes a finished run)
import json, os, sys, time
args = sys.argv[1:]
out = args[args.index("--out") + 1]
sets = dict(args[k + 1].split("=", 1) for k, a in enumerate(args) if a == "--set")
rc = int(float(sets.get("fake.rc", "0")))
os.makedirs(out, exist_ok=True)
with open(os.path.join(out, "pid"), "w") as f:
    f.write(str(os.getpid()))
time.sleep(float(sets.get("fake.sleep", "0")))
if rc == 0:
    with open(os.path.join(out, "monitors.csv"), "w") as f:
        f.write("t,step\\n0,0\\n0.1,10\\n")
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump({{"status": "ok", "threads": 1, "simulated_time_s": 0.1, "wall_time_s": 0.5, "steps": 10,
                   "particles": 5, "particle_steps_per_s": 100.0, "outputs": {{}}}}, f)
else:
    print("fake mixsph: failing as asked", file=sys.stderr)
sys.exit(rc)
"""

OPTIONS = campaign.CaseOptions(description="test", runs="all", known=(1, 2, 3), dx=0.1, dx_help="dx", out="x",
                               case="c.json", t_end="0.1 s", set_example="a=1", twin_help="twin", sphera=(),
                               progress=0.0)


def fake_mixsph(tmp_path):
    fake = tmp_path / "mixsph"
    fake.write_text(FAKE_MIXSPH.format(python=sys.executable))
    fake.chmod(fake.stat().st_mode | stat.S_IXUSR)
    return fake


def settings(tmp_path, *more):
    fake = fake_mixsph(tmp_path)
    case = tmp_path / "case.json"
    case.write_text(json.dumps({"gravity": -9.81, "numerics": {"t_end": 0.1}}))
    args = campaign.parse_args("test", OPTIONS, ["--mixsph", str(fake), "--case", str(case), "--out",
                                                  str(tmp_path / "out"), "--threads", "1", *more])
    return campaign.settings(args, "test", OPTIONS, 3)


def jobs_of(s, codes):
    return [campaign.make_job(s, k, f"run {k}", 0.1, f"run{k}", [("fake.rc", rc)], {"run": k, "rc": rc})
            for k, rc in enumerate(codes, start=1)]


def test_a_bad_input_failure_stops_the_runs_not_started(tmp_path, capsys):
    # two at once: runs 1 and 2 start together; run 2 fails with exit status 2 (bad usage or
    # input, which every run would repeat), so run 3 is not started
    s = settings(tmp_path, "--jobs", "2")
    assert s.jobs == 2 and s.threads == 1 and s.t_end == 0.1
    jobs = jobs_of(s, (0, 2, 0))
    failed = campaign.run(s, jobs, "test_run.json", ("run", "rc"), 1e-3)
    assert [j.source for j in jobs] == ["ran", "FAILED", "not run"] and failed == [jobs[1]]
    assert jobs[1].message == "mixsph exited with 2 (bad usage or input)"
    out = capsys.readouterr().out
    assert "run 2: FAILED" in out and "| fake mixsph: failing as asked" in out
    assert "test: not starting the remaining runs (run 3)" in out
    with pytest.raises(mt.ToolError, match="mixsph failed for run 2: mixsph exited with 2") as e:
        campaign.check_failed(failed)
    assert e.value.code == 1
    r1, r3 = (campaign.RunResult(j.paper, j.dx, j.outdir, j.source) for j in (jobs[0], jobs[2]))
    assert campaign.read_run_summary(jobs[0], r1)["status"] == "ok" and r1.ok and r1.steps == 10.0
    assert campaign.read_run_summary(jobs[2], r3) is None and r3.status == "not run"
    assert campaign.status_cell(r1, 0.5, 1e-3) == "ran, t=0.1 s" and campaign.status_cell(r1, 0.1, 1e-3) == "ran"
    with open(os.path.join(jobs[0].outdir, "test_run.json")) as f:
        stamp = json.load(f)
    assert stamp["run"] == 1 and stamp["t_end"] == 0.1 and "fake.rc=0" in stamp["command"]


def test_reuse_keeps_the_finished_runs_and_runs_the_others(tmp_path, capsys):
    # one at a time, the failure not a bad input (exit 3): the later runs still run
    s = settings(tmp_path)
    failed = campaign.run(s, jobs_of(s, (0, 3, 0)), "test_run.json", ("run", "rc"), 1e-3)
    assert len(failed) == 1 and failed[0].message == "mixsph exited with 3 (unstable run)"
    s = settings(tmp_path, "--reuse")
    jobs = jobs_of(s, (0, 0, 0))
    assert campaign.run(s, jobs, "test_run.json", ("run", "rc"), 1e-3) == []
    # run 2's stamp records rc 3, the other settings: it runs again
    assert [j.source for j in jobs] == ["reused", "ran", "reused"]
    assert "run 2: not reused (no summary.json" in capsys.readouterr().out


def test_tables_with_and_without_column_groups(capsys):
    # no groups: no group line; a header's trailing spaces widen its column, unseen; footer rows
    # between rules
    rows, footer = [["1", "0.50"], ["12", "3.25"]], [["exp.", "0.7"]]
    mt.print_table([("", "run", "<"), ("", "z     ", ">")], rows, footer)
    assert capsys.readouterr().out.splitlines() == [
        "run        z", "-" * 12, "1       0.50", "12      3.25", "-" * 12, "exp.     0.7", "-" * 12]
    # a group: its label above its columns, " | " between groups, the column widened to fit it
    mt.print_table([("", "run", "<"), ("height [m]", "z", ">")], rows)
    assert capsys.readouterr().out.splitlines() == [
        "    | height [m]", "run |          z", "-" * 16, "1   |       0.50", "12  |       3.25", "-" * 16]
    assert mt.markdown_table([("", "run", "<")], [["1"], [""]]) == ["| run |", "| --- |", "| 1 |", "|   |"]


def test_sigterm_stops_the_running_mixsph(tmp_path):
    # SIGTERM to a validation script (as a session's end or a batch system sends it) stops its
    # running mixsph and exits with 130, leaving no process behind
    import signal
    import subprocess
    import time
    fake = fake_mixsph(tmp_path)
    out = tmp_path / "out"
    p = subprocess.Popen([sys.executable, os.path.join(ROOT, "tools", "erosive_dambreak.py"), "--mixsph", str(fake),
                          "--runs", "6", "--dx", "0.02", "--progress", "0", "--out", str(out),
                          "--set", "fake.sleep=120"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    pid_file = out / "run6_dx0.02" / "pid"
    deadline = time.monotonic() + 60
    while not (pid_file.exists() and pid_file.read_text()) and time.monotonic() < deadline:
        time.sleep(0.05)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=30)
    assert p.returncode == 130 and "interrupted; stopped run 6" in err
    with pytest.raises(ProcessLookupError):
        os.kill(int(pid_file.read_text()), 0)
