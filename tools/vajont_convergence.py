#!/usr/bin/env python3
"""Vajont V1 against the particle spacing: is the maximum run-up converged, and which spacing is
the cheapest within a stated error of the finest?

    python tools/vajont_convergence.py [--spacings 0.02,0.015,0.01,0.0075,0.005] [--out out/vajont_conv]
                                       [--threads N] [--mixsph build/mixsph] [--set KEY=VALUE]...
                                       [--tolerance 2] [--checkpoint-every S] [--only-report]
    mixsph-validate convergence ...   (the same, installed by ./tools/do setup)

Each spacing D is ``mixsph-validate vajont --runs 1 --dx D --out OUT/dx<D> --reuse`` (so a
spacing already run with the same settings is kept, and a run cut off continues from its
checkpoint), one after the other, with the --set overrides passed to every run (e.g.
``--set numerics.viscosity=1`` for the implicit viscous step).

Printed and written (OUT/convergence.md, OUT/convergence.csv, OUT/convergence.png): per spacing the
particles, steps, wall time (its run_wall_time_s and threads), the maximum run-up and its time,
d_eta% of the paper's error (13) against the experiment (0.712 m), the difference from the finest
spacing's run-up in mm and in d_eta% (1 % d_eta = 1.345 mm in the lab frame), the mean
iterations of the implicit viscous solve per step (the monitor ``viscous_iterations``: the mean of the monitor samples, each the last step's solve; when the
runs use it), and the cheapest spacing whose run-up is within --tolerance % d_eta (default 2) of
the finest run's. The plot: run-up against dx with the experiment and the band of the
tolerance around the finest run.

Exit status: 0 ok; 1 a run failed; 2 bad usage or input; 130 interrupted.
"""

import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mixsph_tools as mt  # noqa: E402
import vajont_validate as vv  # noqa: E402
from mixsph_tools import campaign, fmt, show  # noqa: E402

PROG = "vajont_convergence.py"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_SPACINGS = "0.02,0.015,0.01,0.0075,0.005"
MM_PER_D_ETA = vv.d_eta_scale_mm()  # [mm] of run-up per 1 % of the error (13), in the lab frame


def parse_args(argv, prog):
    ap = argparse.ArgumentParser(prog=prog, description="Vajont V1 against the particle spacing.")
    ap.add_argument("--spacings", default=DEFAULT_SPACINGS, help=f"particle spacings [m], comma-separated "
                    f"(default {DEFAULT_SPACINGS})")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "vajont_conv"), help="output folder "
                    "(default out/vajont_conv)")
    ap.add_argument("--threads", type=int, help="OpenMP threads of each run (default all cores)")
    ap.add_argument("--mixsph", default=os.path.join(ROOT, "build", "mixsph"), help="mixsph executable")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="sets",
                    help="an override passed to every run (repeatable), e.g. numerics.viscosity=1")
    ap.add_argument("--tolerance", type=float, default=2.0, help="the error, in %% d_eta of (13), within which "
                    "a spacing counts as close enough to the finest (default 2)")
    ap.add_argument("--checkpoint-every", type=float, default=600.0, metavar="SECONDS",
                    help="checkpoint interval of each run in wall seconds (default 600; 0: none)")
    ap.add_argument("--only-report", action="store_true", help="run nothing: report the runs already in OUT")
    args = ap.parse_args(argv)
    try:
        spacings = sorted({float(x) for x in args.spacings.split(",") if x.strip()}, reverse=True)
    except ValueError:
        raise mt.ToolError(f"--spacings: '{args.spacings}' is not a list of numbers (e.g. 0.02,0.01)") from None
    if not spacings or not all(d > 0 and math.isfinite(d) for d in spacings):
        raise mt.ToolError("--spacings: give positive spacings in metres, e.g. 0.02,0.01")
    if not (args.tolerance > 0 and math.isfinite(args.tolerance)):
        raise mt.ToolError("--tolerance must be a positive number of % d_eta")
    return args, spacings


def run_dir(out, dx):
    return os.path.join(out, f"dx{dx:g}")


def run_spacing(args, dx, prog):
    argv = ["--runs", "1", "--dx", f"{dx:g}", "--out", run_dir(args.out, dx), "--reuse", "--mixsph", args.mixsph,
            "--checkpoint-every", f"{args.checkpoint_every:g}", "--progress", "0"]
    if args.threads is not None:
        argv += ["--threads", str(args.threads)]
    for s in args.sets:
        argv += ["--set", s]
    print(f"{prog}: V1 at dx = {dx:g} m")
    try:
        vv.run(argv, prog=f"{prog} (dx = {dx:g})")
        return True
    except SystemExit as e:
        return e.code in (0, None)


def mean_iterations(outdir):
    mon = campaign.read_run_monitors(outdir)
    if mon is None or "viscous_iterations" not in mon:
        return math.nan
    it = [float(v) for v in mon["viscous_iterations"]]
    return sum(it[1:]) / max(1, len(it) - 1) if len(it) > 1 else math.nan


def collect(out, spacings):
    rows = []
    for dx in spacings:
        d = os.path.join(run_dir(out, dx), f"V1_dx{dx:g}")
        path = os.path.join(d, "summary.json")
        row = {"dx": dx, "status": "not run"}
        if os.path.isfile(path):
            s = mt.read_summary(path)
            row["status"] = s.get("status", "?")
            row["particles"] = s.get("particles")
            row["steps"] = s.get("steps")
            row["threads"] = s.get("threads")
            row["wall_s"] = mt.run_wall_time(s)
            row["run_up"] = mt.summary_value(s, "run_up", "max")
            row["t_max"] = mt.summary_value(s, "run_up", "t_max")
            row["iterations"] = mean_iterations(d)
        rows.append(row)
    done = [r for r in rows if r["status"] == "ok" and r.get("run_up") is not None]
    if done:
        finest = min(done, key=lambda r: r["dx"])
        for r in done:
            r["d_eta"] = vv.d_eta(r["run_up"])
            r["diff_mm"] = (r["run_up"] - finest["run_up"]) * 1e3
            r["diff_d_eta"] = abs(r["diff_mm"]) / MM_PER_D_ETA
        return rows, finest
    return rows, None


HEAD = ["dx [m]", "particles", "steps", "wall s (threads)", "max run-up [m]", "at t [s]", "d_eta %",
        "vs finest [mm]", "vs finest [% d_eta]", "solver iterations per step (sampled)"]


def cells(r):
    if r["status"] != "ok":
        return [f"{r['dx']:g}", r["status"]] + [""] * (len(HEAD) - 2)
    return [f"{r['dx']:g}", fmt(r["particles"], ",.0f"), fmt(r["steps"], ",.0f"),
            f"{fmt(r['wall_s'], ',.0f')} ({r['threads']})", fmt(r["run_up"], ".4f"), fmt(r["t_max"], ".3f"),
            fmt(r.get("d_eta"), ".1f"), fmt(r.get("diff_mm"), "+.1f"), fmt(r.get("diff_d_eta"), ".1f"),
            fmt(r["iterations"], ".1f")]


def cheapest_within(rows, finest, tol):
    ok = [r for r in rows if r["status"] == "ok" and r is not finest and r.get("diff_d_eta", math.inf) <= tol]
    return max(ok, key=lambda r: r["dx"]) if ok else None


def plot(path, rows, finest, tol):
    done = [r for r in rows if r["status"] == "ok"]
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot([r["dx"] for r in done], [r["run_up"] for r in done], "o-", label="V1, mixsph")
    ax.axhline(vv.EXP_RUN_UP, color="k", ls="--", lw=0.9, label="experiment 0.712 m")
    if finest is not None:
        band = tol * MM_PER_D_ETA * 1e-3
        ax.axhspan(finest["run_up"] - band, finest["run_up"] + band, color="C0", alpha=0.15,
                   label=f"finest run ± {tol:g} % d_eta")
    ax.set_xscale("log")
    ax.invert_xaxis()
    ax.set_xlabel("particle spacing dx [m]")
    ax.set_ylabel("max run-up [m]")
    ax.set_title("Vajont V1: maximum run-up against the spacing")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def report(args, spacings):
    rows, finest = collect(args.out, spacings)
    table = [HEAD] + [cells(r) for r in rows]
    widths = [max(len(str(x)) for x in col) for col in zip(*table)]
    print()
    for row in table:
        print("  ".join(str(x).rjust(w) for x, w in zip(row, widths)))
    best = cheapest_within(rows, finest, args.tolerance) if finest else None
    verdict = (f"cheapest spacing within {args.tolerance:g} % d_eta ({args.tolerance * MM_PER_D_ETA:.1f} mm) of the "
               f"finest (dx = {finest['dx']:g} m): " + (f"dx = {best['dx']:g} m ({best['diff_mm']:+.1f} mm, "
                                                          f"{fmt(best['wall_s'], ',.0f')} s on {best['threads']} "
                                                          "threads)" if best else "none coarser")) if finest else \
        "no finished run"
    print(f"\n{verdict}")
    os.makedirs(args.out, exist_ok=True)
    csv_path = os.path.join(args.out, "convergence.csv")
    with open(csv_path, "w", newline="") as f:
        csv.writer(f).writerows(table)
    md_path = os.path.join(args.out, "convergence.md")
    with open(md_path, "w") as f:
        f.write("| " + " | ".join(HEAD) + " |\n|" + " --- |" * len(HEAD) + "\n")
        for row in table[1:]:
            f.write("| " + " | ".join(str(x) for x in row) + " |\n")
        f.write(f"\n{verdict}\n\nOverrides: {' '.join(args.sets) or 'none'}\n")
    png_path = os.path.join(args.out, "convergence.png")
    plot(png_path, rows, finest, args.tolerance)
    print(f"table: {show(md_path)}, {show(csv_path)}\nplot:  {show(png_path)}")


def run(argv=None, prog=PROG):
    args, spacings = parse_args(argv, prog)
    args.out = os.path.abspath(args.out)
    failed = []
    if not args.only_report:
        for dx in spacings:
            if not run_spacing(args, dx, prog):
                failed.append(dx)
    report(args, spacings)
    if failed:
        raise mt.ToolError(f"the runs at dx = {', '.join(f'{d:g}' for d in failed)} failed (see their mixsph.log)",
                           code=1)


def main(argv=None, prog=PROG):
    campaign.main(prog, lambda: run(argv, prog))


if __name__ == "__main__":
    main()
