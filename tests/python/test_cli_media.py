"""The law each medium runs, as `mixsph run` reports it (summary.json "media", docs/output.md): a
granular medium that names no law runs the paper's law when it gives mu_thr, else the
elastic-plastic law (docs/cases.md, "Which law a granular medium runs when it names none")."""
import json
import os
import subprocess

from tool_helpers import ROOT, built


def run_column(tmp_path, edit_sand):
    case = json.load(open(os.path.join(ROOT, "cases", "column_collapse.json")))
    edit_sand(case["media"]["sand"])
    path = tmp_path / "case.json"
    path.write_text(json.dumps(case))
    out = tmp_path / "out"
    run = subprocess.run([built("mixsph"), "run", str(path), "--out", str(out), "--no-csv",
                          "--set", "numerics.t_end=0.002"], capture_output=True, text=True, timeout=120)
    return run, out


def test_bundled_column_runs_the_paper_law(tmp_path):
    run, out = run_column(tmp_path, lambda sand: None)
    assert run.returncode == 0, run.stderr
    assert json.loads((out / "summary.json").read_text())["media"] == {"sand": {"law": "paper"}}
    assert "sand (law paper)" in run.stdout


def test_medium_with_only_material_keys_runs_elastic_plastic(tmp_path):
    def plain(sand):  # rho, K, porosity, phi: what a new user knows
        for key in ("mu_thr", "mu0", "tension_cutoff"):
            sand.pop(key, None)
    run, out = run_column(tmp_path, plain)
    assert run.returncode == 0, run.stderr
    assert json.loads((out / "summary.json").read_text())["media"] == {"sand": {"law": "elastic_plastic"}}


def test_paper_key_without_mu_thr_is_refused_by_name(tmp_path):
    run, _ = run_column(tmp_path, lambda sand: sand.pop("mu_thr"))
    assert run.returncode != 0
    assert "a key of the paper law" in run.stderr and "runs the elastic_plastic law" in run.stderr
