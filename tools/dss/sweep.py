"""dss sweep: run a scenario table (grid, samples, CSV) of the FMU on a Dask cluster into
OUT/results.parquet (resumable), and its report."""

from __future__ import annotations

import os
import sys
import uuid

from .cli import UsageError, enumeration_items, item_values, load_settings, resolve_run, save_json


def cmd_sweep(args):
    import pandas as pd
    from . import report, runner, scenarios as S
    from .store import open_store

    saved = load_settings(args.out)
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
    items = enumeration_items(var)  # rheology=elastic_plastic: the item's value
    new = [item_values(s, items) for spec in specs for s in spec]
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
    save_json(os.path.join(args.out, "sweep.json"),
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
        from .html_report import write_page
        try:
            info["files"].append(write_page(args.out, crest=args.crest))
        except Exception as e:   # the results are stored: the page can be made again
            print(f"dss: warning: no page ({type(e).__name__}: {e}; python -m tools.dss page "
                  f"{args.out} tries again)", file=sys.stderr)
        print_report(info)
    return 0


def print_report(info):
    for f in info["files"]:
        print(f"  wrote {f}")
    if "p_exceed" in info:
        print(f"  exceedance of {info['crest']:g} ({info['y']}): P = {info['p_exceed']:.3f} "
              f"({info['n_exceed']} of {info['n_ok']} scenarios)")
