"""A multi-fidelity emulator of FMU outputs over a ladder of particle spacings dx.

The model is the autoregressive one of Kennedy & O'Hagan (2000, Biometrika 87:1) in the
recursive form of Le Gratiet & Garnier (2014, Int. J. Uncertainty Quantification 4:5): with
the levels ordered from the coarsest (largest dx) to the finest,

    f_1(x) = delta_1(x),    f_l(x) = rho_l f_{l-1}(x) + delta_l(x)   (l = 2..L)

where delta_l are independent Gaussian processes and rho_l a constant. Each delta_l is a
scikit-learn GaussianProcessRegressor (kernel ConstantKernel * Matern(nu = 2.5) + WhiteKernel,
the noise term absorbing the FMU's lattice jitter) fitted on the level-l runs with f_{l-1}
replaced by the level-(l-1) posterior mean at those runs; rho_l maximises the profile likelihood
(delta_l's hyperparameters fitted by maximum marginal likelihood at each rho; delta_l's constant
mean the residuals' mean). The recursion is exact for nested designs (the runs of a level a
subset of those of the level below, which the design makes; Le Gratiet 2013, Stat. Comput.).
Prediction at level l: mean rho_l m_{l-1} + m_delta_l, latent variance rho_l^2 v_{l-1} +
v_delta_l, plus the level's fitted noise for the interval of a new run.

The kernel family (KERNELS): 'ard' (the default), a length scale per input of the unit box (the
single-fidelity emulator's), or 'iso', one for all inputs: fewer hyperparameters for a level of
a handful of runs. On the Vajont campaign's training runs the isotropic kernel cross-validated a
little better (docs/dss.md, "Choosing the model by cross-validation"), by less than the CV's own
spread and not on the hold-out; where the runs resolve an anisotropic response (the ladder
stand-in of the tests) it is clearly worse. So ARD stays the default.

The noise: every level's WhiteKernel takes the FMU's lattice jitter (the lattice is anchored
at the reservoir level, so the run-up jitters by a fraction of a particle spacing over the
box). The coarsest level has the most runs and its noise is fitted well; a finer level's few
runs cannot tell jitter from response, and its delta GP would interpolate the jitter with
length scales of a few % of the box. So the noise of level l has a lower bound (a floor, the
likelihood may raise it): the coarsest level's fitted noise variance times (dx_l / dx_1)^2,
i.e. a jitter sd proportional to the spacing (measured: 7.1 mm fitted at dx = 0.04 in the
campaign of docs/dss.md, 2.81 mm by the jitter scan at dx = 0.015 of the earlier campaign:
178 and 187 mm per m of dx). A measured floor per dx (noise=) replaces it;
jitter_floor=False switches it off.

The dx -> 0 value: Richardson extrapolation of the three finest levels a > b > c (dx), with
f(dx) = f_0 + C dx^p. The observed order p(x) solves
(f_a - f_b) / (f_b - f_c) = (dx_a^p - dx_b^p) / (dx_b^p - dx_c^p) at each of N_ORDER random
points of the box (from the emulator's means); where the ratio is not positive (the levels do
not converge monotonically there) there is no order, and that fraction is reported. The
extrapolation uses the median order over the box, f_0 = (1 + c) f_c - c f_b with
c = dx_c^p / (dx_b^p - dx_c^p); its error has two terms: the GP's (f_b and f_c are correlated
through rho: f_0 = ((1 + c) rho_c - c) f_b + (1 + c) delta_c, whose variance follows) and the
order's, the spread of f_0 when p runs over the 2.5-97.5 % quantiles of the box's orders (a
95 % range, entered as a normal sd of half the range / 1.96). With two levels only an order
must be given (and its range), else there is no extrapolation.

Interval calibration: the leave-one-out residuals of each level (closed form for a GP with its
hyperparameters fixed: e_i = [K^-1 y]_i / [K^-1]_ii, variance 1 / [K^-1]_ii, plus rho^2 times
the level below's latent variance there) standardised by their predicted sd; the rms of these
z-scores is the level's variance scale. A scale above 1 (intervals too narrow on the runs the
model was fitted on) widens that level's intervals (and the extrapolation's GP term) by it; a
scale below 1 is reported and not applied: with a dozen fine runs its estimate is too uncertain
to narrow intervals on. The hold-out runs never enter it.

Saved as JSON (schema mixsph-mf-emulator, version 2; version 1, before the kernel family was
saved, is read as 'ard'): the levels' dx, the inputs and their box, per output the kernel
family, per output and level the training runs, rho, the delta GP's standardisation and
hyperparameters (theta), the calibration and the order of convergence; the FMU's GUID and
SHA-256. Loading rebuilds every GP with optimizer=None (the same predictions) and refuses an FMU
of another GUID.
"""

from __future__ import annotations

import json
import math
import os
import time

import numpy as np

from . import emulator as E

SCHEMA = "mixsph-mf-emulator"
SCHEMA_VERSION = 2
READABLE_VERSIONS = (1, 2)           # version 1 files have the ARD kernel
KERNELS = ("ard", "iso")             # the delta GPs' kernel family (module doc)
DEFAULT_KERNEL = "ard"
Z95 = E.Z95
EXTRAPOLATED = "extrapolated"       # the name of the dx -> 0 level
ORDER_BOUNDS = (0.25, 6.0)           # the search range of the observed order p
N_ORDER = 2000                       # box points the order's spread is measured at
RHO_GRID = 9                         # the profile likelihood's start grid of rho
RHO_SPAN = 2.0                       # ... over the least-squares slope +- RHO_SPAN max(1, |slope|)
RHO_GRID_WARM = 5                    # ... about a previous fit's rho (a design's refits)
RHO_SPAN_WARM = 0.25
RHO_TOL = 1e-3


class MFError(E.EmulatorError):
    pass


def _check_kernel_family(family):
    if family not in KERNELS:
        raise MFError(f"unknown kernel family {family!r} ({', '.join(KERNELS)})")


# ---- one level's discrepancy GP ---------------------------------------------------------------------

class DeltaGP:
    """The GP of one level's discrepancy delta_l = y_l - rho_l m_{l-1} (for the coarsest level,
    the level itself), standardised by its own mean and sd."""

    def __init__(self, d, noise=None, kernel_family=DEFAULT_KERNEL):
        _check_kernel_family(kernel_family)
        self.d = d
        self.noise = noise          # a measured noise variance (output units^2) as the floor
        self.kernel_family = kernel_family
        self.rho = 0.0              # 0 for the coarsest level
        self.mean, self.std = 0.0, 1.0
        self.gp = None

    def kernel(self):
        nv = None if self.noise is None else self.noise / self.std ** 2
        if self.kernel_family == "ard":
            return E.build_kernel("product", ["continuous"] * self.d, nv, "floor")
        from sklearn.gaussian_process.kernels import ConstantKernel, Matern, WhiteKernel
        n0, nb = E.noise_bounds(nv, "floor")
        return (ConstantKernel(1.0, E.CONST_BOUNDS)
                * Matern(length_scale=0.5, length_scale_bounds=E.LENGTH_BOUNDS, nu=2.5)
                + WhiteKernel(noise_level=n0, noise_level_bounds=nb))

    def fit(self, U, t, restarts, seed, theta=None):
        self.mean = float(np.mean(t))
        self.std = float(np.std(t)) if np.std(t) > 0 else 1.0
        k = self.kernel()
        if theta is not None and len(theta) == len(k.theta):
            k = k.clone_with_theta(np.clip(np.asarray(theta), k.bounds[:, 0], k.bounds[:, 1]))
        self.gp = E._fit_quiet(E._gp(k, restarts, seed), U, (t - self.mean) / self.std)
        return self

    def rebuild(self, U, t, theta, mean, std):
        self.mean, self.std = float(mean), float(std)
        k = self.kernel().clone_with_theta(np.asarray(theta, float))
        self.gp = E._gp(k, 0, 0, optimizer=False).fit(U, (t - self.mean) / self.std)
        return self

    @property
    def theta(self):
        return self.gp.kernel_.theta

    def noise_var(self) -> float:
        return float(self.gp.kernel_.k2.noise_level) * self.std ** 2

    def predict(self, U):
        """Mean and latent variance (without the noise) in output units."""
        from scipy.linalg import solve_triangular
        gp = self.gp
        k1 = gp.kernel_.k1
        Ks = k1(U, gp.X_train_)
        m = Ks @ gp.alpha_
        V = solve_triangular(gp.L_, Ks.T, lower=True, check_finite=False)
        v = np.maximum(k1.diag(U) - np.einsum("ij,ij->j", V, V), 0.0)
        return m * self.std + self.mean, v * self.std ** 2

    def cov(self, Ua, Ub=None):
        """The latent posterior covariance between the rows of Ua and Ub (default Ua; output
        units^2)."""
        from scipy.linalg import solve_triangular
        gp = self.gp
        k1 = gp.kernel_.k1
        Va = solve_triangular(gp.L_, k1(gp.X_train_, Ua), lower=True, check_finite=False)
        if Ub is None:
            return (k1(Ua) - Va.T @ Va) * self.std ** 2
        Vb = solve_triangular(gp.L_, k1(gp.X_train_, Ub), lower=True, check_finite=False)
        return (k1(Ua, Ub) - Va.T @ Vb) * self.std ** 2

    def loo(self):
        """Leave-one-out residuals (observed minus predicted) and predictive variances of the
        training targets, hyperparameters fixed (closed form; the variance includes the noise)."""
        from scipy.linalg import cho_solve
        gp = self.gp
        Kinv = cho_solve((gp.L_, True), np.eye(len(gp.X_train_)))
        d = np.diag(Kinv)
        return (gp.alpha_ / d) * self.std, (1.0 / d) * self.std ** 2

    def to_json(self):
        k = self.gp.kernel_
        return {"rho": self.rho, "mean": self.mean, "std": self.std, "theta": k.theta.tolist(),
                "kernel": str(k), "hyperparameters": E._hyper(k), "noise_floor": self.noise,
                "log_marginal_likelihood": float(self.gp.log_marginal_likelihood_value_)}


# ---- Richardson extrapolation ----------------------------------------------------------------------

def _ratio_of_order(p, dxa, dxb, dxc):
    return (dxa ** p - dxb ** p) / (dxb ** p - dxc ** p)


def observed_order(fa, fb, fc, dxa, dxb, dxc):
    """The order p with (fa - fb)/(fb - fc) = (dxa^p - dxb^p)/(dxb^p - dxc^p), per element
    (NaN where the ratio is not positive; clipped to ORDER_BOUNDS). The right side increases
    monotonically with p, so a bisection on log p finds it."""
    fa, fb, fc = (np.atleast_1d(np.asarray(a, float)) for a in (fa, fb, fc))
    with np.errstate(divide="ignore", invalid="ignore"):
        R = (fa - fb) / (fb - fc)
    p = np.full(R.shape, np.nan)
    ok = np.isfinite(R) & (R > 0)
    lo = np.full(ok.sum(), math.log(ORDER_BOUNDS[0]))
    hi = np.full(ok.sum(), math.log(ORDER_BOUNDS[1]))
    r = R[ok]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        up = _ratio_of_order(np.exp(mid), dxa, dxb, dxc) < r
        lo = np.where(up, mid, lo)
        hi = np.where(up, hi, mid)
    p[ok] = np.exp(0.5 * (lo + hi))
    return p


def richardson_c(p, dxb, dxc, dx=0.0):
    """c of f(dx) = (1 + c) f_c - c f_b for the order p (the two finest spacings dxb > dxc; dx
    below them, default 0: the limit)."""
    return (dxc ** p - dx ** p) / (dxb ** p - dxc ** p)


# ---- the emulator --------------------------------------------------------------------------------------

class OutputMF:
    """The recursive model of one output over the levels (coarse to fine)."""

    def __init__(self, name, dxs, d, noise=None, jitter_floor=True, kernel_family=DEFAULT_KERNEL):
        _check_kernel_family(kernel_family)
        self.kernel_family = kernel_family
        self.name = name
        self.dxs = list(dxs)
        self.d = d
        self.levels: list[DeltaGP] = []
        self.U: list[np.ndarray] = []         # unit-box training inputs per level
        self.y: list[np.ndarray] = []
        self.noise = noise or {}              # dx -> measured noise variance (floor)
        # without a measured one, the floor of level l's noise is the coarsest level's fitted
        # noise scaled by (dx_l / dx_1)^2 (module doc, "The noise")
        self.jitter_floor = bool(jitter_floor)
        self.scale = [1.0] * len(self.dxs)    # the applied variance scale (sd factor) per level
        self.calibration: list[dict] = []
        self.order: dict = {}

    # fitting
    def fit(self, U_levels, y_levels, restarts=2, seed=0, thetas=None, rhos=None):
        """Fit the levels from the coarsest up. thetas, rhos: a previous fit's per level (the
        optimiser's start, and the centre of a narrower rho search: a design's refits)."""
        self.U = [np.asarray(u, float) for u in U_levels]
        self.y = [np.asarray(v, float) for v in y_levels]
        self.levels = []
        for li, (U, y) in enumerate(zip(self.U, self.y)):
            if len(y) < 3:
                raise MFError(f"{self.name}: level dx = {self.dxs[li]:g} has {len(y)} runs; at "
                              f"least 3 are needed")
            floor = self.noise.get(self.dxs[li])
            if floor is None and li > 0 and self.jitter_floor:
                floor = self.levels[0].noise_var() * (self.dxs[li] / self.dxs[0]) ** 2
            g = DeltaGP(self.d, floor, self.kernel_family)
            th = thetas[li] if thetas and li < len(thetas) else None
            if li == 0:
                g.fit(U, y, restarts, seed, th)
            else:
                m_prev, _ = self.predict_level(U, li - 1, latent=True)
                r_prev = rhos[li] if rhos and li < len(rhos) else None
                rho = self._profile_rho(g, U, y, m_prev, restarts, seed, th, r_prev)
                g.fit(U, y - rho * m_prev, restarts, seed, th)
                g.rho = rho
            self.levels.append(g)
        self.calibrate()
        return self

    @staticmethod
    def _profile_rho(g, U, y, m_prev, restarts, seed, theta, centre=None):
        """rho_l by maximum profile likelihood: for a given rho the delta GP's hyperparameters
        are fitted (maximum marginal likelihood of y - rho m_prev, standardised); the
        likelihood of y is that less n log(sd) (the standardisation's Jacobian). A grid of
        RHO_GRID values about the least-squares slope, then a bounded scalar search between the
        best value's neighbours (scipy.optimize.minimize_scalar). With a centre (a previous
        fit's rho) the grid is RHO_GRID_WARM values over centre +- RHO_SPAN_WARM max(1, |centre|)."""
        from scipy.optimize import minimize_scalar
        F = np.column_stack([np.ones(len(y)), m_prev])
        if centre is None:
            r0 = float(np.linalg.lstsq(F, y, rcond=None)[0][1])
            span, n_grid = RHO_SPAN * max(1.0, abs(r0)), RHO_GRID
        else:
            r0 = float(centre)
            span, n_grid = RHO_SPAN_WARM * max(1.0, abs(r0)), RHO_GRID_WARM
        cache = {}
        # the profile's fits: each from the default start (or theta) and one random restart
        # (warm starts from the neighbouring rho's fit stick in a worse optimum: measured on
        # the three-level stand-in of the tests); the final fit at the chosen rho has the full
        # restarts

        def nll(rho):
            key = round(float(rho), 12)
            if key not in cache:
                g.fit(U, y - rho * m_prev, min(restarts, 1), seed, theta)
                cache[key] = -(float(g.gp.log_marginal_likelihood_value_)
                               - len(y) * math.log(g.std))
            return cache[key]
        grid = r0 + span * np.linspace(-1.0, 1.0, n_grid)
        vals = [nll(r) for r in grid]
        i = int(np.argmin(vals))
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
        res = minimize_scalar(nll, bounds=(lo, hi), method="bounded",
                              options={"xatol": RHO_TOL * max(1.0, abs(r0)), "maxiter": 12})
        return float(res.x) if res.fun <= vals[i] else float(grid[i])

    def rebuild(self, U_levels, y_levels, docs):
        self.U = [np.asarray(u, float) for u in U_levels]
        self.y = [np.asarray(v, float) for v in y_levels]
        self.levels = []
        for li, (U, y, doc) in enumerate(zip(self.U, self.y, docs)):
            g = DeltaGP(self.d, doc.get("noise_floor"), self.kernel_family)
            t = y if li == 0 else y - doc["rho"] * self.predict_level(U, li - 1, latent=True)[0]
            g.rebuild(U, t, doc["theta"], doc["mean"], doc["std"])
            g.rho = float(doc["rho"])
            self.levels.append(g)
        return self

    def calibrate(self):
        """The leave-one-out z-scores of every level and the variance scale applied (module
        doc)."""
        self.calibration, self.scale = [], []
        for li, g in enumerate(self.levels):
            e, v = g.loo()
            if li > 0:
                _, v_prev = self.predict_level(self.U[li], li - 1, latent=True)
                v = v + g.rho ** 2 * v_prev
            z = e / np.sqrt(v)
            rms = float(np.sqrt(np.mean(z ** 2)))
            self.scale.append(max(1.0, rms))
            self.calibration.append({
                "dx": self.dxs[li], "n": int(len(z)), "loo_rmse": float(np.sqrt(np.mean(e ** 2))),
                "loo_rms_z": rms, "loo_coverage95": float(np.mean(np.abs(z) <= Z95)),
                "scale_applied": max(1.0, rms)})

    # prediction
    def linear_form(self, level, dx=0.0, latent=False) -> dict:
        """A level's prediction as a linear form of the delta GPs (independent): mean =
        sum_k coef_k m_k, latent variance sum_k coef_k^2 v_k, predictive variance (latent +
        noise) scale^2 + (sum_k order_k m_k)^2 (the order's term, extrapolation only). level: a
        level index or EXTRAPOLATED (to dx, default 0). The one place the recursion and the
        Richardson extrapolation are composed: predict_level, predict_extrapolated, the design's
        target weights and the study page's in-browser evaluation (html_report) all use it."""
        rho = [g.rho for g in self.levels]
        if level == EXTRAPOLATED:
            if not self.order:
                raise MFError(f"{self.name}: no extrapolation: it needs three levels or a given "
                              f"order (--order)")
            t = len(self.levels) - 1
            a, b = self.extrapolation_coeffs(self.order["p"], dx)
            below = [float(np.prod(rho[k + 1:t])) for k in range(t)]     # f_{t-1} in delta_k
            coef = [a * w for w in below] + [b]
            # f(p) = f_c + c(p) (f_c - f_b), f_c - f_b = (rho_t - 1) f_{t-1} + delta_t: the
            # spread of f between the order's 2.5 and 97.5 % values, as a normal sd
            c_lo = richardson_c(self.order["p_lo"], self.dxs[-2], self.dxs[-1], dx)
            c_hi = richardson_c(self.order["p_hi"], self.dxs[-2], self.dxs[-1], dx)
            d = (c_lo - c_hi) / (2 * Z95)
            order = [d * (rho[t] - 1.0) * w for w in below] + [d]
        else:
            t = int(level)
            coef = [float(np.prod(rho[k + 1:t + 1])) for k in range(t + 1)]
            order = None
        form = {"level": level, "coef": coef, "order": order}
        if not latent:
            form["noise"] = self.levels[t].noise_var()
            form["scale"] = float(self.scale[t])
        return form

    def predict_form(self, U, form, with_terms=False):
        """Mean and variance of a linear form (linear_form) at unit-box inputs U; latent when
        the form has no noise; with_terms also the GP's and the order's variance terms."""
        mv = [g.predict(U) for g in self.levels[:len(form["coef"])]]
        mean = sum(c * m for c, (m, _) in zip(form["coef"], mv))
        v = sum(c * c * vk for c, (_, vk) in zip(form["coef"], mv))
        if "noise" not in form:
            return mean, v
        v_gp = (v + form["noise"]) * form["scale"] ** 2
        v_order = 0.0 * v_gp
        if form["order"] is not None:
            v_order = sum(u * m for u, (m, _) in zip(form["order"], mv)) ** 2
        if with_terms:
            return mean, v_gp + v_order, v_gp, v_order
        return mean, v_gp + v_order

    def predict_level(self, U, li, latent=False):
        """Mean and variance of level li (latent: without the level's noise and uncalibrated;
        else the calibrated predictive variance of a new run)."""
        return self.predict_form(U, self.linear_form(li, latent=latent))

    def extrapolation_coeffs(self, p, dx=0.0):
        """(a, b) of f(dx) = a f_{L-1} + b delta_L for the order p (dx below the ladder)."""
        dxb, dxc = self.dxs[-2], self.dxs[-1]
        c = richardson_c(p, dxb, dxc, dx)
        return (1 + c) * self.levels[-1].rho - c, 1 + c

    def estimate_order(self, seed=0, order=None):
        """The observed order over N_ORDER random points of the box (module doc), or a given
        order: {'p': central, 'p_lo', 'p_hi', 'valid_fraction', ...}."""
        if order is not None:
            p, lo, hi = order
            self.order = {"p": float(p), "p_lo": float(lo), "p_hi": float(hi), "source": "given"}
            return self.order
        if len(self.levels) < 3:
            self.order = {}
            return self.order
        U = np.random.default_rng(seed).random((N_ORDER, self.d))
        f = [self.predict_level(U, li, latent=True)[0] for li in (len(self.levels) - 3,
                                                                 len(self.levels) - 2,
                                                                 len(self.levels) - 1)]
        p = observed_order(*f, *self.dxs[-3:])
        ok = np.isfinite(p)
        frac = float(np.mean(ok))
        if ok.sum() < N_ORDER // 2:
            # the levels do not converge monotonically over most of the box: the order is
            # unknown within the search range
            lo, hi = ORDER_BOUNDS
            pc = math.sqrt(lo * hi)
            src = "the search range (monotone convergence at under half the box)"
        else:
            lo, pc, hi = (float(q) for q in np.quantile(p[ok], [0.025, 0.5, 0.975]))
            src = "observed"
        self.order = {"p": pc, "p_lo": lo, "p_hi": hi, "valid_fraction": frac,
                      "source": src, "levels_dx": self.dxs[-3:],
                      "p_quartiles": (np.quantile(p[ok], [0.25, 0.75]).tolist()
                                      if ok.any() else None)}
        return self.order

    def predict_extrapolated(self, U, with_terms=False, dx=0.0):
        """Mean and predictive variance of the value extrapolated to dx (default 0, the
        limit; a dx below the ladder's finest checks the extrapolation against runs there)
        (module doc); with_terms also the GP's and the order's variance terms."""
        return self.predict_form(U, self.linear_form(EXTRAPOLATED, dx), with_terms=with_terms)

    def sample(self, U, n_draws, level, rng):
        """Joint posterior draws (len(U) x n_draws) of a level (index) or the extrapolation
        (EXTRAPOLATED): the levels' latent covariances composed by the recursion, the noise and
        the calibration scale on top; for the extrapolation every draw takes its own order
        from the box's orders (a normal on the log scale through the 2.5-97.5 % range)."""
        top = len(self.levels) - 1 if level == EXTRAPOLATED else int(level)
        f = prev = None
        for k in range(top + 1):
            g = self.levels[k]
            C = g.cov(U)
            C[np.diag_indices_from(C)] += 1e-10 * max(1.0, float(np.mean(np.diag(C))))
            d = g.predict(U)[0][:, None] + _mvn(C, n_draws, rng)
            prev = f if f is not None else d
            f = d if k == 0 else g.rho * f + d
        noise = rng.normal(0.0, math.sqrt(self.levels[top].noise_var()), f.shape)
        if level != EXTRAPOLATED:
            mean, _ = self.predict_level(U, top, latent=True)
            # the calibration scale widens the spread about the mean
            return mean[:, None] + self.scale[top] * (f - mean[:, None] + noise)
        # the GP's part at the central order, widened by the calibration scale; each draw's
        # own order moves it by the Richardson term
        mean, _ = self.predict_extrapolated(U)

        def f0(c):
            return (1 + c) * f - c * prev
        c_mid = richardson_c(self.order["p"], self.dxs[-2], self.dxs[-1])
        lo, hi = math.log(self.order["p_lo"]), math.log(self.order["p_hi"])
        pk = np.exp(rng.normal(0.5 * (lo + hi), max(hi - lo, 1e-12) / (2 * Z95), n_draws))
        ck = richardson_c(pk, self.dxs[-2], self.dxs[-1])[None, :]
        gp_part = mean[:, None] + self.scale[top] * (f0(c_mid) - mean[:, None] + noise)
        return gp_part + (f0(ck) - f0(c_mid))

    def to_json(self):
        return {"levels": [{"dx": dx, **g.to_json(), "n": int(len(y))}
                           for dx, g, y in zip(self.dxs, self.levels, self.y)],
                "calibration": self.calibration, "scale": self.scale, "order": self.order,
                "jitter_floor": self.jitter_floor, "kernel_family": self.kernel_family}


def _mvn(C, n, rng):
    try:
        L = np.linalg.cholesky(C)
    except np.linalg.LinAlgError:
        w, V = np.linalg.eigh(C)
        L = V * np.sqrt(np.maximum(w, 0.0))
    return L @ rng.standard_normal((C.shape[0], n))


class MFEmulator:
    """Outputs' multi-fidelity models over the same inputs, box and levels (dx, coarse to
    fine); the training runs of a level are X[level] (raw inputs) and Y[level][output]."""

    def __init__(self, inputs, box, dxs, X: list, Y: list, fmu=None, settings=None):
        self.inputs = list(inputs)
        self.box = np.asarray(box, float)
        order = np.argsort(-np.asarray(dxs, float))
        self.dxs = [float(dxs[i]) for i in order]
        self.X = [np.asarray(X[i], float) for i in order]
        self.Y = [{k: np.asarray(v, float) for k, v in Y[i].items()} for i in order]
        self.fmu = dict(fmu or {})
        self.settings = dict(settings or {})
        self.models: dict[str, OutputMF] = {}
        if len(self.dxs) < 2:
            raise MFError("a multi-fidelity emulator needs runs at two or more spacings dx")
        if len(set(self.dxs)) != len(self.dxs):
            raise MFError(f"the levels' dx are not distinct: {self.dxs}")
        if np.any(self.box[:, 1] <= self.box[:, 0]):
            raise MFError("an input of the box does not vary (lo >= hi)")

    def unit(self, X):
        return (np.asarray(X, float) - self.box[:, 0]) / (self.box[:, 1] - self.box[:, 0])

    def out_of_box(self, X, tol=1e-9):
        X = np.atleast_2d(np.asarray(X, float))
        span = self.box[:, 1] - self.box[:, 0]
        bad = (X < self.box[:, 0] - tol * span) | (X > self.box[:, 1] + tol * span) | ~np.isfinite(X)
        names = np.array(self.inputs)
        return np.array([",".join(names[r]) for r in bad], dtype=object)

    def level_index(self, level) -> int | str:
        """A level given as its dx (a number), 'finest', or 'extrapolated' (the limit); a dx
        below the finest level's is the extrapolation to that dx: ('extrapolated', dx)."""
        if level in (EXTRAPOLATED, "dx0", "0", 0, 0.0):
            return EXTRAPOLATED
        if level in (None, "finest"):
            return len(self.dxs) - 1
        try:
            dx = float(level)
        except (TypeError, ValueError):
            dx = math.nan
        for i, d in enumerate(self.dxs):
            if math.isclose(d, dx, rel_tol=1e-9):
                return i
        if 0 < dx < self.dxs[-1]:
            return (EXTRAPOLATED, dx)
        raise MFError(f"no level {level} (the levels: {', '.join(f'{d:g}' for d in self.dxs)}, "
                      f"finest, {EXTRAPOLATED}, or a dx below {self.dxs[-1]:g})")

    def fit_output(self, name, restarts=2, seed=0, noise=None, order=None, thetas=None,
                   rhos=None, jitter_floor=True, kernel_family=DEFAULT_KERNEL):
        U, y = [], []
        for li in range(len(self.dxs)):
            yy = self.Y[li][name]
            ok = np.isfinite(yy)
            U.append(self.unit(self.X[li][ok]))
            y.append(yy[ok])
        m = OutputMF(name, self.dxs, len(self.inputs), noise, jitter_floor, kernel_family)
        m.fit(U, y, restarts=restarts, seed=seed, thetas=thetas, rhos=rhos)
        m.estimate_order(seed=seed, order=order)
        self.models[name] = m
        return m

    def predict(self, X, output, level="finest", with_terms=False):
        """(mean, sd) of the output at a level (a dx of the ladder, 'finest', 'extrapolated' or
        a dx below the ladder) for raw inputs X; with_terms, at an extrapolated level, also the
        sd of the GP's and of the order's terms."""
        m = self._model(output)
        U = self.unit(np.atleast_2d(X))
        li = self.level_index(level)
        if li == EXTRAPOLATED or isinstance(li, tuple):
            dx = 0.0 if li == EXTRAPOLATED else li[1]
            mu, v, vg, vo = m.predict_extrapolated(U, with_terms=True, dx=dx)
            return (mu, np.sqrt(v), np.sqrt(vg), np.sqrt(vo)) if with_terms else (mu, np.sqrt(v))
        mu, v = m.predict_level(U, li)
        return mu, np.sqrt(v)

    def _model(self, output):
        if output not in self.models:
            raise MFError(f"no emulator of {output!r} (this file has {', '.join(self.models)})")
        return self.models[output]

    # ---- save / load --------------------------------------------------------------------------

    def to_json(self) -> dict:
        return {
            **E.file_header(SCHEMA, SCHEMA_VERSION),
            "fmu": self.fmu, "settings": self.settings,
            "model": "recursive autoregressive co-kriging (Kennedy & O'Hagan 2000; Le Gratiet & "
                     "Garnier 2014); delta GPs ConstantKernel*Matern(nu=2.5; isotropic or "
                     "anisotropic: each output's kernel_family)+WhiteKernel; Richardson "
                     "extrapolation of the three finest levels",
            "inputs": [{"name": n, "lo": float(b[0]), "hi": float(b[1])}
                       for n, b in zip(self.inputs, self.box)],
            "levels": [{"dx": dx, "X": X.tolist(),
                        "Y": {k: [None if not np.isfinite(v) else float(v) for v in y]
                              for k, y in Y.items()}}
                       for dx, X, Y in zip(self.dxs, self.X, self.Y)],
            "outputs": {name: m.to_json() for name, m in self.models.items()},
        }

    def save(self, path):
        tmp = path + ".tmp"
        with open(tmp, "w") as f:
            json.dump(E._jsonable(self.to_json()), f, indent=1)
        os.replace(tmp, path)

    @classmethod
    def from_json(cls, doc):
        if doc.get("schema") != SCHEMA:
            raise MFError(f"not a {SCHEMA} file (schema {doc.get('schema')!r})")
        if doc.get("schema_version") not in READABLE_VERSIONS:
            readable = ", ".join(map(str, READABLE_VERSIONS))
            raise MFError(f"multi-fidelity emulator schema version {doc.get('schema_version')} is "
                          f"not one this code reads ({readable}): refit it")
        inp = doc["inputs"]
        lv = doc["levels"]
        em = cls([i["name"] for i in inp], [(i["lo"], i["hi"]) for i in inp],
                 [x["dx"] for x in lv], [x["X"] for x in lv],
                 [{k: np.array([np.nan if v is None else v for v in y], float)
                   for k, y in x["Y"].items()} for x in lv], doc.get("fmu"), doc.get("settings"))
        for name, o in doc["outputs"].items():
            U, y = [], []
            for li in range(len(em.dxs)):
                yy = em.Y[li][name]
                ok = np.isfinite(yy)
                U.append(em.unit(em.X[li][ok]))
                y.append(yy[ok])
            # version 1 had the ARD kernel and did not save its family
            m = OutputMF(name, em.dxs, len(em.inputs), jitter_floor=o.get("jitter_floor", True),
                         kernel_family=o.get("kernel_family", "ard"))
            m.rebuild(U, y, o["levels"])
            m.calibration, m.scale, m.order = o["calibration"], o["scale"], o["order"]
            em.models[name] = m
        return em


def load(path, fmu_path=None, check_fmu=True) -> MFEmulator:
    """The emulator of a JSON file; with check_fmu the FMU must have the GUID it was fitted on
    (another GUID: emulator.GuidMismatch)."""
    with open(path) as f:
        doc = json.load(f)
    if check_fmu:
        want = (doc.get("fmu") or {}).get("guid")
        if fmu_path is None or not os.path.isfile(fmu_path):
            raise MFError(f"FMU {fmu_path} not found: the emulator {path} must be checked against "
                          f"the FMU it emulates (--fmu FILE, or --no-fmu-check)")
        have = E.fmu_identity(fmu_path)
        if want != have["guid"]:
            raise E.GuidMismatch(
                f"the emulator {path} was fitted on the FMU with GUID {want}, but {fmu_path} has "
                f"GUID {have['guid']}: its predictions would be of another model. Refit it on "
                f"this FMU's runs or give the FMU it was fitted on with --fmu")
    return MFEmulator.from_json(doc)


def from_results(df, inputs, dxs, outputs, box=None, fmu=None, settings=None) -> MFEmulator:
    """An (unfitted) emulator of the ok runs of a results table with a dx column, the runs
    assigned to the levels dxs (runs at another dx are left out)."""
    df = df[df["status"] == "ok"] if "status" in df.columns else df
    for n in list(inputs) + ["dx"] + list(outputs):
        if n not in df.columns:
            raise MFError(f"{n!r} is not a column of the results")
    X, Y = [], []
    for dx in dxs:
        sel = df[np.isclose(df["dx"].astype(float), float(dx), rtol=1e-9, atol=0)]
        if sel.empty:
            raise MFError(f"no ok runs at dx = {dx:g}")
        X.append(sel[list(inputs)].astype(float).to_numpy())
        Y.append({o: sel[o].astype(float).to_numpy() for o in outputs})
    if box is None:
        allx = np.vstack(X)
        box = np.column_stack([allx.min(axis=0), allx.max(axis=0)])
    else:
        box = np.asarray([box[n] for n in inputs], float)
    return MFEmulator(inputs, box, dxs, X, Y, fmu=fmu, settings=settings)


# ---- risk and sensitivity ----------------------------------------------------------------------

def exceedance(em: MFEmulator, output, dists: dict, fixed: dict, crest, level=EXTRAPOLATED,
               n=100_000, n_joint=1000, n_draws=200, seed=0, z_grid=None) -> dict:
    """P(output > crest) at a level when the inputs follow the distributions: the mean over n
    samples of Phi((mu - crest) / sd) (the extrapolation's error included in sd), with the band
    from joint posterior draws at n_joint of them (OutputMF.sample; each draw of the
    extrapolation has its own order), as emulator.exceedance does for one level."""
    from scipy.stats import norm
    m = em._model(output)
    li = em.level_index(level)
    if isinstance(li, tuple):
        raise MFError("the risk is of a level of the ladder or of the limit (extrapolated)")
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    X = _inputs(em, dists, fixed, np.clip(rng.random((n, len(dists))), 1e-12, 1 - 1e-12))
    U = em.unit(X)
    mu, v = m.predict_extrapolated(U) if li == EXTRAPOLATED else m.predict_level(U, li)
    sd = np.sqrt(v)
    q = norm.sf((crest - mu) / np.maximum(sd, 1e-300))
    p = float(np.mean(q))
    nj = min(n_joint, n)
    draws = m.sample(U[:nj], n_draws, li, np.random.default_rng([seed, 1]))
    ps = (draws > crest).mean(axis=0)
    lo, hi = np.quantile(ps - ps.mean(), [0.025, 0.975])
    res = {"output": output, "level": level, "crest": crest, "n": n, "p": p,
           "p_lo": float(np.clip(p + lo, 0, 1)), "p_hi": float(np.clip(p + hi, 0, 1)),
           "p_mean_only": float(np.mean(mu > crest)), "mc_se": float(np.std(q) / math.sqrt(n)),
           "n_joint": nj, "n_draws": n_draws, "p_draws_sd": float(np.std(ps)),
           "out_of_box_fraction": float(np.mean(em.out_of_box(X) != ""))}
    if z_grid is not None:
        z = np.asarray(z_grid, float)
        pc = np.array([np.mean(norm.sf((zz - mu) / np.maximum(sd, 1e-300))) for zz in z])
        pd_ = (draws[:, :, None] > z[None, None, :]).mean(axis=0)
        dv = pd_ - pd_.mean(axis=0)
        res["curve"] = {"z": z.tolist(), "p": pc.tolist(),
                        "lo": np.clip(pc + np.quantile(dv, 0.025, axis=0), 0, 1).tolist(),
                        "hi": np.clip(pc + np.quantile(dv, 0.975, axis=0), 0, 1).tolist(),
                        "mean_only": [float(np.mean(mu > zz)) for zz in z]}
    res["seconds"] = time.perf_counter() - t0
    return res


def sobol(em: MFEmulator, output, dists: dict, fixed: dict, level=EXTRAPOLATED, n_base=4096,
          seed=0) -> dict:
    """First-order and total Sobol indices of the emulator's mean at a level (SALib)."""
    from SALib.analyze import sobol as sa
    from SALib.sample import sobol as ss
    import warnings
    names = list(dists)
    problem = {"num_vars": len(names), "names": names, "bounds": [[0.0, 1.0]] * len(names)}
    t0 = time.perf_counter()
    u = np.clip(ss.sample(problem, n_base, calc_second_order=False, seed=seed), 1e-12, 1 - 1e-12)
    mu, _ = em.predict(_inputs(em, dists, fixed, u), output, level)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = sa.analyze(problem, mu, calc_second_order=False, seed=seed)
    return {"names": names, "level": level, "S1": r["S1"].tolist(),
            "S1_conf": r["S1_conf"].tolist(), "ST": r["ST"].tolist(),
            "ST_conf": r["ST_conf"].tolist(), "n_model": int(len(u)),
            "seconds": time.perf_counter() - t0}


def _inputs(em, dists, fixed, u):
    """The emulator's input matrix from unit samples through the distributions (fixed inputs
    filled in): emulator._inputs_from_dists on this emulator's inputs."""
    return E._inputs_from_dists(em, dists, fixed, u)
