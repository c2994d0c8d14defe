#!/usr/bin/env python3
"""Granular column collapse: does the deposit come to rest? The limiting viscosity against the
implicit viscous step with the grains' full frictional viscosity.

    python tools/column_collapse.py [--runs 1,2,3] [--dx 0.01] [--out out/column] [--threads N]
                                    [--jobs J] [--reuse] [--t-end T] [--set KEY=VALUE]...
    mixsph-validate column ...      (the same, installed by ./tools/do setup)

The case (cases/column_collapse.json): a dry sand column, H0 = r0 = 0.2 m, against a left wall on
a no-slip floor, with the Vajont sand (phi = 35 deg, mu_thr = 320 kPa s). Runs:

    run  viscous step  mu0                       why
    1    explicit      5 kPa s (the Vajont case's)  the paper's scheme
    2    implicit      off (mu0 = mu_thr)           no numerical cap: the grains' full viscosity
    3    implicit      5 kPa s                      the scheme alone, with the cap of run 1

A grain capped at mu0 creeps at a strain rate of about tau / (2 mu0) and so never reaches mu_thr
(docs/model.md section 6); without the cap its viscosity grows as it slows, until it is held.

Printed per run: steps and wall time; the front (outermost grain centre, monitor ``front``) at
the end and its run-out (front - r0) / r0; the front speed, over windows of 0.05 s, at the end;
the first time from which it stays below 1 mm/s (``stops at``), also in units of the collapse's
time scale T = sqrt(H0 / g) = 0.143 s; the fraction of grains held fixed (monitor
``fixed_particles``) at t = 0.5, 1.0 s and the end. Writes OUT/column_table.csv and
OUT/column_collapse.png (front speed and fixed fraction against t / T).

Exit status: 0 ok; 1 a run failed; 2 bad usage or input; 130 interrupted. The result and the
command: docs/validation/granular.md. The campaign (options, runs, --reuse):
tools/mixsph_tools/campaign.py.
"""

import math
import os
import sys
from dataclasses import dataclass

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after choosing the backend)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mixsph_tools as mt  # noqa: E402
from mixsph_tools import campaign  # noqa: E402
from mixsph_tools import fmt, show  # noqa: E402

PROG = "column_collapse.py"
H0 = 0.2                 # [m] column height (= its width r0)
G = 9.81                 # [m/s2]
T_SCALE = math.sqrt(H0 / G)
STOP_SPEED = 1e-3        # [m/s] "stopped": the front slower than this from then on
SPEED_WINDOW = 0.05      # [s] front speed over this window
FIXED_AT = (0.5, 1.0)    # [s] fixed fractions reported at these times (and at the end)
T_TOL = 1e-3
STAMP = "column_run.json"
STAMP_KEYS = ("run", "dx", "viscosity", "mu0", "t_end", "case", "case_sha256", "sets")


@dataclass(frozen=True)
class Variant:
    run: int
    viscosity: float     # numerics.viscosity: 0 explicit, 1 implicit
    mu0: float           # [Pa s]
    label: str

    @property
    def name(self):
        return str(self.run)


VARIANTS = {
    1: Variant(1, 0.0, 5e3, "explicit, mu0 = 5 kPa s"),
    2: Variant(2, 1.0, 320e3, "implicit, mu0 off"),
    3: Variant(3, 1.0, 5e3, "implicit, mu0 = 5 kPa s"),
}


@dataclass
class Result(campaign.RunResult):
    t: np.ndarray = None
    speed: np.ndarray = None       # front speed [m/s] at t
    fixed: np.ndarray = None       # fraction of grains held fixed at t
    front: float = math.nan        # [m] at the end
    t_stop: float = math.nan       # [s] front slower than STOP_SPEED from then on


def front_speed(t, front):
    """The front's speed over SPEED_WINDOW (backward differences of the sampled front)."""
    k = max(1, int(round(SPEED_WINDOW / max(t[1] - t[0], 1e-12)))) if len(t) > 1 else 1
    speed = np.full(len(t), np.nan)
    speed[k:] = (front[k:] - front[:-k]) / (t[k:] - t[:-k])
    return speed


def stop_time(t, speed):
    """The first time from which |speed| stays below STOP_SPEED to the end (nan: never)."""
    slow = np.abs(np.nan_to_num(speed, nan=np.inf)) < STOP_SPEED
    if not slow[-1]:
        return math.nan
    fast = np.nonzero(~slow)[0]
    return float(t[fast[-1] + 1]) if len(fast) else float(t[0])


def load_result(job, n_grains):
    r = Result(job.paper, job.dx, job.outdir, job.source)
    if campaign.read_run_summary(job, r) is None:
        return r
    mon = campaign.read_run_monitors(job.outdir)
    if mon is None or "front" not in mon or "fixed_particles" not in mon:
        return r
    r.t = np.asarray(mon["t"], float)
    front = np.asarray(mon["front"], float)
    r.speed = front_speed(r.t, front)
    r.fixed = np.asarray(mon["fixed_particles"], float) / n_grains
    r.front = float(front[-1])
    r.t_stop = stop_time(r.t, r.speed)
    return r


def fixed_at(r, t):
    if r.t is None or t > r.t[-1] + T_TOL:
        return math.nan
    return float(r.fixed[np.argmin(np.abs(r.t - t))])


def table(results, t_end):
    head = ["run", "scheme", "status", "steps", "wall s", "front m", "run-out", "speed end mm/s", "stops at s",
            "stops at T"] + [f"fixed {t:g} s" for t in FIXED_AT] + ["fixed end"]
    rows = []
    for r in results:
        v = r.paper
        speed_end = r.speed[-1] * 1e3 if r.speed is not None else math.nan
        rows.append([v.name, v.label, campaign.status_cell(r, t_end, T_TOL), fmt(r.steps, ",.0f"), fmt(r.wall, ".0f"),
                     fmt(r.front, ".3f"), fmt((r.front - H0) / H0, ".2f"), fmt(speed_end, ".2f"), fmt(r.t_stop, ".2f"),
                     fmt(r.t_stop / T_SCALE, ".1f")] + [fmt(fixed_at(r, t), ".2f") for t in FIXED_AT]
                    + [fmt(r.fixed[-1] if r.fixed is not None else math.nan, ".2f")])
    widths = [max(len(str(x)) for x in col) for col in zip(head, *rows)]
    for row in [head] + rows:
        print("  ".join(str(x).rjust(w) for x, w in zip(row, widths)))
    return head, rows


def plot(path, results):
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for r in results:
        if r.t is None:
            continue
        ax1.semilogy(r.t / T_SCALE, np.maximum(np.abs(r.speed), 1e-6), label=r.paper.label)
        ax2.plot(r.t / T_SCALE, r.fixed, label=r.paper.label)
    ax1.axhline(STOP_SPEED, color="k", lw=0.8, ls="--")
    ax1.set_ylabel("front speed [m/s]")
    ax2.set_ylabel("fraction of grains held fixed")
    ax2.set_xlabel(f"t / sqrt(H0 / g)   (sqrt(H0 / g) = {T_SCALE:.3f} s)")
    ax1.legend()
    ax1.set_title("Dry column collapse, H0 = r0 = 0.2 m")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


OPTIONS = campaign.CaseOptions(
    description="Granular column collapse: the limiting viscosity against the implicit viscous step without it.",
    runs="1,2,3", known=tuple(VARIANTS), dx=0.01, out="column", case="column_collapse.json", t_end="1.5 s",
    dx_help="particle spacing [m] (default 0.01: 400 grains)", set_example="parameters.mu_thr=200000",
    sphera=(), progress=120.0, twin_help="not used by this script")


def run(argv=None, prog=PROG):
    args = campaign.parse_args(prog, OPTIONS, argv)
    if args.twin is not None or args.sphera:
        raise mt.ToolError("--twin and --sphera are not used by this script")
    runs = campaign.parse_runs(args.runs, "--runs", VARIANTS, "1,2")
    s = campaign.settings(args, prog, OPTIONS, len(runs))
    jobs = []
    for k in runs:
        v = VARIANTS[k]
        own = [("numerics.viscosity", v.viscosity), ("parameters.mu0", v.mu0)]
        head = {"run": v.run, "dx": args.dx, "viscosity": v.viscosity, "mu0": v.mu0}
        tail = {"sets": [list(x) for x in s.extra]} if s.extra else None
        jobs.append(campaign.make_job(s, v, f"run {k}", args.dx, f"run{k}_dx{args.dx:g}", own + list(s.extra),
                                      head, tail))
    failed = campaign.run(s, jobs, STAMP, STAMP_KEYS, T_TOL, what=f" at dx = {args.dx:g} m")
    n_grains = round(H0 * H0 / (args.dx * args.dx))
    results = [load_result(job, n_grains) for job in jobs]
    print()
    head, rows = table(results, s.t_end)
    csv_path = os.path.join(s.out, "column_table.csv")
    png_path = os.path.join(s.out, "column_collapse.png")
    with open(csv_path, "w") as f:
        for row in [head] + rows:
            f.write(",".join(str(x) for x in row) + "\n")
    plot(png_path, results)
    print(f"\ntable: {show(csv_path)}\nplot:  {show(png_path)}")
    campaign.check_failed(failed)


def main(argv=None, prog=PROG):
    """The script; argv None: sys.argv; prog: how its help and its messages name it."""
    campaign.main(prog, lambda: run(argv, prog))


if __name__ == "__main__":
    main()
