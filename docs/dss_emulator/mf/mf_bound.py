"""Diagnostics made after the model choice (docs/dss.md, "Why not half"): the jitter at dx = 0.02
and the discrepancy f_0.02 - f_0.04 over the box, from ALL runs at dx = 0.02 (training,
single-fidelity and hold-out: 45) and all distinct runs at dx = 0.04 (119). Not used to choose
anything.   python docs/dss_emulator/mf/mf_bound.py   (runs in $MF_RUNS, default out/mf)"""
import os, sys, warnings
import numpy as np, pandas as pd
warnings.filterwarnings("ignore")
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))))
RUNS = os.environ.get("MF_RUNS", "out/mf")
from tools.dss import multifidelity as M
BOX = np.array([[0.40, 0.52], [25, 40], [0.8, 1.2]]); INP = ["reservoir_level", "phi", "plate_duration_scale"]
def runs(folders, dx):
    df = pd.concat([pd.read_parquet(os.path.join(RUNS, f, "results.parquet")) for f in folders])
    df = df[(df.status == "ok") & np.isclose(df.dx, dx)].drop_duplicates(subset=INP)
    return (df[INP].to_numpy(float) - BOX[:, 0]) / np.ptp(BOX, axis=1), df.max_run_up.to_numpy(float)
U2, y2 = runs(["holdout02", "sf02", "study2", "mflhs"], 0.02)
U4, y4 = runs(["study2", "mflhs", "study"], 0.04)
print("runs at 0.02:", len(y2), " at 0.04:", len(y4))
rng = np.random.default_rng(0); Ub = rng.random((4000, 3))
for fam in ("ard", "iso"):
    g2 = M.DeltaGP(3, kernel_family=fam).fit(U2, y2, 3, 0)
    g4 = M.DeltaGP(3, kernel_family=fam).fit(U4, y4, 3, 0)
    m4, v4 = g4.predict(U2)
    r = y2 - m4
    gd = M.DeltaGP(3, kernel_family=fam).fit(U2, r, 3, 0)
    md, vd = gd.predict(Ub)
    mf2, _ = g2.predict(Ub)
    print(f"[{fam}] jitter sd at 0.02 (GP of the 45 fine runs): {1e3*np.sqrt(g2.noise_var()):.2f} mm;"
          f" at 0.04 ({len(y4)} runs): {1e3*np.sqrt(g4.noise_var()):.2f} mm; coarse mean's latent sd at the fine runs {1e3*np.sqrt(np.mean(v4)):.2f} mm")
    print(f"   f_0.02 over the box: sd {1e3*np.std(mf2):.1f} mm; discrepancy d = f_0.02 - m_0.04 at the fine runs: mean {1e3*r.mean():.1f}, sd {1e3*r.std():.1f} mm;"
          f" its GP: smooth part's sd over the box {1e3*np.std(md):.1f} mm, noise sd {1e3*np.sqrt(gd.noise_var()):.2f} mm, length scales {np.round(gd.gp.kernel_.k1.k2.length_scale, 2)}")
    # best-case MF predictions: the fine level as the coarse mean + the exact constant (mean discrepancy)
    c = r.mean()
    print(f"   RMSE at the 20 hold-out points of m_0.04 + the best constant of all 45: "
          f"{1e3*np.sqrt(np.mean((y2[:20] - m4[:20] - c) ** 2)):.2f} mm (note: rows 0-19 are the hold-out)")

print("--- the discrepancy learned from more fine runs (not the holdout): hold-out RMSE")
Ut, yt = runs(["sf02", "study2", "mflhs"], 0.02)
Uh, yh = runs(["holdout02"], 0.02)
for fam in ("ard", "iso"):
    g4 = M.DeltaGP(3, kernel_family=fam).fit(U4, y4, 3, 0)
    for n in (4, 6, 10, 15, 25):
        idx = np.arange(len(yt))[-n:] if n <= 10 else np.arange(len(yt))[:n]
        # n <= 10: the last n (mflhs' 6, study2's 4); more: sf02's runs first
        m4t, _ = g4.predict(Ut[idx])
        gd = M.DeltaGP(3, noise=(0.5 * np.sqrt(g4.noise_var())) ** 2, kernel_family=fam).fit(Ut[idx], yt[idx] - m4t, 3, 0)
        m4h, _ = g4.predict(Uh)
        p = m4h + gd.predict(Uh)[0]
        lin = np.column_stack([np.ones(len(idx)), Ut[idx]])
        b, *_ = np.linalg.lstsq(lin, yt[idx] - m4t, rcond=None)
        pl = m4h + np.column_stack([np.ones(len(yh)), Uh]) @ b
        print(f"[{fam}] {n:2d} fine runs: rho=1 + GP discrepancy {1e3*np.sqrt(np.mean((yh-p)**2)):.2f} mm"
              f" ({100*np.sqrt(np.mean((yh-p)**2))/0.1682:.2f} %); linear discrepancy "
              f"{1e3*np.sqrt(np.mean((yh-pl)**2)):.2f} mm; constant {1e3*np.sqrt(np.mean((yh-m4h-np.mean(yt[idx]-m4t))**2)):.2f} mm")

print("--- the criterion's ratio on the 20 hold-out runs: paired bootstrap over the runs")
import json
sf_path = os.path.join(RUNS, "sf02_10", "holdout.json")
for name in ("study2/mf_emulator", "study2/mf_iso", "mflhs/mf_emulator"):
    mf_path = os.path.join(RUNS, name + "_holdout.json")
    if not (os.path.isfile(sf_path) and os.path.isfile(mf_path)):
        print(f"  ({mf_path} or {sf_path} missing: made by analysis.sh's validate --json)")
        continue
    sf, mf = json.load(open(sf_path)), json.load(open(mf_path))
    ys, y = np.array(sf["y"]), np.array(mf["y"])
    o1, o2 = np.argsort(ys), np.argsort(y)      # the same runs, matched by their value
    assert np.allclose(ys[o1], y[o2])
    a, b = (ys - np.array(sf["mean"]))[o1], (y - np.array(mf["mean"]))[o2]
    rng = np.random.default_rng(0)
    i = rng.integers(0, len(a), (20000, len(a)))
    r = np.sqrt(np.mean(b[i] ** 2, axis=1) / np.mean(a[i] ** 2, axis=1))
    print(f"  {name}: RMSE ratio to the single-fidelity emulator {np.sqrt(np.mean(b**2) / np.mean(a**2)):.3f},"
          f" 95 % bootstrap {np.quantile(r, 0.025):.2f}-{np.quantile(r, 0.975):.2f}, P(ratio <= 0.5) {np.mean(r <= 0.5):.2f}")
