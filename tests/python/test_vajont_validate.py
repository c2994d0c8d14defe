"""tools/vajont_validate.py without running mixsph: the error (13), the reference densities of the
runs, and the analysis of a run folder written by hand (summary.json, monitors.csv, profiles,
snapshots in the formats of cli/main.c and lib/src/io/monitors.c)."""

import json
import math
import os
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import mixsph_tools as mt  # noqa: E402
import vajont_validate as vv  # noqa: E402
from mixsph_tools import campaign  # noqa: E402


def case_json():
    with open(os.path.join(ROOT, "cases", "vajont_padua.json")) as f:
        return json.load(f)


def test_d_eta_matches_full_scale_map():
    # the paper's Table 5: Z = 1211.8 z + 0.3, d_eta = |Z - 863| / 163 * 100 (within 0.1 %)
    for p in vv.PAPER.values():
        Z = 1211.8 * p.run_up + 0.3
        assert abs(Z - p.Z) < 0.2
        assert abs(vv.d_eta(p.run_up) - 100 * abs(Z - 863.0) / 163.0) < 0.1
    assert math.isnan(vv.d_eta(math.nan))


def test_reference_densities():
    c = case_json()
    dry = vv.reference_densities(c, vv.PAPER[1].sets)      # water, slide, slide_wet (dry in V1)
    assert np.allclose(dry, [1000.0, 0.65 * 2650.0, 0.65 * 2650.0])
    wet = vv.reference_densities(c, vv.PAPER[4].sets)      # V4: the part below the level saturated
    assert np.allclose(wet, [1000.0, 0.65 * 2650.0, 0.35 * 1000.0 + 0.65 * 2650.0])


def test_runs_and_ratios():
    def parse_runs(text):
        return campaign.parse_runs(text, "--runs", vv.PAPER, "1,2,4", prefix="V")
    assert parse_runs("all") == [1, 2, 3, 4, 5, 6]
    assert parse_runs("V4,1, 2") == [1, 2, 4]
    with pytest.raises(mt.ToolError, match="'7' is not a run 1-6"):
        parse_runs("7")
    assert vv.PAPER[5].dx_ratio * 0.005 == pytest.approx(6.25e-3)
    assert vv.PAPER[6].dx_ratio * 0.005 == pytest.approx(7.5e-3)


def write_run(d):
    os.makedirs(d)
    outputs = {
        "lost_particles": {"final": 0, "max": 0, "t_max": 0, "min": 0, "t_min": 0},
        "wall_corrections": {"final": 5, "max": 5, "t_max": 1.0, "min": 0, "t_min": 0},
        "run_up": {"final": 0.65, "max": 0.72, "t_max": 1.2, "min": 0.45, "t_min": 0},
        "run_up_Z": {"final": 788.0, "max": 872.8, "t_max": 1.2, "min": 545.6, "t_min": 0},
        "run_up_d_eta": {"final": 5.9, "max": 190, "t_max": 0, "min": 5.9, "t_min": 1.2},
        "landslide_front": {"final": 0.9, "max": 0.9, "t_max": 1.6, "min": 0.65, "t_min": 0},
    }
    summ = {"case": "vajont_padua", "status": "ok", "particles": 3, "wall_particles": 1, "steps": 100,
            "threads": 1, "simulated_time_s": 1.6, "wall_time_s": 12.5, "particle_steps_per_s": 24.0,
            "outputs": outputs}
    with open(os.path.join(d, "summary.json"), "w") as f:
        json.dump(summ, f)
    with open(os.path.join(d, "monitors.csv"), "w") as f:
        f.write("t,step,kinetic_energy,mass,max_speed,run_up\n0,0,0,10.0,0,0.45\n0.8,50,1,10.0,1.2,0.6\n"
                "1.6,100,0.1,10.0,0.3,0.65\n")
    for name, z in (("water_surface", 0.7), ("landslide_surface_above", 0.5), ("landslide_surface_below", 0.6)):
        with open(os.path.join(d, f"profile_{name}_atmax.csv"), "w") as f:
            f.write(f"# profile {name} of x at t = 1.2 s (requested 1.2 s): top of the medium per x bin, "
                    "at the maximum of run_up so far\nx,z_top\n0.5,nan\n0.7," + str(z) + "\n")
    with open(os.path.join(d, "snap_0000.csv"), "w") as f:
        f.write("# t = 0.8 s\nid,x,z,vx,vz,rho,p,mu,medium,state\n"
                "0,0.8,0.5,0.1,0,1010,-20,0.001,0,0\n1,0.5,0.4,0,0,1722.5,-50,5000,1,1\n"
                "2,0.6,0.3,0,0,2072.5,0,5000,2,0\n3,0,0,0,0,1000,0,0,0,2\n")


def test_load_result_and_outputs(tmp_path):
    d = str(tmp_path / "V4_dx0.02")
    write_run(d)
    job = campaign.Job(vv.PAPER[4], 0.02, d, [], {}, source="reused")
    r = vv.load_result(job, vv.reference_densities(case_json(), vv.PAPER[4].sets), None,
                       vv.granular_media(case_json()))
    assert r.ok and r.particles == 3 and r.steps == 100
    assert r.run_up == 0.72 and r.t_run_up == 1.2 and r.Z == 872.8 and r.d_eta == 5.9
    assert r.lost == 0 and r.mass_drift == 0.0 and r.vmax_stop == 1.2
    assert r.drho == pytest.approx(0.01) and r.drho_t == 0.8        # the water particle at 1010
    assert r.tension == 0.5 and r.tension_t == 0.8   # one of the two grains below p = 0 (the water does not count)
    top = vv.landslide_top(r)
    assert np.isnan(top[1][0]) and top[1][1] == 0.6
    rows = vv.rows_of([r])
    assert rows[0][0] == "V4" and rows[0][8] == "0.720" and rows[-1][0] == "exp."
    csv_path, md_path, png_path = (str(tmp_path / n) for n in ("t.csv", "t.md", "p.png"))
    vv.write_csv(csv_path, [r])
    vv.write_md(md_path, [r], ["head"], vv.ordering([r]))
    assert vv.plot(png_path, [r], [4], [1, 2])
    assert os.path.getsize(png_path) > 1000
    with open(csv_path) as f:
        assert f.readline().startswith("run,change,dx_m")


def test_crossed_walls(tmp_path):
    d = str(tmp_path / "run")
    os.makedirs(d)
    bed = np.array([[0.0, 0.28], [0.66, 0.22], [0.72, 0.0], [0.75, 0.0], [1.02, 0.46], [1.81, 0.878]])
    rows = ["0,0.5,0.30,0,0,1000,0,0,0,0",     # above the bed, ahead of the plate: fine
            "1,0.73,-0.01,0,0,1000,0,0,0,0",   # below the basin's floor: crossed the bed
            "2,0.05,0.50,0,0,1722,0,0,1,0",    # behind the plate's face (x < 0.10): crossed the plate
            "3,0.05,0.40,0,0,0,0,0,1,2",       # the plate's wall particles (wall index 1)
            "4,0.05,0.80,0,0,0,0,0,1,2",
            "5,0.73,-0.01,0,0,1000,0,0,0,3",   # lost particles do not count
            # on the opposite slope's line to the CSV's 7 digits (4e-8 m below it as written,
            # 1e-7 m above it in run.h5): within CROSS_TOL, not a crossing (run V4, dx = 0.0075)
            "6,1.235541,0.5740457,0,0,1000,0,0,0,0",
            "7,1.235541,0.5740357,0,0,1000,0,0,0,0"]   # 1e-5 m below it: a crossing
    with open(os.path.join(d, "snap_0000.csv"), "w") as f:
        f.write("# t = 0.5 s\nid,x,z,vx,vz,rho,p,mu,medium,state\n" + "\n".join(rows) + "\n")
    assert vv.crossed_walls(d, bed, 1, 0.1) == 3
    assert vv.crossed_walls(d, bed, None, 0.1) == 2
    assert vv.crossed_walls(str(tmp_path), bed, 1, 0.1) == -1


def test_ordering_verdicts():
    # the paper: V2 - V1 = +15 mm (holds), V4 - V1 = -17 mm (holds); a difference below
    # ORDER_TOL = 1 mm is no ordering either way
    def result(run, z):
        r = vv.Result(vv.PAPER[run], 0.01, "", "reused")
        r.status, r.run_up = "ok", z
        return r

    checks = vv.ordering([result(1, 0.712), result(2, 0.727), result(4, 0.695)])
    assert [c[1] for c in checks] == [True, True]
    checks = vv.ordering([result(1, 0.712), result(2, 0.700), result(4, 0.720)])
    assert [c[1] for c in checks] == [False, False]
    checks = vv.ordering([result(1, 0.712), result(2, 0.7125), result(4, 0.7117)])
    assert [c[1] for c in checks] == [None, None]
    assert "undecided" in vv.verdict_text(None) and vv.verdict_text(False) == "does NOT hold"
    assert vv.ordering([result(1, 0.712)]) == []
    # with a V1 twin (--twin), a difference no larger than |twin - V1| decides nothing: here the
    # floor is 4 mm, V2 - V1 = +15 mm holds, V4 - V1 = -3 mm is undecided
    twin = result(1, 0.716)
    twin.paper = vv.dataclasses.replace(vv.PAPER[1], twin=True)
    assert vv.twin_floor([result(1, 0.712), twin]) == pytest.approx(0.004)
    checks = vv.ordering([result(1, 0.712), result(2, 0.727), result(4, 0.709), twin])
    assert [c[1] for c in checks] == [True, None]
    assert "twin floor 4.0 mm" in checks[1][2]
    assert math.isnan(vv.twin_floor([result(1, 0.712)]))


def test_criterion_check():
    # issue 59's criterion 6: V1 within 10 % d_eta (13.45 mm of run-up), V2 above V1, V4 below V1;
    # with --known-band LO HI it passes only while the criterion fails and V1's d_eta is in the band
    def result(run, z):
        r = vv.Result(vv.PAPER[run], 0.01, "", "reused")
        r.status, r.run_up, r.d_eta = "ok", z, vv.d_eta(z)
        return r

    met = [result(1, 0.705), result(2, 0.720), result(4, 0.690)]            # d_eta 5.2 %, both orderings
    assert vv.criterion_check(met, 10.0, None)[0]
    assert not vv.criterion_check(met, 10.0, (40.0, 55.0))[0]                 # met: promote the test
    low = [result(1, 0.648), result(2, 0.6675), result(4, 0.6523)]          # 12-07: d_eta 47.6 %, V4 above V1
    assert not vv.criterion_check(low, 10.0, None)[0]
    passed, message = vv.criterion_check(low, 10.0, (40.0, 55.0))
    assert passed and "47.6 %" in message
    assert not vv.criterion_check(low, 10.0, (50.0, 60.0))[0]                 # outside today's band
    reversed_v4 = [result(1, 0.705), result(2, 0.720), result(4, 0.710)]    # V1 close, V4 above it
    assert not vv.criterion_check(reversed_v4, 10.0, None)[0]
    passed, message = vv.criterion_check(low[:2], 10.0, None)
    assert not passed and "V4" in message


def test_set_reaches_every_run(tmp_path):
    # --set KEY=VALUE goes to every run after the run's own overrides, is recorded in the run's
    # stamp (so --reuse tells the runs apart) and named in the table's header; a malformed one is
    # refused before anything runs (exit 2). Runs build/mixsph for 0.01 s of V1 and V4 at dx 0.03.
    import subprocess
    from tool_helpers import built
    mixsph = built("mixsph")
    tool = [sys.executable, os.path.join(ROOT, "tools", "vajont_validate.py"), "--mixsph", mixsph,
            "--runs", "1,4", "--dx", "0.03", "--t-end", "0.01", "--threads", "1", "--progress", "0",
            "--out", str(tmp_path)]
    r = subprocess.run(tool + ["--set", "parameters.tension_cutoff=1"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "with parameters.tension_cutoff=1" in r.stdout
    for run, own in ((1, []), (4, [["parameters.saturated", 1.0]])):
        with open(tmp_path / f"V{run}_dx0.03" / "vajont_run.json") as f:
            stamp = json.load(f)
        assert stamp["sets"] == own + [["parameters.tension_cutoff", 1.0]]
        i = stamp["command"].index("parameters.tension_cutoff=1")
        assert stamp["command"][i - 1] == "--set"
    bad = subprocess.run(tool + ["--set", "parameters.tension_cutoff"], capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2
    assert "--set parameters.tension_cutoff: expected KEY=VALUE" in bad.stderr


def test_reuse_continues_a_killed_run_from_its_checkpoint(tmp_path):
    # A validation run cut off (the script and mixsph killed with SIGKILL, as at the end of a
    # session) is continued by --reuse from the checkpoint it left, not run again: the result is
    # bit-identical to an uninterrupted run (one thread: monitors.csv equal byte for byte, as the
    # CLI's restart guarantees), and the elapsed time is the run's over both pieces. V1 at dx 0.03
    # to t = 0.3 s (seconds), checkpoints every 0.5 s of wall time, cut off after t = 0.1 s.
    import subprocess
    from tool_helpers import ENV, built, cut_off
    mixsph = built("mixsph")
    tool = [sys.executable, os.path.join(ROOT, "tools", "vajont_validate.py"), "--mixsph", mixsph,
            "--runs", "1", "--dx", "0.03", "--t-end", "0.3", "--threads", "1", "--progress", "0",
            "--checkpoint-every", "0.5"]
    cut, whole = tmp_path / "cut", tmp_path / "whole"
    run_dir = cut / "V1_dx0.03"
    carried = cut_off(tool + ["--out", str(cut)], str(run_dir), 0.1)
    assert carried > 0

    r = subprocess.run(tool + ["--out", str(cut), "--reuse"], capture_output=True, text=True, env=ENV, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "V1: not finished (no summary.json): continuing it from" in r.stdout
    r2 = subprocess.run(tool + ["--out", str(whole)], capture_output=True, text=True, env=ENV, timeout=600)
    assert r2.returncode == 0, r2.stdout + r2.stderr
    with open(run_dir / "summary.json") as f:
        summ = json.load(f)
    assert summ["status"] == "ok" and summ["restarted_from"].endswith("checkpoint.h5")
    assert summ["run_wall_time_s"] > carried and summ["wall_time_s"] > 0
    assert (run_dir / "monitors.csv").read_bytes() == (whole / "V1_dx0.03" / "monitors.csv").read_bytes()
    # the table's elapsed time is the whole run's
    res = vv.load_result(campaign.Job(vv.PAPER[1], 0.03, str(run_dir), [], {}, source="ran"))
    assert res.wall == summ["run_wall_time_s"]
    # a third call reuses the finished run
    r3 = subprocess.run(tool + ["--out", str(cut), "--reuse"], capture_output=True, text=True, env=ENV, timeout=600)
    assert r3.returncode == 0 and "V1: reused" in r3.stdout


def test_run_wall_time_of_summaries():
    # one piece: its wall time; continued: the run's over all pieces; continued from a checkpoint
    # that did not record it (an older build): unknown, not the last piece's
    assert mt.run_wall_time({"wall_time_s": 12.0}) == 12.0
    assert mt.run_wall_time({"wall_time_s": 12.0, "run_wall_time_s": 11.5}) == 11.5
    summ = {"wall_time_s": 12.0, "run_wall_time_s": math.nan, "restarted_from": "c.h5", "particles": 10, "steps": 5}
    assert math.isnan(mt.run_wall_time(summ)) and math.isnan(mt.run_particle_steps_per_s(summ))
    summ["run_wall_time_s"] = 25.0
    assert mt.run_particle_steps_per_s(summ) == 2.0


def test_twin_reruns_v1_with_perturbed_gravity(tmp_path):
    # --twin REL runs V1 again with gravity x (1 + REL) into V1_dx<D>_twin (row "V1 twin", CSV
    # column twin = 1); refused (exit 2, nothing created) out of range or without V1 among --runs.
    # Runs build/mixsph for 0.01 s of V1 at dx 0.03, twice.
    import csv
    import subprocess
    from tool_helpers import assert_refused, script_command
    tool = script_command("vajont_validate.py", "--dx", "0.03", "--t-end", "0.01", "--threads", "1", "--progress", "0")
    assert_refused(tool, ((["--runs", "2", "--twin", "1e-6"], "--twin: V1, the run it repeats, is not among --runs"),
                          (["--runs", "1", "--twin", "0.1"], "--twin REL: a relative change of gravity")),
                   tmp_path / "bad")
    out = tmp_path / "out"
    r = subprocess.run(tool + ["--runs", "1", "--twin", "1e-6", "--out", str(out)], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "V1 twin: max run-up" in r.stdout
    with open(out / "vajont_table.csv") as f:
        rows = list(csv.DictReader(f))
    assert [(row["run"], row["twin"], row["status"]) for row in rows] == [("V1", "0", "ok"), ("V1", "1", "ok")]
    assert rows[1]["outdir"].endswith("V1_dx0.03_twin")
    with open(out / "V1_dx0.03_twin" / vv.STAMP) as f:
        stamp = json.load(f)
    assert stamp["sets"] == [["gravity", case_json()["gravity"] * (1 + 1e-6)]]


def test_convergence_report(tmp_path):
    # tools/vajont_convergence.py on hand-written V1 folders: the finest spacing is the reference,
    # 1 % of the error (13) is 1.345 mm of lab run-up, and the cheapest spacing within the
    # tolerance is picked (0.0035 m off the finest = 2.6 % d_eta: outside 2 %, inside 3 %)
    import vajont_convergence as vc
    for dx, z in ((0.02, 0.6925), (0.01, 0.7100), (0.005, 0.7135)):
        d = str(tmp_path / f"dx{dx:g}" / f"V1_dx{dx:g}")
        write_run(d)
        with open(os.path.join(d, "summary.json")) as f:
            s = json.load(f)
        s["outputs"]["run_up"]["max"] = z
        with open(os.path.join(d, "summary.json"), "w") as f:
            json.dump(s, f)
    assert vc.MM_PER_D_ETA == pytest.approx(1.345)
    rows, finest = vc.collect(str(tmp_path), [0.02, 0.01, 0.005])
    assert finest["dx"] == 0.005
    assert rows[1]["diff_mm"] == pytest.approx(-3.5) and rows[1]["diff_d_eta"] == pytest.approx(3.5 / 1.345)
    assert vc.cheapest_within(rows, finest, 2.0) is None
    assert vc.cheapest_within(rows, finest, 3.0)["dx"] == 0.01
    vc.run(["--spacings", "0.02,0.01,0.005", "--out", str(tmp_path), "--only-report", "--tolerance", "3"])
    with open(tmp_path / "convergence.md") as f:
        text = f.read()
    assert "cheapest spacing within 3 % d_eta" in text and "dx = 0.01 m" in text
    assert os.path.getsize(tmp_path / "convergence.png") > 1000
