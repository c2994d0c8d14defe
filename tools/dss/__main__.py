"""python -m tools.dss COMMAND ... : scenario sweeps of LandslideWave.fmu on Dask.

  sweep OUT      run a scenario table (grid, random, lhs or CSV) into OUT/results.parquet
                 (or .csv); resumable; writes the report at the end
  report OUT     the PNG reports and the scenario table of OUT's results
  optimise OUT   the paper's Section 2.2 procedure: mu_thr_min, then mu0_min, and the saving
  emulate ...    a Gaussian-process emulator of the FMU: fit, predict, design, validate, risk,
                 plot (python -m tools.dss emulate --help)

Run with --help after a command for its options. Exit codes: 0 ok (a sweep with failed
scenarios is still 0: they are recorded; see the summary), 1 the sweep or the optimisation
could not do its job, 2 bad usage or input.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import uuid

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_FMU_CANDIDATES = ("build/LandslideWave.fmu", "build-dss/LandslideWave.fmu")
DEFAULT_DX = 0.03          # the default coarse resolution of a sweep (m); --dx to change


class UsageError(Exception):
    pass


def default_fmu() -> str:
    env = os.environ.get("DSS_FMU")
    if env:
        return env
    for c in DEFAULT_FMU_CANDIDATES:
        p = os.path.join(ROOT, c)
        if os.path.isfile(p):
            return p
    return os.path.join(ROOT, DEFAULT_FMU_CANDIDATES[0])


def parse_value(s: str):
    from .scenarios import _num
    return _num(s)


def parse_sets(items) -> dict:
    from .scenarios import split_assignment
    out = {}
    for it in items or []:
        k, v = split_assignment(it)
        out[k] = parse_value(v)
    return out


def model_params(fmu_path: str):
    from fmpy import read_model_description
    md = read_model_description(fmu_path)
    return md, {v.name: v for v in md.modelVariables}


def common_cluster_args(p):
    g = p.add_argument_group("cluster")
    g.add_argument("--scheduler", metavar="ADDR",
                   help="address of an existing Dask scheduler (tcp://host:8786) or a scheduler "
                        "JSON file; default: an embedded local cluster")
    g.add_argument("--workers", type=int, metavar="N",
                   help="workers of the local cluster (default: the machine's cores)")
    g.add_argument("--upload-code", action="store_true",
                   help="upload the worker module to the scheduler and the workers "
                        "(Client.upload_file): workers need fmpy and distributed, not this repository")


def common_run_args(p):
    p.add_argument("--fmu", help="the FMU (default: $DSS_FMU, else build/LandslideWave.fmu)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a parameter fixed in every scenario (repeatable)")
    p.add_argument("--stop-time", type=float, metavar="T",
                   help="simulated time (s; default the FMU's DefaultExperiment stopTime)")
    p.add_argument("--step", type=float, metavar="H",
                   help="communication step (s; default 0.05)")
    p.add_argument("--dx", type=float, metavar="DX",
                   help=f"particle spacing when the FMU has a dx parameter and no --set/axis gives "
                        f"it (default {DEFAULT_DX}, the coarse sweep resolution)")
    p.add_argument("--threads", type=int, default=1, metavar="N",
                   help="OpenMP threads per scenario, set on the FMU's 'threads' parameter (default 1)")
    p.add_argument("--timeout", type=float, default=0.0, metavar="S",
                   help="wall seconds after which a scenario is stopped and recorded as failed")
    p.add_argument("--format", choices=("parquet", "csv"), help="results table format (default parquet)")
    p.add_argument("--quiet", action="store_true", help="no progress display")


def build_parser():
    ap = argparse.ArgumentParser(prog="python -m tools.dss", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)

    s = sub.add_parser("sweep", help="run a scenario sweep (resumable)")
    s.add_argument("out", help="output folder (results, scenario table, report)")
    g = s.add_argument_group("scenarios (--grid and --dist together: the n samples at every grid "
                             "point; --csv rows are added; --set fixes a parameter in all)")
    g.add_argument("--grid", action="append", default=[], metavar="NAME=SPEC",
                   help="a grid axis: NAME=v1,v2,... or NAME=lo:hi:n (repeatable; all combinations)")
    g.add_argument("--dist", action="append", default=[], metavar="NAME=SPEC",
                   help="a sampled parameter: uniform:lo:hi, loguniform:lo:hi, normal:mean:sd[:lo:hi], "
                        "choice:a,b,...")
    g.add_argument("--sample", choices=("lhs", "random"), default="lhs",
                   help="sampling of the --dist parameters (default lhs, Latin hypercube)")
    g.add_argument("-n", "--n", type=int, default=0, help="number of samples")
    g.add_argument("--seed", type=int, default=0, help="sampling seed (default 0)")
    g.add_argument("--csv", metavar="FILE", help="a scenario table: one row per scenario, a column per parameter")
    s.add_argument("--retry-failed", dest="retry_failed", action="store_true", default=True,
                   help="re-run scenarios whose last result failed (default)")
    s.add_argument("--skip-failed", dest="retry_failed", action="store_false",
                   help="leave failed scenarios as they are")
    s.add_argument("--crest", type=float, metavar="Z",
                   help="elevation for the exceedance probability (same units as the run-up reported)")
    s.add_argument("--no-report", action="store_true", help="do not write the report at the end")
    common_run_args(s)
    common_cluster_args(s)

    r = sub.add_parser("report", help="PNG reports of a sweep's results")
    r.add_argument("out")
    r.add_argument("--crest", type=float, metavar="Z")
    r.add_argument("--x", default="reservoir_level", help="parameter on the x axis (default reservoir_level)")
    r.add_argument("--y", help="output column (default max_run_up_Z when finite, else max_run_up)")

    sub.add_parser("emulate", help="the FMU's emulator: fit, predict, design, validate, risk, plot "
                                   "(emulate --help)", add_help=False)

    o = sub.add_parser("optimise", aliases=["optimize"], help="the paper's mu_thr / mu0 procedure")
    o.add_argument("out")
    o.add_argument("--output", default="max_run_up", help="the output judged (default max_run_up)")
    o.add_argument("--history", action="store_true",
                   help="compare the output's history over the communication points (mean error) "
                        "instead of its final value")
    o.add_argument("--error", type=float, required=True, metavar="PCT", help="permitted error, %%")
    o.add_argument("--offset", type=float, default=0.0,
                   help="errors are |y - ref| / |ref - offset| (e.g. the still-water level)")
    o.add_argument("--mu-thr-start", type=float, default=10e3)
    o.add_argument("--mu-thr-factor", type=float, default=2.0)
    o.add_argument("--mu-thr-max", type=float, default=1.28e6)
    o.add_argument("--mu0-factor", type=float, default=0.5)
    o.add_argument("--mu0-lower-bound", type=float, default=1.0)
    o.add_argument("--refine", type=int, default=1,
                   help="rounds of geometric bisection of mu0_min (default 1)")
    common_run_args(o)
    common_cluster_args(o)
    return ap


def _load_settings(out):
    p = os.path.join(out, "sweep.json")
    if os.path.isfile(p):
        with open(p) as f:
            return json.load(f)
    return {}


def _save_json(path, obj):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(obj, f, indent=2)
    os.replace(tmp, path)


def resolve_run(args, saved=None):
    """fmu path, fixed params, opts, format from the arguments (and a previous sweep's settings)."""
    saved = saved or {}
    fmu = args.fmu or saved.get("fmu") or default_fmu()
    if not os.path.isfile(fmu):
        raise UsageError(f"FMU {fmu} not found: build it (cmake --build build --target fmu) "
                         f"or give --fmu / DSS_FMU")
    stop = args.stop_time if args.stop_time is not None else saved.get("stop_time")
    step = args.step if args.step is not None else saved.get("step", 0.05)
    dx = args.dx if args.dx is not None else saved.get("dx", DEFAULT_DX)
    fixed = dict(saved.get("fixed", {})) if not args.set else {}
    fixed.update(parse_sets(args.set))
    md, var = model_params(fmu)
    if stop is None:
        de = md.defaultExperiment
        stop = float(de.stopTime) if de is not None and de.stopTime else None
        if stop is None:
            raise UsageError("the FMU has no default stop time: give --stop-time")
    opts = {"stop_time": float(stop), "step": float(step), "threads": args.threads,
            "timeout": args.timeout}
    return fmu, fixed, opts, md, var, dx


def cmd_sweep(args):
    import pandas as pd
    from . import report, runner, scenarios as S
    from .store import open_store

    saved = _load_settings(args.out)
    fmu, fixed, opts, md, var, dx = resolve_run(args, saved)
    params_known = {n for n, v in var.items() if v.causality == "parameter"}

    # the scenario table: new specification, merged with what OUT already has
    specs = []
    grid_sc = samp_sc = None
    if args.grid:
        axes = {}
        for it in args.grid:
            k, v = S.split_assignment(it)
            axes[k] = S.grid_values(v)
        grid_sc = S.grid(axes, fixed)
    if args.dist:
        if args.n < 1:
            raise UsageError("sampling needs -n N (number of scenarios)")
        dists = [S.Distribution(*S.split_assignment(it)) for it in args.dist]
        samp_sc = S.sample(dists, args.n, args.sample, args.seed, fixed)
    if grid_sc and samp_sc:       # every grid point with every sample
        specs.append([{**g, **smp} for g in grid_sc for smp in samp_sc])
    else:
        specs += [x for x in (grid_sc, samp_sc) if x]
    if args.csv:
        specs.append(S.from_csv(args.csv, fixed))
    new = [s for spec in specs for s in spec]
    if not new and args.set and not os.path.isfile(os.path.join(args.out, "scenarios.csv")):
        new = [dict(fixed)]                          # a single scenario
    if "dx" in var and var["dx"].causality == "parameter":
        for s in new:
            s.setdefault("dx", dx)
    for s in new:
        for k in s:
            if k not in params_known:
                print(f"dss: warning: {k!r} is not a parameter of the FMU: those scenarios will "
                      f"fail", file=sys.stderr)
                break
    table_path = os.path.join(args.out, "scenarios.csv")
    os.makedirs(args.out, exist_ok=True)
    old = pd.read_csv(table_path, dtype={S.ID: str}) if os.path.isfile(table_path) else None
    tab = S.table(new, opts["stop_time"]) if new else pd.DataFrame()
    if old is not None and not old.empty:
        old_ids = set(old[S.ID])
        tab = pd.concat([old, tab[~tab[S.ID].isin(old_ids)]] if not tab.empty else [old],
                        ignore_index=True)
    if tab.empty:
        raise UsageError("no scenarios: give --grid, --dist with -n, --csv or --set "
                         "(or re-run a folder that has scenarios.csv)")
    tab.to_csv(table_path + ".tmp", index=False)
    os.replace(table_path + ".tmp", table_path)
    _save_json(os.path.join(args.out, "sweep.json"),
               {"fmu": os.path.abspath(fmu), "stop_time": opts["stop_time"], "step": opts["step"],
                "dx": dx, "fixed": fixed, "threads": opts["threads"]})

    store = open_store(args.out, args.format)
    latest = store.latest()
    done = set()
    if not latest.empty:
        done = set(latest.loc[latest["status"] == "ok", S.ID])
        if not args.retry_failed:
            done |= set(latest.loc[latest["status"] != "ok", S.ID])
    todo_df = tab[~tab[S.ID].isin(done)]
    todo = [{k: v for k, v in rec.items() if not (isinstance(v, float) and v != v)}
            for rec in todo_df.to_dict(orient="records")]
    todo = [{k: S._plain(v) for k, v in t.items()} for t in todo]
    print(f"dss: {len(tab)} scenarios in {table_path}: {len(tab) - len(todo)} already done, "
          f"{len(todo)} to run (stop time {opts['stop_time']:g} s, results {store.path})",
          file=sys.stderr)
    run_id = uuid.uuid4().hex[:10]
    if todo:
        prog = runner.Progress(len(todo), enabled=not args.quiet)
        with runner.sigterm_as_interrupt(), \
                runner.dask_client(args.scheduler, args.workers, quiet=args.quiet,
                                   upload_code=args.upload_code) as client:
            runner.run_scenarios(client, fmu, todo, opts, on_result=store.append, progress=prog,
                                 run_id=run_id)
    store.compact()
    final = store.latest()
    final = final[final[S.ID].isin(set(tab[S.ID]))]
    n_ok = int((final["status"] == "ok").sum()) if not final.empty else 0
    n_failed = len(final) - n_ok
    print(f"dss: sweep {args.out}: {n_ok} ok, {n_failed} failed, "
          f"{len(tab) - len(final)} missing (run id {run_id})")
    if n_failed:
        for rec in final[final["status"] != "ok"].head(10).to_dict(orient="records"):
            print(f"  failed {rec[S.ID]}: {rec.get('error')}")
    if not args.no_report and not final.empty:
        info = report.make_report(final, args.out, crest=args.crest)
        _print_report(info)
    return 0


def _print_report(info):
    for f in info["files"]:
        print(f"  wrote {f}")
    if "p_exceed" in info:
        print(f"  exceedance of {info['crest']:g} ({info['y']}): P = {info['p_exceed']:.3f} "
              f"({info['n_exceed']} of {info['n_ok']} scenarios)")


def cmd_report(args):
    from . import report
    from .store import open_store
    st = open_store(args.out)
    df = st.latest()
    if df.empty:
        raise UsageError(f"no results in {args.out}")
    info = report.make_report(df, args.out, crest=args.crest, x=args.x, y=args.y)
    _print_report(info)
    return 0


def cmd_optimise(args):
    from . import optimise as O, runner
    fmu, fixed, opts, md, var, dx = resolve_run(args)
    if "dx" in var and "dx" not in fixed:
        fixed["dx"] = dx
    if args.output not in var or var[args.output].causality != "output":
        outs = ", ".join(n for n, v in var.items() if v.causality == "output")
        raise UsageError(f"{args.output!r} is not an output of the FMU ({outs})")
    os.makedirs(args.out, exist_ok=True)
    with runner.sigterm_as_interrupt(), \
            runner.dask_client(args.scheduler, args.workers, quiet=args.quiet,
                               upload_code=args.upload_code) as client:
        try:
            res = O.optimise(client, fmu, args.out, args.output, args.error, fixed, opts,
                             series=args.history, offset=args.offset,
                             mu_thr_start=args.mu_thr_start, mu_thr_factor=args.mu_thr_factor,
                             mu_thr_max=args.mu_thr_max, mu0_factor=args.mu0_factor,
                             mu0_min_bound=args.mu0_lower_bound, refine=args.refine,
                             fmt=args.format or "parquet", progress=not args.quiet)
        except O.OptimiseError as e:
            print(f"dss optimise: {e}", file=sys.stderr)
            return 1
    print(O.format_result(res))
    print(f"  wrote {os.path.join(args.out, 'optimise.json')}, "
          f"{os.path.join(args.out, 'optimise_runs.csv')}")
    return 0


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv and argv[0] == "emulate":
        from .emulate import main as emulate_main
        return emulate_main(argv[1:])
    ap = build_parser()
    args = ap.parse_args(argv)
    os.environ.setdefault("OMP_WAIT_POLICY", "passive")
    try:
        if args.cmd == "sweep":
            return cmd_sweep(args)
        if args.cmd == "report":
            return cmd_report(args)
        return cmd_optimise(args)
    except (UsageError, ValueError, FileNotFoundError) as e:
        print(f"dss: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("\ndss: interrupted: what finished is stored; re-run the same command to "
              "complete the rest", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
