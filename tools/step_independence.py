#!/usr/bin/env python3
"""Does a result depend on the time step? A case at its default CFL, half and a quarter of it,
each setting with twins (gravity perturbed by a round-off-size amount), compared against the
twins' own spread.

    python tools/step_independence.py [--case cases/column_collapse.json] [--factors 1,0.5,0.25]
                                       [--twins 3] [--measure OUTPUT:final|max|min]... [--dx D]
                                       [--set KEY=VALUE]... [--out out/step] [--jobs J] [--reuse]
    mixsph-validate step ...      (the same, installed by ./tools/do setup)

A setting f scales both coefficients of the time step, numerics.cfl and numerics.cfl_visc, by f
(their values for the case come from a probe run's summary.json: the case file's, the --set's or
the code's defaults). Twin k of a setting runs with gravity g (1 + k REL), k = 0 .. twins - 1
(REL = --twin-rel, default 1e-6): a perturbation far below any physical effect, whose spread
shows how much the result moves under round-off alone (a chaotic flow's own scatter). The
measures are summary.json outputs: OUTPUT:final (its value at the end), OUTPUT:max or OUTPUT:min
over the run; by default every front monitor's final value and every max_elevation monitor's max
(a run-up), or its final value when it follows a granular medium (a deposit's height).

Printed and written (OUT/step_independence.md, .csv): per setting and measure the twins' mean,
their spread (max - min) and the difference of the mean from the default setting's; a setting
agrees with the default when that difference is at most the larger of the two settings' spreads
(the criterion of docs/validation/granular.md); steps and wall time per setting.

Exit status: 0 ok (also when a setting does not agree: that is the result); 1 a run failed; 2 bad
usage or input; 130 interrupted.
"""

import math
import os
import subprocess
from dataclasses import dataclass, field

import mixsph_tools as mt
from mixsph_tools import campaign, fmt, show

PROG = "tools/step_independence.py"
STAMP = "step_independence.json"
STAMP_KEYS = ("factor", "twin", "dx", "cfl", "cfl_visc", "gravity", "t_end", "case_sha256", "sets")
T_TOL = 1e-6   # [s] a run that ended this close to t_end finished

OPTIONS = campaign.CaseOptions(
    description="A case at its default time step and at smaller ones, each with gravity-perturbed twins: "
                "do the results move more than the twins' own spread?",
    runs="", known=(), dx=0.01, dx_help="particle spacing [m] of every run (default 0.01)",
    out="step", case="column_collapse.json", t_end="its numerics.t_end",
    set_example="media.sand.phi=30", twin_help=None, sphera=(), progress=60.0,
    own=(("--factors", dict(default="1,0.5,0.25", help="time-step factors: each scales numerics.cfl and "
                            "cfl_visc (default 1,0.5,0.25; 1 is the reference)")),
         ("--twins", dict(type=int, default=3, help="runs per setting, twin k with gravity g (1 + k REL) "
                          "(default 3)")),
         ("--twin-rel", dict(type=float, default=1e-6, metavar="REL", help="relative change of gravity between "
                             "twins (default 1e-6)")),
         ("--measure", dict(action="append", default=[], metavar="OUTPUT:final|max|min",
                            help="a summary.json output to compare (repeatable; default: the fronts' final "
                            "values, the max_elevation monitors' max, or final for a granular medium)"))))


@dataclass
class Setting:
    factor: float
    jobs: list = field(default_factory=list)
    values: dict = field(default_factory=dict)     # measure -> values of the finished twins
    steps: list = field(default_factory=list)
    wall: list = field(default_factory=list)


def parse_factors(text):
    try:
        factors = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise mt.ToolError(f"--factors {text}: expected numbers, e.g. 1,0.5,0.25") from None
    if not factors or any(not (0 < f <= 1) for f in factors) or len(set(factors)) != len(factors):
        raise mt.ToolError(f"--factors {text}: distinct numbers in (0, 1], e.g. 1,0.5,0.25")
    return sorted(factors, reverse=True)


def default_measures(case_json):
    """Every front monitor's final value; every max_elevation monitor's max (a wave's run-up), or
    its final value when it follows a granular medium (a deposit's height)."""
    media = case_json.get("media") or {}
    out = []
    for name, m in (case_json.get("monitors") or {}).items():
        if m.get("type") == "max_elevation":
            granular = (media.get(m.get("medium")) or {}).get("type") == "granular"
            out.append((name, "final" if granular else "max"))
        elif m.get("type") == "front":
            out.append((name, "final"))
    return out


def parse_measures(items, case_json, case):
    if not items:
        measures = default_measures(case_json)
        if not measures:
            raise mt.ToolError(f"{show(case)}: no max_elevation or front monitor to compare: give --measure")
        return measures
    measures = []
    for it in items:
        name, _, what = it.partition(":")
        if not name or what not in ("final", "max", "min"):
            raise mt.ToolError(f"--measure {it}: expected OUTPUT:final, OUTPUT:max or OUTPUT:min")
        measures.append((name, what))
    return measures


def probe_numerics(s, dx):
    """The case's time-step coefficients as the code reads them (a run of one step's length)."""
    out = os.path.join(s.out, "probe")
    cmd = [s.mixsph, "run", s.case, "--out", out, "--set", f"numerics.dx={mt.num(dx)}"]
    for key, val in s.extra:
        cmd += ["--set", f"{key}={mt.num(val)}"]
    cmd += ["--set", "numerics.t_end=1e-9", "--threads", "1", "--quiet"]
    done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if done.returncode != 0:
        raise mt.ToolError(f"the probe run failed (exit {done.returncode}): {done.stdout.strip()[-400:]}", code=1
                           if done.returncode != 2 else 2)
    summ = mt.read_summary(os.path.join(out, "summary.json"))
    num = summ.get("numerics") or {}
    cfl, cfl_visc = num.get("cfl"), num.get("cfl_visc")
    if not (isinstance(cfl, (int, float)) and isinstance(cfl_visc, (int, float))):
        raise mt.ToolError(f"{show(out)}/summary.json: no numerics.cfl / cfl_visc (a mixsph older than this tool?)")
    return float(cfl), float(cfl_visc)


def spread(v):
    return max(v) - min(v) if len(v) > 1 else math.nan


def mean(v):
    return sum(v) / len(v) if v else math.nan


def table(settings, measures):
    """The columns (group, header, align) and rows of cell strings of the comparison."""
    ref = settings[0]
    columns = [("", "factor", ">"), ("", "runs ok", ">"), ("", "steps", ">"), ("", "wall s", ">")]
    for name, what in measures:
        g = f"{name}:{what}"
        columns += [(g, "mean", ">"), (g, "spread", ">"), (g, "diff", ">"), (g, "agrees", ">")]
    rows = []
    for st in settings:
        row = [fmt(st.factor, "g"), str(len(st.steps)), fmt(mean(st.steps), ".6g"), fmt(mean(st.wall), ".3g")]
        for m in measures:
            v, r = st.values.get(m, []), ref.values.get(m, [])
            diff, bound = mean(v) - mean(r), max(spread(v), spread(r))
            if st is ref:
                agrees = "-"
            elif math.isfinite(diff) and math.isfinite(bound):
                agrees = "yes" if abs(diff) <= bound else "NO"
            else:
                agrees = "?"
            row += [fmt(mean(v), ".5g"), fmt(spread(v), ".3g"), "-" if st is ref else fmt(diff, "+.3g"), agrees]
        rows.append(row)
    return columns, rows


def run(argv=None, prog=PROG):
    args = campaign.parse_args(prog, OPTIONS, argv)
    factors = parse_factors(args.factors)
    if args.twins < 2:
        raise mt.ToolError("--twins must be at least 2 (the spread needs two runs)")
    if not (0 < abs(args.twin_rel) < 1e-3):
        raise mt.ToolError("--twin-rel: a relative change of gravity between 0 and 1e-3 in size, e.g. 1e-6")
    s = campaign.settings(args, prog, OPTIONS, len(factors) * args.twins)
    measures = parse_measures(args.measure, s.case_json, s.case)
    os.makedirs(s.out, exist_ok=True)
    cfl0, cfl_visc0 = probe_numerics(s, args.dx)
    print(f"{show(s.case)}: cfl = {cfl0:g}, cfl_visc = {cfl_visc0:g} at factor 1", flush=True)
    settings = []
    for f in factors:
        st = Setting(f)
        for k in range(args.twins):
            g = mt.twin_gravity(s.case_json, s.extra, k * args.twin_rel, show(s.case)) if k else None
            own = [("numerics.cfl", f * cfl0), ("numerics.cfl_visc", f * cfl_visc0)]
            sets = own + list(s.extra) + ([("gravity", g)] if g is not None else [])
            head = {"factor": f, "twin": k, "dx": args.dx, "cfl": f * cfl0, "cfl_visc": f * cfl_visc0,
                    "gravity": g}
            tail = {"sets": [list(x) for x in s.extra]}
            st.jobs.append(campaign.make_job(s, f, f"f{f:g} twin {k}", args.dx, f"f{f:g}_twin{k}", sets, head, tail))
        settings.append(st)
    jobs = [j for st in settings for j in st.jobs]
    failed = campaign.run(s, jobs, STAMP, STAMP_KEYS, T_TOL, what=f" at dx = {args.dx:g} m")
    for st in settings:
        for job in st.jobs:
            r = campaign.RunResult(job.paper, job.dx, job.outdir, job.source)
            summ = campaign.read_run_summary(job, r)
            if summ is None or not r.ok:
                continue
            st.steps.append(r.steps)
            st.wall.append(r.wall)
            for m in measures:
                v = mt.summary_value(summ, *m)
                if math.isfinite(v):
                    st.values.setdefault(m, []).append(v)
    columns, rows = table(settings, measures)
    print()
    mt.print_table(columns, rows)
    csv_path, md_path = os.path.join(s.out, "step_independence.csv"), os.path.join(s.out, "step_independence.md")
    mt.write_csv(csv_path, [f"{g} {h}".strip() for g, h, _ in columns], rows)
    with open(md_path, "w") as f:
        f.write(f"{show(s.case)} at dx = {args.dx:g} m, cfl = {cfl0:g} and cfl_visc = {cfl_visc0:g} at factor 1, "
                f"{args.twins} twins per setting (gravity x (1 + k {args.twin_rel:g}))"
                + (", " + " ".join(f"--set {k}={v}" for k, v in s.extra) if s.extra else "") + "\n\n")
        f.write("\n".join(mt.markdown_table([(g, f"{g} {h}".strip(), a) for g, h, a in columns], rows)) + "\n")
    print(f"\ntable: {show(md_path)}, {show(csv_path)}")
    campaign.check_failed(failed)


def main(argv=None, prog=PROG):
    """The script; argv None: sys.argv; prog: how its help and its messages name it."""
    campaign.main(prog, lambda: run(argv, prog))


if __name__ == "__main__":
    main()
