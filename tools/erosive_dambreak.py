#!/usr/bin/env python3
"""Erosive dam break: run the mixture-model runs of Manenti et al. (2018), Section 3.1, Tables 1-2,
and compare them with the paper.

    python tools/erosive_dambreak.py [--runs 2,5,6,7] [--dx 0.01] [--out out/erosive]
                                     [--threads N] [--jobs J] [--reuse] [--checkpoint-every S]
                                     [--mixsph build/mixsph] [--case cases/erosive_dambreak.json]
                                     [--t-end T] [--at 0.5] [--set KEY=VALUE]... [--sphera]
                                     [--twin REL]
    mixsph-validate erosive ...      (the same, installed by ./tools/do setup)

Each selected run k is ``mixsph run CASE --out OUT/run<k>_dx<D> --set numerics.dx=D --set
media.sediment.mu_thr=... --set media.sediment.mu0=... --threads N --quiet`` (stdout and stderr in
OUT/run<k>_dx<D>/mixsph.log). The paper's runs (viscosities in kPa s; the case takes Pa s):

    run  mu_thr  mu0    paper elapsed s  aver. err. %   reference
    1    10      10.7   12,478           5.97           Run 4
    2    20      20.7   24,224           4.97           Run 4 (and the reference of Runs 5-7)
    3    40      40.7   44,777           4.92           Run 4
    4    80      80.7   77,299           (reference)    -
    5    20      15     19,163           5.4            Run 2
    6    20      5      7,089            5.7            Run 2
    7    mu1 = 5 (mu_thr = 5 kPa s, mu0 = 1e12 Pa s, i.e. no limit)   7,098   -   Run 2

``--jobs J`` runs up to J runs at once, each with max(1, cores // J) threads unless ``--threads``
is given. ``--reuse`` keeps a run whose summary.json says "ok" for the same t_end (and the same
settings, recorded in OUT/run<k>_dx<D>/erosive_run.json) and continues an unfinished one (killed,
stopped, cut off with its session) from the checkpoint it left: every run writes
OUT/run<k>_dx<D>/checkpoint.h5 every ``--checkpoint-every`` seconds of wall time (default 600), so
the paper's dx = 0.005, hours per run, can be done in pieces. ``--t-end T`` shortens every run (for
tests: the profiles at t = 0.5 s then do not exist and the columns that need them say n/a).

Printed table, one row per run, ours beside the paper's:

- wall time of the run (summary.json ``run_wall_time_s``: over all its pieces when it was
  continued from checkpoints) and the paper's total elapsed time;
- saving versus the reference run, 100 (1 - wall / wall_ref), ours and the paper's (Run 6 vs
  Run 2: 71 %; Run 2 vs Run 4: 69 %), and ours by steps, 100 (1 - steps / steps_ref), which
  does not depend on the machine's load (a step costs the same in every run of one resolution);
- interface error versus the reference run, ours and the paper's "aver. err.": the mean, over the
  0.01 m bins of the interface profile (top of the sediment, i.e. the mixture-water interface) at
  t = 0.5 s with bin centre x <= 0.25 m (near the left corner, where the paper compares), of
  |z_run - z_ref| / z_ref * 100, bins empty in either run left out. The reference is Run 4 for
  Runs 1-3 and Run 2 for Runs 5-7, as in the paper; it must be among --runs (with --reuse an
  earlier run of it costs nothing), else the cell says "n/a (reference not run)";
- the same error with the interface taken as the 0.5 iso-line of the sediment fraction (column
  "f=0.5"; from the CSV snapshot at that time, so grains lifted above the bed do not count);
- the maximum rise of the bed load at the left wall (summary ``bedload_rise_left_wall`` max: top
  of the sediment within x < 0.02 m, over the run) and its time, paper ~0.3 m;
- the peak left-wall pressure (summary ``left_wall_pressure`` max) and its time, paper ~10 kPa;
- the time the water reaches the left wall: first monitor sample (monitors.csv, every 0.005 s)
  with ``water_front`` < 0.02 m, paper ~0.29 s.

``--twin REL`` (e.g. 1e-6) also runs each selected reference run (2, 4) again with gravity
multiplied by (1 + REL) into OUT/run<k>_dx<D>_twin, a row "<k> twin" compared with run k itself:
a change far below any physical or numerical error, so its interface error is how far two runs of
the same model drift apart by t = 0.5 s in this splashing flow - the floor under the errors of the
other runs against that reference (CSV column ``twin`` = 1).

Writes OUT/erosive_table.csv (the same, one row per run) and OUT/erosive_profiles.png: the
interface (solid) and the free surface (dashed) at t = 0.5 s of every run for 0 <= x <= 0.5 m,
like the paper's Figs 3 (Runs 1-4) and 4 (Runs 2, 5-7).

Exit status: 0 ok; 1 a mixsph run failed (the others still run, unless mixsph reported bad
usage or input, and the table is still printed); 2 bad usage or input; 130 interrupted.

The current result, the method and the commands that reproduce it:
docs/validation/erosive_dambreak.md; the model and the paper's equations cited here by number:
docs/model.md; the case file's keys: docs/cases.md. The campaign itself (options, runs, --reuse)
is tools/mixsph_tools/campaign.py.

Reference: S. Manenti, A. Amicarelli, S. Todeschini (2018), WCSPH with limiting viscosity for
modeling landslide hazard at the slopes of artificial reservoir, Water 10(4), 515.
"""

import dataclasses
import math
import os
import sys
from dataclasses import dataclass, field

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after choosing the backend)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mixsph_tools as mt  # noqa: E402
from mixsph_tools import campaign  # noqa: E402
from mixsph_tools import fmt, num, show  # noqa: E402

PROG = "erosive_dambreak.py"

KPA = 1e3  # Pa s per kPa s, Pa per kPa


@dataclass(frozen=True)
class PaperRun:
    run: int
    mu_thr: float         # [Pa s] passed to the case
    mu0: float            # [Pa s]
    elapsed_s: float      # paper's total elapsed time [s]
    err_percent: float    # paper's aver. err. [%] (nan: none)
    ref: int              # reference run of the comparison (0: none, this is a reference)
    label_thr: str        # how the table shows mu_thr, mu0 [kPa s]
    label_mu0: str
    twin: bool = False    # --twin: this run again with gravity x (1 + REL), compared with itself

    @property
    def name(self):
        return f"{self.run} twin" if self.twin else str(self.run)


PAPER = {
    1: PaperRun(1, 10e3, 10.7e3, 12478, 5.97, 4, "10", "10.7"),
    2: PaperRun(2, 20e3, 20.7e3, 24224, 4.97, 4, "20", "20.7"),
    3: PaperRun(3, 40e3, 40.7e3, 44777, 4.92, 4, "40", "40.7"),
    4: PaperRun(4, 80e3, 80.7e3, 77299, math.nan, 0, "80", "80.7"),
    5: PaperRun(5, 20e3, 15e3, 19163, 5.4, 2, "20", "15"),
    6: PaperRun(6, 20e3, 5e3, 7089, 5.7, 2, "20", "5"),
    7: PaperRun(7, 5e3, 1e12, 7098, math.nan, 2, "mu1=5", "off"),
}
REFERENCE_RUNS = sorted({p.ref for p in PAPER.values() if p.ref})   # [2, 4]: what --twin repeats
PAPER_DX = 0.005           # [m] the paper's resolution
PAPER_T_END = 0.5          # [s] the paper's runs (and its comparison time)
PAPER_BEDLOAD_RISE = 0.3   # [m] max rise of the bed-load layer at the left wall (converged runs)
PAPER_PEAK_P_KPA = 10.0    # [kPa] peak pressure on the left wall
PAPER_T_IMPACT = 0.29      # [s] plunging wave hits the left wall
ERR_X_MAX = 0.25           # [m] interface error over bins with centre x <= this
WALL_REACH_X = 0.02        # [m] water "at the left wall" when water_front < this
PLOT_X_MAX = 0.5           # [m]
TABLE1 = (1, 2, 3, 4)      # paper Fig. 3
TABLE2 = (2, 5, 6, 7)      # paper Fig. 4
T_TOL = 1e-3               # [s] a summary's simulated time matches t_end within this
# --sphera: the numerical options of SPHERA's own input for this geometry (SPHERA v9.0.0,
# input/release_v_9_0_0/14_edb_2D_demo: partial pressure smoothing TetaP = 0.25 and, in its
# bed-load block, velocity_fixed_bed = 0.0125 m/s with erosion flag 1). Not part of the model as
# docs/model.md states it; passed to every run as --set overrides before the user's own.
SPHERA_OPTIONS = (("numerics.pressure_smoothing", 0.25), ("numerics.fixed_bed_speed", 0.0125))


def warn(msg):
    print(f"{PROG}: warning: {msg}", file=sys.stderr)


# ---- runs and their results ----------------------------------------------------------------------


STAMP = "erosive_run.json"
STAMP_KEYS = ("run", "dx", "mu_thr", "mu0", "t_end", "case", "case_sha256", "sets")   # "sets" only with --set


@dataclass
class Result(campaign.RunResult):
    """A run's result: the campaign's fields, the case's measures and the comparison cells."""
    rise: float = math.nan
    rise_t: float = math.nan
    p_peak: float = math.nan     # [Pa]
    p_peak_t: float = math.nan
    t_wall: float = math.nan     # water reaches the left wall [s]
    interface: mt.Profile = None
    interface_frac: mt.Profile = None   # 0.5 iso-line of the sediment fraction, from the snapshot
    free_surface: mt.Profile = None
    cells: dict = field(default_factory=dict)   # computed comparison cells


def load_result(job, at, dx, sediment):
    r = Result(job.paper, job.dx, job.outdir, job.source)
    summ = campaign.read_run_summary(job, r)
    if summ is None:
        return r
    r.rise = mt.summary_value(summ, "bedload_rise_left_wall", "max")
    r.rise_t = mt.summary_value(summ, "bedload_rise_left_wall", "t_max")
    r.p_peak = mt.summary_value(summ, "left_wall_pressure", "max")
    r.p_peak_t = mt.summary_value(summ, "left_wall_pressure", "t_max")
    mon = campaign.read_run_monitors(job.outdir)
    if mon is not None and "water_front" in mon:
        r.t_wall = mt.first_time_below(mon["t"], mon["water_front"], WALL_REACH_X)
    elif mon is not None:
        warn(f"{show(os.path.join(job.outdir, 'monitors.csv'))}: no column 'water_front'")
    r.interface = mt.find_profile(job.outdir, "interface", at)
    r.free_surface = mt.find_profile(job.outdir, "free_surface", at)
    r.interface_frac = fraction_interface(job.outdir, at, dx, sediment)
    return r


def fraction_interface(outdir, at, dx, sediment, h_over_dx=1.3, bin_width=0.01, x_max=0.5):
    """The mixture-water interface at time ``at`` as the 0.5 iso-line of the sediment fraction:
    along the vertical through each bin centre, from the floor up, the first height where the
    Shepard (kernel-weighted) fraction of sediment particles among the non-wall particles falls
    below 0.5 (linear between samples dx/8 apart; cubic-spline kernel, h = 1.3 dx, as in the
    library). Unlike the top-most particle of the profile monitor, a few grains lifted above
    the bed do not count. From the CSV snapshot taken at ``at`` (within 1e-3 s); None without it."""
    snap = mt.nearest_snapshot(outdir, at)
    if snap is None or abs(snap[0] - at) > 1e-3:
        return None
    t_snap, d = mt.read_snapshot(snap[1])
    keep = (d["state"] != mt.STATE_WALL) & (d["state"] != mt.STATE_LOST)
    x, z, sed = d["x"][keep], d["z"][keep], (d["medium"][keep] == sediment).astype(float)
    h = h_over_dx * dx
    xs = np.arange(0.5 * bin_width, x_max, bin_width)
    zs = np.arange(0.0, float(np.max(z, initial=0.0)) + 2 * h, dx / 8)
    out = np.full(len(xs), math.nan)
    for k, xb in enumerate(xs):
        near = np.abs(x - xb) < 2 * h
        q = np.hypot(x[near][None, :] - xb, z[near][None, :] - zs[:, None]) / h
        w = np.where(q < 1, 1 - 1.5 * q ** 2 + 0.75 * q ** 3, np.where(q < 2, 0.25 * (2 - q) ** 3, 0.0))
        den = w.sum(axis=1)
        f = np.where(den > 0, (w * sed[near][None, :]).sum(axis=1) / np.where(den > 0, den, 1.0), 0.0)
        low = np.nonzero(f < 0.5)[0]
        if len(low) == 0:
            continue
        j = low[0]
        out[k] = zs[0] if j == 0 else zs[j - 1] + (f[j - 1] - 0.5) / (f[j - 1] - f[j]) * (zs[j] - zs[j - 1])
    return mt.Profile(snap[1], "interface_fraction", t_snap, at, xs, out)


def interface_error(run_prof, ref_prof, x_max=ERR_X_MAX):
    """(mean |z - z_ref| / z_ref * 100 over the common finite bins with x <= x_max, bins used)."""
    ref = {round(x, 9): z for x, z in zip(ref_prof.x, ref_prof.z)}
    errs = []
    for x, z in zip(run_prof.x, run_prof.z):
        zr = ref.get(round(x, 9))
        if x <= x_max + 1e-12 and zr is not None and math.isfinite(z) and math.isfinite(zr) and zr > 0:
            errs.append(abs(z - zr) / zr * 100.0)
    return (float(np.mean(errs)), len(errs)) if errs else (math.nan, 0)



def reference_cells(c):
    """The comparison cells of a reference run (Run 4): nothing to compare with."""
    c["ref"] = "-"
    c["saving"] = c["err"] = "(reference)"
    c["paper_saving"] = c["paper_err"] = "(ref)"
    c["err_frac"] = "(reference)"
    c["saving_steps"] = "(reference)"
    c.update(saving_v=math.nan, saving_steps_v=math.nan, paper_saving_v=math.nan, err_v=math.nan, err_bins=0,
             err_frac_v=math.nan)


def measured_cells(c, r, ref, at):
    """The savings and interface errors of r against its finished reference run ref."""
    if math.isfinite(r.wall) and math.isfinite(ref.wall) and ref.wall > 0:
        c["saving_v"] = 100.0 * (1.0 - r.wall / ref.wall)
        c["saving"] = f"{c['saving_v']:.0f}"
    else:
        c["saving"] = "n/a"
    if math.isfinite(r.steps) and math.isfinite(ref.steps) and ref.steps > 0:
        c["saving_steps_v"] = 100.0 * (1.0 - r.steps / ref.steps)
        c["saving_steps"] = f"{c['saving_steps_v']:.0f}"
    if r.interface is None:
        c["err"] = f"n/a (no profile at t={at:g} s)"
    elif ref.interface is None:
        c["err"] = f"n/a (ref. has no profile at t={at:g} s)"
    else:
        e, n = interface_error(r.interface, ref.interface)
        c["err_v"], c["err_bins"] = e, n
        c["err"] = f"{e:.2f}" if n else "n/a (no common bins)"
    if r.interface_frac is not None and ref.interface_frac is not None:
        e, n = interface_error(r.interface_frac, ref.interface_frac)
        c["err_frac_v"] = e
        c["err_frac"] = f"{e:.2f}" if n else "n/a"


def compare(results, at):
    """Fill r.cells: saving and interface error versus the reference run, with the reason when n/a."""
    by_run = {r.paper.run: r for r in results if not r.paper.twin}
    for r in results:
        p, c = r.paper, r.cells
        if p.ref == 0:
            reference_cells(c)
            continue
        c["ref"] = str(p.ref)
        c["paper_saving_v"] = 100.0 * (1.0 - p.elapsed_s / PAPER[p.ref].elapsed_s)
        c["paper_saving"] = fmt(c["paper_saving_v"], ".0f", "-")
        c["paper_err"] = fmt(p.err_percent, ".2f", "-")
        c["saving_v"] = c["saving_steps_v"] = c["err_v"] = c["err_frac_v"] = math.nan
        c["saving_steps"] = "n/a"
        c["err_bins"] = 0
        c["err_frac"] = "n/a"
        ref = by_run.get(p.ref)
        if not r.ok:
            c["saving"] = c["err"] = "n/a (run failed)" if r.status not in ("not run", "missing") else "n/a"
        elif ref is None or ref.status == "not run":
            c["saving"] = c["err"] = "n/a (reference not run)"
        elif not ref.ok:
            c["saving"] = c["err"] = "n/a (reference failed)"
        else:
            measured_cells(c, r, ref, at)


# ---- table ----------------------------------------------------------------------------------------


def table_columns(at):
    err = f"interface err [%], t={at:g} s"
    return [
        ("", "run", ">"), ("", "mu_thr", ">"), ("", "mu0", ">"), ("", "status", "<"),
        ("wall time [s]", "mixsph", ">"), ("wall time [s]", "paper", ">"),
        ("saving vs ref [%]", "ref", ">"), ("saving vs ref [%]", "mixsph", ">"), ("saving vs ref [%]", "steps", ">"),
        ("saving vs ref [%]", "paper", ">"), (err, "mixsph", ">"), (err, "f=0.5", ">"), (err, "paper", ">"),
        ("bed-load rise, wall", "max [m]", ">"), ("bed-load rise, wall", "t [s]", ">"),
        ("peak p, left wall", "[kPa]", ">"), ("peak p, left wall", "t [s]", ">"),
        ("water at wall", "t [s]", ">"), ("", "lost", ">"),
    ]


def table_row(r):
    p, c = r.paper, r.cells
    return [
        p.name, p.label_thr, p.label_mu0, campaign.status_cell(r, PAPER_T_END, T_TOL),
        fmt(r.wall, ".1f"), fmt(p.elapsed_s, ",.0f", "-"),
        c["ref"], c["saving"], c["saving_steps"], c["paper_saving"],
        c["err"], c["err_frac"], c["paper_err"],
        fmt(r.rise, ".3f"), fmt(r.rise_t, ".3f"),
        fmt(r.p_peak / KPA, ".2f"), fmt(r.p_peak_t, ".3f"),
        fmt(r.t_wall, ".3f", "not reached" if r.ok else "n/a"), fmt(r.lost, ".0f"),
    ]


def print_notes(at, twin_rel):
    """What the table's columns mean."""
    print(f"interface err: mean over the 0.01 m bins with x <= {ERR_X_MAX:g} m of |z_run - z_ref| / z_ref * 100, "
          f"z = top of the sediment at t = {at:g} s;")
    print("               reference Run 4 for Runs 1-3, Run 2 for Runs 5-7 (the paper's 'aver. err.');")
    print("               f=0.5: the same with z = 0.5 iso-line of the sediment fraction (from the snapshot at that time;")
    print("               lifted grains do not count; n/a without the snapshot).")
    print("saving:        100 (1 - wall / wall of the reference run), the paper's from its elapsed times;")
    print("               steps: 100 (1 - steps / steps of the reference run), which the machine's load does not change")
    print("               (a step costs the same in every run of one resolution).")
    print(f"bed-load rise: max over the run of the top of the sediment within x < 0.02 m "
          f"(paper: ~{PAPER_BEDLOAD_RISE:g} m for the converged runs).")
    print(f"water at wall: first monitor sample with water_front < {WALL_REACH_X:g} m "
          f"(paper: the plunging wave hits the left wall at ~{PAPER_T_IMPACT:g} s).")
    print("lost:          particles that left the case's domain and were taken out of the run (in this open tank:")
    print("               spray thrown above the domain's top); the walls' guard keeps particles from crossing a wall.")
    if twin_rel is not None:
        print(f"twin:          the reference run again with gravity x (1 + {twin_rel:g}), a perturbation far below any")
        print("               physical or numerical error, compared with the run itself: how far two runs of one model")
        print("               drift apart by t = 0.5 s in this splashing flow, the floor under the interface errors.")
    print("Run 7:         mu1 rheology, mu1 = 5 kPa s, given as mu_thr = 5 kPa s and mu0 = 1e12 Pa s (no limit).")


def table(results, at, dx, t_end, threads_note, twin_rel=None):
    paper_row = ["paper", "", "", "", "", "", "", "", "", "", "", "", "",
                 f"~{PAPER_BEDLOAD_RISE:g}", "", f"~{PAPER_PEAK_P_KPA:g}", "", f"~{PAPER_T_IMPACT:g}", ""]
    print(f"Erosive dam break, mixsph versus Manenti et al. (2018) Tables 1-2: dx = {dx:g} m "
          f"(paper {PAPER_DX:g} m), t_end = {t_end:g} s, {threads_note}")
    print("mu_thr, mu0 in kPa s; the paper's times are SPHERA v8's, on hardware it does not state")
    print()
    mt.print_table(table_columns(at), [table_row(r) for r in results], [paper_row])
    print_notes(at, twin_rel)


CSV_FIELDS = [
    "run", "mu_thr_Pa_s", "mu0_Pa_s", "dx_m", "t_end_s", "status", "source", "threads", "simulated_time_s",
    "wall_time_s", "particle_steps_per_s", "paper_elapsed_s", "ref_run", "saving_percent", "paper_saving_percent",
    "compare_time_s", "interface_err_percent", "interface_err_bins", "interface_err_fraction_percent",
    "paper_err_percent", "bedload_rise_max_m", "bedload_rise_t_s", "peak_left_wall_pressure_kPa",
    "peak_pressure_t_s", "water_at_left_wall_t_s", "outdir", "steps", "saving_steps_percent", "lost_particles",
    "twin"]


def csv_row(r, dx, t_end, at):
    p, c = r.paper, r.cells
    return [p.run, p.mu_thr, p.mu0, dx, t_end, r.status, r.source, r.threads,
            r.sim_time, r.wall, r.psteps, float(p.elapsed_s),
            p.ref if p.ref else "", c["saving_v"], c["paper_saving_v"],
            at, c["err_v"], c["err_bins"], c["err_frac_v"], p.err_percent,
            r.rise, r.rise_t, r.p_peak / KPA, r.p_peak_t, r.t_wall, r.outdir,
            int(r.steps) if math.isfinite(r.steps) else math.nan, c["saving_steps_v"], r.lost, int(p.twin)]


def write_csv(path, results, dx, t_end, at):
    mt.write_csv(path, CSV_FIELDS, [csv_row(r, dx, t_end, at) for r in results])


# ---- figure ---------------------------------------------------------------------------------------


def plot(path, results, at, dx):
    runs = sorted({r.paper.run for r in results})
    sets = []
    if any(k in runs for k in (1, 3, 4)) and any(k in runs for k in (5, 6, 7)):
        sets = [("Runs 1-4 (paper Fig. 3: threshold viscosity)", [r for r in results if r.paper.run in TABLE1]),
                ("Runs 2, 5-7 (paper Fig. 4: limiting viscosity)", [r for r in results if r.paper.run in TABLE2])]
    else:
        sets = [("Runs " + ", ".join(str(k) for k in runs), results)]
    fig, axes = plt.subplots(1, len(sets), figsize=(7.5 * len(sets), 5.2), squeeze=False, constrained_layout=True)
    any_profile = False
    for ax, (title, rs) in zip(axes[0], sets):
        ax.axhline(0.067, color="0.7", lw=0.8, ls=":", label="initial bed (0.067 m)")
        for r in rs:
            color = "0.45" if r.paper.twin else f"C{r.paper.run - 1}"
            name = f"Run {r.paper.name}"
            drew = False
            for prof, style in ((r.interface, "-"), (r.free_surface, "--")):
                if prof is None:
                    continue
                # empty bins (nan) are skipped, not drawn as gaps: at dx > bin every other bin is empty
                m = (prof.x >= 0) & (prof.x <= PLOT_X_MAX) & np.isfinite(prof.z)
                ax.plot(prof.x[m], prof.z[m], style, color=color, lw=1.6 if style == "-" else 1.2,
                        marker="." if style == "-" else None, ms=3)
                drew = True
            any_profile |= drew
            # one legend entry per run (colour); the line styles are explained once below
            ax.plot([], [], "-", color=color, label=name if drew else f"{name} (no profile at t = {at:g} s)")
        ax.plot([], [], "-", color="k", label="interface (bls), solid")
        ax.plot([], [], "--", color="k", label="free surface (fs), dashed")
        ax.set_xlim(0, PLOT_X_MAX)
        ax.set_ylim(0, 0.6)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("z [m]")
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    if not any_profile:
        ended = [r.sim_time for r in results if math.isfinite(r.sim_time)]
        why = f" (runs ended at t = {max(ended):.3g} s)" if ended else ""
        for ax in axes[0]:
            ax.text(0.5, 0.5, f"no profiles at t = {at:g} s{why}", transform=ax.transAxes, ha="center",
                    va="center", color="0.4")
    fig.suptitle(f"Erosive dam break at t = {at:g} s, dx = {dx:g} m\n"
                 f"mixture-water interface (solid), free surface (dashed)")
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ---- main -----------------------------------------------------------------------------------------


OPTIONS = campaign.CaseOptions(
    description="Erosive dam break (Manenti et al. 2018, Tables 1-2): run mixsph and compare with the paper.",
    own=(("--at", dict(type=float, default=0.5, help="time [s] of the profiles compared and plotted, one of the "
                       "case's profile times (default 0.5)")),
         ("--against", dict(metavar="DIR", help="also compare every run with the run of the same number and dx "
                            "in DIR (another campaign, e.g. the other viscous scheme): interface errors, bed-load "
                            "rise, steps, wall time; table printed and written to OUT/erosive_against.csv"))),
    runs="2,5,6,7", known=tuple(PAPER), dx=0.01, out="erosive", case="erosive_dambreak.json", t_end="0.5 s",
    dx_help="particle spacing [m] (default 0.01; the paper's is 0.005)",
    set_example="numerics.fixed_bed_speed=0.0125", sphera=SPHERA_OPTIONS, progress=300.0,
    twin_help="also run each selected reference run (2, 4) again with gravity x (1 + REL), e.g. 1e-6, into "
              "run<k>_dx<D>_twin, and compare it with itself: the floor under the interface errors")


def sediment_index(s, at):
    """The index of the case's medium 'sediment' (whose top is the interface), after checking that
    the case writes its interface profile at time ``at``."""
    case_json = s.case_json
    media = list(case_json.get("media", {})) if isinstance(case_json.get("media"), dict) else []
    if "sediment" not in media:
        raise mt.ToolError(f"{show(s.case)}: no medium 'sediment' (the interface is the top of it)")
    prof_times = [float(t) for t in case_json.get("monitors", {}).get("interface", {}).get("times", [])]
    if not any(abs(t - at) < 1e-9 for t in prof_times):
        raise mt.ToolError(f"--at {at:g}: the case's interface profile is written at t = "
                           f"{', '.join(f'{t:g}' for t in prof_times) or '(never)'} s only")
    if at > s.t_end + 1e-12:
        warn(f"the runs end at t = {s.t_end:g} s, before the profiles at t = {at:g} s: "
             "the interface errors and the plot will say n/a")
    return media.index("sediment")   # the library numbers the media in the case file's order


def plan_jobs(s, runs, dx):
    """The Jobs of the runs and, with --twin, of the twins of the reference runs among them."""
    plan = [(PAPER[k], list(s.extra)) for k in runs]
    if s.twin is not None:
        plan += [(dataclasses.replace(PAPER[k], twin=True, ref=k, elapsed_s=math.nan, err_percent=math.nan),
                  campaign.twin_sets(s)) for k in runs if k in REFERENCE_RUNS]
    jobs = []
    for p, sets in plan:
        own = [("media.sediment.mu_thr", p.mu_thr), ("media.sediment.mu0", p.mu0)]
        head = {"run": p.run, "dx": dx, "mu_thr": p.mu_thr, "mu0": p.mu0}
        tail = {"sets": [list(x) for x in sets]} if sets else None   # absent without --set and --sphera
        jobs.append(campaign.make_job(s, p, f"run {p.name}", dx, f"run{p.run}_dx{dx:g}" + ("_twin" if p.twin else ""),
                                      own + sets, head, tail))
    return jobs


def report(s, args, results, n_ran):
    """Print the comparison with the paper and write the table (CSV) and the plot."""
    compare(results, args.at)
    threads_note = f"threads {campaign.threads_used(results, s.threads)}"
    if n_ran > 1 and s.jobs > 1:
        threads_note += f", up to {s.jobs} runs at once (wall times share the machine)"
    threads_note += "".join(f"; with {k}={num(v)}" for k, v in s.extra)
    print()
    table(results, args.at, args.dx, s.t_end, threads_note, s.twin)
    if len({r.threads for r in results if r.ok}) > 1:
        warn("the runs used different thread counts: the savings compare unlike wall times")
    csv_path = os.path.join(s.out, "erosive_table.csv")
    png_path = os.path.join(s.out, "erosive_profiles.png")
    write_csv(csv_path, results, args.dx, s.t_end, args.at)
    plot(png_path, results, args.at, args.dx)
    print()
    print(f"table: {show(csv_path)}")
    print(f"plot:  {show(png_path)}")


def against(results, jobs, other_dir, at, dx, sediment, out):
    """Each finished run beside the run of the same folder name in other_dir: the interface errors
    (top grain, f = 0.5) of this run against that one, as the paper's measure against a reference,
    and their bed-load rise, steps and wall time. Printed and written to OUT/erosive_against.csv."""
    rows = []
    for r, job in zip(results, jobs):
        if r.paper.twin:
            continue
        twin_job = dataclasses.replace(job, outdir=os.path.join(other_dir, os.path.basename(job.outdir)),
                                       source="reused")
        o = load_result(twin_job, at, dx, sediment)
        row = {"run": r.paper.run, "status": r.status, "other_status": o.status, "err_top": math.nan,
               "err_frac": math.nan, "rise": r.rise, "other_rise": o.rise, "steps": r.steps, "other_steps": o.steps,
               "wall_s": r.wall, "other_wall_s": o.wall, "threads": r.threads, "other_threads": o.threads}
        if r.ok and o.ok:
            if r.interface is not None and o.interface is not None:
                row["err_top"] = interface_error(r.interface, o.interface)[0]
            if r.interface_frac is not None and o.interface_frac is not None:
                row["err_frac"] = interface_error(r.interface_frac, o.interface_frac)[0]
        rows.append(row)
    print()
    print(f"against {show(other_dir)} (the same run there is the reference of each row; t = {at:g} s):")
    print(f"{'run':>4} {'err top %':>10} {'err f=0.5 %':>12} {'rise [m]':>9} {'there':>7} {'steps':>10} "
          f"{'there':>10} {'wall s':>8} {'there':>8}")
    for w in rows:
        if w["status"] != "ok" or w["other_status"] != "ok":
            print(f"{w['run']:>4} n/a (here {w['status']}, there {w['other_status']})")
            continue
        print(f"{w['run']:>4} {fmt(w['err_top'], '.2f', 'n/a'):>10} {fmt(w['err_frac'], '.2f', 'n/a'):>12} "
              f"{fmt(w['rise'], '.3f', 'n/a'):>9} {fmt(w['other_rise'], '.3f', 'n/a'):>7} "
              f"{fmt(w['steps'], ',.0f', 'n/a'):>10} {fmt(w['other_steps'], ',.0f', 'n/a'):>10} "
              f"{fmt(w['wall_s'], '.0f', 'n/a'):>8} {fmt(w['other_wall_s'], '.0f', 'n/a'):>8}")
    path = os.path.join(out, "erosive_against.csv")
    with open(path, "w") as f:
        keys = list(rows[0]) if rows else ["run"]
        f.write(",".join(keys) + "\n")
        for w in rows:
            f.write(",".join(str(w[k]) for k in keys) + "\n")
    print(f"table: {show(path)}")


def run(argv=None, prog=PROG):
    args = campaign.parse_args(prog, OPTIONS, argv)
    runs = campaign.parse_runs(args.runs, "--runs", PAPER, "2,5,6,7")
    if args.twin is not None and not any(k in REFERENCE_RUNS for k in runs):
        raise mt.ToolError("--twin: no reference run (2 or 4) among --runs")
    s = campaign.settings(args, prog, OPTIONS, len(runs))
    sediment = sediment_index(s, args.at)
    jobs = plan_jobs(s, runs, args.dx)
    failed = campaign.run(s, jobs, STAMP, STAMP_KEYS, T_TOL, what=f" at dx = {args.dx:g} m")
    results = [load_result(job, args.at, args.dx, sediment) for job in jobs]
    report(s, args, results, sum(job.source != "reused" for job in jobs))
    if args.against:
        if not os.path.isdir(args.against):
            raise mt.ToolError(f"--against {show(args.against)}: no such folder")
        against(results, jobs, args.against, args.at, args.dx, sediment, s.out)
    campaign.check_failed(failed)


def main(argv=None, prog=PROG):
    """The script; argv None: sys.argv; prog: how its help and its messages name it."""
    campaign.main(prog, lambda: run(argv, prog))


if __name__ == "__main__":
    main()
