"""Tests of the multi-fidelity emulator of tools/dss (multifidelity.py, mfdesign.py,
emulate_mf.py) on analytical stand-ins with known answers: no FMU runs.

The references: the Forrester et al. (2007, Proc. R. Soc. A 463:3251) two-level function pair,
f_hi(x) = (6x - 2)^2 sin(12x - 4), f_lo(x) = 0.5 f_hi(x) + 10 (x - 0.5) - 5, so that
f_hi = 2 f_lo - 20 (x - 0.5) + 10 exactly (rho = 2, a linear discrepancy), with its usual
design (11 low-fidelity runs, 4 high-fidelity ones at 0, 0.4, 0.6, 1); and a ladder
f(x, dx) = g(x) + C(x) dx^p with a known order p and limit g.
"""
import functools
import json
import os
import pathlib
import re
import signal
import subprocess
import sys
import time
import zipfile

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from tools.dss import emulator as E  # noqa: E402
from tools.dss import mfdesign as MD  # noqa: E402
from tools.dss import multifidelity as M  # noqa: E402
from tools.dss import scenarios as S  # noqa: E402
from tools.dss.store import ResultStore  # noqa: E402

ENV = dict(os.environ, OMP_NUM_THREADS="1", OMP_WAIT_POLICY="passive")


def f_hi(x):
    return (6 * x - 2) ** 2 * np.sin(12 * x - 4)


def f_lo(x):
    return 0.5 * f_hi(x) + 10 * (x - 0.5) - 5


@functools.lru_cache(maxsize=1)
def _forrester():
    xl = np.linspace(0, 1, 11)[:, None]
    xh = np.array([0.0, 0.4, 0.6, 1.0])[:, None]
    em = M.MFEmulator(["x"], [(0.0, 1.0)], [2.0, 1.0], [xl, xh],
                      [{"y": f_lo(xl[:, 0])}, {"y": f_hi(xh[:, 0])}])
    em.fit_output("y", restarts=1, seed=0)
    return em, xh


def forrester_emulator():
    """The Forrester pair's emulator (fitted once per session; a copy through its JSON)."""
    em, xh = _forrester()
    return M.MFEmulator.from_json(json.loads(json.dumps(E._jsonable(em.to_json())))), xh


def test_forrester_pair_is_recovered_from_four_high_fidelity_runs():
    em, xh = forrester_emulator()
    m = em.models["y"]
    x = np.linspace(0, 1, 1001)[:, None]
    truth = f_hi(x[:, 0])
    rng = np.ptp(truth)
    mu, sd = em.predict(x, "y", "finest")
    rmse = np.sqrt(np.mean((mu - truth) ** 2)) / rng
    # the known scale factor rho = 2 within 5 %
    assert abs(m.levels[1].rho - 2.0) < 0.1, m.levels[1].rho
    # the high-fidelity function within 2 % of its range (RMSE over 1001 points; measured
    # 0.83 %) and no point off by more than 5 % (measured 3.4 %)
    assert rmse < 0.02, rmse
    assert np.max(np.abs(mu - truth)) / rng < 0.05
    # the 95 % intervals hold at least 90 % of the 1001 points (measured 95.5 %)
    assert np.mean(np.abs(mu - truth) <= M.Z95 * sd) >= 0.90
    # a GP of the four high-fidelity runs alone is at least 10x worse (measured 25 %)
    sf = M.DeltaGP(1).fit(xh, f_hi(xh[:, 0]), 1, 0)
    ms, _ = sf.predict(x)
    assert np.sqrt(np.mean((ms - truth) ** 2)) / rng > 10 * rmse
    # the low level is the low-fidelity function
    ml, _ = em.predict(x, "y", 2.0)
    assert np.sqrt(np.mean((ml - f_lo(x[:, 0])) ** 2)) / np.ptp(f_lo(x[:, 0])) < 0.02


def ladder_g(U):
    return 0.7 + 0.1 * U[:, 0] + 0.03 * np.sin(3 * U[:, 1])


def ladder_c(U):
    return -8.0 * (1 + 0.3 * U[:, 0])


P_TRUE = 1.5
DXS = [0.04, 0.03, 0.02]


def ladder(U, dx):
    return ladder_g(U) + ladder_c(U) * dx ** P_TRUE


def test_observed_order_inverts_the_richardson_ratio():
    dx = (0.04, 0.03, 0.02)
    for p in (0.7, 1.0, 1.5, 2.0, 3.0):
        f = [1.0 - 5 * d ** p for d in dx]
        assert abs(M.observed_order(*f, *dx)[0] - p) < 1e-6
    # oscillatory convergence has no order
    assert np.isnan(M.observed_order(1.0, 1.1, 1.05, *dx)[0])


def test_a_three_level_ladder_gives_its_order_and_its_limit():
    rng = np.random.default_rng(3)
    U1 = rng.random((24, 2))
    X = [U1, U1[:12], U1[:6]]
    em = M.MFEmulator(["a", "b"], [(0, 1), (0, 1)], DXS, X,
                      [{"y": ladder(x, d)} for x, d in zip(X, DXS)])
    m = em.fit_output("y", restarts=1)
    # the order over the box within 0.05 of the true 1.5 (the means are smooth)
    assert abs(m.order["p"] - P_TRUE) < 0.05, m.order
    assert m.order["valid_fraction"] > 0.99
    U = rng.random((500, 2))
    mu, sd = em.predict(U, "y", M.EXTRAPOLATED)
    e = mu - ladder_g(U)
    # the limit within 1 % of the gap between the finest level and the limit (mean 0.023)
    gap = np.mean(np.abs(ladder(U, DXS[-1]) - ladder_g(U)))
    assert np.sqrt(np.mean(e ** 2)) < 0.01 * gap
    # and inside the 95 % intervals at least 95 % of the points
    assert np.mean(np.abs(e) <= M.Z95 * sd) >= 0.95
    # extrapolated to dx = 0.015 (below the ladder) it is the stand-in there, within 1 % of
    # the gap between the finest level and dx = 0.015
    mu15, _ = em.predict(U, "y", 0.015)
    e15 = mu15 - ladder(U, 0.015)
    gap15 = np.mean(np.abs(ladder(U, DXS[-1]) - ladder(U, 0.015)))
    # (its intervals are not asserted: on this noise-free stand-in they hold 82 % of the
    # points, the GP's errors of 1e-4 against sd of 5e-5 there)
    assert np.sqrt(np.mean(e15 ** 2)) < 0.01 * gap15 + np.sqrt(np.mean(e ** 2))
    # the order's term grows the interval: with a wider given order range the sd is larger
    m.estimate_order(order=(1.5, 1.0, 2.5))
    _, sd2 = em.predict(U, "y", M.EXTRAPOLATED)
    assert np.all(sd2 > sd)
    assert m.order["source"] == "given"


def test_save_and_load_give_identical_predictions_and_versions_are_checked(tmp_path):
    em, _ = forrester_emulator()
    em.fmu = {"guid": "{a}"}
    p = tmp_path / "mf.json"
    em.save(str(p))
    em2 = M.load(str(p), check_fmu=False)
    x = np.linspace(0, 1, 50)[:, None]
    for level in ("finest", 2.0):
        assert np.array_equal(em.predict(x, "y", level)[0], em2.predict(x, "y", level)[0])
        assert np.array_equal(em.predict(x, "y", level)[1], em2.predict(x, "y", level)[1])
    doc = json.loads(p.read_text())
    doc["schema_version"] = 99
    (tmp_path / "v99.json").write_text(json.dumps(doc))
    with pytest.raises(M.MFError, match="version 99"):
        M.load(str(tmp_path / "v99.json"), check_fmu=False)


def test_the_kernel_family_is_fitted_saved_and_a_version_1_file_reads_as_ard(tmp_path):
    """'iso' has one length scale per delta GP, 'ard' one per input; each survives its JSON;
    a file of schema version 1 (before the family was saved; its kernels were ARD) loads as ARD
    with the predictions it was saved with."""
    rng = np.random.default_rng(5)
    U1 = rng.random((16, 2))
    X = [U1, U1[:8], U1[:4]]
    Y = [{"y": ladder(x, d)} for x, d in zip(X, DXS)]
    ems = {}
    for fam in M.KERNELS:
        em = M.MFEmulator(["a", "b"], [(0, 1), (0, 1)], DXS, X, Y)
        em.fit_output("y", restarts=0, kernel_family=fam)
        n_ls = [np.size(g.gp.kernel_.k1.k2.length_scale) for g in em.models["y"].levels]
        assert n_ls == ([1, 1, 1] if fam == "iso" else [2, 2, 2]), (fam, n_ls)
        p = tmp_path / f"{fam}.json"
        em.save(str(p))
        em2 = M.load(str(p), check_fmu=False)
        assert em2.models["y"].kernel_family == fam
        U = rng.random((20, 2))
        assert np.array_equal(em.predict(U, "y")[0], em2.predict(U, "y")[0])
        ems[fam] = (em, p, U)
    em, p, U = ems["ard"]
    doc = json.loads(p.read_text())
    doc["schema_version"] = 1
    del doc["outputs"]["y"]["kernel_family"]
    (tmp_path / "v1.json").write_text(json.dumps(doc))
    em1 = M.load(str(tmp_path / "v1.json"), check_fmu=False)
    assert em1.models["y"].kernel_family == "ard"
    assert np.array_equal(em.predict(U, "y")[1], em1.predict(U, "y")[1])
    with pytest.raises(M.MFError, match="kernel family"):
        M.MFEmulator(["a", "b"], [(0, 1), (0, 1)], DXS, X, Y).fit_output("y", kernel_family="rbf")


def _fake_fmu(path, guid):
    """A zip with the repository's modelDescription.xml under another GUID: what
    emulator.fmu_identity reads (no binary needed)."""
    md = (ROOT / "modelDescription.xml").read_text()
    md = re.sub(r'guid="[^"]*"', f'guid="{guid}"', md, count=1)
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("modelDescription.xml", md)
    return str(path)


def test_an_emulator_of_another_fmu_guid_is_refused(tmp_path):
    fmu_a = _fake_fmu(tmp_path / "a.fmu", "{11111111-2222-3333-4444-555555555555}")
    fmu_b = _fake_fmu(tmp_path / "b.fmu", "{99999999-8888-7777-6666-555555555555}")
    em, _ = forrester_emulator()
    em.fmu = E.fmu_identity(fmu_a)
    p = tmp_path / "mf.json"
    em.save(str(p))
    assert M.load(str(p), fmu_a).models["y"].levels[1].rho == em.models["y"].levels[1].rho
    with pytest.raises(E.GuidMismatch):
        M.load(str(p), fmu_b)
    r = subprocess.run([sys.executable, "-m", "tools.dss", "emulate", "mf-predict", str(p),
                        "--set", "x=0.5", "--fmu", fmu_b], cwd=ROOT, env=ENV,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    assert "refused" in r.stderr and "{11111111" in r.stderr and "{99999999" in r.stderr
    r = subprocess.run([sys.executable, "-m", "tools.dss", "emulate", "mf-predict", str(p),
                        "--set", "x=0.5,0.6", "--fmu", fmu_a], cwd=ROOT, env=ENV,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert len(r.stdout.strip().splitlines()) == 3


# ---- the cost-aware design on a stand-in ------------------------------------------------------

STANDIN_DISTS = ["reservoir_level=uniform:0.40:0.52", "phi=uniform:25:40"]
STANDIN_LEVELS = [0.04, 0.03, 0.02]


def standin_cost(dx):
    """CPU seconds of a stand-in run: dx^-4 as the FMU's (particles x steps)."""
    return 1e-6 * dx ** -4


def standin_value(s):
    U = np.array([[(s["reservoir_level"] - 0.40) / 0.12, (s["phi"] - 25.0) / 15.0]])
    return float(ladder(U, s["dx"])[0])


def run_standin_mf_design(out, log, delay, budget):
    """A multi-fidelity design on the ladder stand-in; each evaluated scenario id is appended
    to LOG; after the start every run takes DELAY s of wall time."""
    dists = [S.Distribution(*S.split_assignment(d)) for d in STANDIN_DISTS]
    des = MD.MFDesign(out, dists, {}, 1.6, STANDIN_LEVELS, budget, init=[8, 4, 3], n_workers=4,
                      progress=False, n_candidates=300)

    def evaluate(scen, on_result):
        for s in scen:
            if len(des.state["batches"]) > 1:
                time.sleep(delay)
            with open(log, "a") as f:
                f.write(s[S.ID] + "\n")
                f.flush()
                os.fsync(f.fileno())
            on_result({**s, "status": "ok", "error": "", "max_run_up": standin_value(s),
                       "cpu_time_s": standin_cost(s["dx"]), "wall_time_s": delay,
                       "finished_at": f"{time.time():.6f}"})
    return des, des.run(evaluate)


def test_the_start_is_nested_and_picks_carry_their_levels_below():
    dists = [S.Distribution(*S.split_assignment(d)) for d in STANDIN_DISTS]
    scen = MD.nested_start(dists, {}, STANDIN_LEVELS, [8, 4, 3], 0)
    pts = {dx: {(s["reservoir_level"], s["phi"]) for s in scen if s["dx"] == dx}
           for dx in STANDIN_LEVELS}
    assert [len(pts[d]) for d in STANDIN_LEVELS] == [8, 4, 3]
    assert pts[0.02] <= pts[0.03] <= pts[0.04]
    with pytest.raises(MD.DesignError, match="must not increase"):
        MD.nested_start(dists, {}, STANDIN_LEVELS, [4, 8, 3], 0)


def test_picks_prefer_the_cheap_level_when_its_information_is_as_good():
    """With the levels nearly identical (rho ~ 1, tiny discrepancy), a coarse run tells almost
    as much about the finest level as a fine one, at a fraction of the cost: the picks are
    coarse. With the costs equal, the finest level (which also reduces its own discrepancy's
    variance) is picked."""
    rng = np.random.default_rng(0)
    U1 = rng.random((10, 2))
    X = [U1, U1[:6], U1[:4]]
    em = M.MFEmulator(["a", "b"], [(0, 1), (0, 1)], DXS, X,
                      [{"y": ladder(x, d)} for x, d in zip(X, DXS)])
    m = em.fit_output("y", restarts=0)
    Uc, Ur = rng.random((300, 2)), rng.random((200, 2))
    cheap = MD.pick_batch(m, Uc, Ur, [1.0, 10.0, 100.0], 2)
    assert [li for _, li, _, _ in cheap] == [0, 0]
    equal = MD.pick_batch(m, Uc, Ur, [1.0, 1e-9, 1e-9], 1)
    assert equal[0][1] == 2
    # the batch's cost limit is kept
    assert MD.pick_batch(m, Uc, Ur, [1.0, 10.0, 100.0], 2, max_cost=0.5) == []


def test_a_killed_mf_design_continues_without_repeating_runs(tmp_path):
    out, log = tmp_path / "design", tmp_path / "evaluated.txt"
    budget = 40.0        # the start costs 26.8 s of the stand-in's CPU
    code = (f"import sys; sys.path[:0] = [{str(ROOT)!r}, {str(ROOT / 'tests' / 'python')!r}]; "
            f"import test_emulate_mf as T; T.run_standin_mf_design({str(out)!r}, {str(log)!r}, "
            f"0.5, {budget})")
    proc = subprocess.Popen([sys.executable, "-c", code], cwd=ROOT, env=ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    state = out / "mfdesign.json"
    t0 = time.monotonic()
    while True:           # kill it once its first batch after the start has begun running
        if state.exists() and log.exists():
            st = json.loads(state.read_text())
            if len(st["batches"]) >= 2 and len(log.read_text().split()) >= 15:
                break
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - t0 < 120, "the design did not reach its second batch"
        time.sleep(0.05)
    time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    st = json.loads(state.read_text())
    recorded = [i for b in st["batches"] for i in b["ids"]]
    before = log.read_text().split()
    assert 15 <= len(before) < len(recorded), "killed too late: nothing left to complete"
    des, res = run_standin_mf_design(str(out), str(log), 0.0, budget)
    after = log.read_text().split()
    # no scenario evaluated twice; the batches recorded before the kill completed, not replaced
    assert len(after) == len(set(after)), [i for i in after if after.count(i) > 1]
    st2 = json.loads(state.read_text())
    assert [i for b in st2["batches"] for i in b["ids"]][:len(recorded)] == recorded
    assert set(ResultStore(str(out)).done_ids()) == set(after)
    # the budget is spent, not exceeded; the design stayed nested
    spent = des.spent(des.results())
    assert res["reason"] == "budget"
    assert budget - standin_cost(STANDIN_LEVELS[0]) <= spent <= budget
    df = des.results()
    pts = {dx: set(map(tuple, df.loc[np.isclose(df["dx"], dx), ["reservoir_level", "phi"]]
                       .round(12).to_numpy())) for dx in STANDIN_LEVELS}
    assert pts[0.02] <= pts[0.03] <= pts[0.04]
    # another setting in the same folder is refused
    dists = [S.Distribution(*S.split_assignment(d)) for d in STANDIN_DISTS]
    with pytest.raises(MD.DesignError, match="other settings"):
        MD.MFDesign(str(out), dists, {}, 1.6, [0.05, 0.03, 0.02], budget, init=[8, 4, 3])


def test_risk_uses_the_extrapolation_and_its_error():
    """On the ladder stand-in, P(y > z) at the extrapolated level is that of the limit g
    (computed on 1e5 samples of g itself) within 4 Monte Carlo se plus the band; the finest
    level's P differs (the discretisation error moves it)."""
    rng = np.random.default_rng(1)
    U1 = rng.random((24, 2))
    X = [U1, U1[:12], U1[:6]]
    em = M.MFEmulator(["a", "b"], [(0, 1), (0, 1)], DXS, X,
                      [{"y": ladder(x, d)} for x, d in zip(X, DXS)])
    em.fit_output("y", restarts=0)
    dists = {"a": S.Distribution("a", "uniform:0:1"), "b": S.Distribution("b", "uniform:0:1")}
    z = 0.75
    u = np.random.default_rng(9).random((100_000, 2))
    p_true = float(np.mean(ladder_g(u) > z))
    p_fine = float(np.mean(ladder(u, DXS[-1]) > z))
    r = M.exceedance(em, "y", dists, {}, z, level=M.EXTRAPOLATED, n=100_000, n_draws=100,
                     n_joint=300)
    assert r["p_lo"] - 4 * r["mc_se"] <= p_true <= r["p_hi"] + 4 * r["mc_se"], (r, p_true)
    assert abs(p_fine - p_true) > 0.1          # the stand-in's discretisation error matters
    rf = M.exceedance(em, "y", dists, {}, z, level="finest", n=100_000, n_draws=50, n_joint=300)
    assert abs(rf["p"] - p_fine) < 0.02
    s = M.sobol(em, "y", dists, {}, level=M.EXTRAPOLATED, n_base=1024)
    # g = 0.7 + 0.1 a + 0.03 sin(3 b) with a term -8 (1 + 0.3 a) dx^1.5 gone at dx -> 0: the
    # variance of 0.1 a is 8.3e-4, of 0.03 sin(3 b) 1.6e-4: S_a = 0.84 (within 0.05)
    var_a = 0.1 ** 2 / 12
    sb = 0.03 * np.sin(3 * np.linspace(0, 1, 200001))
    var_b = float(np.var(sb))
    assert abs(s["S1"][0] - var_a / (var_a + var_b)) < 0.05
