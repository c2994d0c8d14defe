"""python -m tools.dss emulate COMMAND ... : a Gaussian-process emulator of LandslideWave.fmu.

  fit SWEEP          fit the emulator of a sweep folder's results (varied parameters ->
                     max_run_up, time_of_max_run_up, max_run_up_Z, landslide_front), with k-fold
                     cross-validation; writes SWEEP/emulator.json and the plots
  predict EMU        mean, sd and 95 % interval per scenario (--set NAME=VALUE ... or --csv);
                     queries outside the training box are flagged in the column out_of_box
  design OUT         sequential design on the Dask cluster: a Latin hypercube, then batches at
                     the largest integrated-variance reduction (--criterion imse, default), the
                     largest predictive sd (--criterion sd) or, with --crest, the most uncertain
                     exceedance
                     until the CV error is below --target-error or --budget runs are spent;
                     resumable; writes OUT/emulator.json
  validate EMU SWEEP the emulator against runs it was not fitted on (a hold-out sweep): RMSE,
                     largest error, 95 % coverage, in % of the output's range
  risk EMU           P(output > crest) under parameter distributions (--dist, the sweep's
                     syntax), with its band from joint posterior draws, and Sobol indices
  plot EMU           the response surface over reservoir_level and phi with its uncertainty
  curve DESIGN HOLD  the hold-out error of emulators of a design's first n runs, against n
  mf-design, mf-fit, mf-predict, mf-validate, mf-risk, study
                     the multi-fidelity emulator over a ladder of spacings dx, with the
                     dx -> 0 extrapolation and its error (emulate_mf.py)
  jitter OUT         measure the FMU's discretisation noise: runs at a box point with the
                     reservoir level moved by up to half a particle spacing; writes
                     OUT/jitter.json, which fit and design take as the noise term's lower bound
                     (--noise-floor)

The emulator file is JSON (docs/dss.md, section Emulator); it is checked against the FMU
(--fmu, default build/LandslideWave.fmu): another GUID is refused. Exit codes: 0 ok, 1 the job
could not be done, 2 bad usage or input (a refused FMU included), 130 interrupted.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np
import pandas as pd

from . import emulator as E
from .cli import (UsageError, common_cluster_args, common_run_args, default_fmu, enumeration_items, fmu_items,
                  item_choices, item_value, item_values, parse_box, parse_dists, parse_sets, parse_value,
                  resolve_run, save_json)


def _load(args):
    fmu = args.fmu or default_fmu()
    return E.load(args.emulator, fmu, check_fmu=not args.no_fmu_check)


def _fmu_args(p):
    p.add_argument("--fmu", help="the FMU the emulator must belong to (default: $DSS_FMU, else "
                                 "build/LandslideWave.fmu)")
    p.add_argument("--no-fmu-check", action="store_true",
                   help="do not check the emulator's FMU GUID (no FMU at hand)")


def build_parser():
    ap = argparse.ArgumentParser(prog="python -m tools.dss emulate", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)

    def fit_opts(p, design=False):
        p.add_argument("--categorical", choices=("auto",) + E.MODES,
                       default="product" if design else "auto",
                       help="how binary inputs (saturated) enter the GP: product (x a two-level "
                            "kernel), binary (a 0/1 coordinate), separate (a GP per level), auto "
                            "(the lowest CV RMSE of the three) (default "
                            f"{'product' if design else 'auto'})")
        p.add_argument("--folds", type=int, default=5 if design else 10,
                       help=f"k of the k-fold cross-validation (default {5 if design else 10})")
        p.add_argument("--restarts", type=int, default=1 if design else 3,
                       help="optimizer restarts of the hyperparameters (default "
                            f"{2 if design else 3})")
        p.add_argument("--seed", type=int, default=0)
        p.add_argument("--noise-floor", metavar="JITTER.json",
                       help="the measured noise variance per output (emulate jitter) as the "
                            "lower bound of the GP's noise term (default: the bounds "
                            f"{E.NOISE_BOUNDS[0]:g}..{E.NOISE_BOUNDS[1]:g} of the standardised "
                            "variance, fitted)")
        p.add_argument("--noise", choices=E.NOISE_MODES, default="floor",
                       help="with --noise-floor: floor (the lower bound; the fit may put more "
                            "noise) or fixed (the noise term is the measured variance)")

    f = sub.add_parser("fit", help="fit the emulator of a sweep folder's results")
    f.add_argument("sweep", help="a sweep folder (results.parquet or results.csv)")
    f.add_argument("--output", action="append", default=[], metavar="NAME",
                   help="an output to emulate (repeatable; default max_run_up, "
                        "time_of_max_run_up, max_run_up_Z, landslide_front)")
    f.add_argument("--inputs", help="comma-separated inputs (default: the physical and "
                                    "numerical parameters the sweep varied)")
    f.add_argument("--box", action="append", default=[], metavar="NAME=LO:HI",
                   help="the training box of an input (default: the range of its runs)")
    f.add_argument("-o", "--out", help="emulator file (default SWEEP/emulator.json)")
    f.add_argument("--fmu", help="the FMU the runs are of (default: the sweep's, from sweep.json)")
    f.add_argument("--no-plots", action="store_true")
    fit_opts(f)

    p = sub.add_parser("predict", help="predict scenarios")
    p.add_argument("emulator")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="an input value (repeatable; a comma list gives several scenarios, all "
                        "lists of the same length)")
    p.add_argument("--csv", help="scenarios: one row each, a column per input")
    p.add_argument("--output", action="append", default=[], metavar="NAME")
    p.add_argument("-o", "--out", help="write the table as CSV (default: print it)")
    _fmu_args(p)

    d = sub.add_parser("design", help="sequential design of FMU runs (resumable)")
    d.add_argument("out")
    d.add_argument("--dist", action="append", default=[], metavar="NAME=SPEC", required=True,
                   help="the box of an input: uniform:lo:hi, loguniform:lo:hi, choice:a,b, "
                        "normal:mean:sd:lo:hi (repeatable)")
    d.add_argument("--budget", type=int, required=True, help="FMU runs at most")
    d.add_argument("--target-error", type=float, required=True, metavar="PCT",
                   help="stop when the CV RMSE is at most PCT %% of the output's range")
    d.add_argument("--output", default="max_run_up", help="the output designed for")
    d.add_argument("--init", type=int, help="runs of the Latin-hypercube start (default "
                                            "min(budget/3, 10 per input), at least one batch)")
    d.add_argument("--min-runs", type=int, metavar="N",
                   help="runs before the CV target may stop the design (default 10 per input, "
                        "at most the budget)")
    d.add_argument("--crest", type=float, metavar="Z",
                   help="pick where P(output > Z) is most uncertain (max p(1-p)) instead of by "
                        "--criterion")
    d.add_argument("--criterion", choices=("imse", "sd"),
                   help="without --crest: imse, the largest reduction of the posterior variance "
                        "integrated over 500 random points of the box (default), or sd, the "
                        "largest predictive sd (the design of before; its picks sit on the box's "
                        "faces); a setting of the design (a resumed design keeps it)")
    d.add_argument("--candidates", type=int,
                   help="random candidates per batch (1000 per input; with imse at most 2000)")
    d.add_argument("--no-plots", action="store_true")
    d.add_argument("--fit-output", action="append", default=[], metavar="NAME",
                   help="another output the final emulator fits (repeatable; default: "
                        "max_run_up_Z when the output is max_run_up)")
    d.add_argument("--final-categorical", choices=("auto",) + E.MODES, default="auto",
                   help="the binary inputs' handling of the final fit (10-fold CV, refitted "
                        "per fold; default auto)")
    fit_opts(d, design=True)
    common_run_args(d)
    common_cluster_args(d)

    v = sub.add_parser("validate", help="the emulator against a hold-out sweep")
    v.add_argument("emulator")
    v.add_argument("sweep")
    v.add_argument("--output", default="max_run_up")
    v.add_argument("--range", type=float, help="the output's range the errors are relative to "
                                               "(default: of the training and hold-out runs)")
    v.add_argument("--plot", help="predicted vs simulated PNG (CV and hold-out)")
    v.add_argument("--json", help="write the metrics as JSON")
    _fmu_args(v)

    r = sub.add_parser("risk", help="exceedance probability and Sobol indices")
    r.add_argument("emulator")
    r.add_argument("--dist", action="append", default=[], metavar="NAME=SPEC",
                   help="an input's distribution (the sweep's syntax; repeatable)")
    r.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="an input fixed")
    r.add_argument("--crest", type=float, required=True, metavar="Z")
    r.add_argument("--output", default="max_run_up_Z",
                   help="the output compared with the crest (default max_run_up_Z, else the first)")
    r.add_argument("-n", "--n", type=int, default=100_000, help="samples (default 1e5)")
    r.add_argument("--draws", type=int, default=200, help="joint posterior draws (default 200)")
    r.add_argument("--joint", type=int, default=1000,
                   help="samples the joint draws are taken at (default 1000)")
    r.add_argument("--sobol-n", type=int, default=4096,
                   help="base samples of the Sobol indices (N (d+2) evaluations; default 4096)")
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--plots", metavar="DIR", help="write exceedance.png and sobol.png there")
    r.add_argument("--json", help="write the result as JSON")
    _fmu_args(r)

    c = sub.add_parser("curve", help="hold-out error against the number of a design's runs")
    c.add_argument("design", help="a design folder (emulate design)")
    c.add_argument("holdout", help="a hold-out sweep folder")
    c.add_argument("--sizes", default="", help="comma-separated run counts (default: after "
                                               "every 10 runs and at the end)")
    c.add_argument("--output", default="max_run_up")
    c.add_argument("--categorical", choices=E.MODES, help="default: the design's emulator's")
    c.add_argument("--range", type=float, help="the range the errors are relative to")
    c.add_argument("--compare", action="append", default=[], metavar="SWEEP",
                   help="another folder (e.g. a Latin hypercube) fitted whole and validated alike")
    c.add_argument("--plot", help="PNG of the curve")
    c.add_argument("--json", help="write the table as JSON")
    _fmu_args(c)

    j = sub.add_parser("jitter", help="measure the FMU's discretisation noise (resumable)")
    j.add_argument("out")
    j.add_argument("--at", action="append", default=[], required=True, metavar="NAME=V[,V...]",
                   help="the box point (repeatable; a comma list gives one point per value, "
                        "e.g. saturated=0,1; the lists' product)")
    j.add_argument("--perturb", action="append", default=[], metavar="NAME=H",
                   help="an input moved by offsets in [-H, H] (a Latin hypercube per point; "
                        "default reservoir_level=dx/2: the lattice is anchored at the level, so "
                        "this moves the water's particles through one particle spacing against "
                        "the slide and the terrain)")
    j.add_argument("-n", "--n", type=int, default=6, help="runs per point (default 6)")
    j.add_argument("--seed", type=int, default=0)
    j.add_argument("--output", action="append", default=[], metavar="NAME",
                   help="an output to measure (default: the emulator's default outputs)")
    j.add_argument("--no-plots", action="store_true")
    common_run_args(j)
    common_cluster_args(j)

    from . import emulate_mf
    emulate_mf.add_parsers(sub)

    q = sub.add_parser("plot", help="the response surface over two inputs")
    q.add_argument("emulator")
    q.add_argument("--output", default="max_run_up")
    q.add_argument("--x", default="reservoir_level")
    q.add_argument("--y", default="phi")
    q.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="the value of another input (default: the middle of its box)")
    q.add_argument("-o", "--out", help="PNG (default: beside the emulator, surface_OUTPUT.png)")
    _fmu_args(q)
    return ap


# ---- commands ---------------------------------------------------------------------------------

def _print_noise(em, name):
    m = em.models[name]
    fit = ", ".join(f"{math.sqrt(v):.4g}" for v in m.fitted_noise())
    if m.noise:
        print(f"  {name}: noise term: measured sd {m.noise['sd']:.4g} (95 % CI "
              f"{m.noise['ci95_sd'][0]:.4g}-{m.noise['ci95_sd'][1]:.4g}, {m.noise['dof']} dof) as "
              f"its {'lower bound' if m.noise['mode'] == 'floor' else 'fixed value'}; fitted sd "
              f"{fit}")
    else:
        print(f"  {name}: noise term: fitted sd {fit} (no measured floor)")


def _print_cv(name, cv, comparison=None):
    if comparison:
        for mode, c in comparison.items():
            if "error" in c:
                print(f"  {name}: mode {mode}: not fitted ({c['error']})")
            else:
                print(f"  {name}: mode {mode:8s} CV RMSE {c['rmse_pct']:.2f} %, max "
                      f"{c['max_error_pct']:.2f} %, coverage {100 * c['coverage95']:.0f} % "
                      f"({c['seconds']:.1f} s)")
    if cv:
        print(f"{name}: {cv['folds']}-fold CV over {cv['n']} runs (mode {cv['mode']}): RMSE "
              f"{cv['rmse']:.4g} ({cv['rmse_pct']:.2f} % of the range {cv['range']:.4g}), "
              f"largest error {cv['max_error']:.4g} ({cv['max_error_pct']:.2f} %), "
              f"95 % coverage {100 * cv['coverage95']:.1f} %")


def fit_folder(folder, outputs=None, inputs=None, box=None, fmu=None, mode="auto", folds=10,
               restarts=3, seed=0, out=None, plots=True, noise_file=None, noise_mode="floor"):
    from .store import open_store
    df = open_store(folder).latest()
    if df.empty:
        raise UsageError(f"no results in {folder}")
    settings = {}
    sp = os.path.join(folder, "sweep.json")
    if os.path.isfile(sp):
        with open(sp) as f:
            settings = json.load(f)
    fmu = fmu or settings.get("fmu") or default_fmu()
    if not os.path.isfile(fmu):
        raise UsageError(f"the FMU {fmu} of these runs is not there: give --fmu")
    ident = E.fmu_identity(fmu)
    ok = df[df["status"] == "ok"]
    em = E.from_results(ok, outputs=outputs, inputs=inputs, box=box, fmu=ident,
                        sweep={**settings, "source": os.path.abspath(folder), "n_runs": len(ok),
                               "n_failed": int((df["status"] != "ok").sum())})
    if noise_file:
        em.noise = E.noise_from_file(noise_file, list(em.Y), noise_mode, ident,
                                     dx=settings.get("dx"))
    t0 = time.perf_counter()
    for name in list(em.Y):
        if not np.isfinite(em.Y[name]).any():
            del em.Y[name]
            continue
        em.fit_output(name, mode=mode, restarts=restarts, seed=seed, folds=folds)
    fit_s = time.perf_counter() - t0
    out = out or os.path.join(folder, "emulator.json")
    em.save(out)
    files = [out]
    if plots:
        from . import emulate_plots as P
        d = os.path.dirname(os.path.abspath(out))
        for name in em.models:
            if name in em.cv:
                files.append(P.cv_plot(em.cv[name], name, os.path.join(d, f"cv_{name}.png")))
        if "reservoir_level" in em.inputs and "phi" in em.inputs and "max_run_up" in em.models:
            files.append(P.surface(em, "max_run_up", os.path.join(d, "surface_max_run_up.png")))
    return em, files, fit_s


def cmd_fit(args):
    inputs = [s.strip() for s in args.inputs.split(",")] if args.inputs else None
    em, files, fit_s = fit_folder(args.sweep, args.output or None, inputs, parse_box(args.box),
                                  args.fmu, args.categorical, args.folds, args.restarts,
                                  args.seed, args.out, not args.no_plots,
                                  args.noise_floor, args.noise)
    print(f"emulate: {len(em.X)} runs, inputs " + ", ".join(
        f"{n} [{b[0]:g}, {b[1]:g}]{' (binary)' if k == 'binary' else ''}"
        for n, k, b in zip(em.inputs, em.kinds, em.box)) + f"; fitted in {fit_s:.1f} s")
    for name in em.models:
        _print_cv(name, em.cv.get(name), em.mode_comparison.get(name))
        _print_noise(em, name)
        print(f"  kernel: {em.models[name].parts[next(iter(em.models[name].parts))].kernel_}")
    for f in files:
        print(f"  wrote {f}")
    return 0


def _scenarios_from_args(em, args) -> pd.DataFrame:
    if args.csv:
        df = pd.read_csv(args.csv)
    else:
        cols = {}
        items = fmu_items(args.fmu or default_fmu())  # rheology=elastic_plastic: its value
        for it in args.set:
            from .scenarios import split_assignment
            k, v = split_assignment(it)
            cols[k] = [float(item_value(k, x.strip(), items)) for x in v.split(",")]
        if not cols:
            raise UsageError("give the scenarios: --set NAME=VALUE ... or --csv FILE")
        lens = {len(v) for v in cols.values()}
        n = max(lens)
        if lens - {1, n}:
            raise UsageError("--set lists must have one value or the same length")
        df = pd.DataFrame({k: v * n if len(v) == 1 else v for k, v in cols.items()})
    missing = [n for n in em.inputs if n not in df.columns]
    if missing:
        raise UsageError(f"no value of {', '.join(missing)} (the emulator's inputs: "
                         f"{', '.join(em.inputs)})")
    return df


def predict_table(em, df, outputs=None) -> pd.DataFrame:
    X = df[em.inputs].astype(float).to_numpy()
    res = em.predict(X, outputs)
    out = df.copy()
    for name in outputs or list(em.models):
        mu, sd = res[name]
        out[f"{name}_mean"] = mu
        out[f"{name}_sd"] = sd
        out[f"{name}_lo95"] = mu - E.Z95 * sd
        out[f"{name}_hi95"] = mu + E.Z95 * sd
    out["out_of_box"] = res["out_of_box"]
    return out


def cmd_predict(args):
    em = _load(args)
    df = _scenarios_from_args(em, args)
    t0 = time.perf_counter()
    tab = predict_table(em, df, args.output or None)
    ms = 1e3 * (time.perf_counter() - t0)
    n_oob = int((tab["out_of_box"] != "").sum())
    if args.out:
        tab.to_csv(args.out, index=False)
        print(f"emulate: wrote {args.out}")
    else:
        with pd.option_context("display.max_columns", None, "display.width", 200):
            print(tab.to_string(index=False))
    print(f"emulate: {len(tab)} scenarios predicted in {ms:.1f} ms"
          + (f"; {n_oob} outside the training box (column out_of_box: those inputs; "
             f"extrapolated, not trusted)" if n_oob else ""), file=sys.stderr)
    return 0


def cmd_validate(args):
    from .store import open_store
    em = _load(args)
    df = open_store(args.sweep).latest()
    df = df[df["status"] == "ok"]
    if df.empty:
        raise UsageError(f"no ok runs in {args.sweep}")
    out = args.output
    train_ids = set()
    X = df[em.inputs].astype(float).to_numpy()
    y = df[out].astype(float).to_numpy()
    mu, sd = em.predict(X, [out])[out]
    oob = em.out_of_box(X)
    rows, y_tr = em._rows(out)
    rng = args.range or float(max(y.max(), y_tr.max()) - min(y.min(), y_tr.min()))
    m = E.metrics(y, mu, sd, y_range=rng)
    m.update({"y": y.tolist(), "mean": mu.tolist(), "sd": sd.tolist(),
              "n_out_of_box": int((oob != "").sum()), "training_runs": len(rows),
              "holdout": os.path.abspath(args.sweep)})
    # the same runs must not be in the training set
    Xtr = em.X[rows]
    dup = sum(bool(np.any(np.all(np.isclose(Xtr, x, rtol=0, atol=1e-12), axis=1))) for x in X)
    m["in_training_set"] = int(dup)
    del train_ids
    print(f"emulate validate: {m['n']} hold-out runs ({m['n_out_of_box']} outside the box, "
          f"{dup} also training runs), emulator of {len(rows)} runs: RMSE {m['rmse']:.4g} "
          f"({m['rmse_pct']:.2f} % of the range {rng:.4g}), largest error {m['max_error']:.4g} "
          f"({m['max_error_pct']:.2f} %), 95 % coverage {100 * m['coverage95']:.1f} %")
    if args.plot:
        from . import emulate_plots as P
        P.ensure_dir(args.plot)
        cv = em.cv.get(out)
        if cv:
            cv = dict(cv)
            cvm = E.metrics(cv["y"], cv["mean"], cv["sd"], y_range=rng)
            cv.update({k: cvm[k] for k in ("rmse_pct", "max_error_pct")})
            P.cv_plot(cv, out, args.plot, title=f"{cv['folds']}-fold CV", holdout=m)
        else:
            P.cv_plot(m, out, args.plot, title="hold-out")
        print(f"  wrote {args.plot}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(E._jsonable(m), f, indent=1)
        print(f"  wrote {args.json}")
    return 0


def cmd_risk(args):
    em = _load(args)
    output = args.output
    if output not in em.models:
        if args.output == "max_run_up_Z" and em.models:
            output = next(iter(em.models))
        else:
            raise UsageError(f"no emulator of {output!r} ({', '.join(em.models)})")
    items = fmu_items(args.fmu or default_fmu())
    dists = parse_dists(args.dist)
    item_choices(dists.values(), items)
    fixed = item_values(parse_sets(args.set), items)
    if not dists:
        raise UsageError("give the inputs' distributions with --dist NAME=SPEC")
    t0 = time.perf_counter()
    probe = E.exceedance(em, output, dists, fixed, args.crest, n=2000, n_joint=10, n_draws=2,
                         seed=args.seed)
    lo, hi = np.quantile(probe["_mu"], [0.001, 0.999])
    pad = 0.15 * (hi - lo) + 1e-12
    z = np.linspace(min(lo - pad, args.crest), max(hi + pad, args.crest), 61)
    t0 = time.perf_counter()
    r = E.exceedance(em, output, dists, fixed, args.crest, n=args.n, n_joint=args.joint,
                     n_draws=args.draws, seed=args.seed, z_grid=z)
    t_exc = time.perf_counter() - t0
    t1 = time.perf_counter()
    s = E.sobol(em, output, dists, fixed, n_base=args.sobol_n, seed=args.seed)
    t_sob = time.perf_counter() - t1
    r.pop("_mu", None)
    print(f"emulate risk: P({output} > {args.crest:g}) = {r['p']:.4f}, 95 % band "
          f"[{r['p_lo']:.4f}, {r['p_hi']:.4f}] from {r['n_draws']} joint posterior draws at "
          f"{r['n_joint']} samples (sd {r['p_draws_sd']:.4f}); Monte Carlo se {r['mc_se']:.1e} "
          f"over {r['n']} samples; from the mean alone {r['p_mean_only']:.4f}"
          + (f"; {100 * r['out_of_box_fraction']:.1f} % of the samples outside the training box"
             if r["out_of_box_fraction"] else ""))
    print(f"  {r['n']} samples + the joint draws in {t_exc:.2f} s; Sobol indices "
          f"({s['n_model']} evaluations of the mean) in {t_sob:.2f} s; total "
          f"{t_exc + t_sob:.2f} s")
    print("  Sobol indices of the mean:   " + "  ".join(f"{n:>22s}" for n in s["names"]))
    print("    first order S1 (+- 95 %):  " + "  ".join(
        f"{a:10.3f} +- {c:9.3f}" for a, c in zip(s["S1"], s["S1_conf"])))
    print("    total ST (+- 95 %):        " + "  ".join(
        f"{a:10.3f} +- {c:9.3f}" for a, c in zip(s["ST"], s["ST_conf"])))
    r["sobol"] = s
    r["timing_s"] = {"exceedance": t_exc, "sobol": t_sob}
    if args.plots:
        from . import emulate_plots as P
        os.makedirs(args.plots, exist_ok=True)
        for f in (P.exceedance_plot(r, os.path.join(args.plots, "exceedance.png")),
                  P.sobol_plot(s, output, os.path.join(args.plots, "sobol.png"))):
            print(f"  wrote {f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(E._jsonable(r), f, indent=1)
        print(f"  wrote {args.json}")
    return 0


def cmd_curve(args):
    """Fit the design's first n runs (in the order the design ran them) for several n and
    validate each on the hold-out: the hold-out error against the number of runs."""
    from .store import open_store
    from .scenarios import ID
    em_final = _load(argparse.Namespace(emulator=os.path.join(args.design, "emulator.json"),
                                        fmu=args.fmu, no_fmu_check=args.no_fmu_check))
    out = args.output
    mode = args.categorical or em_final.models[out].mode
    with open(os.path.join(args.design, "design.json")) as f:
        st = json.load(f)
    order = [i for b in st["batches"] for i in b["ids"]]
    runs = open_store(args.design).latest().set_index(ID)
    runs = runs.loc[[i for i in order if i in runs.index]]
    hold = open_store(args.holdout).latest()
    hold = hold[hold["status"] == "ok"]
    n_all = len(runs)
    sizes = [int(x) for x in args.sizes.split(",") if x.strip()] or \
        sorted(set(list(range(10, n_all, 10)) + [n_all]))
    box = {n: (float(lo), float(hi)) for n, (lo, hi) in zip(em_final.inputs, em_final.box)}
    y_h = hold[out].astype(float).to_numpy()
    rng = args.range or float(np.ptp(np.concatenate([y_h, runs[out].astype(float).to_numpy()])))
    rows = []

    def one(label, df, n):
        ok = df[df["status"] == "ok"]
        em = E.from_results(ok, outputs=[out], inputs=em_final.inputs, box=box,
                            noise=em_final.noise)
        em.fit_output(out, mode=mode, restarts=3, cv=False)
        mu, sd = em.predict(hold[em.inputs].astype(float).to_numpy(), [out])[out]
        m = E.metrics(y_h, mu, sd, y_range=rng)
        rows.append({"set": label, "runs": n, **{k: m[k] for k in (
            "rmse", "max_error", "coverage95", "rmse_pct", "max_error_pct")}})
        r = rows[-1]
        print(f"  {label:10s} {n:4d} runs: hold-out RMSE {r['rmse_pct']:.2f} %, max "
              f"{r['max_error_pct']:.2f} %, coverage {100 * r['coverage95']:.1f} %")

    nz = em_final.noise.get(out)
    print(f"emulate curve: {len(hold)} hold-out runs, mode {mode}, errors in % of {rng:.4g}, "
          + (f"the design's measured noise sd {nz['sd']:.4g} ({nz['mode']})" if nz else
             "no measured noise floor"))
    for n in sizes:
        if n < 3 or n > n_all:
            continue
        one("design", runs.iloc[:n].reset_index(), n)
    for folder in args.compare:
        df = open_store(folder).latest()
        one(os.path.basename(os.path.normpath(folder)), df, int((df["status"] == "ok").sum()))
    if args.plot:
        from . import emulate_plots as P
        P.ensure_dir(args.plot)
        P.curve_plot(rows, args.plot)
        print(f"  wrote {args.plot}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(E._jsonable({"range": rng, "mode": mode, "holdout_runs": len(hold),
                                   "noise": nz, "rows": rows}), f, indent=1)
        print(f"  wrote {args.json}")
    return 0


def cmd_plot(args):
    from . import emulate_plots as P
    em = _load(args)
    out = args.out or os.path.join(os.path.dirname(os.path.abspath(args.emulator)),
                                   f"surface_{args.output}.png")
    P.surface(em, args.output, out, x=args.x, y=args.y, fixed=parse_sets(args.set))
    print(f"emulate: wrote {out}")
    return 0


def cmd_design(args):
    from . import design as D, runner
    from .scenarios import Distribution, split_assignment
    saved = {}
    sp = os.path.join(args.out, "sweep.json")
    if os.path.isfile(sp):
        with open(sp) as f:
            saved = json.load(f)
    fmu, fixed, opts, md, var, dx = resolve_run(args, saved)
    if "dx" in var and var["dx"].causality == "parameter":
        fixed.setdefault("dx", dx)
    if not args.fit_output and args.output == "max_run_up" and "max_run_up_Z" in var:
        args.fit_output = ["max_run_up_Z"]
    if args.criterion and args.crest is not None:
        raise UsageError(f"--criterion {args.criterion} applies without --crest only (with a "
                         f"crest the picks are at the largest p(1 - p))")
    dists = item_choices([Distribution(*split_assignment(it)) for it in args.dist], enumeration_items(var))
    for d_ in dists:
        if d_.name not in var or var[d_.name].causality != "parameter":
            raise UsageError(f"{d_.name!r} is not a parameter of the FMU")
        fixed.pop(d_.name, None)
    ident = E.fmu_identity(fmu)
    outs = [args.output] + [o for o in args.fit_output if o != args.output]
    noise = E.noise_from_file(args.noise_floor, outs, args.noise, ident,
                              dx=fixed.get("dx", dx)) if args.noise_floor else None
    if args.noise_floor and args.output not in noise:
        raise UsageError(f"{args.noise_floor} has no measurement of {args.output}")
    os.makedirs(args.out, exist_ok=True)
    settings = {"fmu": os.path.abspath(fmu), "stop_time": opts["stop_time"], "step": opts["step"],
                "dx": fixed.get("dx", dx), "fixed": fixed, "threads": opts["threads"]}
    save_json(sp, settings)
    quiet = args.quiet
    with runner.sigterm_as_interrupt(), \
            runner.dask_client(args.scheduler, args.workers, quiet=quiet,
                               upload_code=args.upload_code) as client:
        nw = runner.n_workers(client)

        def evaluate(scen, on_result):
            runner.run_scenarios(client, fmu, scen, opts, on_result=on_result, progress=None)

        try:
            # a folder holding a design of other settings (the criterion among them) is refused
            des = D.Design(args.out, dists, fixed, opts["stop_time"], output=args.output,
                           budget=args.budget, target_error=args.target_error, n_init=args.init,
                           crest=args.crest, seed=args.seed, n_workers=nw, mode=args.categorical,
                           folds=args.folds, restarts=args.restarts, n_candidates=args.candidates,
                           fmu=ident, settings=settings, progress=not quiet,
                           min_runs=args.min_runs, noise=noise, criterion=args.criterion)
            res = des.run(evaluate)
        except D.DesignError as e:
            print(f"emulate design: {e}", file=sys.stderr)
            return 1
    print(f"emulate design: {res['runs']} runs, stopped: "
          + {"target": f"the CV RMSE reached the target {args.target_error:g} %",
             "budget": f"the budget of {args.budget} runs is spent",
             "no new point": "no new candidate"}.get(res["reason"], str(res["reason"])))
    em, files, fit_s = fit_folder(args.out, outs, [d_.name for d_ in dists],
                                  {d_.name: D.box_of(d_) for d_ in dists}, fmu,
                                  args.final_categorical, 10, 3, args.seed, None,
                                  not args.no_plots, args.noise_floor, args.noise)
    for name in em.models:
        _print_cv(name, em.cv.get(name), em.mode_comparison.get(name))
        _print_noise(em, name)
    if not args.no_plots:
        from . import emulate_plots as P
        files.append(P.design_history(res["history"], os.path.join(args.out, "design_history.png"),
                                      target=args.target_error))
        from .html_report import write_page
        try:
            files.append(write_page(args.out, crest=args.crest))
        except Exception as e:   # the emulator and the runs are saved: the page can be made again
            print(f"emulate design: no page ({type(e).__name__}: {e}; python -m tools.dss page "
                  f"{args.out} tries again)", file=sys.stderr)
    for f in files:
        print(f"  wrote {f}")
    return 0


def jitter_scenarios(points: list[dict], perturb: dict, n: int, seed: int) -> list[dict]:
    """n scenarios per point: the point with the perturbed inputs moved by a Latin hypercube of
    offsets in [-H, H] (scipy.stats.qmc, seeded per point)."""
    from scipy.stats import qmc
    out = []
    names = list(perturb)
    for k, pt in enumerate(points):
        u = qmc.LatinHypercube(d=len(names), seed=np.random.default_rng([seed, k])).random(n)
        for row in u:
            s = dict(pt)
            for j, nm in enumerate(names):
                s[nm] = float(pt[nm]) + (2 * row[j] - 1) * perturb[nm]
            out.append(s)
    return out


def cmd_jitter(args):
    """Run the jitter scan (through the sweep machinery: resumable) and estimate the noise."""
    import itertools
    from .sweep import cmd_sweep
    from .scenarios import split_assignment
    from .store import open_store
    fmu, fixed, opts, md, var, dx = resolve_run(args, {})
    dx = float(fixed.get("dx", dx))
    axes = {}
    items = enumeration_items(var)  # rheology=elastic_plastic: its value
    for it in args.at:
        k, v = split_assignment(it)
        axes[k] = [item_value(k, parse_value(x), items) for x in v.split(",")]
    points = [dict(zip(axes, c)) for c in itertools.product(*axes.values())]
    perturb = {}
    for it in args.perturb or [f"reservoir_level={dx / 2!r}"]:
        k, v = split_assignment(it)
        perturb[k] = float(v)
    for nm in list(axes) + list(perturb):
        if nm not in var or var[nm].causality != "parameter":
            raise UsageError(f"{nm!r} is not a parameter of the FMU")
    missing = [nm for nm in perturb if nm not in axes]
    if missing:
        raise UsageError(f"the perturbed input(s) {', '.join(missing)} need a value in --at")
    if args.n < 3:
        raise UsageError("a jitter scan needs at least 3 runs per point (-n)")
    scen = jitter_scenarios(points, perturb, args.n, args.seed)
    os.makedirs(args.out, exist_ok=True)
    csv = os.path.join(args.out, "jitter_scenarios.csv")
    pd.DataFrame(scen).to_csv(csv, index=False)
    sw = argparse.Namespace(**{**vars(args), "csv": csv, "grid": [], "dist": [], "n": 0,
                               "sample": "random", "retry_failed": True, "crest": None,
                               "no_report": True})
    rc = cmd_sweep(sw)
    if rc:
        return rc
    df = open_store(args.out).latest()
    df = df[df["status"] == "ok"]
    groups, offs, keep = [], [], []
    for i, rec in enumerate(df.to_dict(orient="records")):
        for k, pt in enumerate(points):
            if all(math.isclose(float(rec[nm]), float(v), rel_tol=0, abs_tol=1e-12)
                   for nm, v in pt.items() if nm not in perturb):
                d = [float(rec[nm]) - float(pt[nm]) for nm in perturb]
                if all(abs(x) <= h * (1 + 1e-9) for x, h in zip(d, perturb.values())):
                    groups.append(k)
                    offs.append(d)
                    keep.append(i)
                    break
    df = df.iloc[keep]
    outputs = args.output or [o for o in E.DEFAULT_OUTPUTS if o in df.columns]
    est = {}
    for o in outputs:
        y = df[o].astype(float).to_numpy()
        if not np.isfinite(y).any():
            continue
        est[o] = E.jitter_noise(np.array(offs), y, groups)
    doc = {"schema": "mixsph-jitter", "schema_version": 1,
           "fmu": E.fmu_identity(fmu),
           "settings": {"dx": dx, "stop_time": opts["stop_time"], "step": opts["step"],
                        "fixed": fixed, "points": points, "perturb": perturb, "n_per_point": args.n,
                        "seed": args.seed},
           "method": "residual variance about a linear trend in the offsets per point "
                     "(emulator.jitter_noise); 95 % CI from the chi-square distribution",
           "runs": {"group": groups, "offsets": offs,
                    **{o: df[o].astype(float).tolist() for o in outputs}},
           "outputs": est}
    path = os.path.join(args.out, "jitter.json")
    with open(path, "w") as f:
        json.dump(E._jsonable(doc), f, indent=1)
    print(f"emulate jitter: {len(df)} runs at {len(points)} point(s), offsets "
          + ", ".join(f"{nm} +-{h:g}" for nm, h in perturb.items()))
    for o, e in est.items():
        print(f"  {o}: noise sd {e['sd']:.4g} (95 % CI {e['ci95_sd'][0]:.4g}-{e['ci95_sd'][1]:.4g}, "
              f"{e['dof']} dof; about the point means without the trend: sd "
              f"{math.sqrt(e['variance_about_means']):.4g})")
    print(f"  wrote {path}")
    if not args.no_plots and "max_run_up" in est:
        from . import emulate_plots as P
        f = P.jitter_plot(doc, "max_run_up", os.path.join(args.out, "jitter.png"))
        print(f"  wrote {f}")
    return 0


def main(argv=None):
    ap = build_parser()
    args = ap.parse_args(argv)
    os.environ.setdefault("OMP_WAIT_POLICY", "passive")
    from .emulate_mf import COMMANDS as MF_COMMANDS
    try:
        if args.cmd in MF_COMMANDS:
            return MF_COMMANDS[args.cmd](args)
        return {"fit": cmd_fit, "predict": cmd_predict, "validate": cmd_validate,
                "risk": cmd_risk, "plot": cmd_plot, "design": cmd_design,
                "curve": cmd_curve, "jitter": cmd_jitter}[args.cmd](args)
    except E.GuidMismatch as e:
        print(f"emulate: refused: {e}", file=sys.stderr)
        return 2
    except (UsageError, E.EmulatorError, ValueError, FileNotFoundError) as e:
        print(f"emulate: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("\nemulate: interrupted: the finished runs are stored; re-run the same command to "
              "continue", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
