"""python -m tools.dss COMMAND ... : scenario sweeps of LandslideWave.fmu on Dask.

  sweep OUT      run a scenario table (grid, random, lhs or CSV) into OUT/results.parquet
                 (or .csv); resumable; writes the report at the end
  report OUT     the PNG reports and the scenario table of OUT's results
  page DIR       the interactive HTML page (DIR/report.html) of a study, a sweep or a mixsph
                 run folder: predictions with sliders, risk, sensitivity, the runs
  optimise OUT   the paper's Section 2.2 procedure: mu_thr_min, then mu0_min, and the saving
  emulate ...    a Gaussian-process emulator of the FMU: fit, predict, design, validate, risk,
                 plot (python -m tools.dss emulate --help)

Run with --help after a command for its options. Exit codes: 0 ok (a sweep with failed
scenarios is still 0: they are recorded; see the summary), 1 the sweep or the optimisation
could not do its job, 2 bad usage or input.
"""

from __future__ import annotations

import argparse
import os
import sys

# the emulators' linear algebra (GP predictions, the joint draws' Cholesky factors) in one BLAS
# thread unless told otherwise: on cores the FMU runs share, a second BLAS thread slowed the
# risk of 1e5 samples from 0.6 s to 2-4.5 s (tools/dss/bench_mf.py, load 3.5, docs/dss.md)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from .cli import UsageError, common_cluster_args, common_run_args, resolve_run  # noqa: E402
from .sweep import cmd_sweep, print_report  # noqa: E402


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

    pg = sub.add_parser("page", help="the interactive HTML page of a study, sweep or mixsph run "
                                     "folder (DIR/report.html)")
    pg.add_argument("dir", help="a study (emulate study), a sweep (dss sweep) or the output folder "
                                "of a mixsph run")
    pg.add_argument("-o", "--out", help="the page (default DIR/report.html)")
    pg.add_argument("--crest", type=float, metavar="Z",
                    help="a sweep's elevation for the exceedance (a study has its own)")
    pg.add_argument("--animate", type=int, default=3, metavar="N",
                    help="runs of a study or sweep replayed with mixsph for a particle animation "
                         "(the lowest, median, highest run-up; default 3; kept in DIR/replays)")
    pg.add_argument("--mixsph", help="the mixsph executable of the replays (default build/mixsph)")

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


def cmd_report(args):
    from . import report
    from .store import open_store
    st = open_store(args.out)
    df = st.latest()
    if df.empty:
        raise UsageError(f"no results in {args.out}")
    info = report.make_report(df, args.out, crest=args.crest, x=args.x, y=args.y)
    print_report(info)
    return 0


def cmd_page(args):
    from .html_report import PageError, write_page
    if not os.path.isdir(args.dir):
        raise UsageError(f"{args.dir}: no such folder")
    try:
        path = write_page(args.dir, args.out, crest=args.crest, animate=args.animate,
                          mixsph=args.mixsph)
    except PageError as e:
        raise UsageError(str(e)) from None
    print(f"dss page: wrote {path} ({os.path.getsize(path) / 1e6:.1f} MB; open it in a browser)")
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
        if args.cmd == "page":
            return cmd_page(args)
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
