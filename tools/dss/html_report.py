"""The page of a study: one self-contained HTML file (report.html) per DSS study, sweep or run.

    python -m tools.dss page DIR [-o FILE]

DIR is a multi-fidelity study (`emulate study`: mf_emulator.json, study.json, mfdesign.json), a
sweep (`dss sweep`: results.parquet or results.csv) or the output folder of one `mixsph run`
(monitors.csv, summary.json); `emulate study` and `dss sweep` write the page themselves at the
end. The page needs no server and no network: Plotly's JavaScript bundle (from the plotly wheel)
is inlined, the data is one JSON block in the page, and report_page.js (beside this module)
draws it.

The prediction panel evaluates the emulator in the browser from the emulator file's own fitted
data: per GP (a multi-fidelity level's discrepancy, or a single-fidelity output's GP or its
parts by the levels of a binary input) its training inputs (unit box), the weights
alpha = K^-1 y and the Cholesky factor L of K (scikit-learn's alpha_ and L_, exported bit for
bit as base64 float64), its constant, kernel factors and length scales; and per output and
level the linear form of the GPs that multifidelity.OutputMF.linear_form gives (the only place
the recursion and the Richardson extrapolation are composed; Python's own predictions use it
too). The browser computes the kernel, the weighted sums and one triangular solve per GP;
tests/python/test_report_html.py checks the page's numbers against Python's at 20 random points
to 1e-9, and the page itself recomputes Python's predictions at a few points it carries
(self_checks) and shows no number when they differ. No grid: the evaluation is exact at every
point, it costs 0.03 ms a point in Chromium for 302 runs, and the page grows with n^2/2 per GP
of n runs (L's lower triangle), not with the number of inputs: 1.25 MB for two outputs of a
500-run ladder (docs/dss.md, "The study page").

The runs of a study or sweep have their monitors over time (the runner's series) and, for
ANIMATE of them replayed with mixsph (replay.py), a decimated particle animation.
"""

from __future__ import annotations

import base64
import datetime as _dt
import glob
import html
import json
import math
import os
import subprocess

import numpy as np

from .emulator import _jsonable

from .scenarios import ID

PAGE = "report.html"
SERIES_POINTS = 80          # monitors over time: at most this many points per run and series
FRAMES = 25                 # particle animation: at most this many frames ...
FRAME_PARTICLES = 1500      # ... of at most this many particles (every k-th particle)
ANIMATE = 3                 # runs of a study or sweep replayed for their particles
CHECK_POINTS = 3            # the page's self-check: points per output and level
RISK_POINTS = 1000          # box points of the stated discretisation error (finest vs limit)
_HERE = os.path.dirname(os.path.abspath(__file__))
_ROOT = os.path.dirname(os.path.dirname(_HERE))


class PageError(ValueError):
    pass


# ---- encoding ----------------------------------------------------------------------------------

def f64(a) -> str:
    """A float64 array as base64 of its little-endian bytes (exact, 10.7 bytes a number)."""
    return base64.b64encode(np.ascontiguousarray(np.asarray(a, dtype="<f8")).tobytes()).decode()


def _round(v, digits=6):
    """A number for display data: 6 significant digits, None for NaN/inf."""
    try:
        x = float(v)
    except (TypeError, ValueError):
        return v
    if not math.isfinite(x):
        return None
    return float(f"{x:.{digits}g}")


def _plain(obj):
    """JSON-ready: numpy scalars and arrays to Python, NaN to None (the emulator file's rule)."""
    return _jsonable(obj)


# ---- the emulator for the browser --------------------------------------------------------------

def _factors(k, d) -> list[dict]:
    """The kernel factors (a product of Matern 5/2 and RBF kernels, each with its length
    scales over the GP's d columns) of a fitted kernel without its constant."""
    from sklearn.gaussian_process.kernels import RBF, Matern, Product
    if isinstance(k, Product):
        return _factors(k.k1, d) + _factors(k.k2, d)
    ls = np.broadcast_to(np.asarray(k.length_scale, float), (d,)).tolist()
    if isinstance(k, Matern):
        if float(k.nu) != 2.5:
            raise PageError(f"the page evaluates Matern 5/2 kernels only (nu = {k.nu})")
        return [{"type": "matern52", "ls": ls}]
    if isinstance(k, RBF):
        return [{"type": "rbf", "ls": ls}]
    raise PageError(f"the page cannot evaluate the kernel {k}")


def export_gp(gp, mean, std, noise=None) -> dict:
    """A fitted GaussianProcessRegressor whose kernel is ConstantKernel * (product of Matern 5/2
    and RBF factors) + WhiteKernel, as the page evaluates it: latent mean k(x, X) alpha * std +
    mean and variance (c - |L^-1 k(x, X)|^2) std^2 (its own noise, noise_level std^2, added
    where the form says so)."""
    k1 = gp.kernel_.k1
    d = int(gp.X_train_.shape[1])
    L = np.asarray(gp.L_, float)
    n = L.shape[0]
    return {"n": int(n), "d": d, "c": float(k1.k1.constant_value), "factors": _factors(k1.k2, d),
            "mean": float(mean), "std": float(std), "noise": noise,
            "X": f64(gp.X_train_), "alpha": f64(np.ravel(gp.alpha_)),
            "L": f64(L[np.tril_indices(n)])}


def export_delta(g) -> dict:
    """One delta GP of the multi-fidelity emulator (multifidelity.DeltaGP.predict)."""
    return export_gp(g.gp, g.mean, g.std)


def export_sf(em) -> dict:
    """The single-fidelity emulator (emulator.Emulator, emulate fit/design): per output its
    GP, or one per level of the binary inputs (mode separate), routed by them; the prediction
    is the GP's mean and its variance with its own fitted noise (OutputModel.predict)."""
    outs = {}
    for name, m in em.models.items():
        keys = list(m.parts)
        gps = [export_gp(m.parts[k], m.y_mean, m.y_std,
                         noise=float(m.parts[k].kernel_.k2.noise_level)) for k in keys]
        route = ({"bin": m.bin_idx, "cont": m.cont_idx,
                  "parts": {",".join(str(int(v)) for v in k): i for i, k in enumerate(keys)}}
                 if m.split else None)
        cv = (em.cv.get(name) or {})
        outs[name] = {"gps": gps, "forms": {"sf": {"coef": [1.0], "order": None, "noise": None,
                                                   "scale": 1.0, "route": route}},
                      "mode": m.mode,
                      "cv": {k: cv.get(k) for k in ("n", "rmse", "rmse_pct", "max_error_pct",
                                                    "coverage95", "folds", "mode")} if cv else None}
    return {"kind": "sf", "inputs": [{"name": n, "lo": float(b[0]), "hi": float(b[1]), "kind": k}
                                     for n, k, b in zip(em.inputs, em.kinds, em.box)],
            "levels": [{"key": "sf", "label": "the runs' dx"}], "outputs": outs}


def level_keys(em) -> list[tuple[str, str]]:
    """(key, label) of the levels the page offers: the limit first when there is one."""
    from . import multifidelity as M
    keys = []
    if em.models and all(m.order for m in em.models.values()):
        keys.append((M.EXTRAPOLATED, "dx -> 0 (extrapolated)"))
    last = len(em.dxs) - 1
    for i in range(last, -1, -1):
        keys.append((str(i), f"dx = {em.dxs[i]:g} m" + (" (finest run)" if i == last else "")))
    return keys


def export_mf(em) -> dict:
    from . import multifidelity as M
    outs = {}
    for name, m in em.models.items():
        forms = {}
        for key, _ in level_keys(em):
            if key == M.EXTRAPOLATED and not m.order:
                continue
            f = m.linear_form(key if key == M.EXTRAPOLATED else int(key))
            forms[key] = {"coef": f["coef"], "order": f["order"], "noise": f["noise"],
                          "scale": f["scale"]}
        outs[name] = {"gps": [export_delta(g) for g in m.levels], "forms": forms,
                      "order": m.order, "calibration": m.calibration,
                      "kernel_family": m.kernel_family,
                      "rho": [g.rho for g in m.levels]}
    return {"kind": "mf", "inputs": [{"name": n, "lo": float(b[0]), "hi": float(b[1])}
                                     for n, b in zip(em.inputs, em.box)],
            "levels": [{"key": k, "label": lab} for k, lab in level_keys(em)],
            "dxs": em.dxs, "outputs": outs}


def python_predict(em, output, level_key, X):
    """The emulator's (mean, sd) as the page's level key names it: a multi-fidelity level
    ('extrapolated' or a level's index) or 'sf' (the single-fidelity emulator)."""
    from . import multifidelity as M
    X = np.atleast_2d(np.asarray(X, float))
    if level_key == "sf":
        return em.predict(X, [output])[output]
    lv = level_key if level_key == M.EXTRAPOLATED else em.dxs[int(level_key)]
    return em.predict(X, output, lv)


def page_levels(em) -> list[str]:
    return ["sf"] if not hasattr(em, "dxs") else [k for k, _ in level_keys(em)]


# ---- what every page has -----------------------------------------------------------------------

def versions(fmu: dict | None = None) -> dict:
    """mixsph's version and commit (of this checkout), the FMU's model version and GUID, and the
    Python libraries'."""
    out = {}
    try:
        with open(os.path.join(_ROOT, "CMakeLists.txt")) as f:
            for line in f:
                if line.strip().startswith("project(mixsph VERSION"):
                    out["mixsph"] = line.split("VERSION")[1].split()[0]
                    break
    except OSError:
        pass
    try:
        out["commit"] = subprocess.run(["git", "-C", _ROOT, "describe", "--always", "--dirty"],
                                       capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        pass
    fmu = dict(fmu or {})
    if fmu:
        out["fmu_guid"] = fmu.get("guid")
        out["fmu_sha256"] = fmu.get("sha256")
        out["fmu_path"] = fmu.get("path")
        p = fmu.get("path")
        if p and os.path.isfile(p):
            try:
                from fmpy import read_model_description
                md = read_model_description(p)
                out["fmu_version"] = md.version
                out["fmu_model"] = md.modelName
                if md.guid != fmu.get("guid"):
                    out["fmu_note"] = (f"the FMU now at {p} has GUID {md.guid}, not the one the "
                                       f"study ran on")
            except Exception as e:          # a broken FMU file: say so, the page still works
                out["fmu_note"] = f"cannot read {p}: {e}"
    import plotly
    import sklearn
    out["libraries"] = {"numpy": np.__version__, "scikit-learn": sklearn.__version__,
                        "plotly": plotly.__version__}
    return out


def _series(text) -> dict | None:
    """A run's recorded series (the store's JSON text) decimated to SERIES_POINTS."""
    if not isinstance(text, str) or not text:
        return None
    try:
        s = json.loads(text)
    except ValueError:
        return None
    t = np.asarray(s.get("time") or [], float)
    if t.size == 0:
        return None
    idx = np.unique(np.linspace(0, t.size - 1, min(SERIES_POINTS, t.size)).round().astype(int))
    return {k: [_round(v[i]) for i in idx] for k, v in s.items() if isinstance(v, list) and len(v) == t.size}


def runs_table(df, inputs, outputs) -> dict:
    """The runs as the page's table: columns, rows (display precision) and each run's series."""
    cols = [c for c in [ID, "dx"] + list(inputs) + list(outputs)
            + ["cpu_time_s", "wall_time_s", "status", "error"] if c in df.columns]
    cols = list(dict.fromkeys(cols))
    rows, series = [], []
    for rec in df.to_dict(orient="records"):
        rows.append([_round(rec.get(c)) if c not in (ID, "status", "error") else
                     ("" if rec.get(c) is None or (isinstance(rec.get(c), float) and rec.get(c) != rec.get(c))
                      else str(rec.get(c))[:300]) for c in cols])
        series.append(_series(rec.get("series")))
    return {"columns": cols, "rows": rows, "series": series}


# ---- a run's own files -------------------------------------------------------------------------

def _mixsph_tools():
    """tools/mixsph_tools (installed in .venv, or from this checkout's tools/)."""
    try:
        import mixsph_tools as mt
    except ImportError:
        import sys
        sys.path.insert(0, os.path.dirname(_HERE))
        import mixsph_tools as mt
    return mt


def run_data(run_dir) -> dict:
    """Monitors, profiles and a decimated particle animation of a mixsph run folder."""
    mt = _mixsph_tools()
    mon_path = os.path.join(run_dir, "monitors.csv")
    if not os.path.isfile(mon_path):
        raise PageError(f"{run_dir}: no monitors.csv: not the output folder of a mixsph run")
    mon = mt.read_monitors(mon_path)
    t = np.asarray(mon["t"], float)
    idx = np.unique(np.linspace(0, t.size - 1, min(4 * SERIES_POINTS, t.size)).round().astype(int)) \
        if t.size else np.array([], int)
    monitors = {k: [_round(v) for v in np.asarray(a, float)[idx]] for k, a in mon.items()}
    summary = {}
    sp = os.path.join(run_dir, "summary.json")
    if os.path.isfile(sp):
        summary = mt.read_summary(sp)
    profiles = []
    for p in sorted(glob.glob(os.path.join(glob.escape(run_dir), "profile_*.csv"))):
        pr = mt.read_profile(p)
        profiles.append({"name": pr.name, "t": pr.t, "x": [_round(v) for v in pr.x],
                         "z": [_round(v) for v in pr.z]})
    snaps = mt.list_snapshots(run_dir)
    frames = []
    if snaps:
        pick = np.unique(np.linspace(0, len(snaps) - 1, min(FRAMES, len(snaps))).round().astype(int))
        for i in pick:
            ts, cols = mt.read_snapshot(snaps[i][1])
            keep = cols["state"] != mt.STATE_LOST
            order = np.argsort(cols["id"][keep], kind="stable")
            x, z = cols["x"][keep][order], cols["z"][keep][order]
            med = cols["medium"][keep][order]
            st = cols["state"][keep][order]
            step = max(1, int(math.ceil(len(x) / FRAME_PARTICLES)))
            frames.append({"t": _round(ts), "x": [_round(v, 4) for v in x[::step]],
                           "z": [_round(v, 4) for v in z[::step]],
                           "c": [int(m) if s != mt.STATE_WALL else -1
                                 for m, s in zip(med[::step], st[::step])]})
    return {"path": os.path.abspath(run_dir), "summary": _plain(summary), "monitors": monitors,
            "profiles": profiles, "frames": frames}


# ---- particles of a study's or sweep's runs (replayed with mixsph) ------------------------------

def pick_runs(df, n) -> list[str]:
    """n scenario ids spread over the run-up: the lowest, the highest, then the median, ... of
    the ok runs at the finest dx."""
    ok = df[df["status"] == "ok"] if "status" in df.columns else df
    if ok.empty or n <= 0 or "max_run_up" not in ok.columns:
        return []
    if "dx" in ok.columns:
        dx = ok["dx"].astype(float)
        ok = ok[np.isclose(dx, dx.min())]
    ok = ok.sort_values("max_run_up")
    idx = np.unique(np.linspace(0, len(ok) - 1, min(n, len(ok))).round().astype(int))
    return [str(ok.iloc[i][ID]) for i in idx]


def animations(folder, df, settings, n, mixsph=None, log=print) -> dict:
    """{scenario_id: {frames, max_run_up (the replay's), note}} of n runs replayed with mixsph,
    or {'_note': why none}."""
    import pandas as pd
    from . import replay as RP
    from .cli import UsageError
    ids = pick_runs(df, n)
    if not ids:
        return {}
    tab = os.path.join(folder, "scenarios.csv")
    if not os.path.isfile(tab):
        return {"_note": "no scenarios.csv: the runs' own parameters are unknown"}
    sc = pd.read_csv(tab, dtype={ID: str})
    rows = []
    for sid in ids:
        r = sc[sc[ID] == sid]
        if not r.empty:
            rows.append({k: v for k, v in r.iloc[0].to_dict().items()
                         if not (isinstance(v, float) and math.isnan(v))})
    try:
        done = RP.replay(folder, rows, settings.get("fmu"), float(settings.get("stop_time") or 1.6),
                         mixsph=mixsph, snapshots=FRAMES, log=log)
    except UsageError as e:
        log(f"dss page: no particle animation: {e}")
        return {"_note": str(e)}
    out = {}
    for sid, run_dir in done.items():
        try:
            rd = run_data(run_dir)
        except Exception as e:       # a replay's files unreadable: the page goes without it
            log(f"dss page: replay {run_dir}: {e}")
            continue
        runup = ((rd["summary"].get("outputs") or {}).get("run_up") or {}).get("max")
        out[sid] = {"frames": rd["frames"], "max_run_up": runup, "path": run_dir}
    return out


# ---- the three kinds of page -------------------------------------------------------------------

def _read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except ValueError as e:
        raise PageError(f"{path}: not a JSON file ({e})") from None


def _discretisation(em, output, n=RISK_POINTS, seed=0) -> dict | None:
    """The study's discretisation error: finest level against the limit over the box."""
    from . import multifidelity as M
    m = em.models.get(output)
    if m is None or not m.order:
        return None
    U = np.random.default_rng(seed).random((n, len(em.inputs)))
    X = em.box[:, 0] + U * (em.box[:, 1] - em.box[:, 0])
    fin, _ = em.predict(X, output, "finest")
    lim, sd = em.predict(X, output, M.EXTRAPOLATED)
    d = fin - lim
    return {"output": output, "finest_dx": em.dxs[-1], "mean": float(np.mean(d)),
            "mean_abs": float(np.mean(np.abs(d))), "max_abs": float(np.max(np.abs(d))),
            "sd_limit_mean": float(np.mean(sd)), "order": m.order}


def study_data(folder, animate=0, mixsph=None) -> dict:
    """The page data of a multi-fidelity study folder (emulate study)."""
    from . import multifidelity as M
    from .store import open_store
    ep = os.path.join(folder, "mf_emulator.json")
    doc = _read_json(ep)
    try:
        em = M.MFEmulator.from_json(doc)
    except (KeyError, ValueError) as e:
        raise PageError(f"{ep}: not a multi-fidelity emulator this code reads ({e})") from None
    study = _read_json(os.path.join(folder, "study.json")) if os.path.isfile(
        os.path.join(folder, "study.json")) else {}
    design = _read_json(os.path.join(folder, "mfdesign.json")) if os.path.isfile(
        os.path.join(folder, "mfdesign.json")) else {}
    sweep = _read_json(os.path.join(folder, "sweep.json")) if os.path.isfile(
        os.path.join(folder, "sweep.json")) else {}
    risk, sobol = study.get("risk") or {}, study.get("sobol") or {}
    risk_output = risk.get("output") or next(iter(em.models))
    df = open_store(folder).latest() if (os.path.isdir(os.path.join(folder, "results.parquet"))
                                         or os.path.isfile(os.path.join(folder, "results.csv"))) else None
    spec = design.get("spec") or {}
    dists = spec.get("dists") or {}
    inputs = []
    for n, b in zip(em.inputs, em.box):
        s = dists.get(n, "")
        choices = None
        if s.startswith("choice:"):
            choices = [float(x) for x in s.split(":", 1)[1].split(",")]
        inputs.append({"name": n, "lo": float(b[0]), "hi": float(b[1]), "dist": s,
                       "choices": choices})
    runs = None
    cost = {}
    if df is not None and not df.empty:
        runs = runs_table(df, em.inputs, [o for o in ("max_run_up", "max_run_up_Z",
                                                       "time_of_max_run_up") if o in df.columns])
        ok = df[df["status"] == "ok"]
        for dx in em.dxs:
            c = ok.loc[np.isclose(ok["dx"].astype(float), dx), "cpu_time_s"].astype(float)
            cost[f"{dx:g}"] = {"runs": int(len(c)), "median_cpu_s": _round(np.median(c)) if len(c) else None,
                               "sum_cpu_s": _round(c.sum())}
        cost["total_cpu_s"] = _round(df["cpu_time_s"].astype(float).sum())
    validation = []
    for p in sorted(glob.glob(os.path.join(glob.escape(folder), "*.json"))):
        try:
            v = _read_json(p)
        except (OSError, ValueError):
            continue
        if isinstance(v, dict) and "metrics" in v and "level" in v:     # mf-validate --json
            validation.append({"file": os.path.basename(p), "level": v["level"],
                               "holdout_dx": v.get("holdout_dx"), "metrics": v["metrics"],
                               "rms_z": v.get("rms_z")})
    data = {
        "kind": "study", "title": f"DSS study {os.path.basename(os.path.abspath(folder))}",
        "folder": os.path.abspath(folder),
        "created": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "emulator": export_mf(em), "inputs": inputs,
        "risk": _plain(risk), "sobol": _plain(sobol), "risk_output": risk_output,
        "design": _plain({"spec": spec, "stopped": design.get("stopped"),
                          "budget_cpu_s": design.get("budget_cpu_s"),
                          "batches": [{"kind": b.get("kind"), "n": len(b.get("ids", []))}
                                      for b in design.get("batches", [])]}),
        "settings": _plain({k: v for k, v in sweep.items() if k != "fmu"}),
        "cost": cost, "validation": _plain(validation),
        "discretisation": _plain(_discretisation(em, risk_output)),
        "versions": _plain({**versions(doc.get("fmu")), "emulator_file": doc.get("created"),
                            "emulator_libraries": doc.get("library")}),
        "runs": runs, "elapsed_s": study.get("elapsed_s"),
        "checks": self_checks(em),
        "animations": animations(folder, df, sweep, animate, mixsph) if df is not None else {},
    }
    return data


def self_checks(em, n=CHECK_POINTS, seed=1) -> list[dict]:
    """Python's predictions at a few random points of the box, per output and level: the page
    recomputes them when it opens and refuses to show numbers that differ (by over 1e-9)."""
    rng = np.random.default_rng(seed)
    out = []
    for name in em.models:
        for key in page_levels(em):
            X = em.box[:, 0] + rng.random((n, len(em.inputs))) * (em.box[:, 1] - em.box[:, 0])
            try:
                mu, sd = python_predict(em, name, key, X)
            except Exception:        # a level this output has no extrapolation for
                continue
            out += [{"output": name, "level": key, "x": x.tolist(), "mean": float(m), "sd": float(s)}
                    for x, m, s in zip(X, mu, sd)]
    return out


def sweep_data(folder, crest=None, animate=0, mixsph=None) -> dict:
    """The page data of a sweep folder (dss sweep)."""
    from .report import pick_runup, varied_params
    from .store import open_store
    df = open_store(folder).latest()
    if df.empty:
        raise PageError(f"{folder}: no results")
    sweep = _read_json(os.path.join(folder, "sweep.json")) if os.path.isfile(
        os.path.join(folder, "sweep.json")) else {}
    outs = [o for o in ("max_run_up", "max_run_up_Z", "time_of_max_run_up") if o in df.columns]
    tab = os.path.join(folder, "scenarios.csv")
    if os.path.isfile(tab):      # the scenarios' own parameters, those that vary
        import pandas as pd
        sc = pd.read_csv(tab, dtype={ID: str})
        inputs = [c for c in sc.columns if c != ID and c in df.columns and sc[c].nunique() > 1]
    else:
        inputs = [c for c in varied_params(df) if c not in outs and c != "series"]
    ok = df[df["status"] == "ok"] if "status" in df.columns else df
    ycol = None
    if not ok.empty:
        try:
            ycol = pick_runup(ok)[0]
        except ValueError:
            ycol = None
    fmu = {}
    if sweep.get("fmu") and os.path.isfile(sweep["fmu"]):
        try:
            from .emulator import fmu_identity
            fmu = fmu_identity(sweep["fmu"])
        except Exception:
            fmu = {"path": sweep["fmu"]}
    extra = {}
    ep = os.path.join(folder, "emulator.json")
    if os.path.isfile(ep):
        # an emulator of these runs (emulate fit / design): the prediction panel
        from . import emulator as E
        doc = _read_json(ep)
        try:
            em = E.Emulator.from_json(doc)
        except (KeyError, ValueError) as e:
            raise PageError(f"{ep}: not an emulator this code reads ({e})") from None
        extra = {"emulator": export_sf(em), "checks": self_checks(em),
                 "emulator_inputs": [{"name": n, "lo": float(b[0]), "hi": float(b[1]),
                                      "choices": [0.0, 1.0] if k == "binary" else None}
                                     for n, k, b in zip(em.inputs, em.kinds, em.box)],
                 "emulator_created": doc.get("created")}
    return {**extra, "kind": "sweep", "title": f"DSS sweep {os.path.basename(os.path.abspath(folder))}",
            "folder": os.path.abspath(folder),
            "created": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "settings": _plain({k: v for k, v in sweep.items() if k != "fmu"}),
            "inputs": [{"name": n, "lo": _round(ok[n].astype(float).min()) if not ok.empty else None,
                        "hi": _round(ok[n].astype(float).max()) if not ok.empty else None,
                        "values": int(df[n].nunique())} for n in inputs],
            "y": ycol, "crest": crest, "runs": runs_table(df, inputs, outs),
            "animations": animations(folder, df, sweep, animate, mixsph),
            "versions": _plain(versions(fmu))}


def run_page_data(run_dir) -> dict:
    r = run_data(run_dir)
    return {"kind": "run", "title": f"mixsph run {os.path.basename(os.path.abspath(run_dir))}",
            "folder": os.path.abspath(run_dir),
            "created": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "run": r, "versions": _plain(versions())}


def kind_of(folder) -> str:
    if os.path.isfile(os.path.join(folder, "mf_emulator.json")):
        return "study"
    if os.path.isdir(os.path.join(folder, "results.parquet")) or \
            os.path.isfile(os.path.join(folder, "results.csv")):
        return "sweep"
    if os.path.isfile(os.path.join(folder, "monitors.csv")):
        return "run"
    raise PageError(f"{folder}: neither a study (mf_emulator.json), a sweep (results.parquet or "
                    f"results.csv) nor a mixsph run folder (monitors.csv)")


# ---- the HTML ----------------------------------------------------------------------------------

def render(data: dict) -> str:
    """The page: Plotly's bundle, the data as one JSON block, report_page.js."""
    from plotly.offline import get_plotlyjs
    blob = json.dumps(_plain(data), separators=(",", ":"), allow_nan=False)
    blob = blob.replace("</", "<\\/")            # no "</script>" inside the block
    with open(os.path.join(_HERE, "report_page.js")) as f:
        app = f.read()
    with open(os.path.join(_HERE, "report_page.css")) as f:
        css = f.read()
    title = html.escape(data.get("title", "mixsph report"))
    return (f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
            f"<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            f"<title>{title}</title>\n<style>{css}</style>\n"
            f"<script>{get_plotlyjs()}</script>\n</head>\n<body>\n"
            f"<div id=\"page-status\" data-status=\"loading\">loading ...</div>\n"
            f"<main id=\"app\"><h1>{title}</h1></main>\n"
            f"<script type=\"application/json\" id=\"page-data\">{blob}</script>\n"
            f"<script>{app}</script>\n</body></html>\n")


def write_page(folder, out=None, crest=None, animate=ANIMATE, mixsph=None) -> str:
    """Write the page of a study, sweep or run folder (kind_of) to out (default
    FOLDER/report.html); returns its path. animate: runs of a study or sweep replayed with
    mixsph for their particles (replay.py; kept in FOLDER/replays for the next page)."""
    kind = kind_of(folder)
    data = {"study": lambda f: study_data(f, animate, mixsph),
            "sweep": lambda f: sweep_data(f, crest, animate, mixsph),
            "run": run_page_data}[kind](folder)
    path = out or os.path.join(folder, PAGE)
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(render(data))
    os.replace(tmp, path)
    return path
