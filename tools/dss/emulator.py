"""A Gaussian-process emulator of FMU outputs over the parameters a sweep varied.

One GP per output (scikit-learn's GaussianProcessRegressor): inputs scaled to the unit box of
their training range (or a given box), the output standardised (mean 0, sd 1 over the training
runs), kernel ConstantKernel * Matern(nu = 2.5, one length scale per input) + WhiteKernel (a
noise term: the FMU's output is deterministic, but not smooth at the scale of a particle
spacing). A binary input (a Boolean parameter such as ``saturated``) is handled in one of three
ways, chosen with ``mode`` (``auto`` picks the one of lowest cross-validated RMSE):

  product    Matern over the continuous inputs times an RBF over the binary ones: the RBF of a
             0/1 input is a two-level categorical (exchangeable) kernel, exp(-1/(2 l^2)) the
             correlation between the levels, from ~0 (independent) to ~1 (no effect); the
             length scales the other kernel must not see are fixed at 1e5 (no effect)
  binary     the 0/1 input is one more coordinate of the Matern, with its own length scale
  separate   an independent GP per level of the binary inputs (each on the continuous inputs)

Predictions give mean and sd (the sd includes the fitted noise, so the 95 % interval
mean +- 1.96 sd is one for a new FMU run); a query outside the training box (or a binary input
not 0/1) is flagged, not refused.

The noise term can be measured instead of fitted alone (``noise``, per output): the variance of
the FMU's discretisation jitter from a jitter scan (``jitter_noise``: runs at one box point with
the reservoir level, which the particle lattice is anchored at, moved by up to half a particle
spacing; the residual variance about a linear trend in the offset), used as the lower bound of
the WhiteKernel (mode 'floor': the likelihood may still put more noise) or as its fixed value
('fixed').

Saved as JSON (no pickle): schema name and version, the inputs with their kind and box, the
training inputs and outputs, per output the standardisation, the kernel's structure (mode and
the input kinds rebuild it) with its fitted hyperparameters (theta, log scale, as scikit-learn
keeps them) and description, the cross-validation; the FMU's GUID and SHA-256 and the sweep's
settings. Loading rebuilds each GP from the JSON with optimizer=None, which gives the same
predictions, and refuses an FMU whose GUID differs.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import time
import warnings

import numpy as np

SCHEMA = "mixsph-emulator"
SCHEMA_VERSION = 2
# version 1: no measured noise term (read as noise None); 2 adds outputs.NAME.noise
READABLE_VERSIONS = (1, 2)
NOISE_MODES = ("floor", "fixed")
MODES = ("product", "binary", "separate")

# the FMU's physical parameters and the numerical ones an emulator may take as inputs when a
# sweep varies them; never inputs: threads, file names, output settings. rheology (the granular
# law, 0 paper / 1 elastic_plastic) is a two-level input like saturated; mu0, mu_thr and
# tension_cutoff are the paper law's, nu and cohesion the elastic-plastic law's, bed_friction
# the bed's Coulomb friction angle of either law (90: none); the grains' bulk
# modulus is the weakly compressible stiffness (numerical, as dx)
PHYSICAL = ("reservoir_level", "phi", "saturated", "porosity", "grain_density",
            "plate_duration_scale", "plate_stroke_scale", "nu", "cohesion", "bed_friction")
NUMERICAL = ("dx", "rheology", "mu0", "mu_thr", "pressure_smoothing", "tension_cutoff", "av_wall",
             "implicit_viscosity", "grain_bulk_modulus")
NOT_INPUTS = ("threads", "case_file", "output_interval")
DEFAULT_OUTPUTS = ("max_run_up", "time_of_max_run_up", "max_run_up_Z", "landslide_front")

# hyperparameter bounds, in the unit box and the standardised output
LENGTH_BOUNDS = (1e-2, 1e2)
CAT_LENGTH_BOUNDS = (5e-2, 1e2)      # RBF of a 0/1 input: level correlation exp(-200) .. ~1
FIXED_LENGTH = 1e5                   # a length scale that makes a coordinate irrelevant
CONST_BOUNDS = (1e-2, 1e2)
NOISE_BOUNDS = (1e-8, 1.0)
Z95 = 1.959963984540054



def file_header(schema: str, version: int) -> dict:
    """The first keys of an emulator file: its schema and version, when it was made (UTC) and
    the versions of the libraries that fitted it."""
    import sklearn
    return {"schema": schema, "schema_version": version,
            "created": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "library": {"scikit-learn": sklearn.__version__, "numpy": np.__version__}}

class EmulatorError(ValueError):
    pass


class GuidMismatch(EmulatorError):
    pass


# ---- kernels -------------------------------------------------------------------------------------

def noise_bounds(noise_std: float | None, noise_mode: str = "floor"):
    """(initial noise level, bounds) of the WhiteKernel in standardised units: the default
    bounds, or the measured variance noise_std (variance / y_std^2) as the lower bound
    ('floor') or the fixed value ('fixed')."""
    if noise_std is None:
        return 1e-4, NOISE_BOUNDS
    v = max(float(noise_std), NOISE_BOUNDS[0])
    if noise_mode == "fixed":
        return v, "fixed"
    if noise_mode != "floor":
        raise EmulatorError(f"unknown noise mode {noise_mode!r} ({', '.join(NOISE_MODES)})")
    hi = max(NOISE_BOUNDS[1], 2.0 * v)
    return min(max(1e-4, v), hi), (v, hi)


def build_kernel(mode: str, kinds: list[str], noise_std: float | None = None,
                 noise_mode: str = "floor"):
    """The (unfitted) kernel of a mode over inputs of the given kinds ('continuous'/'binary');
    noise_std: a measured noise variance in standardised units (see noise_bounds)."""
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel, Matern, WhiteKernel
    d = len(kinds)
    cont = [k == "continuous" for k in kinds]
    if mode == "separate" or not any(k == "binary" for k in kinds) or mode == "binary":
        # 'separate' builds the kernel of its continuous inputs only (kinds are those)
        core = Matern(length_scale=np.full(d, 0.5), length_scale_bounds=LENGTH_BOUNDS, nu=2.5)
    elif mode == "product":
        if not any(cont):
            core = RBF(length_scale=np.full(d, 0.5), length_scale_bounds=CAT_LENGTH_BOUNDS)
        else:
            ls_m = np.where(cont, 0.5, FIXED_LENGTH)
            b_m = np.array([LENGTH_BOUNDS if c else (FIXED_LENGTH, FIXED_LENGTH) for c in cont])
            ls_r = np.where(cont, FIXED_LENGTH, 0.5)
            b_r = np.array([(FIXED_LENGTH, FIXED_LENGTH) if c else CAT_LENGTH_BOUNDS for c in cont])
            core = (Matern(length_scale=ls_m, length_scale_bounds=b_m, nu=2.5)
                    * RBF(length_scale=ls_r, length_scale_bounds=b_r))
    else:
        raise EmulatorError(f"unknown mode {mode!r} ({', '.join(MODES)})")
    n0, nb = noise_bounds(noise_std, noise_mode)
    return (ConstantKernel(1.0, CONST_BOUNDS) * core
            + WhiteKernel(noise_level=n0, noise_level_bounds=nb))


def _gp(kernel, restarts: int, seed: int, optimizer=True):
    from sklearn.gaussian_process import GaussianProcessRegressor
    kw = {} if optimizer else {"optimizer": None}
    return GaussianProcessRegressor(kernel=kernel, alpha=1e-10, normalize_y=False,
                                    n_restarts_optimizer=restarts, random_state=seed, **kw)


def _fit_quiet(gp, X, y):
    from sklearn.exceptions import ConvergenceWarning
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        warnings.filterwarnings("ignore", message=".*lbfgs.*")
        gp.fit(X, y)
    return gp


def _hyper(kernel) -> dict:
    """The fitted hyperparameters by name, in the kernel's own (not log) units."""
    out = {}
    params = kernel.get_params()
    for h in kernel.hyperparameters:
        v = params[h.name]
        out[h.name] = np.atleast_1d(v).astype(float).tolist() if np.ndim(v) else float(v)
    return out


# ---- one output's model -------------------------------------------------------------------------

class OutputModel:
    """The GP(s) of one output: 'parts' maps a level key (a tuple of binary values, () for all)
    to a fitted GaussianProcessRegressor over the part's input columns."""

    def __init__(self, name, mode, kinds, y_mean, y_std, noise: dict | None = None):
        self.name, self.mode, self.kinds = name, mode, list(kinds)
        self.y_mean, self.y_std = float(y_mean), float(y_std)
        # the measured noise term: {'variance': in the output's units squared, 'mode':
        # 'floor'|'fixed', ...} or None (the default bounds)
        self.noise = dict(noise) if noise else None
        self.parts: dict[tuple, object] = {}
        self.bin_idx = [i for i, k in enumerate(self.kinds) if k == "binary"]
        self.cont_idx = [i for i, k in enumerate(self.kinds) if k == "continuous"]

    @property
    def split(self) -> bool:
        return self.mode == "separate" and bool(self.bin_idx)

    def kernel(self, mode, kinds):
        """The unfitted kernel of this output (the noise term from self.noise)."""
        if not self.noise:
            return build_kernel(mode, kinds)
        return build_kernel(mode, kinds, self.noise["variance"] / self.y_std ** 2,
                            self.noise.get("mode", "floor"))

    def part_kinds(self):
        return ["continuous"] * len(self.cont_idx) if self.split else self.kinds

    def _route(self, U):
        """(key, row indices, columns) for each part, for unit-box inputs U."""
        if not self.split:
            return [((), np.arange(len(U)), U)]
        lv = np.clip(np.rint(U[:, self.bin_idx]), 0, 1).astype(int)
        out = []
        for key in self.parts:
            rows = np.flatnonzero((lv == np.array(key)).all(axis=1))
            if len(rows):
                out.append((key, rows, U[np.ix_(rows, self.cont_idx)]))
        return out

    def fit(self, U, y, restarts=3, seed=0, init: dict | None = None):
        """Fit the hyperparameters (maximum marginal likelihood; the first start is the
        default kernel's, or init's thetas by part key, then `restarts` random starts)."""
        ys = (np.asarray(y, float) - self.y_mean) / self.y_std

        def kernel(mode, kinds, key):
            k = self.kernel(mode, kinds)
            if init and key in init and len(init[key]) == len(k.theta):
                k = k.clone_with_theta(np.clip(np.asarray(init[key]), k.bounds[:, 0],
                                               k.bounds[:, 1]))
            return k
        if self.split:
            lv = np.rint(U[:, self.bin_idx]).astype(int)
            keys = sorted({tuple(r) for r in lv})
            for key in keys:
                rows = np.flatnonzero((lv == np.array(key)).all(axis=1))
                if len(rows) < 3:
                    raise EmulatorError(f"{self.name}: mode 'separate' needs at least 3 runs per "
                                        f"level; level {key} has {len(rows)}")
                gp = _gp(kernel("separate", self.part_kinds(), key), restarts, seed)
                self.parts[key] = _fit_quiet(gp, U[np.ix_(rows, self.cont_idx)], ys[rows])
        else:
            gp = _gp(kernel(self.mode, self.kinds, ()), restarts, seed)
            self.parts[()] = _fit_quiet(gp, U, ys)
        return self

    def thetas(self) -> dict:
        return {key: gp.kernel_.theta.copy() for key, gp in self.parts.items()}

    def rebuild(self, U, y, thetas: dict):
        """Fit with the given hyperparameters (no optimisation): what loading does."""
        ys = (np.asarray(y, float) - self.y_mean) / self.y_std
        if self.split:
            lv = np.rint(U[:, self.bin_idx]).astype(int)
            for key, theta in thetas.items():
                rows = np.flatnonzero((lv == np.array(key)).all(axis=1))
                if rows.size == 0:
                    continue
                k = self.kernel("separate", self.part_kinds()).clone_with_theta(np.asarray(theta))
                self.parts[key] = _gp(k, 0, 0, optimizer=False).fit(U[np.ix_(rows, self.cont_idx)],
                                                                    ys[rows])
        else:
            k = self.kernel(self.mode, self.kinds).clone_with_theta(np.asarray(thetas[()]))
            self.parts[()] = _gp(k, 0, 0, optimizer=False).fit(U, ys)
        return self

    def predict(self, U):
        """Mean and sd in the output's units (the sd includes the fitted noise)."""
        mu = np.full(len(U), np.nan)
        sd = np.full(len(U), np.nan)
        for key, rows, X in self._route(U):
            m, s = self.parts[key].predict(X, return_std=True)
            mu[rows] = m * self.y_std + self.y_mean
            sd[rows] = s * self.y_std
        return mu, sd

    def sample(self, U, n_draws, seed=0):
        """Joint posterior draws (len(U) x n_draws) in the output's units: the GP's predictive
        mean and full covariance (predict(return_cov=True), the noise on its diagonal), drawn
        from with numpy's multivariate_normal (what sklearn's sample_y does, with a Cholesky
        factor instead of its SVD: 20x faster at 1000 points; eigh if the Cholesky fails). The
        levels of 'separate' are independent."""
        out = np.full((len(U), n_draws), np.nan)
        for i, (key, rows, X) in enumerate(self._route(U)):
            mu, cov = self.parts[key].predict(X, return_cov=True)
            rng = np.random.default_rng(seed + 7919 * i)
            try:
                draws = rng.multivariate_normal(mu, cov, n_draws, method="cholesky").T
            except np.linalg.LinAlgError:
                draws = rng.multivariate_normal(mu, cov, n_draws, method="eigh").T
            out[rows] = draws * self.y_std + self.y_mean
        return out

    def correlation(self, Ua, Ub):
        """The fitted kernel's correlation (without the noise) between rows of Ua and Ub."""
        C = np.zeros((len(Ua), len(Ub)))
        ra = self._route(Ua)
        rb = {key: (rows, X) for key, rows, X in self._route(Ub)}
        for key, rows_a, Xa in ra:
            if key not in rb:
                continue
            rows_b, Xb = rb[key]
            k = self.parts[key].kernel_.k1
            K = k(Xa, Xb) / math.sqrt(float(k.diag(Xa[:1])[0]) * float(k.diag(Xb[:1])[0]))
            C[np.ix_(rows_a, rows_b)] = K
        return C

    def posterior_cov(self, Ua, Ub):
        """The posterior covariance of the latent response (without the noise term) between
        rows of Ua and Ub, in the output's units squared: k(a, b) - k(a, X) K^-1 k(X, b), k the
        fitted kernel without its WhiteKernel, X the part's training inputs, K = kernel_(X) +
        alpha (the fitted GP's own Cholesky factor L_). The rows of different levels of
        'separate' are independent: covariance 0 (as in sample and correlation)."""
        from scipy.linalg import solve_triangular
        C = np.zeros((len(Ua), len(Ub)))
        rb = {key: (rows, X) for key, rows, X in self._route(Ub)}
        for key, rows_a, Xa in self._route(Ua):
            if key not in rb:
                continue
            rows_b, Xb = rb[key]
            gp = self.parts[key]
            k = gp.kernel_.k1
            Va = solve_triangular(gp.L_, k(gp.X_train_, Xa), lower=True, check_finite=False)
            Vb = solve_triangular(gp.L_, k(gp.X_train_, Xb), lower=True, check_finite=False)
            C[np.ix_(rows_a, rows_b)] = (k(Xa, Xb) - Va.T @ Vb) * self.y_std ** 2
        return C

    def posterior_var(self, U):
        """The diagonal of posterior_cov(U, U) without the U x U matrix (output units squared;
        NaN for a level without a GP)."""
        from scipy.linalg import solve_triangular
        out = np.full(len(U), np.nan)
        for key, rows, X in self._route(U):
            gp = self.parts[key]
            k = gp.kernel_.k1
            V = solve_triangular(gp.L_, k(gp.X_train_, X), lower=True, check_finite=False)
            out[rows] = (k.diag(X) - np.einsum("ij,ij->j", V, V)) * self.y_std ** 2
        return out

    def noise_at(self, U):
        """The fitted WhiteKernel variance at each row of U (its level's in 'separate'), in the
        output's units squared (NaN for a level without a GP)."""
        out = np.full(len(U), np.nan)
        for key, rows, _ in self._route(U):
            out[rows] = float(self.parts[key].kernel_.k2.noise_level) * self.y_std ** 2
        return out

    def to_json(self):
        parts = []
        for key, gp in self.parts.items():
            k = gp.kernel_
            parts.append({"level": dict(zip(self.bin_names, key)) if self.split else None,
                          "key": list(key), "theta": k.theta.tolist(), "kernel": str(k),
                          "hyperparameters": _hyper(k),
                          "log_marginal_likelihood": float(gp.log_marginal_likelihood_value_)})
        return {"mode": self.mode, "y_mean": self.y_mean, "y_std": self.y_std, "parts": parts,
                "noise": self.noise}

    def fitted_noise(self) -> list[float]:
        """The fitted WhiteKernel variance of each part, in the output's units squared."""
        return [float(gp.kernel_.k2.noise_level) * self.y_std ** 2 for gp in self.parts.values()]


# ---- the emulator ---------------------------------------------------------------------------------

class Emulator:
    def __init__(self, inputs, kinds, box, X, Y: dict, fmu=None, sweep=None, noise=None):
        self.inputs = list(inputs)
        self.kinds = list(kinds)
        self.box = np.asarray(box, dtype=float)       # d x 2: lo, hi
        self.X = np.asarray(X, dtype=float)
        self.Y = {k: np.asarray(v, dtype=float) for k, v in Y.items()}
        self.fmu = dict(fmu or {})
        self.sweep = dict(sweep or {})
        self.models: dict[str, OutputModel] = {}
        self.cv: dict[str, dict] = {}
        self.mode_comparison: dict[str, dict] = {}
        # the measured noise term per output (see OutputModel.noise); outputs not in it get
        # the default bounds
        self.noise: dict[str, dict] = dict(noise or {})
        span = self.box[:, 1] - self.box[:, 0]
        if np.any(span <= 0):
            bad = [n for n, s in zip(self.inputs, span) if s <= 0]
            raise EmulatorError(f"inputs {bad} do not vary in the training box")

    # scaling
    def unit(self, X):
        X = np.asarray(X, dtype=float)
        return (X - self.box[:, 0]) / (self.box[:, 1] - self.box[:, 0])

    def out_of_box(self, X, tol=1e-9):
        """Per row, the names of inputs outside the box ('' when inside)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        lo, hi = self.box[:, 0], self.box[:, 1]
        span = hi - lo
        bad = (X < lo - tol * span) | (X > hi + tol * span) | ~np.isfinite(X)
        for j, k in enumerate(self.kinds):
            if k == "binary":
                bad[:, j] |= ~np.isin(X[:, j], (0.0, 1.0))
        names = np.array(self.inputs)
        return np.array([",".join(names[r]) for r in bad], dtype=object)

    def _rows(self, name):
        y = self.Y[name]
        ok = np.isfinite(y)
        return np.flatnonzero(ok), y[ok]

    def _new_model(self, name, mode, y):
        m = OutputModel(name, mode, self.kinds, np.mean(y), np.std(y) if np.std(y) > 0 else 1.0,
                        noise=self.noise.get(name))
        m.bin_names = [self.inputs[i] for i in m.bin_idx]
        return m

    def fit_output(self, name, mode="auto", restarts=3, seed=0, folds=10, cv=True,
                   cv_refit=True, init=None):
        """Fit the emulator of one output. cv_refit: the k-fold CV refits the hyperparameters
        in every fold (honest, slower); otherwise every fold keeps the full fit's (what the
        design's stopping rule uses). init: the thetas to start the optimiser from."""
        rows, y = self._rows(name)
        if len(rows) < 3:
            raise EmulatorError(f"{name}: {len(rows)} finite values; at least 3 are needed")
        U = self.unit(self.X[rows])
        modes = [mode]
        if mode == "auto":
            modes = ["product", "binary", "separate"] if "binary" in self.kinds else ["product"]
        results = {}
        if not cv_refit:
            if len(modes) != 1:
                raise EmulatorError("a CV without refits needs one mode")
            m = self._new_model(name, modes[0], y).fit(U, y, restarts=restarts, seed=seed,
                                                        init=init)
            self.models[name] = m
            if cv:
                self.cv[name] = cross_validate(self, name, modes[0], folds=folds, seed=seed,
                                               fixed=m)
            return m
        for md in modes:
            try:
                res = cross_validate(self, name, md, folds=folds, restarts=restarts, seed=seed) \
                    if (cv or len(modes) > 1) else None
            except EmulatorError as e:
                results[md] = {"error": str(e)}
                continue
            results[md] = res
        good = {m: r for m, r in results.items() if r is not None and "error" not in r}
        if len(modes) > 1:
            if not good:
                raise EmulatorError(f"{name}: no mode could be fitted: {results}")
            best = min(good, key=lambda m: good[m]["rmse"])
            self.mode_comparison[name] = results
        else:
            best = modes[0]
            if results.get(best) and "error" in results[best]:
                raise EmulatorError(results[best]["error"])
        m = self._new_model(name, best, y).fit(U, y, restarts=restarts, seed=seed)
        self.models[name] = m
        if results.get(best) is not None:
            self.cv[name] = results[best]
        return m

    def predict(self, X, outputs=None) -> dict:
        """{'out_of_box': names per row, output: (mean, sd)} for raw inputs X (n x d)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        U = self.unit(X)
        res = {"out_of_box": self.out_of_box(X)}
        for name in outputs or list(self.models):
            if name not in self.models:
                raise EmulatorError(f"no emulator of {name!r} (this file has "
                                    f"{', '.join(self.models)})")
            res[name] = self.models[name].predict(U)
        return res

    def matrix(self, rows: list[dict]) -> np.ndarray:
        """The input matrix of scenarios given as dicts (every input must be there)."""
        X = np.empty((len(rows), len(self.inputs)))
        for i, r in enumerate(rows):
            for j, n in enumerate(self.inputs):
                if n not in r:
                    raise EmulatorError(f"scenario {i + 1}: no value of the input {n!r} (the "
                                        f"emulator's inputs: {', '.join(self.inputs)})")
                X[i, j] = float(r[n])
        return X

    # ---- save / load ------------------------------------------------------------------------

    def to_json(self) -> dict:
        return {
            **file_header(SCHEMA, SCHEMA_VERSION),
            "fmu": self.fmu, "sweep": self.sweep,
            "inputs": [{"name": n, "kind": k, "lo": float(b[0]), "hi": float(b[1])}
                       for n, k, b in zip(self.inputs, self.kinds, self.box)],
            "kernel_family": "ConstantKernel*Matern(nu=2.5, anisotropic)+WhiteKernel; modes: "
                             "product (x RBF of the binary inputs), binary, separate; noise: "
                             "the WhiteKernel's default bounds, or a measured variance as its "
                             "lower bound (floor) or value (fixed)",
            "X": self.X.tolist(),
            "outputs": {name: {**m.to_json(), "y": [None if not np.isfinite(v) else float(v)
                                                     for v in self.Y[name]],
                               "cv": self.cv.get(name),
                               "mode_comparison": self.mode_comparison.get(name)}
                        for name, m in self.models.items()},
        }

    def save(self, path):
        tmp = path + ".tmp"
        with open(tmp, "w") as f:
            json.dump(_jsonable(self.to_json()), f, indent=1)
        os.replace(tmp, path)

    @classmethod
    def from_json(cls, doc: dict) -> "Emulator":
        if doc.get("schema") != SCHEMA:
            raise EmulatorError(f"not a {SCHEMA} file (schema {doc.get('schema')!r})")
        if doc.get("schema_version") not in READABLE_VERSIONS:
            raise EmulatorError(f"emulator schema version {doc.get('schema_version')} is not one "
                                f"this code reads ({', '.join(map(str, READABLE_VERSIONS))}): "
                                f"refit it")
        inp = doc["inputs"]
        Y = {name: np.array([np.nan if v is None else v for v in o["y"]], dtype=float)
             for name, o in doc["outputs"].items()}
        em = cls([i["name"] for i in inp], [i["kind"] for i in inp],
                 [(i["lo"], i["hi"]) for i in inp], doc["X"], Y, doc.get("fmu"), doc.get("sweep"))
        for name, o in doc["outputs"].items():
            rows, y = em._rows(name)
            m = OutputModel(name, o["mode"], em.kinds, o["y_mean"], o["y_std"],
                            noise=o.get("noise"))     # version 1: no noise key
            if m.noise:
                em.noise[name] = m.noise
            m.bin_names = [em.inputs[i] for i in m.bin_idx]
            thetas = {tuple(p["key"]): p["theta"] for p in o["parts"]}
            m.rebuild(em.unit(em.X[rows]), y, thetas)
            em.models[name] = m
            if o.get("cv"):
                em.cv[name] = o["cv"]
            if o.get("mode_comparison"):
                em.mode_comparison[name] = o["mode_comparison"]
        return em


def _jsonable(x):
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, (np.floating, float)):
        return float(x) if math.isfinite(float(x)) else None
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def fmu_identity(fmu_path: str) -> dict:
    """GUID, model name and SHA-256 of an FMU file."""
    import hashlib
    from fmpy import read_model_description
    md = read_model_description(fmu_path)
    with open(fmu_path, "rb") as f:
        sha = hashlib.sha256(f.read()).hexdigest()
    return {"guid": md.guid, "model_name": md.modelName, "sha256": sha,
            "path": os.path.abspath(fmu_path)}


def load(path: str, fmu_path: str | None = None, check_fmu: bool = True) -> Emulator:
    """The emulator of a JSON file; with check_fmu, the FMU (fmu_path) must have the GUID the
    emulator was fitted on. A different build of the same model description (same GUID, other
    SHA-256) is allowed with a warning."""
    with open(path) as f:
        doc = json.load(f)
    if check_fmu:
        want = (doc.get("fmu") or {}).get("guid")
        if fmu_path is None or not os.path.isfile(fmu_path):
            raise EmulatorError(f"FMU {fmu_path} not found: the emulator {path} must be checked "
                                f"against the FMU it emulates (--fmu FILE, or --no-fmu-check)")
        have = fmu_identity(fmu_path)
        if want != have["guid"]:
            raise GuidMismatch(
                f"the emulator {path} was fitted on the FMU with GUID {want} "
                f"({(doc.get('fmu') or {}).get('path')}), but {fmu_path} has GUID {have['guid']}: "
                f"its predictions would be of another model. Refit it on this FMU's runs "
                f"(emulate fit / emulate design) or give the FMU it was fitted on with --fmu")
        if doc["fmu"].get("sha256") and doc["fmu"]["sha256"] != have["sha256"]:
            import sys
            print(f"emulate: warning: {fmu_path} has the emulator's GUID but other contents than "
                  f"the FMU it was fitted on (SHA-256 {have['sha256'][:12]} vs "
                  f"{doc['fmu']['sha256'][:12]}): a rebuild of the same model description; the "
                  f"library may have changed", file=sys.stderr)
    return Emulator.from_json(doc)


# ---- inputs from a results table ------------------------------------------------------------------

def choose_inputs(df, candidates=None) -> tuple[list[str], list[str]]:
    """The varied parameters among the physical and numerical ones (or the given candidates)
    and their kinds: 'binary' when every value is 0/1 (or a Boolean), else 'continuous'."""
    names = list(candidates) if candidates else [c for c in PHYSICAL + NUMERICAL if c in df.columns]
    inputs, kinds = [], []
    for n in names:
        if n not in df.columns:
            raise EmulatorError(f"{n!r} is not a column of the results")
        v = df[n].astype(float).to_numpy()
        if np.unique(v[np.isfinite(v)]).size < 2 and not candidates:
            continue
        inputs.append(n)
        kinds.append("binary" if np.isin(v, (0.0, 1.0)).all() else "continuous")
    if not inputs:
        raise EmulatorError("no parameter varies in these results: nothing to emulate over")
    return inputs, kinds


def from_results(df, outputs=None, inputs=None, box=None, fmu=None, sweep=None,
                 noise=None) -> Emulator:
    """An (unfitted) emulator of the ok rows of a results table."""
    df = df[df["status"] == "ok"] if "status" in df.columns else df
    if df.empty:
        raise EmulatorError("no ok runs to fit")
    names, kinds = choose_inputs(df, inputs)
    X = df[names].astype(float).to_numpy()
    b = np.column_stack([X.min(axis=0), X.max(axis=0)])
    for j, k in enumerate(kinds):
        if k == "binary":
            b[j] = (0.0, 1.0)
    for n, (lo, hi) in (box or {}).items():
        if n in names:
            j = names.index(n)
            if X[:, j].min() < lo or X[:, j].max() > hi:
                raise EmulatorError(f"--box {n}={lo}:{hi} does not hold the training runs "
                                    f"({X[:, j].min():g}..{X[:, j].max():g})")
            b[names.index(n)] = (lo, hi)
    outs = list(outputs or [o for o in DEFAULT_OUTPUTS if o in df.columns])
    Y = {}
    for o in outs:
        if o not in df.columns:
            raise EmulatorError(f"{o!r} is not a column of the results")
        Y[o] = df[o].astype(float).to_numpy()
    return Emulator(names, kinds, b, X, Y, fmu=fmu, sweep=sweep, noise=noise)


# ---- cross-validation ----------------------------------------------------------------------------

def metrics(y, mu, sd, y_range=None) -> dict:
    """RMSE, largest error, coverage of the 95 % intervals (and both errors in % of y_range,
    default the range of y)."""
    y, mu, sd = (np.asarray(a, float) for a in (y, mu, sd))
    e = mu - y
    rng = float(np.ptp(y)) if y_range is None else float(y_range)
    rmse = float(np.sqrt(np.mean(e ** 2)))
    mx = float(np.max(np.abs(e)))
    inside = np.abs(e) <= Z95 * sd
    return {"n": int(len(y)), "rmse": rmse, "max_error": mx, "coverage95": float(np.mean(inside)),
            "range": rng, "rmse_pct": 100 * rmse / rng if rng > 0 else math.nan,
            "max_error_pct": 100 * mx / rng if rng > 0 else math.nan}


def cross_validate(em: Emulator, name: str, mode: str, folds=10, restarts=3, seed=0,
                   fixed: OutputModel | None = None) -> dict:
    """k-fold cross-validation: metrics, and the out-of-fold predictions (for the
    predicted-vs-simulated plot). The hyperparameters are refitted in every fold, or, with
    `fixed` (a model fitted on all runs), kept at its values (cheaper, a little optimistic)."""
    from sklearn.model_selection import KFold
    rows, y = em._rows(name)
    n = len(rows)
    k = max(2, min(folds, n))
    U = em.unit(em.X[rows])
    mu = np.full(n, np.nan)
    sd = np.full(n, np.nan)
    t0 = time.perf_counter()
    for tr, te in KFold(n_splits=k, shuffle=True, random_state=seed).split(U):
        m = em._new_model(name, mode, y[tr])
        if fixed is None:
            m.fit(U[tr], y[tr], restarts=restarts, seed=seed)
        else:
            m.y_mean, m.y_std = fixed.y_mean, fixed.y_std
            m.rebuild(U[tr], y[tr], fixed.thetas())
        mu[te], sd[te] = m.predict(U[te])
    if not np.isfinite(mu).all():
        raise EmulatorError(f"{name}, mode {mode}: a fold left a level without runs")
    res = metrics(y, mu, sd)
    res.update({"mode": mode, "folds": k, "refit": fixed is None,
                "seconds": time.perf_counter() - t0,
                "y": y.tolist(), "mean": mu.tolist(), "sd": sd.tolist(), "rows": rows.tolist()})
    return res


# ---- risk and sensitivity -------------------------------------------------------------------------

def _inputs_from_dists(em: Emulator, dists: dict, fixed: dict, u: np.ndarray) -> np.ndarray:
    """Map unit samples u (n x len(dists)) through the distributions' quantile functions into
    the emulator's input matrix (fixed inputs filled in)."""
    X = np.empty((len(u), len(em.inputs)))
    names = list(dists)
    for j, n in enumerate(em.inputs):
        if n in dists:
            X[:, j] = np.asarray(dists[n].ppf(u[:, names.index(n)]), dtype=float)
        elif n in fixed:
            X[:, j] = float(fixed[n])
        else:
            raise EmulatorError(f"the input {n!r} has neither a distribution (--dist) nor a value "
                                f"(--set); the emulator's inputs: {', '.join(em.inputs)}")
    extra = [n for n in list(dists) + list(fixed) if n not in em.inputs]
    if extra:
        raise EmulatorError(f"{', '.join(extra)}: not inputs of the emulator "
                            f"({', '.join(em.inputs)})")
    return X


def exceedance(em: Emulator, output: str, dists: dict, fixed: dict, crest: float,
               n=100_000, n_joint=1000, n_draws=200, seed=0, z_grid=None) -> dict:
    """P(output > crest) when the inputs follow the distributions, with its uncertainty due to
    the emulator.

    P is E_x[Phi((mu(x) - crest) / sd(x))] over n samples of x (the probability that an FMU
    run at a random x exceeds the crest, the emulator's uncertainty averaged in). Its band comes
    from n_draws joint posterior draws of the output (OutputModel.sample: the GP's full
    predictive covariance) at the first n_joint of the samples: each draw is a plausible response surface,
    and its exceedance fraction P_s varies with it; the band is P + the 2.5/97.5 % quantiles of
    P_s - mean(P_s) (the draws share the sample points, so the spread is the emulator's, not
    Monte Carlo error, which is reported separately as mc_se)."""
    from scipy.stats import norm
    m = em.models.get(output)
    if m is None:
        raise EmulatorError(f"no emulator of {output!r} ({', '.join(em.models)})")
    rng = np.random.default_rng(seed)
    u = np.clip(rng.random((n, len(dists))), 1e-12, 1 - 1e-12)
    t0 = time.perf_counter()
    X = _inputs_from_dists(em, dists, fixed, u)
    oob = em.out_of_box(X)
    mu, sd = m.predict(em.unit(X))
    q = norm.sf((crest - mu) / np.maximum(sd, 1e-300))
    p = float(np.mean(q))
    nj = min(n_joint, n)
    draws = m.sample(em.unit(X[:nj]), n_draws, seed=seed)
    ps = (draws > crest).mean(axis=0)
    dev = ps - ps.mean()
    lo, hi = np.quantile(dev, [0.025, 0.975])
    res = {"output": output, "crest": crest, "n": n, "p": p,
           "p_lo": float(np.clip(p + lo, 0, 1)), "p_hi": float(np.clip(p + hi, 0, 1)),
           "p_mean_only": float(np.mean(mu > crest)),
           "mc_se": float(np.std(q) / math.sqrt(n)), "n_joint": nj, "n_draws": n_draws,
           "p_draws_sd": float(np.std(ps)), "out_of_box_fraction": float(np.mean(oob != "")),
           "seconds": None}
    if z_grid is not None:
        z = np.asarray(z_grid, float)
        pc = np.array([np.mean(norm.sf((zz - mu) / np.maximum(sd, 1e-300))) for zz in z])
        pd_ = (draws[:, :, None] > z[None, None, :]).mean(axis=0)     # draws x z
        dv = pd_ - pd_.mean(axis=0)
        res["curve"] = {"z": z.tolist(), "p": pc.tolist(),
                        "lo": np.clip(pc + np.quantile(dv, 0.025, axis=0), 0, 1).tolist(),
                        "hi": np.clip(pc + np.quantile(dv, 0.975, axis=0), 0, 1).tolist(),
                        "mean_only": [float(np.mean(mu > zz)) for zz in z]}
    res["seconds"] = time.perf_counter() - t0
    res["_mu"] = mu
    return res


def sobol(em: Emulator, output: str, dists: dict, fixed: dict, n_base=4096, seed=0) -> dict:
    """First-order and total Sobol indices of the emulator's mean of the output (SALib's
    Saltelli/Sobol sampling and analysis, the samples mapped through the distributions)."""
    from SALib.analyze import sobol as sa
    from SALib.sample import sobol as ss
    names = list(dists)
    problem = {"num_vars": len(names), "names": names, "bounds": [[0.0, 1.0]] * len(names)}
    t0 = time.perf_counter()
    u = ss.sample(problem, n_base, calc_second_order=False, seed=seed)
    u = np.clip(u, 1e-12, 1 - 1e-12)
    X = _inputs_from_dists(em, dists, fixed, u)
    mu, _ = em.models[output].predict(em.unit(X))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = sa.analyze(problem, mu, calc_second_order=False, seed=seed)
    return {"names": names, "S1": r["S1"].tolist(), "S1_conf": r["S1_conf"].tolist(),
            "ST": r["ST"].tolist(), "ST_conf": r["ST_conf"].tolist(), "n_model": int(len(u)),
            "seconds": time.perf_counter() - t0}


# ---- the measured noise term ---------------------------------------------------------------------

def jitter_noise(offsets, y, groups=None) -> dict:
    """The variance of an output's discretisation jitter from a jitter scan: runs at one or
    more box points (groups) with inputs moved by small offsets (n x p) that change the
    physics only smoothly. The variance is the residual one about a linear trend in the
    offsets, fitted per group (least squares, numpy.linalg.lstsq): s^2 = RSS / (n - rank), with
    its 95 % confidence interval from the chi-square distribution of (n - rank) s^2 / sigma^2
    (scipy.stats.chi2; exact for independent normal jitter). Also the plain pooled variance
    about the group means (without the trend), for comparison."""
    from scipy.stats import chi2
    y = np.asarray(y, dtype=float)
    D = np.atleast_2d(np.asarray(offsets, dtype=float))
    if D.shape[0] != len(y):
        D = D.T
    g = np.zeros(len(y), dtype=int) if groups is None else np.unique(
        np.asarray(groups, dtype=object).astype(str), return_inverse=True)[1]
    ok = np.isfinite(y)
    y, D, g = y[ok], D[ok], g[ok]
    cols = []
    for k in np.unique(g):
        ind = (g == k).astype(float)
        cols.append(ind)
        cols += [ind * D[:, j] for j in range(D.shape[1])]
    A = np.column_stack(cols)
    coef, _, rank, _ = np.linalg.lstsq(A, y, rcond=None)
    res = y - A @ coef
    dof = len(y) - int(rank)
    if dof < 1:
        raise EmulatorError(f"a jitter scan of {len(y)} runs in {len(np.unique(g))} group(s) "
                            f"with {D.shape[1]} offset(s) leaves no degree of freedom: more runs")
    s2 = float(res @ res / dof)
    lo, hi = dof * s2 / chi2.ppf(0.975, dof), dof * s2 / chi2.ppf(0.025, dof)
    dev = y - np.array([y[g == k].mean() for k in g])
    dof0 = len(y) - len(np.unique(g))
    return {"variance": s2, "sd": math.sqrt(s2), "dof": dof, "n": int(len(y)),
            "groups": int(len(np.unique(g))), "ci95_variance": [float(lo), float(hi)],
            "ci95_sd": [math.sqrt(lo), math.sqrt(hi)],
            "variance_about_means": float(dev @ dev / dof0) if dof0 > 0 else None,
            "trend": coef.tolist(), "residuals": res.tolist()}


def noise_from_file(path: str, outputs, mode: str = "floor", fmu: dict | None = None,
                    dx=None) -> dict:
    """The noise spec per output ({'variance', 'mode', 'source', ...}) of a jitter file
    (emulate jitter's jitter.json), checked against the emulator's FMU (GUID) and dx: a floor
    measured on another FMU or resolution is refused."""
    if mode not in NOISE_MODES:
        raise EmulatorError(f"unknown noise mode {mode!r} ({', '.join(NOISE_MODES)})")
    with open(path) as f:
        doc = json.load(f)
    if doc.get("schema") != "mixsph-jitter":
        raise EmulatorError(f"{path} is not a jitter file of emulate jitter")
    guid = (doc.get("fmu") or {}).get("guid")
    if fmu and fmu.get("guid") and guid != fmu["guid"]:
        raise EmulatorError(f"the jitter scan {path} is of the FMU with GUID {guid}, the runs of "
                            f"the FMU with GUID {fmu['guid']}: measure the noise on this FMU")
    jdx = (doc.get("settings") or {}).get("dx")
    if dx is not None and jdx is not None and not math.isclose(float(dx), float(jdx)):
        raise EmulatorError(f"the jitter scan {path} is at dx = {jdx:g}, the runs at dx = "
                            f"{float(dx):g}: the jitter depends on the particle spacing")
    out = {}
    for name in outputs:
        est = (doc.get("outputs") or {}).get(name)
        if est is None:
            continue
        out[name] = {"variance": est["variance"], "sd": est["sd"], "mode": mode,
                     "dof": est["dof"], "ci95_sd": est["ci95_sd"],
                     "source": os.path.abspath(path), "dx": jdx, "fmu_guid": guid}
    return out
