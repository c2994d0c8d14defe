"""Tests of tools/dss (scenario sweeps of LandslideWave.fmu on Dask, the mu_thr/mu0 optimisation).

The FMU runs are small: the Vajont case at dx = 0.05 m (about 100 particles), shortened stop
times, one OpenMP thread per scenario, a local cluster of 2 workers. The FMU is taken from the
build folder (MIXSPH_BUILD_DIR, default build/); a missing FMU fails these tests, as it does the
FMU's own tests. The unit tests at the top need no FMU.
"""
import json
import os
import pathlib
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from tools.dss import optimise as O  # noqa: E402
from tools.dss import scenarios as S  # noqa: E402
from tools.dss.store import ResultStore  # noqa: E402

BUILD = pathlib.Path(os.environ.get("MIXSPH_BUILD_DIR", ROOT / "build"))
ENV = dict(os.environ, OMP_NUM_THREADS="1", OMP_WAIT_POLICY="passive")
COARSE = ["--set", "dx=0.05"]


def fmu_path():
    p = pathlib.Path(os.environ.get("DSS_FMU", BUILD / "LandslideWave.fmu"))
    if not p.is_file():
        pytest.fail(f"{p} not found: build it with `cmake --build {BUILD} --target fmu`")
    return str(p)


def dss(*args, check=True, timeout=900):
    """Run `python -m tools.dss ARGS` and return the completed process."""
    cmd = [sys.executable, "-m", "tools.dss", *map(str, args)]
    p = subprocess.run(cmd, cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=timeout)
    if check and p.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} exited {p.returncode}\n{p.stdout}\n{p.stderr}")
    return p


def run_id_of(stdout):
    for line in stdout.splitlines():
        if "(run id " in line:
            return line.rsplit("(run id ", 1)[1].rstrip(")")
    raise AssertionError(f"no run id in\n{stdout}")


# ---- unit tests: no FMU ------------------------------------------------------------------------

def test_grid_is_every_combination_and_ids_are_stable():
    axes = {"reservoir_level": S.grid_values("0.40:0.50:3"), "phi": S.grid_values("30,35")}
    sc = S.grid(axes, {"dx": 0.03})
    assert len(sc) == 6
    assert sorted({s["reservoir_level"] for s in sc}) == pytest.approx([0.40, 0.45, 0.50])
    assert all(s["dx"] == 0.03 for s in sc)
    t1, t2 = S.table(sc, 1.6), S.table(list(reversed(sc)), 1.6)
    assert set(t1[S.ID]) == set(t2[S.ID]) and t1[S.ID].is_unique
    # 35 and 35.0 are the same scenario; another stop time is another scenario
    assert S.scenario_id({"phi": 35}, 1.6) == S.scenario_id({"phi": 35.0}, 1.6)
    assert S.scenario_id({"phi": 35}, 1.6) != S.scenario_id({"phi": 35}, 1.2)


def test_latin_hypercube_has_one_sample_per_stratum():
    n = 20
    d = [S.Distribution("reservoir_level", "uniform:0.40:0.50"),
         S.Distribution("phi", "normal:35:3:25:45"),
         S.Distribution("mu0", "loguniform:1e3:1e4")]
    sc = S.sample(d, n, "lhs", seed=3)
    lv = np.array([s["reservoir_level"] for s in sc])
    strata = np.floor((lv - 0.40) / 0.10 * n).astype(int)
    assert sorted(strata) == list(range(n))            # LHS: every 1/n stratum exactly once
    mu0 = np.array([s["mu0"] for s in sc])
    assert sorted(np.floor(np.log(mu0 / 1e3) / np.log(10) * n).astype(int)) == list(range(n))
    assert all(25 <= s["phi"] <= 45 for s in sc)
    assert S.sample(d, n, "lhs", seed=3) == sc          # reproducible from the seed
    r = S.sample(d, n, "random", seed=3)
    assert len(r) == n and all(0.40 <= s["reservoir_level"] <= 0.50 for s in r)
    with pytest.raises(ValueError):
        S.Distribution("phi", "gamma:1:2")


def test_csv_store_drops_a_torn_last_line_and_keeps_the_last_result(tmp_path):
    st = ResultStore(str(tmp_path), "csv")
    st.append({S.ID: "a", "status": "failed", "error": "x", "finished_at": "1"})
    st.append({S.ID: "b", "status": "ok", "max_run_up": 0.7, "finished_at": "2"})
    st.append({S.ID: "a", "status": "ok", "max_run_up": 0.6, "finished_at": "3"})
    with open(st.path, "a") as f:
        f.write("c,ok,0.5")                             # a kill in the middle of a line
    latest = st.latest().set_index(S.ID)
    assert set(latest.index) == {"a", "b"}
    assert latest.loc["a", "status"] == "ok" and latest.loc["a", "max_run_up"] == 0.6
    assert st.done_ids() == {"a", "b"}
    st.append({S.ID: "c", "status": "ok", "max_run_up": 0.5, "finished_at": "4"})
    assert st.done_ids() == {"a", "b", "c"}


def test_optimise_procedure_on_a_model_response(monkeypatch, tmp_path):
    """The procedure's logic on a known response: y converges in mu_thr as 1 - 1/mu_thr (in kPa s),
    and lowering mu0 raises y by 2 % per halving; steps and wall time ~ min(mu0, mu_thr) (the
    viscous time step is ~ 1 / min(mu0, mu_thr))."""
    calls = []

    def fake_run(client, fmu_path, scen, opts, on_result=None, progress=None, run_id=None):
        rows = []
        for s in scen:
            thr, mu0 = s["mu_thr"], s["mu0"]
            y = 1.0 - 1e3 / thr
            if mu0 < thr:
                y *= 1.0 + 0.02 * np.log2(thr / mu0)
            m = min(thr, mu0)
            row = {**s, "status": "ok", "error": "", "max_run_up": y, "steps": 10 * m,
                   "wall_time_s": m / 1e3, "cpu_time_s": m / 1e3, "finished_at": str(len(calls))}
            calls.append((thr, mu0))
            on_result(row)
            rows.append(row)
        return rows

    monkeypatch.setattr(O.runner, "run_scenarios", fake_run)
    monkeypatch.setattr(O.runner, "n_workers", lambda c: 2)
    res = O.optimise(None, "x.fmu", str(tmp_path), "max_run_up", 5.0, {"dx": 0.05},
                     {"stop_time": 1.0}, mu_thr_start=10e3, mu0_factor=0.5, refine=1,
                     progress=False)
    # 1 - 1/m: m = 10, 20, 40 kPa s -> 0.9, 0.95, 0.975: 10 vs 20 differ by 5.3 %, 20 vs 40 by 2.6 %
    assert res["mu_thr_min"] == 20e3
    # each halving adds ~2 %: 2 halvings (5e3) are 4 % <= 5, 3 halvings 6 % > 5; refined between
    assert 2500 < res["mu0_min"] <= 5000 * 1.0001
    assert res["error_pct"] <= 5.0
    assert res["wall_time_saved_pct"] > 70
    # a re-run reuses the stored results: no new runs
    n = len(calls)
    res2 = O.optimise(None, "x.fmu", str(tmp_path), "max_run_up", 5.0, {"dx": 0.05},
                      {"stop_time": 1.0}, mu_thr_start=10e3, mu0_factor=0.5, refine=1,
                      progress=False)
    assert len(calls) == n and res2["mu0_min"] == res["mu0_min"]


# ---- with the FMU ------------------------------------------------------------------------------

def test_optimise_command_finds_a_cheaper_mu0_within_the_error(tmp_path):
    out = tmp_path / "opt"
    err = 6.0
    p = dss("optimise", out, "--fmu", fmu_path(), "--output", "max_run_up", "--error", err,
            *COARSE, "--stop-time", 1.2, "--mu-thr-start", 20e3, "--mu-thr-max", 80e3,
            "--workers", 2, "--quiet")
    res = json.loads((out / "optimise.json").read_text())
    thr, mu0 = res["mu_thr_min"], res["mu0_min"]
    assert mu0 is not None and mu0 < thr, p.stdout
    # check the claim from the stored runs themselves, not from what the command says
    df = ResultStore(str(out)).latest()
    df = df[df["status"] == "ok"]
    ref = df[(df["mu_thr"] == thr) & (df["mu0"] >= O.MU0_OFF)].iloc[0]
    best = df[(df["mu_thr"] == thr) & np.isclose(df["mu0"], mu0, rtol=1e-12)].iloc[0]
    e = abs(best["max_run_up"] - ref["max_run_up"]) / abs(ref["max_run_up"]) * 100
    assert e <= err
    assert best["wall_time_s"] < ref["wall_time_s"]
    assert best["steps"] < ref["steps"]
    # the converged reference: the next mu_thr rung changes the output by at most the error
    nxt = df[(df["mu_thr"] == 2 * thr) & (df["mu0"] >= O.MU0_OFF)].iloc[0]
    assert abs(nxt["max_run_up"] - ref["max_run_up"]) / ref["max_run_up"] * 100 <= err
    assert f"mu0_min = {mu0:g}" in p.stdout


def test_sweep_on_two_workers_gives_the_run_ups_of_the_fmu_run_directly(tmp_path):
    from fmpy import simulate_fmu
    fmu = fmu_path()
    out = tmp_path / "sweep"
    table = tmp_path / "scen.csv"
    pd.DataFrame({"reservoir_level": [0.42, 0.46, 0.46, 0.50],
                  "phi": [35.0, 30.0, 35.0, 35.0]}).to_csv(table, index=False)
    stop, step = 0.8, 0.05
    dss("sweep", out, "--fmu", fmu, "--csv", table, *COARSE, "--stop-time", stop, "--step", step,
        "--workers", 2, "--crest", 760.0)
    df = ResultStore(str(out)).latest()
    assert len(df) == 4 and (df["status"] == "ok").all(), df.get("error")
    # two worker processes did the work and each unzipped the FMU once
    assert df["worker_pid"].nunique() == 2
    assert (df["unzip_count"] == 1).all()
    for rec in df.to_dict(orient="records"):
        start = {"reservoir_level": rec["reservoir_level"], "phi": rec["phi"], "dx": 0.05,
                 "threads": 1}
        r = simulate_fmu(fmu, start_values=start, stop_time=stop, output_interval=step,
                         output=["max_run_up", "time_of_max_run_up", "max_run_up_Z"])
        last = r[-1]
        for k in ("max_run_up", "time_of_max_run_up", "max_run_up_Z"):
            assert rec[k] == pytest.approx(float(last[k]), rel=1e-12, abs=1e-12), k
    # the report
    for f in ("runup_vs_level.png", "exceedance.png", "scenario_table.png", "scenario_table.csv"):
        assert (out / f).stat().st_size > 0
    assert (pd.read_csv(out / "scenario_table.csv")["status"] == "ok").all()


def test_killed_sweep_rerun_completes_only_the_missing_scenarios(tmp_path):
    out = tmp_path / "sweep"
    args = ["sweep", out, "--fmu", fmu_path(), "--grid", "phi=26,30,34,38,42,46", *COARSE,
            "--stop-time", 0.5, "--workers", 2, "--format", "csv", "--no-report", "--quiet"]
    proc = subprocess.Popen([sys.executable, "-m", "tools.dss", *map(str, args)], cwd=ROOT,
                            env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    st = ResultStore(str(out), "csv")
    t0 = time.monotonic()
    while True:
        if os.path.exists(st.path) and len(st.done_ids()) >= 1:
            break
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - t0 < 600, "no scenario finished in 10 min"
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)              # the client and its local cluster
    proc.wait()
    done_before = st.done_ids()
    all_ids = set(pd.read_csv(out / "scenarios.csv", dtype={S.ID: str})[S.ID])
    assert len(all_ids) == 6
    assert 1 <= len(done_before) < 6, "the sweep finished before it was killed: nothing to show"
    rows_before = len(st.read_all())

    p = dss(*args)
    rid = run_id_of(p.stdout)
    allrows = st.read_all()
    new = allrows[allrows["run_id"] == rid]
    assert set(new[S.ID]) == all_ids - done_before   # exactly the missing ones
    assert len(new) == len(all_ids - done_before)
    assert len(allrows) == rows_before + len(new)
    assert st.done_ids() == all_ids
    assert f"{len(done_before)} already done, {6 - len(done_before)} to run" in p.stderr


def test_scenario_with_invalid_parameters_is_recorded_as_failed(tmp_path):
    out = tmp_path / "sweep"
    table = tmp_path / "scen.csv"
    pd.DataFrame({"phi": [35.0, 90.0, 35.0],
                  "case_file": ["vajont_padua.json", "vajont_padua.json", "no_such_case.json"]}
                 ).to_csv(table, index=False)
    p = dss("sweep", out, "--fmu", fmu_path(), "--csv", table, *COARSE, "--stop-time", 0.2,
            "--workers", 2, "--no-report")
    df = ResultStore(str(out)).latest().set_index("phi", drop=False)
    assert len(df) == 3
    ok = df[(df["phi"] == 35.0) & (df["case_file"] == "vajont_padua.json")]
    assert list(ok["status"]) == ["ok"] and np.isfinite(ok["max_run_up"]).all()
    bad_range = df[df["phi"] == 90.0].iloc[0]
    assert bad_range["status"] == "failed" and "phi" in bad_range["error"]
    bad_case = df[df["case_file"] == "no_such_case.json"].iloc[0]
    assert bad_case["status"] == "failed" and bad_case["error"]
    assert "1 ok, 2 failed" in p.stdout


def test_optimise_stops_lowering_mu0_where_the_steps_stop_falling(monkeypatch, tmp_path):
    """Below an acoustic bound (here mu = 2.5 kPa s) the step count no longer falls: mu0_min is the
    last rung that still saved steps, even though lower mu0 would be within the error."""
    def fake_run(client, fmu_path, scen, opts, on_result=None, progress=None, run_id=None):
        rows = []
        for s in scen:
            thr, mu0 = s["mu_thr"], s["mu0"]
            m = max(min(thr, mu0), 2500.0)
            y = 1.0 - 1e3 / thr
            row = {**s, "status": "ok", "error": "", "max_run_up": y, "steps": 10 * m,
                   "wall_time_s": m / 1e3, "cpu_time_s": m / 1e3, "finished_at": "0"}
            on_result(row)
            rows.append(row)
        return rows

    monkeypatch.setattr(O.runner, "run_scenarios", fake_run)
    monkeypatch.setattr(O.runner, "n_workers", lambda c: 1)
    res = O.optimise(None, "x.fmu", str(tmp_path), "max_run_up", 5.0, {}, {"stop_time": 1.0},
                     mu_thr_start=10e3, progress=False)
    assert res["mu_thr_min"] == 20e3
    assert res["mu0_min"] == 2500.0
    assert "steps no longer fall" in res["stop_reason"]
    assert res["steps_saved_pct"] == pytest.approx(100 * (1 - 2500 / 20e3))


def _ancestors(pid):
    out = []
    while pid > 1:
        try:
            with open(f"/proc/{pid}/stat") as f:
                pid = int(f.read().rsplit(")", 1)[1].split()[1])
        except OSError:
            break
        out.append(pid)
    return out


def test_sweep_on_an_existing_cluster_without_the_repository(tmp_path):
    """--scheduler: the scenarios run on the workers of a separately started cluster (a scheduler
    and a worker started in a folder where tools/ is not importable; --upload-code)."""
    dask = pathlib.Path(sys.executable).parent / "dask"
    env = {k: v for k, v in ENV.items() if k != "PYTHONPATH"}
    sched_file = tmp_path / "scheduler.json"
    cwd = tmp_path / "elsewhere"
    cwd.mkdir()
    procs = []
    try:
        procs.append(subprocess.Popen(
            [str(dask), "scheduler", "--host", "127.0.0.1", "--port", "0",
             "--dashboard-address", ":0", "--scheduler-file", str(sched_file)],
            cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            start_new_session=True))
        t0 = time.monotonic()
        while not sched_file.exists():
            assert time.monotonic() - t0 < 120, "the scheduler did not start"
            time.sleep(0.2)
        procs.append(subprocess.Popen(
            [str(dask), "worker", "--scheduler-file", str(sched_file), "--nthreads", "1",
             "--nworkers", "1"],
            cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            start_new_session=True))
        out = tmp_path / "sweep"
        dss("sweep", out, "--fmu", fmu_path(), "--grid", "phi=30,35", *COARSE, "--stop-time", 0.2,
            "--scheduler", sched_file, "--upload-code", "--no-report", "--quiet")
        df = ResultStore(str(out)).latest()
        assert len(df) == 2 and (df["status"] == "ok").all(), df.get("error")
        worker = procs[1].pid
        for pid in df["worker_pid"]:
            assert worker in _ancestors(int(pid)) or int(pid) == worker
    finally:
        for p in reversed(procs):
            try:
                os.killpg(p.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)


def test_bed_friction_is_swept_and_is_a_physical_emulator_input(tmp_path):
    # bed_friction (the bed's Coulomb friction angle, docs/model.md [BF]) varied by a sweep: each
    # run is the FMU's own with that value, the values change the slide, and the emulator takes
    # the column as a physical input
    from fmpy import simulate_fmu
    from tools.dss import emulator as E
    fmu = fmu_path()
    out = tmp_path / "sweep"
    stop = 0.4
    dss("sweep", out, "--fmu", fmu, "--grid", "bed_friction=20,90", *COARSE, "--stop-time", stop, "--step", 0.05,
        "--workers", 1, "--no-report", "--quiet")
    df = ResultStore(str(out)).latest().sort_values("bed_friction")
    assert list(df["bed_friction"]) == [20.0, 90.0] and (df["status"] == "ok").all(), df.get("error")
    for rec in df.to_dict(orient="records"):
        r = simulate_fmu(fmu, start_values={"bed_friction": rec["bed_friction"], "dx": 0.05, "threads": 1},
                         stop_time=stop, output_interval=0.05, output=["landslide_front"])
        assert rec["landslide_front"] == pytest.approx(float(r[-1]["landslide_front"]), rel=1e-12, abs=1e-12)
    assert df["landslide_front"].iloc[0] != df["landslide_front"].iloc[1]
    assert "bed_friction" in E.PHYSICAL
    names, kinds = E.choose_inputs(df)
    assert names == ["bed_friction"], names


def test_the_granular_law_is_swept_by_its_item_name_and_is_a_binary_emulator_input(tmp_path):
    # rheology (an Enumeration of the FMU) given by item names: the scenario table, its ids and
    # the results hold the items' values (0 paper, 1 elastic_plastic), each run is the FMU's own
    # with that value, and the emulator takes the column as a two-level input like saturated
    from fmpy import simulate_fmu
    from tools.dss import emulator as E
    fmu = fmu_path()
    out = tmp_path / "sweep"
    stop = 0.4
    dss("sweep", out, "--fmu", fmu, "--grid", "rheology=paper,elastic_plastic", "--set", "nu=0.3", *COARSE,
        "--stop-time", stop, "--step", 0.05, "--workers", 1, "--no-report", "--quiet")
    df = ResultStore(str(out)).latest().sort_values("rheology")
    assert list(df["rheology"]) == [0, 1] and (df["status"] == "ok").all(), df.get("error")
    for rec in df.to_dict(orient="records"):
        r = simulate_fmu(fmu, start_values={"rheology": rec["rheology"], "nu": 0.3, "dx": 0.05, "threads": 1},
                         stop_time=stop, output_interval=0.05, output=["max_run_up"])
        assert rec["max_run_up"] == pytest.approx(float(r[-1]["max_run_up"]), rel=1e-12, abs=1e-12)
    assert df["max_run_up"].iloc[0] != df["max_run_up"].iloc[1]
    names, kinds = E.choose_inputs(df)
    assert names == ["rheology"] and kinds == ["binary"]
    # an item the FMU does not have: a usage error that lists its items, before any run
    p = dss("sweep", tmp_path / "bad", "--fmu", fmu, "--set", "rheology=bingham", *COARSE, "--stop-time", 0.1,
            check=False)
    assert p.returncode == 2 and "paper (0), elastic_plastic (1)" in p.stderr, p.stderr
