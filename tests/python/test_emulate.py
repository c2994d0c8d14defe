"""Tests of the FMU emulator (tools/dss/emulator.py, design.py, emulate.py).

Most run on stand-in models (known functions), without the FMU; the last ones use the FMU
(build/LandslideWave.fmu, MIXSPH_BUILD_DIR or DSS_FMU) at the coarse dx = 0.05 m with a short
stop time. Every reference and tolerance is stated beside its assertion.
"""
import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import time
import zipfile

import numpy as np
import pandas as pd
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from tools.dss import design as D  # noqa: E402
from tools.dss import emulator as E  # noqa: E402
from tools.dss import scenarios as S  # noqa: E402
from tools.dss.store import ResultStore  # noqa: E402

BUILD = pathlib.Path(os.environ.get("MIXSPH_BUILD_DIR", ROOT / "build"))
ENV = dict(os.environ, OMP_NUM_THREADS="1", OMP_WAIT_POLICY="passive")


def fmu_path():
    p = pathlib.Path(os.environ.get("DSS_FMU", BUILD / "LandslideWave.fmu"))
    if not p.is_file():
        pytest.fail(f"{p} not found: build it with `cmake --build {BUILD} --target fmu`")
    return str(p)


def emulate(*args, check=True, timeout=600):
    cmd = [sys.executable, "-m", "tools.dss", "emulate", *map(str, args)]
    p = subprocess.run(cmd, cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=timeout)
    if check and p.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} exited {p.returncode}\n{p.stdout}\n{p.stderr}")
    return p


# ---- stand-in models ----------------------------------------------------------------------------

def smooth3(X):
    """A known smooth function of 3 inputs on the unit cube (range about 1.7)."""
    a, b, c = X[:, 0], X[:, 1], X[:, 2]
    return np.sin(3 * a) + 0.5 * b ** 2 + 0.3 * np.cos(2 * np.pi * c) * a


def fitted(X, y, names, kinds=None, mode="product", box=None, cv=True):
    df = pd.DataFrame(X, columns=names)
    df["y"] = y
    df["status"] = "ok"
    em = E.from_results(df, outputs=["y"], inputs=names, box=box)
    em.fit_output("y", mode=mode, cv=cv)
    return em


def standin_runup(s):
    """A stand-in of the FMU's run-up over (reservoir_level, phi, saturated)."""
    a = (s["reservoir_level"] - 0.40) / 0.12
    b = (s["phi"] - 25.0) / 15.0
    return 0.6 + 0.1 * a + 0.03 * np.sin(3 * b) + 0.02 * s["saturated"] * a


STANDIN_DISTS = ["reservoir_level=uniform:0.40:0.52", "phi=uniform:25:40", "saturated=choice:0,1"]


def run_standin_design(out, log, delay, budget):
    """A design on the stand-in; each evaluated scenario id is appended to LOG (what the kill
    test counts); after the start batch every run takes DELAY s."""
    dists = [S.Distribution(*S.split_assignment(d)) for d in STANDIN_DISTS]
    des = D.Design(out, dists, {"dx": 0.05}, 1.6, budget=budget, target_error=0.0, n_init=6,
                   n_workers=2, folds=3, restarts=0, progress=False)

    def evaluate(scen, on_result):
        for s in scen:
            if des.state["batches"] and len(des.state["batches"]) > 1:
                time.sleep(delay)
            with open(log, "a") as f:
                f.write(s[S.ID] + "\n")
                f.flush()
                os.fsync(f.fileno())
            on_result({**s, "status": "ok", "error": "", "max_run_up": standin_runup(s),
                       "wall_time_s": delay, "finished_at": f"{time.time():.6f}"})
    return des.run(evaluate)


# ---- without the FMU ---------------------------------------------------------------------------

def test_gp_recovers_a_smooth_function_of_three_inputs_with_calibrated_intervals():
    from scipy.stats import qmc
    X = qmc.LatinHypercube(d=3, seed=1).random(30)
    names = ["reservoir_level", "phi", "porosity"]
    em = fitted(X, smooth3(X), names, box={n: (0.0, 1.0) for n in names})
    Xt = np.random.default_rng(5).random((1000, 3))
    yt = smooth3(Xt)
    mu, sd = em.predict(Xt)["y"]
    m = E.metrics(yt, mu, sd)
    # the targets for the FMU emulator: RMSE <= 2 % of the range, 90-98 % of the
    # points inside their 95 % intervals (1000 independent uniform test points)
    assert m["rmse_pct"] <= 2.0, m
    assert 0.90 <= m["coverage95"] <= 0.98, m
    # the cross-validation sees the same: its RMSE within a factor 2 of the test points'
    assert 0.5 <= em.cv["y"]["rmse_pct"] / m["rmse_pct"] <= 2.0, (em.cv["y"]["rmse_pct"], m)


@pytest.mark.parametrize("mode", E.MODES)
def test_save_and_load_give_identical_predictions(tmp_path, mode):
    rng = np.random.default_rng(2)
    X = np.column_stack([0.40 + 0.12 * rng.random(24), 25 + 15 * rng.random(24),
                         np.tile([0.0, 1.0], 12)])
    y = [standin_runup(dict(zip(["reservoir_level", "phi", "saturated"], x))) for x in X]
    em = fitted(X, np.array(y), ["reservoir_level", "phi", "saturated"], mode=mode)
    assert em.kinds == ["continuous", "continuous", "binary"]
    path = str(tmp_path / "em.json")
    em.save(path)
    doc = json.loads(pathlib.Path(path).read_text())
    assert doc["schema"] == "mixsph-emulator" and doc["schema_version"] == E.SCHEMA_VERSION == 2
    em2 = E.Emulator.from_json(doc)
    Xq = np.column_stack([0.40 + 0.12 * rng.random(200), 25 + 15 * rng.random(200),
                          rng.integers(0, 2, 200)])
    a, b = em.predict(Xq)["y"], em2.predict(Xq)["y"]
    # identical: the loaded GP is rebuilt from the saved hyperparameters (optimizer=None)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_out_of_box_queries_are_flagged():
    rng = np.random.default_rng(3)
    X = np.column_stack([0.40 + 0.12 * rng.random(12), 25 + 15 * rng.random(12),
                         np.tile([0.0, 1.0], 6)])
    em = fitted(X, X[:, 0] + 0.01 * X[:, 1], ["reservoir_level", "phi", "saturated"],
                box={"reservoir_level": (0.40, 0.52), "phi": (25.0, 40.0)})
    q = np.array([[0.46, 30.0, 1.0],        # inside
                  [0.55, 30.0, 0.0],        # level above the box
                  [0.46, 20.0, 0.5],        # phi below, saturated not 0/1
                  [0.52, 40.0, 0.0]])       # on the box's corner: inside
    oob = em.predict(q)["out_of_box"]
    assert list(oob) == ["", "reservoir_level", "phi,saturated", ""]


def test_a_killed_design_continues_without_repeating_runs(tmp_path):
    out, log = tmp_path / "design", tmp_path / "evaluated.txt"
    code = (f"import sys; sys.path[:0] = [{str(ROOT)!r}, {str(ROOT / 'tests' / 'python')!r}]; "
            f"import test_emulate as T; T.run_standin_design({str(out)!r}, {str(log)!r}, 0.5, 12)")
    proc = subprocess.Popen([sys.executable, "-c", code], cwd=ROOT, env=ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    state = out / "design.json"
    t0 = time.monotonic()
    # kill it once its first batch after the start is recorded and has begun running
    while True:
        if state.exists() and log.exists():
            st = json.loads(state.read_text())
            if len(st["batches"]) >= 2 and len(log.read_text().split()) >= 6:
                break
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - t0 < 120, "the design did not reach its second batch"
        time.sleep(0.05)
    time.sleep(0.7)                      # into the second batch's 0.5 s runs
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    before = log.read_text().split()
    st = json.loads(state.read_text())
    recorded = [i for b in st["batches"] for i in b["ids"]]
    assert 6 <= len(before) < 12, "killed too late: nothing left to continue"
    res = run_standin_design(str(out), str(log), 0.0, 12)
    after = log.read_text().split()
    # no scenario was evaluated twice, and the design spent exactly its budget of 12 runs
    assert len(after) == len(set(after)), [i for i in after if after.count(i) > 1]
    assert res["runs"] == 12 and len(after) == 12
    # the batches recorded before the kill were completed, not replaced
    st2 = json.loads(state.read_text())
    assert [i for b in st2["batches"] for i in b["ids"]][:len(recorded)] == recorded
    assert set(ResultStore(str(out)).done_ids()) == set(after)


@pytest.mark.parametrize("criterion", D.CRITERIA)
def test_design_batches_are_not_clustered_and_follow_the_uncertainty(criterion):
    """With 10 start runs in one half of the level range, the picks go to the empty half, and
    the two picks of a batch are apart (sd: the correlation penalty; imse: the conditioning on
    the first pick)."""
    rng = np.random.default_rng(4)
    X = np.column_stack([0.40 + 0.06 * rng.random(10), 25 + 15 * rng.random(10)])
    y = np.array([standin_runup({"reservoir_level": a, "phi": b, "saturated": 0}) for a, b in X])
    em = fitted(X, y, ["reservoir_level", "phi"], box={"reservoir_level": (0.40, 0.52),
                                                       "phi": (25.0, 40.0)}, cv=False)
    dists = [S.Distribution("reservoir_level", "uniform:0.40:0.52"),
             S.Distribution("phi", "uniform:25:40")]
    b = D.pick_batch(em, "y", dists, {}, 2, np.random.default_rng(0), 2000, criterion=criterion)
    assert len(b) == 2
    assert all(s["reservoir_level"] > 0.46 for s in b), b       # the unexplored half
    u = em.unit(em.matrix(b))
    assert np.linalg.norm(u[0] - u[1]) > 0.2, b                # 0.2 of the unit box apart


SMOOTH3_NAMES = ["reservoir_level", "phi", "porosity"]


def run_smooth3_design(criterion, budget=30, seed=0):
    """A design on smooth3 over the unit cube as Design.run makes it (10 Latin-hypercube start
    runs, then batches of 2 picked by pick_batch from the warm-started refit, the candidates
    and their rng as Design's), without its store and CV (cheaper; they do not change the
    picks): the picks after the start (unit box, in order) and a fresh fit of all the runs
    (3 restarts, as the final fit of emulate design)."""
    dists = [S.Distribution(n, "uniform:0:1") for n in SMOOTH3_NAMES]
    box = {n: (0.0, 1.0) for n in SMOOTH3_NAMES}
    n_cand = min(3000, D.IMSE_CANDIDATES) if criterion == "imse" else 3000
    runs = S.sample(dists, 10, "lhs", seed, {})
    thetas, picks = None, []

    def fit(restarts, init):
        df = pd.DataFrame([{n: r[n] for n in SMOOTH3_NAMES} for r in runs])
        df["y"] = smooth3(df[SMOOTH3_NAMES].to_numpy())
        df["status"] = "ok"
        em = E.from_results(df, outputs=["y"], inputs=SMOOTH3_NAMES, box=box)
        em.fit_output("y", mode="product", restarts=restarts, seed=seed, cv=False,
                      cv_refit=False, init=init)
        return em
    bi = 1
    while len(runs) < budget:
        em = fit(0, thetas)
        thetas = em.models["y"].thetas()
        batch = D.pick_batch(em, "y", dists, {}, 2, np.random.default_rng([seed, bi]), n_cand,
                             criterion=criterion)
        runs += batch
        picks += [[s[n] for n in SMOOTH3_NAMES] for s in batch]
        bi += 1
    return np.array(picks), fit(3, None)


@pytest.fixture(scope="module")
def smooth3_designs():
    """sd and imse designs of 30 runs on smooth3 for the seeds 0, 1, 2 (the first three, not
    chosen), each with its hold-out RMSE at 1,000 random points (% of the range)."""
    Xt = np.random.default_rng(5).random((1000, 3))
    yt = smooth3(Xt)
    res = {}
    for crit in ("sd", "imse"):
        for seed in range(3):
            picks, em = run_smooth3_design(crit, seed=seed)
            mu, sd = em.predict(Xt)["y"]
            res[crit, seed] = {"picks": picks, "rmse_pct": E.metrics(yt, mu, sd)["rmse_pct"]}
    return res


def test_imse_picks_are_not_on_the_faces_of_the_box(smooth3_designs):
    """The sd picks sit on the box's faces (the Vajont campaign's problem: all 48 within 5 % of
    a face, median 0.6 %); the imse picks do not."""
    face = {c: np.concatenate([np.minimum(r["picks"], 1 - r["picks"]).min(axis=1)
                               for (cc, _), r in smooth3_designs.items() if cc == c])
            for c in ("sd", "imse")}
    for c, f in face.items():
        print(c, "median distance to the nearest face", np.median(f), "within 5 %",
              np.mean(f < 0.05))
    # sd: the median of the 60 picks (3 designs x 20) within 2 % of a face (measured 0.3-0.9 %
    # per design over 10 seeds), most of them within 5 %
    assert np.median(face["sd"]) < 0.02 and np.mean(face["sd"] < 0.05) > 0.6
    # imse: the median at least 4 % of the box: twice the bound sd stays under and 4x its
    # largest measured median, below the 10.3 % of uniform random points (P(min > t) =
    # (1 - 2t)^3 = 1/2), which an integrated-variance design need not reach (it keeps some picks
    # near the faces, where the variance is largest); and fewer than half the picks within 5 %
    # of a face (uniform random points: 1 - 0.9^3 = 27 %)
    assert np.median(face["imse"]) >= 0.04
    assert np.mean(face["imse"] < 0.05) < 0.5


def test_imse_designs_are_no_worse_than_sd_designs_on_the_hold_out(smooth3_designs):
    """The mean hold-out RMSE of the 3 imse designs is no worse than of the 3 sd designs of the
    same budget (tolerance 0; per design it can go either way: over seeds 0-9 imse was lower in
    7 of 10, see docs/dss.md)."""
    r = {c: [smooth3_designs[c, s]["rmse_pct"] for s in range(3)] for c in ("sd", "imse")}
    print(r)
    assert np.mean(r["imse"]) <= np.mean(r["sd"]), r


def test_the_criterion_is_a_setting_of_the_design(tmp_path):
    dists = [S.Distribution(*S.split_assignment(d)) for d in STANDIN_DISTS]
    kw = dict(budget=8, target_error=0.0, n_init=6, n_workers=2, folds=3, restarts=0,
              progress=False)

    def evaluate(scen, on_result):
        for s in scen:
            on_result({**s, "status": "ok", "error": "", "max_run_up": standin_runup(s),
                       "wall_time_s": 0.0, "finished_at": f"{time.time():.6f}"})
    out = str(tmp_path / "d")
    des = D.Design(out, dists, {"dx": 0.05}, 1.6, **kw)          # the default: imse
    des.run(evaluate)
    st = json.loads((tmp_path / "d" / "design.json").read_text())
    assert st["spec"]["criterion"] == "imse"
    assert [b["kind"] for b in st["batches"]] == ["lhs", "imse"]
    # resuming with another criterion is refused, naming it; with the same one it continues
    with pytest.raises(D.DesignError, match="criterion"):
        D.Design(out, dists, {"dx": 0.05}, 1.6, criterion="sd", **kw)
    D.Design(out, dists, {"dx": 0.05}, 1.6, criterion="imse", **kw)
    # a design.json of before the setting was made with sd: it continues with sd only
    del st["spec"]["criterion"]
    (tmp_path / "d" / "design.json").write_text(json.dumps(st))
    with pytest.raises(D.DesignError, match="criterion"):
        D.Design(out, dists, {"dx": 0.05}, 1.6, **kw)
    assert D.Design(out, dists, {"dx": 0.05}, 1.6, criterion="sd", **kw).criterion == "sd"
    # with a crest the picks are at the largest p(1-p): a criterion is refused
    with pytest.raises(D.DesignError, match="crest"):
        D.Design(str(tmp_path / "c"), dists, {"dx": 0.05}, 1.6, crest=0.65, criterion="imse",
                 **kw)
    assert D.Design(str(tmp_path / "c"), dists, {"dx": 0.05}, 1.6, crest=0.65,
                    **kw).criterion == "crest"


def test_imse_conditioning_equals_a_refit_with_the_picks_added():
    """The rank-1 updates within a batch give the picks of recomputing the scores from a GP
    with the previous picks added as runs (same hyperparameters), and posterior_cov is
    scikit-learn's predictive covariance less the noise on its diagonal."""
    from scipy.stats import qmc
    X = qmc.LatinHypercube(d=3, seed=1).random(20)
    y = smooth3(X) + 0.01 * np.random.default_rng(1).standard_normal(20)
    em = fitted(X, y, SMOOTH3_NAMES, box={n: (0.0, 1.0) for n in SMOOTH3_NAMES}, cv=False)
    m = em.models["y"]
    rng = np.random.default_rng(3)
    Uc, Ur = rng.random((300, 3)), rng.random((100, 3))
    _, cov = m.parts[()].predict(Uc[:50], return_cov=True)
    ref = cov * m.y_std ** 2 - np.diag(m.noise_at(Uc[:50]))
    assert np.allclose(m.posterior_cov(Uc[:50], Uc[:50]), ref, rtol=0, atol=1e-9 * ref.max())
    assert np.allclose(m.posterior_var(Uc[:50]), np.diag(ref), rtol=0, atol=1e-9 * ref.max())
    picked = D.imse_pick(m, Uc, Ur, 3)
    brute = []
    for _ in range(3):
        m2 = em._new_model("y", "product", y)
        m2.y_mean, m2.y_std = m.y_mean, m.y_std
        m2.rebuild(np.vstack([X, Uc[brute]]), np.concatenate([y, np.zeros(len(brute))]),
                   m.thetas())
        sc = (m2.posterior_cov(Ur, Uc) ** 2).sum(axis=0) / (m2.posterior_var(Uc)
                                                            + m2.noise_at(Uc))
        sc[brute] = -np.inf
        brute.append(int(np.argmax(sc)))
    assert picked == brute, (picked, brute)


def test_separate_levels_are_independent_in_the_posterior_covariance():
    rng = np.random.default_rng(2)
    X = np.column_stack([0.40 + 0.12 * rng.random(24), 25 + 15 * rng.random(24),
                         np.tile([0.0, 1.0], 12)])
    y = [standin_runup(dict(zip(["reservoir_level", "phi", "saturated"], x))) for x in X]
    em = fitted(X, np.array(y), ["reservoir_level", "phi", "saturated"], mode="separate",
                cv=False)
    m = em.models["y"]
    U = em.unit(np.column_stack([0.40 + 0.12 * rng.random(40), 25 + 15 * rng.random(40),
                                 np.tile([0.0, 1.0], 20)]))
    C = m.posterior_cov(U, U)
    lv = U[:, 2] == 1
    # across the levels exactly 0; within a level the predictive variance less the noise
    assert not C[np.ix_(lv, ~lv)].any()
    _, sd = m.predict(U)
    assert np.allclose(np.diag(C) + m.noise_at(U), sd ** 2, rtol=0,
                       atol=1e-9 * np.max(sd ** 2))


def test_risk_and_sobol_of_a_known_response():
    """y = a + 0.5 b, a, b ~ U(0, 1): P(y > 1) = 0.25; Sobol S1 = ST = 0.8 and 0.2."""
    from scipy.stats import qmc
    X = qmc.LatinHypercube(d=2, seed=2).random(30)
    names = ["reservoir_level", "phi"]
    em = fitted(X, X[:, 0] + 0.5 * X[:, 1], names, box={n: (0.0, 1.0) for n in names})
    dists = {n: S.Distribution(n, "uniform:0:1") for n in names}
    t0 = time.perf_counter()
    r = E.exceedance(em, "y", dists, {}, 1.0, n=100_000, n_joint=1000, n_draws=200, seed=1)
    took = time.perf_counter() - t0
    # exact 0.25; the Monte Carlo se of 1e5 samples is 0.0014: 4 se
    assert abs(r["p"] - 0.25) <= 4 * 0.0014 + 0.002, r
    # the band brackets P (up to rounding) and is narrow: the emulator of a linear function is
    # all but exact, its draws hardly differ
    assert r["p_lo"] - 1e-9 <= r["p"] <= r["p_hi"] + 1e-9 and r["p_hi"] - r["p_lo"] < 0.05, r
    assert took < 10.0, took                         # the issue: 1e5 samples in under 10 s
    s = E.sobol(em, "y", dists, {}, n_base=4096, seed=1)
    # exact: var(a) = 1/12, var(0.5 b) = 1/48 -> S1 = 0.8, 0.2; additive -> ST = S1. SALib's
    # bootstrap 95 % half-widths at N = 4096 are about 0.03
    assert s["S1"] == pytest.approx([0.8, 0.2], abs=0.05)
    assert s["ST"] == pytest.approx([0.8, 0.2], abs=0.05)
    Xq = np.random.default_rng(0).random((1000, 2))
    t0 = time.perf_counter()
    em.predict(Xq)
    assert time.perf_counter() - t0 < 1.0            # the issue: 1000 scenarios under 1 s


# ---- the measured noise term (emulate jitter, --noise-floor) ---------------------------------------

def standin_fmu(X, rng, sigma):
    """A stand-in of the FMU over (reservoir_level, phi, saturated, plate_duration_scale): a
    smooth response (range about 0.2, like the Vajont run-up's) plus independent normal jitter
    of sd sigma (the FMU's discretisation noise)."""
    a = (X[:, 0] - 0.40) / 0.12
    b = (X[:, 1] - 25.0) / 15.0
    d = (X[:, 3] - 0.8) / 0.4
    f = 0.62 + 0.12 * a + 0.02 * np.sin(3 * b) + 0.01 * X[:, 2] * a - 0.06 * d + 0.02 * a * d
    return f + sigma * rng.standard_normal(len(X))


FMU_BOX = {"reservoir_level": (0.40, 0.52), "phi": (25.0, 40.0), "saturated": (0.0, 1.0),
           "plate_duration_scale": (0.8, 1.2)}
SIGMA = 0.004          # the stand-in's jitter sd: 2 % of its range


def standin_jitter_scan(rng, sigma, n=6, dx=0.015):
    """emulate jitter's scan on the stand-in: n runs at each of 2 box points (saturated 0, 1),
    the level moved by a Latin hypercube of offsets in [-dx/2, dx/2] (jitter_scenarios)."""
    from tools.dss.emulate import jitter_scenarios
    pts = [{"reservoir_level": 0.46, "phi": 32.5, "saturated": s, "plate_duration_scale": 1.0}
           for s in (0, 1)]
    scen = jitter_scenarios(pts, {"reservoir_level": dx / 2}, n, int(rng.integers(1 << 30)))
    X = np.array([[s[k] for k in FMU_BOX] for s in scen])
    y = standin_fmu(X, rng, sigma)
    return E.jitter_noise(X[:, :1] - 0.46, y, X[:, 2])


def test_jitter_scan_recovers_a_known_noise_variance():
    """200 seeded scans of 12 runs (2 points x 6, the campaign's scan) of the stand-in with
    jitter sd SIGMA: the estimated variance's 95 % CI covers SIGMA^2 in 95 % of them, and the
    estimate is unbiased. The trend over the offsets (0.12 / 0.12 m x 7.5 mm = 7.5 mm of run-up
    end to end, more than the jitter) must be removed: the variance about the point means
    without it is biased high."""
    from scipy.stats import chi2
    rng = np.random.default_rng(27)
    est = [standin_jitter_scan(rng, SIGMA) for _ in range(200)]
    assert all(e["dof"] == 8 for e in est)           # 12 runs - 2 points x (mean, slope)
    cover = np.mean([e["ci95_variance"][0] <= SIGMA ** 2 <= e["ci95_variance"][1] for e in est])
    # binomial(200, 0.95): sd 1.5 %; 0.91-0.99 is about 2.7 sd either side
    assert 0.91 <= cover <= 0.99, cover
    ratio = np.array([e["variance"] for e in est]) / SIGMA ** 2
    # E[s^2] = sigma^2; the mean of 200 ratios, each of sd sqrt(2/8) = 0.5, has sd 0.035:
    # within 0.12 (3.4 sd)
    assert abs(ratio.mean() - 1) <= 0.12, ratio.mean()
    # a single scan: within the chi-square 99 % range of 8 dof (0.17-2.5 x sigma^2)
    lo, hi = chi2.ppf([0.005, 0.995], 8) / 8
    assert np.mean((ratio >= lo) & (ratio <= hi)) >= 0.97, ratio
    # without the trend the variance is too large: the trend's own variance
    # (0.12/0.12 x 0.0075)^2 / 3 = 1.9e-5 = 1.2 sigma^2 adds to it (mean ratio ~2.2)
    about = np.array([e["variance_about_means"] for e in est]) / SIGMA ** 2
    assert about.mean() > 1.6, about.mean()


def _fit_standin(X, y, noise=None, mode="binary"):
    df = pd.DataFrame(X, columns=list(FMU_BOX))
    df["y"] = y
    df["status"] = "ok"
    em = E.from_results(df, outputs=["y"], inputs=list(FMU_BOX), box=FMU_BOX, noise=noise)
    em.fit_output("y", mode=mode, cv=False)
    return em


def _standin_lhs(n, seed):
    from scipy.stats import qmc
    u = qmc.LatinHypercube(d=4, seed=seed).random(n)
    lo = np.array([b[0] for b in FMU_BOX.values()])
    hi = np.array([b[1] for b in FMU_BOX.values()])
    X = lo + u * (hi - lo)
    X[:, 2] = np.rint(u[:, 2])
    return X


def test_intervals_with_the_measured_floor_are_calibrated():
    """The campaign on the stand-in, 5 times over: a 12-run jitter scan gives the floor, a GP of
    a 40-run Latin hypercube (the issue's budget) is fitted with it, and 1000 independent new
    "runs" (new jitter) at random points are predicted. Over the 5 campaigns, 90-98 % of the
    new runs are inside their 95 % intervals (the issue's target; one campaign's coverage
    varies with its design, so the mean of 5 is what is asserted, each one is printed)."""
    rng = np.random.default_rng(11)
    lo = np.array([b[0] for b in FMU_BOX.values()])
    span = np.array([b[1] - b[0] for b in FMU_BOX.values()])
    cov = []
    for rep in range(5):
        scan = standin_jitter_scan(rng, SIGMA)
        noise = {"y": {"variance": scan["variance"], "sd": scan["sd"], "mode": "floor",
                       "dof": scan["dof"], "ci95_sd": scan["ci95_sd"]}}
        X = _standin_lhs(40, 100 + rep)
        em = _fit_standin(X, standin_fmu(X, rng, SIGMA), noise)
        # the fitted noise is at least the floor (its bound), in the output's units
        assert min(em.models["y"].fitted_noise()) >= scan["variance"] * (1 - 1e-6)
        Xt = lo + rng.random((1000, 4)) * span
        Xt[:, 2] = rng.integers(0, 2, 1000)
        m = E.metrics(standin_fmu(Xt, rng, SIGMA), *em.predict(Xt)["y"])
        print(f"campaign {rep}: floor sd {scan['sd']:.4f} (true {SIGMA}), RMSE "
              f"{m['rmse_pct']:.2f} %, coverage {m['coverage95']:.3f}")
        cov.append(m["coverage95"])
    # the target for the intervals: 90-98 % of the new runs inside
    assert 0.90 <= np.mean(cov) <= 0.98, cov


@pytest.mark.parametrize("noise_mode", E.NOISE_MODES)
def test_the_noise_term_is_saved_and_old_files_load(tmp_path, noise_mode):
    rng = np.random.default_rng(6)
    X = _standin_lhs(24, 6)
    y = standin_fmu(X, rng, SIGMA)
    noise = {"y": {"variance": SIGMA ** 2, "sd": SIGMA, "mode": noise_mode, "dof": 8,
                   "ci95_sd": [0.5 * SIGMA, 2 * SIGMA]}}
    em = _fit_standin(X, y, noise)
    fn = em.models["y"].fitted_noise()[0]
    # floor: at least the measured variance; fixed: exactly it (float rounding of the
    # standardisation: relative 1e-9)
    if noise_mode == "fixed":
        assert fn == pytest.approx(SIGMA ** 2, rel=1e-9)
    else:
        assert fn >= SIGMA ** 2 * (1 - 1e-9)
    path = tmp_path / "em.json"
    em.save(str(path))
    doc = json.loads(path.read_text())
    assert doc["schema_version"] == 2 and doc["outputs"]["y"]["noise"]["mode"] == noise_mode
    em2 = E.Emulator.from_json(doc)
    Xq = _standin_lhs(100, 7)
    a, b = em.predict(Xq)["y"], em2.predict(Xq)["y"]
    # bit-identical after loading (the noise term's structure rebuilt from the file)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    assert em2.noise["y"]["mode"] == noise_mode
    # a version-1 file (no noise key) of an emulator without a floor still loads, identically
    old = _fit_standin(X, y)
    d1 = json.loads(json.dumps(E._jsonable(old.to_json())))
    d1["schema_version"] = 1
    for o in d1["outputs"].values():
        o.pop("noise")
    e1 = E.Emulator.from_json(d1)
    assert not e1.noise
    assert np.array_equal(old.predict(Xq)["y"][1], e1.predict(Xq)["y"][1])
    # another version is refused, naming the versions this code reads
    d1["schema_version"] = 99
    with pytest.raises(E.EmulatorError, match="version 99 .* reads \\(1, 2\\)"):
        E.Emulator.from_json(d1)


def test_a_floor_of_another_fmu_or_dx_is_refused(tmp_path):
    rng = np.random.default_rng(8)
    scan = standin_jitter_scan(rng, SIGMA)
    path = tmp_path / "jitter.json"
    path.write_text(json.dumps(E._jsonable(
        {"schema": "mixsph-jitter", "schema_version": 1, "fmu": {"guid": "{a}"},
         "settings": {"dx": 0.015}, "outputs": {"max_run_up": scan}})))
    nz = E.noise_from_file(str(path), ["max_run_up", "landslide_front"], "floor",
                           {"guid": "{a}"}, dx=0.015)
    assert list(nz) == ["max_run_up"] and nz["max_run_up"]["variance"] == scan["variance"]
    with pytest.raises(E.EmulatorError, match="GUID"):
        E.noise_from_file(str(path), ["max_run_up"], "floor", {"guid": "{b}"}, dx=0.015)
    with pytest.raises(E.EmulatorError, match="dx = 0.015"):
        E.noise_from_file(str(path), ["max_run_up"], "floor", {"guid": "{a}"}, dx=0.03)


def test_a_design_uses_the_floor_and_keeps_it_as_a_setting(tmp_path):
    dists = [S.Distribution(*S.split_assignment(d)) for d in STANDIN_DISTS]
    floor = {"max_run_up": {"variance": 1e-6, "sd": 1e-3, "mode": "floor", "dof": 8,
                            "ci95_sd": [7e-4, 2e-3]}}

    def evaluate(scen, on_result):
        for s in scen:
            on_result({**s, "status": "ok", "error": "", "max_run_up": standin_runup(s),
                       "wall_time_s": 0.0, "finished_at": f"{time.time():.6f}"})
    des = D.Design(str(tmp_path / "d"), dists, {"dx": 0.05}, 1.6, budget=10, target_error=0.0,
                   n_init=6, n_workers=2, folds=3, restarts=0, progress=False, noise=floor)
    des.run(evaluate)
    em = des.fit()
    # the floor is the noise term's lower bound: the fitted noise is at least the floor's
    # variance (to the optimiser's 1e-3 relative), and the model keeps the floor it was given
    m = em.models["max_run_up"]
    assert m.fitted_noise()[0] >= 1e-6 * (1 - 1e-3)
    assert m.noise["variance"] == 1e-6 and m.noise["mode"] == "floor"
    # the floor is a setting of the design: another one is refused in the same folder
    with pytest.raises(D.DesignError, match="noise"):
        D.Design(str(tmp_path / "d"), dists, {"dx": 0.05}, 1.6, budget=10, target_error=0.0,
                 n_init=6, n_workers=2, folds=3, restarts=0, progress=False)


# ---- with the FMU ------------------------------------------------------------------------------

def _with_guid(src, dst, guid):
    """A copy of the FMU whose modelDescription.xml has another GUID."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                text = data.decode()
                i = text.index('guid="') + 6
                text = text[:i] + guid + text[text.index('"', i):]
                data = text.encode()
            zout.writestr(item, data)


def test_design_on_the_fmu_end_to_end_and_a_foreign_guid_is_refused(tmp_path):
    from fmpy import simulate_fmu
    fmu = fmu_path()
    out = tmp_path / "design"
    stop = 0.8
    p = emulate("design", out, "--fmu", fmu, "--dist", "reservoir_level=uniform:0.40:0.52",
                "--dist", "phi=uniform:25:40", "--budget", 6, "--init", 4, "--target-error", 0,
                "--dx", 0.05, "--stop-time", stop, "--workers", 2, "--folds", 4, "--no-plots")
    df = ResultStore(str(out)).latest()
    # the budget: 6 runs, all ok, 4 from the start and one batch of 2 (2 workers)
    assert len(df) == 6 and (df["status"] == "ok").all(), df.get("error")
    st = json.loads((out / "design.json").read_text())
    assert [len(b["ids"]) for b in st["batches"]] == [4, 2] and st["stopped"] == "budget"
    doc = json.loads((out / "emulator.json").read_text())
    from fmpy import read_model_description
    assert doc["fmu"]["guid"] == read_model_description(fmu).guid
    assert sorted(doc["X"]) == sorted(df[["reservoir_level", "phi"]].to_numpy().tolist())
    # the emulator reproduces its own training runs within their 95 % intervals (inputs and
    # outputs kept together through scaling, standardisation and the JSON)
    tr = df[["reservoir_level", "phi"]].copy()
    tr.to_csv(tmp_path / "train.csv", index=False)
    emulate("predict", out / "emulator.json", "--fmu", fmu, "--csv", tmp_path / "train.csv",
            "--output", "max_run_up", "-o", tmp_path / "pred_train.csv")
    pt = pd.read_csv(tmp_path / "pred_train.csv")
    y = df["max_run_up"].to_numpy()
    assert ((pt["max_run_up_lo95"] <= y) & (y <= pt["max_run_up_hi95"])).all(), (pt, y)
    # a scenario not in the design, run on the FMU directly: the emulator is nearer to it than
    # half the spread of the 6 runs (a gross check only: at dx = 0.05 the run-up moves in
    # lattice steps and 6 runs cannot calibrate the intervals; the CV in the file says so)
    q = {"reservoir_level": 0.47, "phi": 31.0}
    r = simulate_fmu(fmu, start_values={**q, "dx": 0.05, "threads": 1}, stop_time=stop,
                     output_interval=0.05, output=["max_run_up"])
    y_new = float(r[-1]["max_run_up"])
    emulate("predict", out / "emulator.json", "--fmu", fmu, "--set", "reservoir_level=0.47",
            "--set", "phi=31", "--output", "max_run_up", "-o", tmp_path / "pred.csv")
    row = pd.read_csv(tmp_path / "pred.csv").iloc[0]
    assert abs(row["max_run_up_mean"] - y_new) <= 0.5 * np.ptp(y), (y_new, row.to_dict())
    assert pd.isna(row["out_of_box"]) or row["out_of_box"] == ""
    # out of the box: flagged in the output
    emulate("predict", out / "emulator.json", "--fmu", fmu, "--set", "reservoir_level=0.60",
            "--set", "phi=31", "-o", tmp_path / "pred2.csv")
    assert pd.read_csv(tmp_path / "pred2.csv").iloc[0]["out_of_box"] == "reservoir_level"
    # another FMU (another GUID) is refused with a message naming both GUIDs
    other = tmp_path / "Other.fmu"
    _with_guid(fmu, other, "{00000000-1111-2222-3333-444444444444}")
    p = emulate("predict", out / "emulator.json", "--fmu", other, "--set", "reservoir_level=0.47",
                "--set", "phi=31", check=False)
    assert p.returncode == 2, p.stderr
    assert "refused" in p.stderr and "{00000000-1111-2222-3333-444444444444}" in p.stderr
    assert doc["fmu"]["guid"] in p.stderr
    with pytest.raises(E.GuidMismatch):
        E.load(str(out / "emulator.json"), str(other))
    # the same emulator loads against its own FMU
    assert E.load(str(out / "emulator.json"), fmu).inputs == ["reservoir_level", "phi"]


def test_jitter_takes_item_names_at_its_point(tmp_path):
    # emulate jitter --at rheology=NAME: an Enumeration's item by its name, as sweep and predict
    # take it; a name that is no item is a usage error (exit 2) naming the items, before any run.
    fmu = fmu_path()
    p = emulate("jitter", tmp_path / "j", "--fmu", fmu, "--at", "reservoir_level=0.46", "--at", "rheology=granite",
                check=False)
    assert p.returncode == 2, p.stderr
    assert "rheology = 'granite' is not one of its items: paper (0), elastic_plastic (1)" in p.stderr
    assert not (tmp_path / "j").exists()
