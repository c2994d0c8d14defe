"""The multi-fidelity commands of `python -m tools.dss emulate` (docs/dss.md, section
Multi-fidelity emulator):

  mf-design OUT      the cost-aware sequential design over a ladder of spacings (mfdesign.py) on
                     the Dask cluster, resumable; writes OUT/mf_emulator.json
  mf-fit FOLDER...   the multi-fidelity emulator of the runs of one or more folders
  mf-predict EMU     mean, sd and 95 % interval at a level (a dx, finest or extrapolated)
  mf-validate EMU H  the emulator at a level against the runs of a hold-out folder
  mf-risk EMU        P(output > crest) at a level (default the extrapolation) with its band,
                     and Sobol indices
  study OUT          design, fit and risk in one command, ending with P(output > crest)
"""

from __future__ import annotations

import json
import os
import sys
import time

import numpy as np
import pandas as pd

from . import emulator as E
from . import multifidelity as M
from .cli import (UsageError, common_cluster_args, common_run_args, default_fmu, parse_box, parse_dists,
                  parse_sets)

# the default ladder: the coarse spacings of the convergence table of docs/validation/vajont.md
DEFAULT_LEVELS = "0.03,0.02,0.015"
DEFAULT_FIT_OUTPUTS = ("max_run_up", "max_run_up_Z")


def _levels(text):
    try:
        v = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise UsageError(f"--levels {text}: expected comma-separated spacings dx") from None
    if len(v) < 2:
        raise UsageError(f"--levels {text}: two or more spacings")
    return v


def _order(text):
    if not text:
        return None
    try:
        v = [float(x) for x in text.split(":")]
    except ValueError:
        v = []
    if len(v) != 3 or not (0 < v[1] <= v[0] <= v[2]):
        raise UsageError(f"--order {text}: expected P:LO:HI with 0 < LO <= P <= HI")
    return v


def _fmu_args(p):
    p.add_argument("--fmu", help="the FMU the emulator must belong to (default: $DSS_FMU, else "
                                 "build/LandslideWave.fmu)")
    p.add_argument("--no-fmu-check", action="store_true",
                   help="do not check the emulator's FMU GUID (no FMU at hand)")


def _level_arg(p, default):
    p.add_argument("--level", default=default,
                   help=f"a level's dx, finest, or {M.EXTRAPOLATED} (dx -> 0) (default {default})")


def add_parsers(sub):
    d = sub.add_parser("mf-design", help="cost-aware multi-fidelity sequential design (resumable)")
    d.add_argument("out")
    _design_args(d)

    s = sub.add_parser("study", help="a whole study: mf-design, fit, risk (P(output > crest))")
    s.add_argument("out")
    _design_args(s)
    s.add_argument("--crest", type=float, required=True, metavar="Z")
    s.add_argument("--risk-output", default="max_run_up_Z",
                   help="the output compared with the crest (default max_run_up_Z)")
    _level_arg(s, M.EXTRAPOLATED)
    s.add_argument("-n", "--n", type=int, default=100_000, help="risk samples (default 1e5)")

    f = sub.add_parser("mf-fit", help="fit the multi-fidelity emulator of runs at several dx")
    f.add_argument("folders", nargs="+", help="folders of runs (results.parquet), e.g. sweeps at "
                                              "each dx or an mf-design")
    f.add_argument("--levels", required=True, help="the spacings dx of the levels (comma list)")
    f.add_argument("--inputs", required=True, help="comma-separated inputs")
    f.add_argument("--box", action="append", default=[], metavar="NAME=LO:HI")
    f.add_argument("--output", action="append", default=[], metavar="NAME",
                   help=f"outputs (default {', '.join(DEFAULT_FIT_OUTPUTS)})")
    f.add_argument("--order", help="P:LO:HI, the order of convergence and its range when there "
                                   "are two levels (with three or more it is observed)")
    f.add_argument("--restarts", type=int, default=3)
    f.add_argument("--seed", type=int, default=0)
    f.add_argument("--no-jitter-floor", action="store_true",
                   help="no lower bound on the finer levels' noise (default: the coarsest "
                        "level's fitted noise variance times (dx / dx_coarsest)^2)")
    f.add_argument("--kernel", choices=M.KERNELS, default=M.DEFAULT_KERNEL,
                   help=f"the GPs' kernel: Matern 5/2 with a length scale per input (ard) or "
                        f"one for all (iso) (default {M.DEFAULT_KERNEL}; docs/dss.md, 'Choosing "
                        f"the model by cross-validation')")
    f.add_argument("-o", "--out", required=True, help="the emulator file")
    f.add_argument("--fmu", help="the FMU of the runs (default: the first folder's sweep.json)")

    p = sub.add_parser("mf-predict", help="predict scenarios at a level")
    p.add_argument("emulator")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    p.add_argument("--csv")
    p.add_argument("--output", action="append", default=[], metavar="NAME")
    _level_arg(p, "finest")
    p.add_argument("-o", "--out")
    _fmu_args(p)

    v = sub.add_parser("mf-validate", help="the emulator at a level against hold-out runs")
    v.add_argument("emulator")
    v.add_argument("holdout", nargs="+", help="folder(s) of hold-out runs")
    v.add_argument("--output", default="max_run_up")
    _level_arg(v, "finest")
    v.epilog = ("A dx below the ladder's finest as --level is the extrapolation to that dx: "
                "the check of the extrapolation against runs one level finer than the ladder.")
    v.add_argument("--holdout-dx", type=float,
                   help="use the hold-out runs at this dx (default: the level's; for the "
                        "extrapolation the finest dx of the hold-out runs)")
    v.add_argument("--range", type=float, help="the range the errors are relative to")
    v.add_argument("--plot")
    v.add_argument("--json")
    _fmu_args(v)

    r = sub.add_parser("mf-risk", help="exceedance probability and Sobol indices at a level")
    r.add_argument("emulator")
    r.add_argument("--dist", action="append", default=[], metavar="NAME=SPEC")
    r.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    r.add_argument("--crest", type=float, required=True)
    r.add_argument("--output", default="max_run_up_Z")
    _level_arg(r, M.EXTRAPOLATED)
    r.add_argument("-n", "--n", type=int, default=100_000)
    r.add_argument("--draws", type=int, default=200)
    r.add_argument("--joint", type=int, default=1000)
    r.add_argument("--sobol-n", type=int, default=4096)
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--plots", metavar="DIR")
    r.add_argument("--json")
    _fmu_args(r)


def _design_args(d):
    d.add_argument("--dist", action="append", default=[], metavar="NAME=SPEC", required=True,
                   help="the box of an input (uniform:lo:hi, ...; any FMU parameter; repeatable)")
    d.add_argument("--levels", default=DEFAULT_LEVELS,
                   help=f"the spacings dx of the ladder (default {DEFAULT_LEVELS}, the coarse "
                        f"spacings of the convergence table of docs/validation/vajont.md)")
    d.add_argument("--budget-cpu", type=float, required=True, metavar="S",
                   help="CPU seconds of FMU runs at most (the start included)")
    d.add_argument("--init", help="runs of the nested start per level, coarse to fine (default "
                                  "(d+1) at the finest, doubling per coarser level)")
    d.add_argument("--target", choices=("finest", M.EXTRAPOLATED), default="finest",
                   help="the prediction whose integrated variance the picks reduce")
    d.add_argument("--output", default="max_run_up", help="the output designed for")
    d.add_argument("--fit-output", action="append", default=[], metavar="NAME",
                   help="another output of the final emulator (default max_run_up_Z)")
    d.add_argument("--restarts", type=int, default=3, help="restarts of the final fit")
    d.add_argument("--seed", type=int, default=0)
    d.add_argument("--no-jitter-floor", action="store_true",
                   help="no lower bound on the finer levels' noise (see mf-fit)")
    common_run_args(d)
    common_cluster_args(d)


# ---- commands ---------------------------------------------------------------------------------

def cmd_mf_design(args, quiet_summary=False):
    from . import mfdesign as MD, runner
    from .cli import resolve_run, save_json
    from .design import DesignError
    from .scenarios import Distribution, split_assignment
    saved = {}
    sp = os.path.join(args.out, "sweep.json")
    if os.path.isfile(sp):
        with open(sp) as f:
            saved = json.load(f)
    fmu, fixed, opts, md, var, _ = resolve_run(args, saved)
    levels = _levels(args.levels)
    if "dx" not in var:
        raise UsageError("the FMU has no dx parameter: no ladder of spacings")
    lo, hi = float(var["dx"].min), float(var["dx"].max)
    bad = [x for x in levels if not lo <= x <= hi]
    if bad:
        raise UsageError(f"--levels: dx {bad} outside the FMU's range {lo:g}..{hi:g}")
    from .cli import enumeration_items, item_choices
    dists = item_choices([Distribution(*split_assignment(it)) for it in args.dist], enumeration_items(var))
    for d_ in dists:
        if d_.name not in var or var[d_.name].causality != "parameter":
            raise UsageError(f"{d_.name!r} is not a parameter of the FMU")
        if d_.name == "dx":
            raise UsageError("dx is the level (--levels), not an input")
        fixed.pop(d_.name, None)
    fixed.pop("dx", None)
    init = [int(x) for x in args.init.split(",")] if args.init else None
    outs = [args.output] + [o for o in (args.fit_output or
                                        [o for o in DEFAULT_FIT_OUTPUTS if o in var])
                            if o != args.output]
    ident = E.fmu_identity(fmu)
    os.makedirs(args.out, exist_ok=True)
    settings = {"fmu": os.path.abspath(fmu), "stop_time": opts["stop_time"], "step": opts["step"],
                "fixed": fixed, "threads": opts["threads"], "levels": levels}
    save_json(sp, settings)
    with runner.sigterm_as_interrupt(), \
            runner.dask_client(args.scheduler, args.workers, quiet=args.quiet,
                               upload_code=args.upload_code) as client:
        nw = runner.n_workers(client)

        def evaluate(scen, on_result):
            runner.run_scenarios(client, fmu, scen, opts, on_result=on_result, progress=None)
        try:
            des = MD.MFDesign(args.out, dists, fixed, opts["stop_time"], levels, args.budget_cpu,
                              output=args.output, init=init, seed=args.seed, n_workers=nw,
                              target=args.target, fmu=ident, settings=settings,
                              progress=not args.quiet, jitter_floor=not args.no_jitter_floor)
            res = des.run(evaluate)
        except DesignError as e:
            print(f"emulate mf-design: {e}", file=sys.stderr)
            return 1, None
    df = des.results()
    t0 = time.perf_counter()
    em = des.fit(df, outputs=[o for o in outs if o in df.columns], restarts=args.restarts)
    fit_s = time.perf_counter() - t0
    path = os.path.join(args.out, "mf_emulator.json")
    em.save(path)
    print(f"emulate mf-design: stopped ({res['reason']}) after {res['runs']} runs, "
          f"{des.spent(df):.0f} CPU s of {args.budget_cpu:g}; final fit {fit_s:.1f} s")
    _print_summary(em)
    print(f"  wrote {path}")
    from . import emulate_plots as P
    for f in (P.mf_design_history(des.state, os.path.join(args.out, "mf_design_history.png")),
              P.level_costs(df, levels, os.path.join(args.out, "level_costs.png"))):
        print(f"  wrote {f}")
    return 0, em


def _print_summary(em: M.MFEmulator):
    for name, m in em.models.items():
        print(f"  {name}: levels dx " + ", ".join(f"{d:g} ({len(y)} runs)"
                                               for d, y in zip(em.dxs, m.y))
              + "; rho " + ", ".join(f"{g.rho:.3f}" for g in m.levels[1:])
              + f"; kernel {m.kernel_family}")
        for c in m.calibration:
            print(f"    dx {c['dx']:g}: LOO RMSE {c['loo_rmse']:.4g}, rms z {c['loo_rms_z']:.2f}, "
                  f"coverage {100 * c['loo_coverage95']:.0f} %, interval scale applied "
                  f"{c['scale_applied']:.2f}")
        o = m.order
        if o:
            print(f"    order of convergence {o['p']:.2f} (95 % over the box {o['p_lo']:.2f}-"
                  f"{o['p_hi']:.2f}; {o['source']}"
                  + (f"; monotone at {100 * o['valid_fraction']:.0f} % of the box"
                     if "valid_fraction" in o else "") + ")")


def cmd_study(args):
    """mf-design, then the risk at the level (default the extrapolation), in one command."""
    t0 = time.monotonic()
    rc, em = cmd_mf_design(args)
    if rc:
        return rc
    from .scenarios import Distribution, split_assignment
    dists = {k: Distribution(k, v) for k, v in (split_assignment(it) for it in args.dist)}
    out = args.risk_output if args.risk_output in em.models else args.output
    finish_study(args.out, em, dists, out, args.crest, args.level, args.n, args.seed, t0)
    return 0


def finish_study(folder, em, dists, output, crest, level, n, seed, t0):
    """A study's end: the risk at the level and the Sobol indices into FOLDER/study.json,
    exceedance.png and the study's page FOLDER/report.html."""
    r = M.exceedance(em, output, dists, {}, crest, level=level, n=n, seed=seed,
                     z_grid=_z_grid(em, output, crest))
    s = M.sobol(em, output, dists, {}, level=level, seed=seed)
    doc = {"risk": r, "sobol": s, "elapsed_s": time.monotonic() - t0,
           "emulator": os.path.join(folder, "mf_emulator.json")}
    with open(os.path.join(folder, "study.json"), "w") as f:
        json.dump(E._jsonable(doc), f, indent=1)
    from . import emulate_plots as P
    from .html_report import write_page
    P.exceedance_plot(r, os.path.join(folder, "exceedance.png"))
    try:
        page = write_page(folder) + " (open it in a browser)"
    except Exception as e:       # the study's results are saved: the page can be made again
        page = f"no page ({type(e).__name__}: {e}; python -m tools.dss page {folder} tries again)"
    _print_risk(r, s)
    print(f"emulate study: done in {(time.monotonic() - t0) / 60:.1f} min; wrote "
          f"{os.path.join(folder, 'study.json')}, exceedance.png, {page}")
    return doc


def _z_grid(em, out, crest):
    y = np.concatenate([Y[out][np.isfinite(Y[out])] for Y in em.Y])
    lo, hi = float(y.min()), float(y.max())
    pad = 0.3 * (hi - lo)
    return np.linspace(min(lo - pad, crest), max(hi + pad, crest), 61)


def _print_risk(r, s):
    print(f"P({r['output']} > {r['crest']:g}) at the level {r['level']} = {r['p']:.4f}, 95 % band "
          f"[{r['p_lo']:.4f}, {r['p_hi']:.4f}] ({r['n_draws']} joint draws at {r['n_joint']} "
          f"samples; Monte Carlo se {r['mc_se']:.1e} over {r['n']}; from the mean alone "
          f"{r['p_mean_only']:.4f}; {r['seconds']:.2f} s)")
    print("  Sobol indices of the mean (S1 / ST): " + ", ".join(
        f"{n} {a:.3f} / {b:.3f}" for n, a, b in zip(s["names"], s["S1"], s["ST"]))
          + f" ({s['n_model']} evaluations, {s['seconds']:.2f} s)")


def _runs(folders):
    from .store import open_store
    frames = []
    for fo in folders:
        df = open_store(fo).latest()
        if df.empty:
            raise UsageError(f"no results in {fo}")
        frames.append(df[df["status"] == "ok"])
    return pd.concat(frames, ignore_index=True)


def cmd_mf_fit(args):
    df = _runs(args.folders)
    fmu = args.fmu
    if not fmu:
        sp = os.path.join(args.folders[0], "sweep.json")
        if os.path.isfile(sp):
            with open(sp) as fh:
                fmu = json.load(fh).get("fmu")
    fmu = fmu or default_fmu()
    if not os.path.isfile(fmu):
        raise UsageError(f"the FMU {fmu} of these runs is not there: give --fmu")
    inputs = [x.strip() for x in args.inputs.split(",") if x.strip()]
    box = parse_box(args.box) or None
    if box is not None:
        missing = [n for n in inputs if n not in box]
        if missing:
            raise UsageError(f"--box: no box of {', '.join(missing)} (give all inputs' or none)")
    outs = args.output or [o for o in DEFAULT_FIT_OUTPUTS if o in df.columns]
    em = M.from_results(df, inputs, _levels(args.levels), outs, box=box,
                        fmu=E.fmu_identity(fmu),
                        settings={"sources": [os.path.abspath(x) for x in args.folders]})
    t0 = time.perf_counter()
    for o in outs:
        em.fit_output(o, restarts=args.restarts, seed=args.seed, order=_order(args.order),
                      jitter_floor=not args.no_jitter_floor, kernel_family=args.kernel)
    em.save(args.out)
    print(f"emulate mf-fit: {sum(len(x) for x in em.X)} runs at dx "
          + ", ".join(f"{d:g}" for d in em.dxs) + f", fitted in {time.perf_counter() - t0:.1f} s")
    _print_summary(em)
    print(f"  wrote {args.out}")
    return 0


def _load(args):
    return M.load(args.emulator, args.fmu or default_fmu(), check_fmu=not args.no_fmu_check)


def cmd_mf_predict(args):
    em = _load(args)
    if args.csv:
        tab = pd.read_csv(args.csv)
    elif args.set:
        vals = {k: (v if isinstance(v, list) else [v]) for k, v in
                ((k, [float(x) for x in str(v).split(",")] if isinstance(v, str) else v)
                 for k, v in parse_sets(args.set).items())}
        n = max(len(v) for v in vals.values())
        if any(len(v) not in (1, n) for v in vals.values()):
            raise UsageError("--set lists must have one value or the same length")
        tab = pd.DataFrame({k: v * n if len(v) == 1 else v for k, v in vals.items()})
    else:
        raise UsageError("give the scenarios: --set NAME=VALUE ... or --csv FILE")
    missing = [n for n in em.inputs if n not in tab.columns]
    if missing:
        raise UsageError(f"no value of {', '.join(missing)} (the emulator's inputs: "
                         f"{', '.join(em.inputs)})")
    X = tab[em.inputs].astype(float).to_numpy()
    t0 = time.perf_counter()
    res = tab.copy()
    for o in args.output or list(em.models):
        mu, sd = em.predict(X, o, args.level)
        res[o] = mu
        res[o + "_sd"] = sd
        res[o + "_lo95"] = mu - M.Z95 * sd
        res[o + "_hi95"] = mu + M.Z95 * sd
    dt = time.perf_counter() - t0
    res["out_of_box"] = em.out_of_box(X)
    print(f"emulate mf-predict: {len(X)} scenarios at the level {args.level} in "
          f"{1e3 * dt:.1f} ms", file=sys.stderr)
    if args.out:
        res.to_csv(args.out, index=False)
        print(f"  wrote {args.out}", file=sys.stderr)
    else:
        print(res.to_string(index=False))
    return 0


def cmd_mf_validate(args):
    em = _load(args)
    li = em.level_index(args.level)
    df = _runs(args.holdout)
    extrap = li == M.EXTRAPOLATED or isinstance(li, tuple)
    if args.holdout_dx is not None:
        dx = args.holdout_dx
    elif li == M.EXTRAPOLATED:
        dx = float(df["dx"].astype(float).min())
    else:
        dx = li[1] if extrap else em.dxs[li]
    h = df[np.isclose(df["dx"].astype(float), dx)]
    if h.empty:
        raise UsageError(f"no hold-out runs at dx = {dx:g}")
    X = h[em.inputs].astype(float).to_numpy()
    y = h[args.output].astype(float).to_numpy()
    res = em.predict(X, args.output, args.level, with_terms=True)
    mu, sd = res[:2]
    met = E.metrics(y, mu, sd, y_range=args.range)
    extra = {}
    if extrap:
        extra = {"sd_gp_mean": float(np.mean(res[2])), "sd_order_mean": float(np.mean(res[3]))}
        fin, fsd = em.predict(X, args.output, "finest")
        extra["finest_level_as_prediction"] = E.metrics(y, fin, fsd, y_range=args.range)
    z = (y - mu) / sd
    print(f"emulate mf-validate: {len(y)} hold-out runs at dx = {dx:g} against the level "
          f"{args.level}: RMSE {met['rmse']:.4g} ({met['rmse_pct']:.2f} % of {met['range']:.4g}), "
          f"largest {met['max_error']:.4g} ({met['max_error_pct']:.2f} %), inside the 95 % "
          f"intervals {100 * met['coverage95']:.0f} % ({int(round(met['coverage95'] * len(y)))} "
          f"of {len(y)}), rms z {float(np.sqrt(np.mean(z ** 2))):.2f}, mean sd "
          f"{float(np.mean(sd)):.4g}")
    if extra:
        f = extra["finest_level_as_prediction"]
        print(f"  sd terms (mean): GP {extra['sd_gp_mean']:.4g}, order {extra['sd_order_mean']:.4g};"
              f" the finest level's prediction as the answer instead: RMSE {f['rmse']:.4g}, "
              f"inside its intervals {100 * f['coverage95']:.0f} %")
    doc = {"level": args.level, "holdout_dx": dx, "metrics": met, "rms_z": float(np.sqrt(np.mean(z ** 2))),
           "y": y.tolist(), "mean": mu.tolist(), "sd": sd.tolist(), **extra}
    if args.plot:
        from . import emulate_plots as P
        P.ensure_dir(args.plot)
        P.mf_validation_plot(doc, args.output, args.plot)
        print(f"  wrote {args.plot}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(E._jsonable(doc), fh, indent=1)
        print(f"  wrote {args.json}")
    return 0


def cmd_mf_risk(args):
    em = _load(args)
    dists = parse_dists(args.dist)
    if not dists:
        raise UsageError("give the inputs' distributions with --dist NAME=SPEC")
    fixed = parse_sets(args.set)
    r = M.exceedance(em, args.output, dists, fixed, args.crest, level=args.level, n=args.n,
                     n_joint=args.joint, n_draws=args.draws, seed=args.seed,
                     z_grid=_z_grid(em, args.output, args.crest))
    s = M.sobol(em, args.output, dists, fixed, level=args.level, n_base=args.sobol_n,
                seed=args.seed)
    _print_risk(r, s)
    if args.plots:
        from . import emulate_plots as P
        os.makedirs(args.plots, exist_ok=True)
        for f in (P.exceedance_plot(r, os.path.join(args.plots, "mf_exceedance.png")),
                  P.sobol_plot(s, args.output, os.path.join(args.plots, "mf_sobol.png"))):
            print(f"  wrote {f}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(E._jsonable({"risk": r, "sobol": s}), fh, indent=1)
        print(f"  wrote {args.json}")
    return 0


COMMANDS = {"mf-design": lambda a: cmd_mf_design(a)[0], "study": cmd_study,
            "mf-fit": cmd_mf_fit, "mf-predict": cmd_mf_predict, "mf-validate": cmd_mf_validate,
            "mf-risk": cmd_mf_risk}
