"""Cross-validation of multi-fidelity model variants on the stored runs of the Vajont campaign
(docs/dss.md, "Choosing the model by cross-validation"): the training runs of study2 and mflhs
only, never the hold-out.

    python docs/dss_emulator/mf/mf_cv.py TARGET [VARIANT...]     (runs in $MF_RUNS, default out/mf)

TARGET 2: leave out each dx = 0.02 run (and the runs at the same point on the coarser levels:
the hold-out's situation, a new point with no run at any level); TARGET 1: the same at dx = 0.03
with the two coarser levels. Prints per variant the CV RMSE (% of 0.1682 m), rms z and 95 %
coverage per set and pooled, and the residuals; writes $MF_RUNS/cv_targetT.json. The variants
swap the discrepancy GP's kernel by replacing DeltaGP.kernel (an experiment, not the emulator's
code); NARGP (Perdikaris et al. 2017) is built here on scikit-learn.
"""
import json
import math
import sys
import warnings

import numpy as np
import pandas as pd

import os
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, ROOT)
RUNS = os.environ.get("MF_RUNS", "out/mf")
from tools.dss import emulator as E  # noqa
from tools.dss import multifidelity as M  # noqa

warnings.filterwarnings("ignore")
BOX = np.array([[0.40, 0.52], [25, 40], [0.8, 1.2]])
INP = ["reservoir_level", "phi", "plate_duration_scale"]
DXS = [0.04, 0.03, 0.02]
OUT = "max_run_up"
RANGE = 0.1682


def load(folder):
    df = pd.read_parquet(os.path.join(RUNS, folder, "results.parquet"))
    df = df[df.status == "ok"]
    U, y = [], []
    for dx in DXS:
        s = df[np.isclose(df.dx, dx)]
        U.append((s[INP].to_numpy(float) - BOX[:, 0]) / (BOX[:, 1] - BOX[:, 0]))
        y.append(s[OUT].to_numpy(float))
    return U, y


# ---- variants: fit(U_levels, y_levels) -> predict(U) -> (mean, sd) at the finest level -----------

def ar1(levels=(0, 1, 2), jitter_floor=True, restarts=1, kernel=None, family="ard"):
    def fit(U, y):
        Ul = [U[i] for i in levels]
        yl = [y[i] for i in levels]
        m = M.OutputMF(OUT, [DXS[i] for i in levels], 3, None, jitter_floor, family)
        if kernel is not None:
            old = M.DeltaGP.kernel
            M.DeltaGP.kernel = kernel
        try:
            m.fit(Ul, yl, restarts=restarts, seed=0)
        finally:
            if kernel is not None:
                M.DeltaGP.kernel = old
        return lambda Ut: _sd(m.predict_level(Ut, len(levels) - 1))
    return fit


def _sd(mv):
    return mv[0], np.sqrt(mv[1])


def rbf_kernel(self):
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel
    nv = None if self.noise is None else self.noise / self.std ** 2
    n0, nb = E.noise_bounds(nv, "floor")
    return (ConstantKernel(1.0, E.CONST_BOUNDS) * RBF(np.full(self.d, 0.5), E.LENGTH_BOUNDS)
            + WhiteKernel(n0, nb))


def m32_kernel(self):
    from sklearn.gaussian_process.kernels import Matern, ConstantKernel, WhiteKernel
    nv = None if self.noise is None else self.noise / self.std ** 2
    n0, nb = E.noise_bounds(nv, "floor")
    return (ConstantKernel(1.0, E.CONST_BOUNDS) * Matern(np.full(self.d, 0.5), E.LENGTH_BOUNDS, nu=1.5)
            + WhiteKernel(n0, nb))


def iso_kernel(self):
    from sklearn.gaussian_process.kernels import Matern, ConstantKernel, WhiteKernel
    nv = None if self.noise is None else self.noise / self.std ** 2
    n0, nb = E.noise_bounds(nv, "floor")
    return (ConstantKernel(1.0, E.CONST_BOUNDS) * Matern(0.5, E.LENGTH_BOUNDS, nu=2.5)
            + WhiteKernel(n0, nb))


def coarse_gp(U, y, restarts=1):
    g = M.DeltaGP(3, kernel_family="ard").fit(U, y, restarts, 0)
    return g


def linear_link(levels=(0, 2), rho_fixed=None, trend=False):
    """y_fine = a + rho m_coarse(x) [+ b.x] + eps by least squares (a parametric discrepancy);
    variance: the regression's prediction variance + rho^2 v_coarse + s^2."""
    def design(X, m):
        """The regression's columns at inputs X with the coarse mean m there."""
        cols = [np.ones(len(X))]
        if trend:
            cols += [X[:, j] for j in range(3)]
        if rho_fixed is None:
            cols.append(m)
        return np.column_stack(cols)

    def fit(U, y):
        g = coarse_gp(U[levels[0]], y[levels[0]])
        Uf, yf = U[levels[-1]], y[levels[-1]]
        mp, vp = g.predict(Uf)
        F = design(Uf, mp)
        t = yf if rho_fixed is None else yf - rho_fixed * mp
        beta, *_ = np.linalg.lstsq(F, t, rcond=None)
        r = t - F @ beta
        dof = max(len(yf) - F.shape[1], 1)
        s2 = float(r @ r) / dof
        # floor the residual variance by the scaled coarse noise
        s2 = max(s2, g.noise_var() * (DXS[levels[-1]] / DXS[levels[0]]) ** 2)
        FtFi = np.linalg.pinv(F.T @ F)
        rho = beta[-1] if rho_fixed is None else rho_fixed

        def pred(Ut):
            m, v = g.predict(Ut)
            Ft = design(Ut, m)
            mu = Ft @ beta + (0 if rho_fixed is None else rho_fixed * m)
            var = s2 * (1 + np.einsum("ij,jk,ik->i", Ft, FtFi, Ft)) + rho ** 2 * v
            return mu, np.sqrt(var)
        return pred
    return fit


def nargp(levels=(0, 1, 2), restarts=1, n_mc=0, floor=True):
    """Perdikaris et al. 2017: level l's GP on [x, m_{l-1}(x)], kernel
    C1 k_f(f) k_x(x) + C2 k_d(x) + white; prediction with the level below's mean plugged in
    (n_mc = 0) or propagated by Monte Carlo over its marginal."""
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel as C, WhiteKernel, Matern
    from sklearn.gaussian_process import GaussianProcessRegressor

    def fit(U, y):
        gs = []
        g0 = M.DeltaGP(3, kernel_family="ard").fit(U[levels[0]], y[levels[0]], restarts, 0)
        nv0 = g0.noise_var()

        def pred_chain(Ut, upto):
            m, v = g0.predict(Ut)
            for (gp, mu_, sd_, lvl) in gs[:upto]:
                Z = np.column_stack([Ut, (m - mu_) / sd_])
                a, s = gp.predict(Z, return_std=True)
                # remove the white noise from the latent sd
                wn = gp.kernel_.k2.noise_level
                s2 = np.maximum(s ** 2 - wn, 0)
                m, v = a * sd_ + mu_, s2 * sd_ ** 2
            return m, v
        for k, li in enumerate(levels[1:], 1):
            Ul, yl = U[li], y[li]
            mprev, _ = pred_chain(Ul, len(gs))
            mu_, sd_ = float(np.mean(mprev)), float(np.std(mprev))
            ym, ys = float(np.mean(yl)), float(np.std(yl))
            floor_v = nv0 * (DXS[li] / DXS[levels[0]]) ** 2 / ys ** 2 if floor else 1e-8
            lo = min(max(floor_v, 1e-8), 0.99)
            kx = Matern(np.full(3, 0.5), E.LENGTH_BOUNDS, nu=2.5)
            kf = RBF(1.0, E.LENGTH_BOUNDS)
            from sklearn.gaussian_process.kernels import Kernel
            k = (C(1.0, E.CONST_BOUNDS) * _Proj(kf, [3]) * _Proj(kx, [0, 1, 2])
                 + C(0.1, E.CONST_BOUNDS) * _Proj(Matern(np.full(3, 0.5), E.LENGTH_BOUNDS, nu=2.5), [0, 1, 2]))
            k = k + WhiteKernel(max(lo, 1e-2) if lo < 1e-2 else lo, (lo, 1.0))
            Z = np.column_stack([Ul, (mprev - mu_) / sd_])
            gp = GaussianProcessRegressor(k, alpha=1e-10, n_restarts_optimizer=restarts, random_state=0)
            gp.fit(Z, (yl - ym) / ys)
            gs.append((gp, mu_, sd_, li))
            gs[-1] = (_Wrap(gp, ym, ys), mu_, sd_, li)

        def pred(Ut):
            if n_mc == 0:
                m, v = pred_chain(Ut, len(gs))
            else:
                rng = np.random.default_rng(0)
                m0, v0 = g0.predict(Ut)
                samples = m0[None, :] + np.sqrt(v0)[None, :] * rng.standard_normal((n_mc, len(Ut)))
                for (gp, mu_, sd_, lvl) in gs:
                    new = []
                    for s in samples:
                        a, sd = gp.predict(np.column_stack([Ut, (s - mu_) / sd_]), return_std=True)
                        new.append(a + sd * rng.standard_normal(len(Ut)))
                    samples = np.array(new)
                m, v = samples.mean(0), samples.var(0)
            wn = gs[-1][0].noise()
            return m, np.sqrt(v + wn)
        return pred
    return fit


class _Wrap:
    """GP on standardised target -> output units."""
    def __init__(self, gp, ym, ys):
        self.gp, self.ym, self.ys = gp, ym, ys
        self.kernel_ = gp.kernel_

    def predict(self, Z, return_std=False):
        a, s = self.gp.predict(Z, return_std=True)
        wn = self.gp.kernel_.k2.noise_level
        s = np.sqrt(np.maximum(s ** 2 - wn, 0))
        return a * self.ys + self.ym, s * self.ys

    def noise(self):
        return self.gp.kernel_.k2.noise_level * self.ys ** 2


from sklearn.gaussian_process.kernels import Kernel, Hyperparameter  # noqa


class _Proj(Kernel):
    """A kernel on some columns of the input."""
    def __init__(self, base, cols):
        self.base, self.cols = base, cols

    @property
    def hyperparameters(self):
        return [Hyperparameter("base__" + h.name, h.value_type, h.bounds, h.n_elements)
                for h in self.base.hyperparameters]

    @property
    def theta(self):
        return self.base.theta

    @theta.setter
    def theta(self, th):
        self.base.theta = th

    @property
    def bounds(self):
        return self.base.bounds

    def get_params(self, deep=True):
        p = {"base": self.base, "cols": self.cols}
        if deep:
            p.update({"base__" + k: v for k, v in self.base.get_params().items()})
        return p

    def __call__(self, X, Y=None, eval_gradient=False):
        X = np.asarray(X)[:, self.cols]
        Y = None if Y is None else np.asarray(Y)[:, self.cols]
        return self.base(X, Y, eval_gradient=eval_gradient)

    def diag(self, X):
        return self.base.diag(np.asarray(X)[:, self.cols])

    def is_stationary(self):
        return True

    def clone_with_theta(self, theta):
        import copy
        c = copy.deepcopy(self)
        c.theta = theta
        return c


def sf(level=2):
    def fit(U, y):
        g = M.DeltaGP(3, kernel_family="ard").fit(U[level], y[level], 1, 0)
        return lambda Ut: (g.predict(Ut)[0], np.sqrt(g.predict(Ut)[1] + g.noise_var()))
    return fit


# ---- CV -----------------------------------------------------------------------------------------

def same(a, b):
    return np.all(np.isclose(a, b, atol=1e-9), axis=1)


def cv(variant, U, y, target=2, drop_all=True):
    """Leave out each run of the target level (and, drop_all, the runs at that point on every
    level; levels above the target removed)."""
    U = U[:target + 1]
    y = y[:target + 1]
    res, zs = [], []
    for i in range(len(y[target])):
        x = U[target][i]
        Uc, yc = [], []
        for li in range(target + 1):
            keep = ~same(U[li], x[None, :]) if (drop_all or li == target) else np.ones(len(y[li]), bool)
            Uc.append(U[li][keep])
            yc.append(y[li][keep])
        pred = variant(Uc, yc)
        mu, sd = pred(x[None, :])
        res.append(y[target][i] - mu[0])
        zs.append(res[-1] / sd[0])
    return np.array(res), np.array(zs)


VARIANTS = {
    "ar1_3lev_matern52_floor (current)": ar1(),
    "ar1_3lev_nofloor": ar1(jitter_floor=False),
    "ar1_3lev_rbf": ar1(kernel=rbf_kernel),
    "ar1_3lev_matern32": ar1(kernel=m32_kernel),
    "ar1_3lev_iso52": ar1(kernel=iso_kernel),
    "ar1_2lev_04_02": ar1(levels=(0, 2)),
    "ar1_2lev_03_02": ar1(levels=(1, 2)),
    "linear_04_02 (y=a+rho m04)": linear_link((0, 2)),
    "offset_04_02 (y=a+m04)": linear_link((0, 2), rho_fixed=1.0),
    "offset+trend_04_02": linear_link((0, 2), rho_fixed=1.0, trend=True),
    "nargp_3lev": nargp(),
    "nargp_2lev_04_02": nargp(levels=(0, 2)),
    "sf_finest_only": sf(),
}


def main():
    target = int(sys.argv[1]) if len(sys.argv) > 1 else 2
    # the variants named T1_ are of the two coarser levels (target 1), the others of all three
    sel = sys.argv[2:] if len(sys.argv) > 2 else [
        k for k in VARIANTS if k.startswith("T1_") == (target == 1)]
    out = {}
    for name in sel:
        v = VARIANTS[name]
        row = {}
        allr, allz = [], []
        for ds in ("study2", "mflhs"):
            U, y = load(ds)
            try:
                r, z = cv(v, U, y, target)
            except Exception as e:  # a variant that cannot fit this set
                row[ds] = f"fail: {e}"
                continue
            row[ds] = {"rmse_pct": 100 * math.sqrt(np.mean(r ** 2)) / RANGE,
                       "rms_z": float(np.sqrt(np.mean(z ** 2))),
                       "cov95": float(np.mean(np.abs(z) <= 1.96)), "res_mm": (1e3 * r).round(1).tolist()}
            allr += list(r)
            allz += list(z)
        allr, allz = np.array(allr), np.array(allz)
        row["pooled"] = {"rmse_pct": 100 * math.sqrt(np.mean(allr ** 2)) / RANGE,
                         "rms_z": float(np.sqrt(np.mean(allz ** 2))),
                         "cov95": float(np.mean(np.abs(allz) <= 1.96))}
        out[name] = row
        print(f"{name:38s} " + "  ".join(
            f"{k}: {v['rmse_pct']:.2f}% z{v['rms_z']:.2f} c{v['cov95']:.2f}" if isinstance(v, dict) else f"{k}: {v}"
            for k, v in row.items()), flush=True)
        for ds in ("study2", "mflhs"):
            if isinstance(row.get(ds), dict):
                print(f"{'':40s}{ds} residuals mm {row[ds]['res_mm']}")
    json.dump(out, open(os.path.join(RUNS, f"cv_target{target}.json"), "w"), indent=1)


# ---- round 2: the discrepancy's kernel per level (the coarsest level keeps Matern 5/2 ARD) -------

def _kern(kind, self):
    from sklearn.gaussian_process.kernels import (ConstantKernel as C, DotProduct, Matern,
                                                  WhiteKernel, RBF)
    nv = None if self.noise is None else self.noise / self.std ** 2
    n0, nb = E.noise_bounds(nv, "floor")
    if kind == "ard52":
        core = C(1.0, E.CONST_BOUNDS) * Matern(np.full(self.d, 0.5), E.LENGTH_BOUNDS, nu=2.5)
    elif kind == "iso52":
        core = C(1.0, E.CONST_BOUNDS) * Matern(0.5, E.LENGTH_BOUNDS, nu=2.5)
    elif kind == "linear":
        core = C(1.0, E.CONST_BOUNDS) * DotProduct(1.0, (1e-2, 1e2))
    elif kind == "linear+iso52":
        core = (C(1.0, E.CONST_BOUNDS) * DotProduct(1.0, (1e-2, 1e2))
                + C(0.1, E.CONST_BOUNDS) * Matern(0.5, E.LENGTH_BOUNDS, nu=2.5))
    elif kind == "const":
        core = C(1.0, E.CONST_BOUNDS) * DotProduct(1.0, (1e-2, 1e2)) * 0 + C(1.0, E.CONST_BOUNDS)
    return core + WhiteKernel(n0, nb)


def ar1k(fine_kind, levels=(0, 1, 2), coarse_kind="ard52", jitter_floor=True):
    def kernel(self):
        return _kern(coarse_kind if self.noise is None else fine_kind, self)
    return ar1(levels=levels, jitter_floor=jitter_floor, kernel=kernel)


for _k in ("iso52", "linear", "linear+iso52"):
    VARIANTS[f"ar1_3lev_fine_{_k}"] = ar1k(_k)
    VARIANTS[f"ar1_2lev_04_02_fine_{_k}"] = ar1k(_k, levels=(0, 2))
VARIANTS["ar1_3lev_all_iso52"] = ar1k("iso52", coarse_kind="iso52")

def shared(intercept=True, free=False, kind="ard52"):
    """the finest level from the middle level's AR1 model and its discrepancy d = m03 - rho m04:
    y02 = m03 + [a] + kappa d(x) (free: y02 = a + b m04 + c m03)."""
    def fit(U, y):
        kern = (lambda self: _kern(kind, self))
        old = M.DeltaGP.kernel
        M.DeltaGP.kernel = kern
        try:
            m = M.OutputMF(OUT, DXS[:2], 3, None, True).fit(U[:2], y[:2], restarts=1, seed=0)
        finally:
            M.DeltaGP.kernel = old
        nv = m.levels[0].noise_var() * (DXS[2] / DXS[0]) ** 2

        def feats(Ut):
            m4, v4 = m.predict_level(Ut, 0, latent=True)
            m3, v3 = m.predict_level(Ut, 1, latent=True)
            if free:
                return np.column_stack([np.ones(len(Ut)), m4, m3]), 0 * m3, v3
            c = [np.ones(len(Ut))] if intercept else []
            return np.column_stack(c + [m3 - m.levels[1].rho * m4]), m3, v3
        F, off, _ = feats(U[2])
        t = y[2] - off
        beta, *_ = np.linalg.lstsq(F, t, rcond=None)
        r = t - F @ beta
        dof = max(len(t) - F.shape[1], 1)
        s2 = max(float(r @ r) / dof, nv)
        FtFi = np.linalg.pinv(F.T @ F)

        def pred(Ut):
            Ft, o, v3 = feats(Ut)
            mu = Ft @ beta + o
            return mu, np.sqrt(s2 * (1 + np.einsum("ij,jk,ik->i", Ft, FtFi, Ft)) + v3)
        return pred
    return fit


VARIANTS["shared_kappa_intercept"] = shared()
VARIANTS["shared_kappa_only"] = shared(intercept=False)
VARIANTS["regress_on_m04_m03"] = shared(free=True)
VARIANTS["shared_kappa_intercept_iso"] = shared(kind="iso52")

VARIANTS["ar1_3lev_iso (the code's kernel_family='iso')"] = ar1(family="iso")
VARIANTS["T1_ar1_iso (the code's kernel_family='iso')"] = ar1(levels=(0, 1), family="iso")
VARIANTS["T1_ar1_ard52 (current)"] = ar1(levels=(0, 1))
VARIANTS["T1_ar1_all_iso52"] = ar1k("iso52", levels=(0, 1), coarse_kind="iso52")
VARIANTS["T1_ar1_fine_iso52"] = ar1k("iso52", levels=(0, 1))
VARIANTS["T1_ar1_fine_linear"] = ar1k("linear", levels=(0, 1))
VARIANTS["T1_offset+trend"] = linear_link((0, 1), rho_fixed=1.0, trend=True)
VARIANTS["T1_offset"] = linear_link((0, 1), rho_fixed=1.0)
VARIANTS["T1_nofloor"] = ar1(levels=(0, 1), jitter_floor=False)
VARIANTS["T1_nargp"] = nargp(levels=(0, 1))


def rho1(levels=(0, 2), family="ard"):
    """rho = 1 fixed: the finest level is the coarsest's mean plus a discrepancy GP of the
    differences (noise floored by the coarsest level's noise x (dx ratio)^2)."""
    def fit(U, y):
        g0 = M.DeltaGP(3, kernel_family=family).fit(U[levels[0]], y[levels[0]], 1, 0)
        chain = [(g0, 0)]
        for li in levels[1:]:
            m_prev = _chain_mean(chain, U[li])
            floor = g0.noise_var() * (DXS[li] / DXS[levels[0]]) ** 2
            chain.append((M.DeltaGP(3, floor, family).fit(U[li], y[li] - m_prev, 1, 0), li))

        def pred(Ut):
            m = _chain_mean(chain, Ut)
            v = sum(g.predict(Ut)[1] for g, _ in chain) + chain[-1][0].noise_var()
            return m, np.sqrt(v)
        return pred
    return fit


def _chain_mean(chain, Ut):
    return sum(g.predict(Ut)[0] for g, _ in chain)


VARIANTS["rho1_gp_2lev_04_02"] = rho1()
VARIANTS["rho1_gp_3lev"] = rho1(levels=(0, 1, 2))
VARIANTS["T1_rho1_gp"] = rho1(levels=(0, 1))


main()
