"""tools/erosive_dambreak.py: the two interface measures on snapshots and profiles written by hand
in the formats of cli/main.c and lib/src/io/monitors.c, and the campaign's options on short, coarse
runs of mixsph."""

import math
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import erosive_dambreak as ed  # noqa: E402
import mixsph_tools as mt  # noqa: E402

DX = 0.01
WATER, SEDIMENT = 0, 1


def write_snapshot(folder, t, rows):
    """snap_0000.csv with rows (x, z, medium, state)."""
    path = os.path.join(folder, "snap_0000.csv")
    with open(path, "w") as f:
        f.write(f"# t = {t:.9g} s\n" + ",".join(mt.SNAP_COLUMNS) + "\n")
        for k, (x, z, medium, state) in enumerate(rows):
            f.write(f"{k},{x:.9g},{z:.9g},0,0,1000,0,0,{medium},{state}\n")
    return path


def layered_tank(bed_top, extra=()):
    """A lattice of spacing DX on 0 <= x <= 0.5: sediment below bed_top, water above up to 0.2 m,
    a floor of wall particles (medium 0, state wall) below z = 0, plus extra rows."""
    rows = []
    for i in range(50):
        x = (i + 0.5) * DX
        for k in range(3):
            rows.append((x, -(k + 0.5) * DX, 0, mt.STATE_WALL))
        for j in range(20):
            z = (j + 0.5) * DX
            rows.append((x, z, SEDIMENT if z < bed_top else WATER, mt.STATE_MOBILE))
    return rows + list(extra)


def test_fraction_interface_of_a_flat_bed_is_the_bed_top(tmp_path):
    # reference: sediment rows at z = 0.005 ... 0.065, water from 0.075: with a symmetric kernel on
    # a regular lattice the sediment fraction is 1/2 exactly midway, at z = 0.07 m; tolerance
    # DX/20 (the linear interpolation between samples DX/8 apart)
    write_snapshot(tmp_path, 0.5, layered_tank(0.07))
    prof = ed.fraction_interface(str(tmp_path), 0.5, DX, SEDIMENT)
    assert prof is not None and len(prof.x) == 50
    inner = (prof.x > 2.6 * DX) & (prof.x < 0.5 - 2.6 * DX)   # away from the lattice's open ends
    assert np.all(np.abs(prof.z[inner] - 0.07) < DX / 20), prof.z[inner]


def test_lifted_grains_move_the_top_particle_but_not_the_fraction_interface(tmp_path):
    # one grain lifted 0.05 m above the bed at x = 0.105: the top-particle profile of that bin
    # jumps to it, the 0.5 iso-line stays at the bed (within DX/20 as above)
    lifted = [(0.105, 0.125, SEDIMENT, mt.STATE_MOBILE)]
    write_snapshot(tmp_path, 0.5, layered_tank(0.07, lifted))
    prof = ed.fraction_interface(str(tmp_path), 0.5, DX, SEDIMENT)
    k = int(np.argmin(np.abs(prof.x - 0.105)))
    assert abs(prof.z[k] - 0.07) < DX / 20
    flat = mt.Profile("", "interface", 0.5, 0.5, prof.x, np.full(len(prof.x), 0.07))
    top = flat.z.copy()
    top[k] = 0.125 + DX / 2   # what the profile monitor reports: highest centre + dx/2
    err_top, n_top = ed.interface_error(mt.Profile("", "interface", 0.5, 0.5, prof.x, top), flat)
    err_frac, _ = ed.interface_error(prof, flat)
    assert n_top == 25                         # bins with centre x <= 0.25 m
    assert abs(err_top - (0.13 - 0.07) / 0.07 * 100 / 25) < 1e-9   # one bin off by 86 %
    assert err_frac < 0.1


def test_fraction_interface_needs_the_snapshot_at_that_time(tmp_path):
    write_snapshot(tmp_path, 0.45, layered_tank(0.07))
    assert ed.fraction_interface(str(tmp_path), 0.5, DX, SEDIMENT) is None
    assert ed.fraction_interface(str(tmp_path / "missing"), 0.5, DX, SEDIMENT) is None


def test_interface_error_skips_empty_and_far_bins():
    x = np.array([0.005, 0.015, 0.025, 0.3])
    ref = mt.Profile("", "interface", 0.5, 0.5, x, np.array([0.1, 0.1, math.nan, 0.1]))
    run = mt.Profile("", "interface", 0.5, 0.5, x, np.array([0.11, math.nan, 0.2, 0.5]))
    err, n = ed.interface_error(run, ref)
    assert n == 1 and abs(err - 10.0) < 1e-9


def test_savings_by_wall_time_and_by_steps_against_the_reference_run():
    # Reference: Run 2 for Run 6 (the paper's Table 2); saving = 100 (1 - x / x_ref) for the wall
    # time and for the steps (exact arithmetic on these numbers).
    r2 = ed.Result(paper=ed.PAPER[2], outdir="", source="ran", status="ok", wall=100.0, steps=400.0)
    r6 = ed.Result(paper=ed.PAPER[6], outdir="", source="ran", status="ok", wall=50.0, steps=100.0)
    ed.compare([r2, r6], 0.5)
    assert r6.cells["saving_v"] == 50.0 and r6.cells["saving"] == "50"
    assert r6.cells["saving_steps_v"] == 75.0 and r6.cells["saving_steps"] == "75"
    assert r2.cells["saving_steps"] == "n/a"   # Run 2's own reference, Run 4, is not among them
    r6_alone = ed.Result(paper=ed.PAPER[6], outdir="", source="ran", status="ok", wall=50.0, steps=100.0)
    ed.compare([r6_alone], 0.5)
    assert r6_alone.cells["saving_steps"] == "n/a" and math.isnan(r6_alone.cells["saving_steps_v"])


def test_reuse_continues_a_killed_run_from_its_checkpoint(tmp_path):
    # As tools/vajont_validate.py: a run cut off with SIGKILL is continued by --reuse from its
    # checkpoint and ends bit-identical to an uninterrupted one (one thread), its wall time the
    # run's over both pieces. Run 6 at dx 0.02 to t = 0.1 s, cut off after t = 0.03 s.
    import json
    import subprocess
    from tool_helpers import ENV, built, cut_off
    mixsph = built("mixsph")
    tool = [sys.executable, os.path.join(ROOT, "tools", "erosive_dambreak.py"), "--mixsph", mixsph,
            "--runs", "6", "--dx", "0.02", "--t-end", "0.1", "--threads", "1", "--progress", "0",
            "--checkpoint-every", "0.5"]
    cut, whole = tmp_path / "cut", tmp_path / "whole"
    run_dir = cut / "run6_dx0.02"
    carried = cut_off(tool + ["--out", str(cut)], str(run_dir), 0.03)
    r = subprocess.run(tool + ["--out", str(cut), "--reuse"], capture_output=True, text=True, env=ENV, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "run 6: not finished (no summary.json): continuing it from" in r.stdout
    r2 = subprocess.run(tool + ["--out", str(whole)], capture_output=True, text=True, env=ENV, timeout=600)
    assert r2.returncode == 0, r2.stdout + r2.stderr
    with open(run_dir / "summary.json") as f:
        summ = json.load(f)
    assert summ["status"] == "ok" and summ["run_wall_time_s"] > carried > 0
    assert (run_dir / "monitors.csv").read_bytes() == (whole / "run6_dx0.02" / "monitors.csv").read_bytes()
    import csv
    with open(cut / "erosive_table.csv") as f:
        row = next(csv.DictReader(f))
    assert math.isclose(float(row["wall_time_s"]), summ["run_wall_time_s"], rel_tol=1e-5)   # 6 digits in the CSV
    # nothing has left the tank's domain by t = 0.1 s (the wave reaches the left wall at ~0.27 s)
    assert row["lost_particles"] == "0" and summ["outputs"]["lost_particles"]["max"] == 0


BAD_OPTIONS = [
    (["--checkpoint-every", "-1"], "--checkpoint-every must be a number of seconds >= 0"),
    (["--set", "numerics.fixed_bed_speed"], "--set numerics.fixed_bed_speed: expected KEY=VALUE"),
]


def test_bad_options_are_refused_before_any_run(tmp_path):
    import subprocess
    for k, (opts, message) in enumerate(BAD_OPTIONS):
        for tool in ("erosive_dambreak.py", "vajont_validate.py"):
            out = tmp_path / f"{k}_{tool}"
            r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", tool)] + opts + ["--out", str(out)],
                               capture_output=True, text=True, timeout=120)
            assert r.returncode == 2 and message in r.stderr, r.stderr
            assert not out.exists()


def test_set_reaches_every_run_and_its_stamp(tmp_path):
    # --set passes an override to every run (after the run's own) and is part of the run's
    # settings: a folder run without it is not reused for a sweep with it. Run 6, dx 0.02, 0.01 s.
    import json
    import subprocess
    from tool_helpers import ENV, built
    mixsph = built("mixsph")
    tool = [sys.executable, os.path.join(ROOT, "tools", "erosive_dambreak.py"), "--mixsph", mixsph, "--runs", "6",
            "--dx", "0.02", "--t-end", "0.01", "--threads", "1", "--progress", "0", "--out", str(tmp_path)]
    r = subprocess.run(tool, capture_output=True, text=True, env=ENV, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    r = subprocess.run(tool + ["--reuse", "--set", "numerics.fixed_bed_speed=0.0125"], capture_output=True, text=True,
                       env=ENV, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "records other settings" in r.stdout and "; with numerics.fixed_bed_speed=0.0125" in r.stdout
    with open(tmp_path / "run6_dx0.02" / ed.STAMP) as f:
        stamp = json.load(f)
    assert stamp["sets"] == [["numerics.fixed_bed_speed", 0.0125]]
    assert "numerics.fixed_bed_speed=0.0125" in stamp["command"]
    with open(tmp_path / "run6_dx0.02" / "summary.json") as f:
        assert json.load(f)["status"] == "ok"


def test_a_run_of_an_edited_case_file_is_not_reused(tmp_path):
    # The stamp records the case file's SHA-256, not only its path: after the case file is edited
    # (here its CFL number), --reuse runs again instead of keeping a run of the old content.
    # Run 6, dx 0.02, to t = 0.01 s, on a copy of the case.
    import json
    import shutil
    import subprocess
    from tool_helpers import ENV, built
    mixsph = built("mixsph")
    case = tmp_path / "erosive.json"
    shutil.copy(os.path.join(ROOT, "cases", "erosive_dambreak.json"), case)
    tool = [sys.executable, os.path.join(ROOT, "tools", "erosive_dambreak.py"), "--mixsph", mixsph, "--runs", "6",
            "--dx", "0.02", "--t-end", "0.01", "--threads", "1", "--progress", "0", "--case", str(case),
            "--out", str(tmp_path / "out"), "--reuse"]
    first = subprocess.run(tool, capture_output=True, text=True, env=ENV, timeout=600)
    assert first.returncode == 0, first.stdout + first.stderr
    again = subprocess.run(tool, capture_output=True, text=True, env=ENV, timeout=600)
    assert again.returncode == 0 and "run 6: reused" in again.stdout, again.stdout + again.stderr
    c = json.loads(case.read_text())
    c["numerics"]["cfl"] = 0.09
    case.write_text(json.dumps(c))
    edited = subprocess.run(tool, capture_output=True, text=True, env=ENV, timeout=600)
    assert edited.returncode == 0, edited.stdout + edited.stderr
    assert "records other settings (case_sha256)" in edited.stdout and "run 6: reused" not in edited.stdout
    with open(tmp_path / "out" / "run6_dx0.02" / ed.STAMP) as f:
        assert json.load(f)["case_sha256"] == mt.case_digest(str(case))


def test_sphera_option_passes_spheras_own_settings_to_every_run(tmp_path):
    # --sphera adds the numerical options of SPHERA's own input for the test (the SPHERA_OPTIONS
    # of each script) as --set overrides, recorded in the run's stamp and command; a --set of the
    # user comes after them, so it wins. One very short run of each script at a coarse dx.
    import json
    import subprocess
    import vajont_validate as vv
    from tool_helpers import ENV, built
    mixsph = built("mixsph")
    for mod, args, run_dir in ((ed, ["--runs", "6", "--dx", "0.02"], "run6_dx0.02"),
                               (vv, ["--runs", "1", "--dx", "0.03"], "V1_dx0.03")):
        out = tmp_path / mod.__name__
        tool = [sys.executable, mod.__file__, "--mixsph", mixsph, *args, "--t-end", "0.01", "--threads", "1",
                "--progress", "0", "--out", str(out), "--sphera", "--set", "numerics.pressure_smoothing=0.1"]
        r = subprocess.run(tool, capture_output=True, text=True, env=ENV, timeout=600)
        assert r.returncode == 0, r.stdout + r.stderr
        with open(out / run_dir / mod.STAMP) as f:
            stamp = json.load(f)
        expected = [list(s) for s in mod.SPHERA_OPTIONS] + [["numerics.pressure_smoothing", 0.1]]
        assert stamp["sets"][-3:] == expected
        cmd = " ".join(stamp["command"])
        assert all(f"{k}={mt.num(v)}" in cmd for k, v in mod.SPHERA_OPTIONS)
        assert cmd.index("numerics.pressure_smoothing=0.1") > cmd.index(f"numerics.pressure_smoothing="
                                                                         f"{mt.num(mod.SPHERA_OPTIONS[0][1])}")


def test_twin_reruns_the_reference_with_perturbed_gravity(tmp_path):
    # --twin REL runs each selected reference run again with gravity x (1 + REL) into
    # run<k>_dx<D>_twin and compares it with the run itself (its row's reference is the run).
    # Run 2 at dx 0.02 to t = 0.01 s; a --twin without a reference run or out of range is refused.
    import csv
    import json
    import subprocess
    from tool_helpers import ENV, assert_refused, script_command
    tool = script_command("erosive_dambreak.py", "--dx", "0.02", "--t-end", "0.01", "--threads", "1", "--progress", "0")
    assert_refused(tool, ((["--runs", "6", "--twin", "1e-6"], "--twin: no reference run (2 or 4) among --runs"),
                          (["--runs", "2", "--twin", "0.1"], "--twin REL: a relative change of gravity")),
                   tmp_path / "bad")
    r = subprocess.run(tool + ["--runs", "2", "--twin", "1e-6", "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, env=ENV, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    with open(tmp_path / "out" / "erosive_table.csv") as f:
        rows = list(csv.DictReader(f))
    assert [(row["run"], row["twin"], row["ref_run"]) for row in rows] == [("2", "0", "4"), ("2", "1", "2")]
    assert rows[1]["outdir"].endswith("run2_dx0.02_twin") and rows[1]["status"] == "ok"
    with open(tmp_path / "out" / "run2_dx0.02_twin" / ed.STAMP) as f:
        stamp = json.load(f)
    with open(os.path.join(ROOT, "cases", "erosive_dambreak.json")) as f:
        g = json.load(f)["gravity"]
    assert stamp["sets"] == [["gravity", g * (1 + 1e-6)]]


def test_mixsph_validate_dispatches_to_the_scripts(capsys):
    # mixsph-validate CASE ... (pyproject.toml's console script) is the script of CASE with its
    # options and exit status, its messages naming it "mixsph-validate CASE"; no case or an
    # unknown one: the list of cases and exit status 2.
    import pytest
    from mixsph_tools import validate
    assert validate.main(["--help"]) == 0 and "vajont" in capsys.readouterr().out
    assert validate.main([]) == 2 and validate.main(["nope"]) == 2
    assert "unknown case 'nope'" in capsys.readouterr().err
    for case, message in (("vajont", "--runs: '9' is not a run 1-6"), ("erosive", "--runs: '9' is not a run 1-7")):
        with pytest.raises(SystemExit) as e:
            validate.main([case, "--runs", "9"])
        assert e.value.code == 2 and f"mixsph-validate {case}: error: {message}" in capsys.readouterr().err


def test_every_script_is_installed():
    # pyproject.toml installs tools/'s scripts as top-level modules (py-modules): one left out
    # runs from the source tree (as these tests do) but not through mixsph-validate in .venv.
    import glob
    import tomllib
    from mixsph_tools import validate
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as f:
        listed = set(tomllib.load(f)["tool"]["setuptools"]["py-modules"])
    scripts = {os.path.basename(p)[:-3] for p in glob.glob(os.path.join(ROOT, "tools", "*.py"))}
    assert scripts - listed == set() and listed - scripts == set()
    assert {module for module, _ in validate.CASES.values()} <= listed


def test_against_compares_each_run_with_the_same_run_of_another_folder(tmp_path):
    # --against DIR: each run beside the run of the same number and dx in DIR. Run 6 at dx 0.04 to
    # t = 0.5 s (the comparison time) with the implicit scheme against the explicit one: finite,
    # non-zero interface errors and different step counts; against a copy of its own folder: every
    # error exactly 0 (the same profiles); a run missing there is n/a, not an error.
    import csv
    import shutil
    import subprocess
    from tool_helpers import ENV, script_command
    tool = script_command("erosive_dambreak.py", "--runs", "6", "--dx", "0.04", "--threads", "1", "--progress", "0")
    explicit, implicit = tmp_path / "explicit", tmp_path / "implicit"
    r = subprocess.run(tool + ["--out", str(explicit)], capture_output=True, text=True, env=ENV, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    shutil.copytree(explicit, tmp_path / "copy")
    r = subprocess.run(tool + ["--out", str(implicit), "--set", "numerics.viscosity=1", "--against", str(explicit)],
                       capture_output=True, text=True, env=ENV, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    with open(implicit / "erosive_against.csv") as f:
        (row,) = list(csv.DictReader(f))
    assert row["run"] == "6" and row["status"] == "ok" and row["other_status"] == "ok"
    assert 0.0 < float(row["err_top"]) < 100.0 and 0.0 < float(row["err_frac"]) < 100.0
    assert float(row["steps"]) < float(row["other_steps"])   # the acoustic time step of the implicit scheme
    r = subprocess.run(tool + ["--out", str(explicit), "--reuse", "--against", str(tmp_path / "copy")],
                       capture_output=True, text=True, env=ENV, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    with open(explicit / "erosive_against.csv") as f:
        (row,) = list(csv.DictReader(f))
    assert float(row["err_top"]) == 0.0 and float(row["err_frac"]) == 0.0
    shutil.rmtree(tmp_path / "copy" / "run6_dx0.04")
    r = subprocess.run(tool + ["--out", str(explicit), "--reuse", "--against", str(tmp_path / "copy")],
                       capture_output=True, text=True, env=ENV, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "n/a (here ok, there" in r.stdout
