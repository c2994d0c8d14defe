#!/usr/bin/env python3
"""Dry granular columns of several aspect ratios: their deposits against the experimental laws,
and whether they come to rest.

    python tools/column_runout.py [--aspects 0.5,1,2] [--dx 0.01] [--refine] [--threshold 0.02]
                                  [--set KEY=VALUE]... [--out out/column_runout] [--jobs J] [--threads N] [--reuse]
                                  [--check]
    mixsph-validate runout ...      (the same, installed by ./tools/do setup)

The case (cases/column_collapse.json): a column of width L0 (the case's parameter, 0.2 m) and
height H0 = a L0 against a left wall on a no-slip floor; per aspect ratio a the wall, the floor
and the domain are made long and high enough for the deposit (parameters wall_top, floor_end,
x_max, z_max), and a snapshot is written at 5 T, T = sqrt(H0 / g). The material law and its
constants are the case's, or a --set's (e.g. --set media.sand.law=1 for "elastic_plastic").

The experimental laws (Lube, Huppert, Sparks & Freundt 2005, Phys. Rev. E 72, 041301, quasi-2D
columns of sand, sugar, rice and salt; Lajeunesse, Monnier & Homsy 2005, Phys. Fluids 17, 103302,
the same shapes with material-dependent prefactors):
    run-out     (L_inf - L0) / L0 = 1.2 a            for a < 1.8
                                  = 1.9 a^(2/3)      for a > 2.8  (in between: both shown)
    final height  H_inf / L0      = a                for a < 1.15 (the top is left untouched)
                                  = a^(2/5)          above
and the motion stops near 3 T. These are fits to experiments with their own scatter (their
prefactors vary by some 10-20 % between materials); the comparison states the difference, it
does not pass or fail a number.

Measured at 5 T, from the monitors (front: the outermost grain centre; height: the highest grain
with 3 neighbours) and the snapshot at 5 T: the run-out and the final height against the laws;
the front's speed over the last 0.05 s; the fraction of grains slower than 1 mm/s. The criterion
of a deposit at rest (docs/validation/granular.md): the front below 1 mm/s and at least 95 % of
the grains below 1 mm/s at 5 T.

The threshold measures (issue 59): the script runs the case with monitors of its own added
(OUT/case_column.json): `deposit`, a runout monitor (docs/cases.md) whose run-out is where the
deposit is still --threshold thick, with the deposit's thickest column as H_inf; `speed_p99` and
`speed_max`, the 0.99 quantile and the largest speed of the grains; `deposit_t1`, ... the
run-outs at the --also-thresholds, tabled beside (no criterion). A threshold is a thickness in
metres (0.02, the default) or a number of particle spacings at each run's spacing (1.5dx: the
validation suite's, two rows of grains; docs/validation/granular_thresholds.md argues it: the
experiments' run-out is the deposit's edge, a grain thick, and a grain is far below what a
particle of 5-10 mm resolves, so the model's edge is its thinnest layer that is more than one
row). Criteria, each within 15 % of the fits (2D continuum against
quasi-2D experiments): the threshold run-out (for 1.8 < a < 2.8, where Lube et al. give no fit,
within 15 % of the band between the two fits: the ends 1.2 a and 1.9 a^(2/3) scaled by 0.85 and
1.15), the height H_inf / L0, and 99 % of the grains below 1 mm/s at 5 T. --refine runs each
column at dx and at dx / 2 and gives the change from one to the other; --check makes the exit
status 1 when a criterion fails (the validation suite's test).

Written: OUT/column_runout.md, .csv and OUT/column_runout.png (run-out and height against a
with the laws), OUT/column_threshold.md (the threshold measures and criteria). Exit status: 0 ok;
1 a run failed (or, with --check, a criterion); 2 bad usage or input; 130 interrupted.
"""

import dataclasses
import json
import math
import os
import sys
from dataclasses import dataclass

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after choosing the backend)

import mixsph_tools as mt  # noqa: E402
from mixsph_tools import campaign, fmt, show  # noqa: E402

PROG = "tools/column_runout.py"
STOP_SPEED = 1e-3        # [m/s] "at rest"
AT_REST_FRACTION = 0.95  # of the grains slower than STOP_SPEED
CRITERION = 0.15         # the threshold run-out and H_inf within 15 % of the fits (issue 59)
QUANTILE_AT_REST = 0.99  # this quantile of the grains' speeds below STOP_SPEED at 5 T
SPEED_WINDOW = 0.05      # [s] the front's speed over this window
REST_TIMES = 5.0         # the deposit is judged at this many T = sqrt(H0 / g)
T_TOL = 1e-3
STAMP = "column_runout.json"
STAMP_KEYS = ("aspect", "L0", "dx", "t_end", "case_sha256", "sets")
GRAIN_MEDIUM = "sand"    # the column's medium in cases/column_collapse.json


def lube_runout(a):
    """(L_inf - L0) / L0 of Lube et al. (2005): 1.2 a below a = 1.8, 1.9 a^(2/3) above 2.8; in
    between the two fits (low, high)."""
    if a < 1.8:
        return 1.2 * a, 1.2 * a
    if a > 2.8:
        return 1.9 * a ** (2 / 3), 1.9 * a ** (2 / 3)
    lo, hi = sorted((1.2 * a, 1.9 * a ** (2 / 3)))
    return lo, hi


def lube_height(a):
    """H_inf / L0 of Lube et al. (2005): a below a = 1.15 (the top untouched), a^(2/5) above."""
    return a if a < 1.15 else a ** 0.4


@dataclass
class Result(campaign.RunResult):
    aspect: float = math.nan
    t_rest: float = math.nan      # 5 T [s]
    runout: float = math.nan      # (front - L0) / L0 at 5 T
    height: float = math.nan      # height / L0 at 5 T
    front_speed: float = math.nan  # [m/s] over SPEED_WINDOW before 5 T
    slow_fraction: float = math.nan  # grains slower than STOP_SPEED in the snapshot at 5 T
    t_snapshot: float = math.nan
    runout_thr: float = math.nan  # (x where the deposit is --threshold thick - L0) / L0 at 5 T
    height_thr: float = math.nan  # the deposit's thickest column / L0 at 5 T
    speed_p99: float = math.nan   # [m/s] the 0.99 quantile of the grains' speeds at 5 T
    runout_also: tuple = ()       # the run-outs at the thresholds given for comparison (--also-thresholds)


def parse_aspects(text):
    try:
        aspects = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise mt.ToolError(f"--aspects {text}: expected numbers, e.g. 0.5,1,2") from None
    if not aspects or any(not (0.1 <= a <= 10) for a in aspects) or len(set(aspects)) != len(aspects):
        raise mt.ToolError(f"--aspects {text}: distinct aspect ratios H0 / L0 between 0.1 and 10")
    return aspects


def geometry(a, L0):
    """The parameters of the case for aspect ratio a: the column, a wall above it, a floor and a
    domain past the longest run-out the laws give (twice it, plus L0)."""
    H0 = a * L0
    reach = L0 * (2.0 + 2.0 * lube_runout(a)[1])
    return {"parameters.H0": H0, "parameters.L0": L0, "parameters.wall_top": 1.5 * H0,
            "parameters.z_max": 2.0 * H0, "parameters.floor_end": reach, "parameters.x_max": reach + 0.05}


def value_at(t, v, t0):
    """v at the sample nearest t0."""
    return float(v[int(np.argmin(np.abs(t - t0)))])


def load_result(job, a, L0, g, n_also=0):
    r = Result(job.paper, job.dx, job.outdir, job.source, aspect=a)
    if campaign.read_run_summary(job, r) is None:
        return r
    r.t_rest = REST_TIMES * math.sqrt(a * L0 / g)
    mon = campaign.read_run_monitors(job.outdir)
    if mon is None or "front" not in mon or "height" not in mon or mon["t"][-1] < r.t_rest - T_TOL:
        return r
    t, front = np.asarray(mon["t"], float), np.asarray(mon["front"], float)
    r.runout = (value_at(t, front, r.t_rest) - L0) / L0
    r.height = value_at(t, np.asarray(mon["height"], float), r.t_rest) / L0
    back = value_at(t, front, r.t_rest - SPEED_WINDOW)
    r.front_speed = abs(value_at(t, front, r.t_rest) - back) / SPEED_WINDOW
    if "deposit" in mon:
        r.runout_thr = (value_at(t, np.asarray(mon["deposit"], float), r.t_rest) - L0) / L0
        r.height_thr = value_at(t, np.asarray(mon["deposit_height"], float), r.t_rest) / L0
        r.speed_p99 = value_at(t, np.asarray(mon["speed_p99"], float), r.t_rest)
        r.runout_also = tuple((value_at(t, np.asarray(mon[deposit_monitor(k)], float), r.t_rest) - L0) / L0
                              if deposit_monitor(k) in mon else math.nan for k in range(1, n_also + 1))
    snap = mt.nearest_snapshot(job.outdir, r.t_rest)
    if snap is not None:
        r.t_snapshot, cols = mt.read_snapshot(snap[1])
        grain = cols["state"] <= 1   # mobile or held grains (not walls, not lost)
        speed = np.hypot(cols["vx"][grain], cols["vz"][grain])
        r.slow_fraction = float(np.mean(speed < STOP_SPEED)) if speed.size else math.nan
    return r


def table(results):
    columns = [("", "a", ">"), ("", "status", "<"), ("", "steps", ">"), ("", "wall s", ">"), ("", "5T s", ">"),
               ("run-out", "run", ">"), ("run-out", "Lube", ">"), ("run-out", "diff %", ">"),
               ("height / L0", "run", ">"), ("height / L0", "Lube", ">"), ("height / L0", "diff %", ">"),
               ("at 5T", "front mm/s", ">"), ("at 5T", "slow %", ">"), ("at 5T", "at rest", ">")]
    rows = []
    for r in results:
        lo, hi = lube_runout(r.aspect)
        law = fmt(lo, ".2f") if lo == hi else f"{lo:.2f}-{hi:.2f}"
        mid = 0.5 * (lo + hi)
        hl = lube_height(r.aspect)
        rest = r.front_speed < STOP_SPEED and r.slow_fraction >= AT_REST_FRACTION
        rows.append([fmt(r.aspect, "g"), "ok" if r.ok else r.status, fmt(r.steps, ".0f"), fmt(r.wall, ".3g"),
                     fmt(r.t_rest, ".3f"), fmt(r.runout, ".2f"), law, fmt(100 * (r.runout - mid) / mid, "+.0f"),
                     fmt(r.height, ".2f"), fmt(hl, ".2f"), fmt(100 * (r.height - hl) / hl, "+.0f"),
                     fmt(1e3 * r.front_speed, ".2g"), fmt(100 * r.slow_fraction, ".1f"),
                     "yes" if rest else ("no" if math.isfinite(r.slow_fraction) else "?")])
    return columns, rows


@dataclass(frozen=True)
class Threshold:
    """The deposit's thickness at a run-out: `value` metres, or `value` particle spacings at each
    run's spacing (per_dx)."""
    value: float
    per_dx: bool = False

    def at(self, dx):
        """The thickness [m] at spacing dx."""
        return self.value * dx if self.per_dx else self.value

    def __str__(self):
        return f"{self.value:g} dx" if self.per_dx else f"{self.value:g} m"


def parse_threshold(text):
    """--threshold's value: a thickness in metres ("0.02") or a number of particle spacings ("2dx")."""
    t = str(text).strip()
    per_dx = t.endswith("dx")
    try:
        value = float(t[:-2] if per_dx else t)
    except ValueError:
        value = math.nan
    if not (value > 0 and math.isfinite(value)):
        raise mt.ToolError(f"--threshold {text}: expected a positive thickness in metres (0.02) or a number of "
                           "particle spacings (2dx)")
    return Threshold(value, per_dx)


def deposit_monitor(k):
    """The name of the runout monitor of threshold k (0: the criterion's, the others for comparison)."""
    return "deposit" if k == 0 else f"deposit_t{k}"


def with_threshold_monitors(case_json, thresholds):
    """A copy of the column case with the monitors of the threshold measures added: the deposit's
    run-out and height over the floor (x from 0, the wall, to the floor's end), one runout monitor
    per thickness of `thresholds` [m] (the first the criterion's), and the grains' speeds."""
    out = json.loads(json.dumps(case_json))
    mons = out.setdefault("monitors", {})
    for k, threshold in enumerate([thresholds] if isinstance(thresholds, (int, float)) else thresholds):
        mons[deposit_monitor(k)] = {"type": "runout", "medium": GRAIN_MEDIUM, "x_min": 0.0, "x_max": "$floor_end",
                                    "threshold": threshold, "direction": "+x"}
    mons["speed_p99"] = {"type": "speed", "medium": GRAIN_MEDIUM, "quantile": QUANTILE_AT_REST}
    mons["speed_max"] = {"type": "speed", "medium": GRAIN_MEDIUM}
    return out


def within_fit(value, lo, hi):
    """The relative distance [-] of value from the fit (lo == hi) or the band [lo, hi]: 0 inside."""
    if not math.isfinite(value):
        return math.nan
    if value < lo:
        return (value - lo) / lo
    return (value - hi) / hi if value > hi else 0.0


def criteria(r):
    """(run-out ok, height ok, at rest ok) of a result against the criteria (CRITERION)."""
    lo, hi = lube_runout(r.aspect)
    run = abs(within_fit(r.runout_thr, lo, hi)) <= CRITERION
    hl = lube_height(r.aspect)
    height = abs(within_fit(r.height_thr, hl, hl)) <= CRITERION
    rest = r.speed_p99 < STOP_SPEED
    return run, height, rest


def threshold_table(results, coarse):
    """The threshold measures, one row per run; coarse[k]: the run at twice the spacing of run k
    (None): the change from it."""
    yn = {True: "yes", False: "**no**"}
    columns = [("", "a", ">"), ("", "dx", ">"), ("", "status", "<"), ("", "wall s", ">"),
               ("run-out", "run", ">"), ("run-out", "Lube", ">"), ("run-out", "off fit %", ">"),
               ("run-out", "ok", "<"), ("run-out", "vs 2 dx %", ">"),
               ("H_inf / L0", "run", ">"), ("H_inf / L0", "Lube", ">"), ("H_inf / L0", "off %", ">"),
               ("H_inf / L0", "ok", "<"), ("H_inf / L0", "vs 2 dx %", ">"),
               ("at 5T", "99 % speed mm/s", ">"), ("at 5T", "< 1 mm/s", "<")]
    rows = []
    for r, c in zip(results, coarse):
        lo, hi = lube_runout(r.aspect)
        hl = lube_height(r.aspect)
        run_ok, h_ok, rest_ok = criteria(r)
        law = fmt(lo, ".2f") if lo == hi else f"{lo:.2f}-{hi:.2f}"
        d_run = 100 * (r.runout_thr - c.runout_thr) / c.runout_thr if c else math.nan
        d_h = 100 * (r.height_thr - c.height_thr) / c.height_thr if c else math.nan
        rows.append([fmt(r.aspect, "g"), fmt(r.dx, "g"), "ok" if r.ok else r.status, fmt(r.wall, ".3g"),
                     fmt(r.runout_thr, ".2f"), law, fmt(100 * within_fit(r.runout_thr, lo, hi), "+.0f"),
                     yn[run_ok], fmt(d_run, "+.0f", ""),
                     fmt(r.height_thr, ".2f"), fmt(hl, ".2f"), fmt(100 * within_fit(r.height_thr, hl, hl), "+.0f"),
                     yn[h_ok], fmt(d_h, "+.0f", ""),
                     fmt(1e3 * r.speed_p99, ".2g"), yn[rest_ok]])
    return columns, rows


def also_table(results, coarse, thresholds):
    """The run-out at every threshold (the criterion's first), its distance from the fit and its
    change from the run at twice the spacing; one row per run."""
    columns = [("", "a", ">"), ("", "dx", ">"), ("", "Lube", ">")]
    for t in thresholds:
        columns += [(str(t), "run", ">"), (str(t), "off fit %", ">"), (str(t), "vs 2 dx %", ">")]
    rows = []
    for r, c in zip(results, coarse):
        lo, hi = lube_runout(r.aspect)
        row = [fmt(r.aspect, "g"), fmt(r.dx, "g"), fmt(lo, ".2f") if lo == hi else f"{lo:.2f}-{hi:.2f}"]
        for k in range(len(thresholds)):
            v = r.runout_thr if k == 0 else r.runout_also[k - 1]
            vc = (c.runout_thr if k == 0 else c.runout_also[k - 1]) if c else math.nan
            row += [fmt(v, ".2f"), fmt(100 * within_fit(v, lo, hi), "+.0f"), fmt(100 * (v - vc) / vc, "+.0f", "")]
        rows.append(row)
    return columns, rows


def plot(path, results):
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    aa = np.linspace(0.2, max(3.0, max(r.aspect for r in results) * 1.2), 200)
    ax1.plot(aa[aa < 1.8], 1.2 * aa[aa < 1.8], "k-", label="Lube et al. 2005: 1.2 a")
    ax1.plot(aa[aa > 2.8], 1.9 * aa[aa > 2.8] ** (2 / 3), "k--", label="1.9 a^(2/3)")
    ax2.plot(aa, [lube_height(a) for a in aa], "k-", label="Lube et al. 2005")
    ax1.plot([r.aspect for r in results], [r.runout for r in results], "o", label="mixsph")
    ax2.plot([r.aspect for r in results], [r.height for r in results], "o", label="mixsph")
    ax1.set_xlabel("a = H0 / L0")
    ax1.set_ylabel("(L_inf - L0) / L0 at 5 T")
    ax2.set_xlabel("a = H0 / L0")
    ax2.set_ylabel("H_inf / L0 at 5 T")
    ax1.legend()
    ax2.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


OPTIONS = campaign.CaseOptions(
    description="Dry granular columns of several aspect ratios against the run-out and final-height laws of "
                "Lube et al. (2005), and whether their deposits rest at 5 sqrt(H0/g).",
    runs="", known=(), dx=0.01, out="column_runout", case="column_collapse.json", t_end="1.5 s",
    dx_help="particle spacing [m] (default 0.01)", set_example="media.sand.phi=30", twin_help=None, sphera=(),
    progress=120.0,
    own=(("--aspects", dict(default="0.5,1,2", help="aspect ratios H0 / L0 (default 0.5,1,2)")),
         ("--threshold", dict(default="0.02", help="the deposit's thickness at its threshold run-out: metres "
                                                   "(0.02, the default) or particle spacings at each spacing (2dx)")),
         ("--also-thresholds", dict(default="", help="other thicknesses (as --threshold, comma-separated) whose "
                                                     "run-outs are tabled beside, for comparison (no criterion)")),
         ("--refine", dict(action="store_true", help="also run each column at dx / 2 and give the change")),
         ("--check", dict(action="store_true", help="exit status 1 when a threshold criterion fails")),
         ("--doc", dict(help="also write the threshold table (with the command) to this file"))))


def run(argv=None, prog=PROG):
    args = campaign.parse_args(prog, OPTIONS, argv)
    aspects = parse_aspects(args.aspects)
    thresholds = [parse_threshold(args.threshold)] + [parse_threshold(t) for t in args.also_thresholds.split(",")
                                                      if t.strip()]
    spacings = [args.dx, args.dx / 2] if args.refine else [args.dx]
    s = campaign.settings(args, prog, OPTIONS, len(aspects) * len(spacings))
    params = s.case_json.get("parameters") or {}
    L0, g = params.get("L0"), s.case_json.get("gravity")
    if not isinstance(L0, (int, float)) or not isinstance(g, (int, float)):
        raise mt.ToolError(f"{show(s.case)}: a column case declares the parameter L0 and a numeric gravity "
                           "(cases/column_collapse.json)")
    g = next((float(v) for k, v in reversed(s.extra) if k == "gravity"), float(g))
    L0 = next((float(v) for k, v in reversed(s.extra) if k == "parameters.L0"), float(L0))
    too_short = [a for a in aspects if REST_TIMES * math.sqrt(a * L0 / g) > s.t_end + T_TOL]
    if too_short:
        raise mt.ToolError(f"t_end = {s.t_end:g} s is shorter than 5 sqrt(H0/g) of a = "
                           f"{','.join(f'{a:g}' for a in too_short)}: give --t-end")
    # the case with the threshold monitors, written once the options are known to be good
    case_json = with_threshold_monitors(s.case_json, [t.at(args.dx) for t in thresholds])
    case = os.path.join(s.out, "case_column.json")
    os.makedirs(s.out, exist_ok=True)
    with open(case, "w") as f:
        json.dump(case_json, f, indent=2)
        f.write("\n")
    s = dataclasses.replace(s, case=case, case_json=case_json, case_sha=campaign.case_digest(case))
    jobs, runs = [], []
    for a in aspects:
        for dx in spacings:
            t_rest = REST_TIMES * math.sqrt(a * L0 / g)
            own = list(geometry(a, L0).items()) + [("output.snapshot_interval", t_rest / 5.0)]
            own += [(f"monitors.{deposit_monitor(k)}.threshold", t.at(dx))
                    for k, t in enumerate(thresholds) if t.per_dx]
            head = {"aspect": a, "L0": L0, "dx": dx}
            tail = {"sets": [list(x) for x in s.extra]}
            jobs.append(campaign.make_job(s, a, f"a = {a:g}, dx = {dx:g}", dx, f"a{a:g}_dx{dx:g}",
                                          own + list(s.extra), head, tail))
            runs.append((a, dx))
    spacing_text = " and ".join(f"{dx:g}" for dx in spacings)
    failed = campaign.run(s, jobs, STAMP, STAMP_KEYS, T_TOL, what=f" at dx = {spacing_text} m")
    results = [load_result(job, a, L0, g, len(thresholds) - 1) for job, (a, _) in zip(jobs, runs)]
    coarse = [next((c for c, (a2, dx2) in zip(results, runs) if a2 == a and abs(dx2 - 2 * dx) < 1e-12), None)
              for a, dx in runs]
    columns, rows = table(results)
    print()
    mt.print_table(columns, rows)
    md, csv_path, png = (os.path.join(s.out, f"column_runout.{e}") for e in ("md", "csv", "png"))
    mt.write_csv(csv_path, [f"{g_} {h}".strip() for g_, h, _ in columns], rows)
    with open(md, "w") as f:
        f.write(f"{show(s.case)} at dx = {args.dx:g} m, L0 = {L0:g} m"
                + (", " + " ".join(f"--set {k}={mt.num(v)}" for k, v in s.extra) if s.extra else "") + "\n\n")
        f.write("\n".join(mt.markdown_table([(g_, f"{g_} {h}".strip(), al) for g_, h, al in columns], rows)) + "\n")
    plot(png, results)
    t_columns, t_rows = threshold_table(results, coarse)
    print(f"\nthreshold measures (run-out where the deposit is {thresholds[0]} thick; criteria within "
          f"{100 * CRITERION:g} % of the fits, 99 % of the grains below 1 mm/s at 5 T):")
    mt.print_table(t_columns, t_rows)
    md_thr = os.path.join(s.out, "column_threshold.md")
    command = mt.reproduce_command(PROG, list(argv if argv is not None else sys.argv[1:]))
    text = (f"Columns of cases/column_collapse.json at dx = {spacing_text} m, L0 = {L0:g} m, threshold "
            f"{thresholds[0]}" + (", " + " ".join(f"--set {k}={mt.num(v)}" for k, v in s.extra) if s.extra else "")
            + "\n\n" + "\n".join(mt.markdown_table([(g_, f"{g_} {h}".strip(), al) for g_, h, al in t_columns], t_rows)))
    if len(thresholds) > 1:
        a_columns, a_rows = also_table(results, coarse, thresholds)
        print("\nthe run-out at other thresholds (for comparison):")
        mt.print_table(a_columns, a_rows)
        text += ("\n\nThe run-out (L - L0) / L0 at other thresholds, for comparison (no criterion):\n\n"
                 + "\n".join(mt.markdown_table([(g_, f"{g_} {h}".strip(), al) for g_, h, al in a_columns], a_rows)))
    text += "\n\n```sh\n" + command + "\n```\n"
    for path in [md_thr] + ([args.doc] if args.doc else []):
        with open(path, "w") as f:
            f.write(text)
    print(f"\ntable: {show(md)}, {show(csv_path)}, {show(md_thr)}\nplot:  {show(png)}")
    campaign.check_failed(failed)
    if args.check and not all(all(criteria(r)) for r in results):
        raise SystemExit(1)


def main(argv=None, prog=PROG):
    """The script; argv None: sys.argv; prog: how its help and its messages name it."""
    campaign.main(prog, lambda: run(argv, prog))


if __name__ == "__main__":
    main()
