#!/usr/bin/env python3
"""Vajont validation: run the paper's runs V1-V6 of the Padua 1968 experiment (test No. 48) and
compare them with Manenti et al. (2018), Section 3.2, Tables 3-5 and Figs 7-10.

    python tools/vajont_validate.py [--runs 1,2,4 | all] [--dx 0.02] [--threads N] [--jobs J]
                                    [--out out/vajont] [--reuse] [--checkpoint-every S] [--t-end T]
                                    [--plot-runs 1,2,4] [--mixsph build/mixsph] [--twin REL]
                                    [--case cases/vajont_padua.json] [--set KEY=VALUE]... [--sphera]
    mixsph-validate vajont ...      (the same, installed by ./tools/do setup)

Runs are done one after the other (each with --threads N, default all cores), or up to J at once
with --jobs J (each with max(1, cores // J) threads unless --threads is given). Run k is
``mixsph run CASE --out OUT/V<k>_dx<D> --set numerics.dx=... --set parameters.<...>=...
--threads N --quiet`` (stdout and stderr in OUT/V<k>_dx<D>/mixsph.log):

    run  change from V1 (the case's default)               paper dx
    V1   -                                                 0.005
    V2   phi = 25 deg            (parameters.phi)          0.005
    V3   mu0 = 10 kPa s          (parameters.mu0)          0.005
    V4   saturated below z = 0.46 (parameters.saturated=1) 0.005
    V5   as V4, mu0 = 7.5 kPa s, dx x 1.25                 0.00625
    V6   as V4, mu0 = 10 kPa s,  dx x 1.5                  0.0075

``--dx D`` is the spacing of V1-V4; V5 and V6 keep the paper's ratios to it (1.25 D and 1.5 D), so
``--dx 0.005`` gives exactly the paper's runs. ``--set KEY=VALUE`` (repeatable) is passed to every
run after the run's own overrides (e.g. ``--set parameters.tension_cutoff=1``, ``--set
media.water.alpha_m=0.0375``): a sensitivity study of all runs at once. ``--reuse`` keeps a run whose summary.json says
"ok" for the same t_end and settings (recorded in OUT/V<k>_dx<D>/vajont_run.json) and continues an
unfinished one (killed, stopped, cut off with its session) from the checkpoint it left: every run
writes OUT/V<k>_dx<D>/checkpoint.h5 every ``--checkpoint-every`` seconds of wall time (default
600), so the paper's dx = 0.005, hours per run, can be done in pieces. Elapsed times are the
runs' ``run_wall_time_s`` (over all their pieces).

``--twin REL`` (e.g. 1e-6; V1 among --runs) also runs V1 again with gravity multiplied by
(1 + REL) into OUT/V1_dx<D>_twin, the row "V1 twin": a change far below any physical or numerical
error, so how far its maximum run-up ends from V1's is the floor under the differences between
runs at that spacing (how much the splashing run-up tongue amplifies a perturbation of round-off
size). A difference V2 - V1 or V4 - V1 no larger than that floor decides no ordering.

Run-up (the case's monitor ``run_up``, lib/src/io/monitors.c): the highest z of a water particle
centre over the opposite slope (x in [0.75, 1.81] m) among the water particles that have at least
3 water neighbours within the kernel support 2h (isolated spray does not count), sampled every
0.005 s; the maximum over the run and its time. Full scale Z = 1211.8 z + 0.3 m a.m.s.l. (the
case's ``full_scale`` map, fitted to the paper's Table 5) and the paper's error (13)
d_eta% = |Z - Z_exp| / (Z_exp - Z_still) * 100 with Z_exp = 863.0, Z_still = 700.0, i.e.
100 |z - 0.712| / 0.1345 in the lab frame.

Printed: the paper's Tables 4-5 beside ours (elapsed time, max run-up, its time, Z, d_eta%), the
steps, particles, lost particles, the mass balance (largest relative change of the total mass of
fluid and granular particles), the wall-crossing corrections, the particles found below the bed
or behind the plate in the snapshots (none should be), the largest density variation
|rho / rho0 - 1| of the snapshots (rho0: the medium's reference density, the mixture density (5)
for grains; the paper asks for <= 1 %) and whether the paper's ordering holds
(lower phi, V2, raises the run-up; saturation, V4, lowers it). Written: OUT/vajont_table.csv,
OUT/vajont_table.md and OUT/vajont_profiles.png (like the paper's Figs 7-10): per plotted run the
water surface and the landslide surface at the time of the maximum run-up (the case's profiles
``*_atmax``, rewritten at every new maximum of ``run_up``) over the bed, with the experimental
maximum run-up line, and velocity-magnitude snapshots of the first plotted run at the plate's stop
(t = 0.8 s) and at its maximum run-up (nearest snapshot, one every 0.1 s).

``--check`` tests the criterion of issue 59 (number 6) for a granular law: V1 within
``--deta-limit`` (default 10) % d_eta of the experiment, V2 above V1 and V4 below V1 (each ordering
decided, as above); V1, V2 and V4 must be among --runs. With ``--known-band LO HI`` (a known
failure, tests/known_failure.h's rule) it passes only while the criterion is not met and V1's
d_eta lies in [LO, HI] %: a regression and an improvement short of the criterion both fail it.

Exit status: 0 ok; 1 a run failed (the others still run and the table is printed), or, with
--check, the check failed; 2 bad usage or input; 130 interrupted.

The current result, the method and the commands that reproduce it: docs/validation/vajont.md; the
model and the paper's equations cited here by number: docs/model.md; the case file's keys:
docs/cases.md. The campaign itself (options, runs, --reuse) is tools/mixsph_tools/campaign.py.

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
from mixsph_tools import fmt, num  # noqa: E402

PROG = "vajont_validate.py"

EXP_RUN_UP = 0.712        # [m] lab frame, test No. 48
EXP_Z = 863.0             # [m a.m.s.l.]
STILL_LEVEL = 0.46        # [m] reservoir level of the model
PAPER_DX = 0.005          # [m]
PLATE_STOP = 0.8          # [s] the plate stops
T_TOL = 1e-3              # [s]
CASE_T_END = 1.6          # [s] the case's end time (a run that ended elsewhere says so)
# --sphera: the numerical options of SPHERA's own input for this test (SPHERA v9.0.0,
# input/release_v_9_0_0/35_2D_Vajont_experiment: partial pressure smoothing TetaP = 0.4 and, in
# its bed-load block, velocity_fixed_bed = 0 with erosion flag 1). Not part of the model as
# docs/model.md states it; passed to every run as --set overrides after the run's own, before the user's.
SPHERA_OPTIONS = (("numerics.pressure_smoothing", 0.4), ("numerics.fixed_bed_speed", 0.0))


@dataclass(frozen=True)
class PaperRun:
    run: int
    change: str
    sets: tuple           # (key, value) overrides besides numerics.dx
    dx_ratio: float       # dx of the run / dx of V1
    elapsed_s: float      # paper's elapsed time (16 cores, 2.3 GHz) [s]
    run_up: float         # [m]
    t_run_up: float       # [s]
    Z: float              # [m a.m.s.l.]
    d_eta: float          # [%]
    twin: bool = False    # --twin: V1 again with gravity x (1 + REL), compared with V1

    @property
    def label(self):
        return f"V{self.run} twin" if self.twin else f"V{self.run}"


PAPER = {
    1: PaperRun(1, "reference", (), 1.0, 21395, 0.718, 1.35, 870.3, 5),
    2: PaperRun(2, "phi = 25 deg", (("parameters.phi", 25.0),), 1.0, 22705, 0.733, 1.35, 888.5, 16),
    3: PaperRun(3, "mu0 = 10 kPa s", (("parameters.mu0", 10e3),), 1.0, 43814, 0.708, 1.35, 858.2, 3),
    4: PaperRun(4, "saturated", (("parameters.saturated", 1),), 1.0, 21738, 0.701, 1.35, 849.7, 8),
    5: PaperRun(5, "V4, mu0 = 7.5 kPa s, dx x1.25", (("parameters.saturated", 1), ("parameters.mu0", 7.5e3)), 1.25,
                14476, 0.702, 1.35, 850.9, 7),
    6: PaperRun(6, "V4, mu0 = 10 kPa s, dx x1.5", (("parameters.saturated", 1), ("parameters.mu0", 10e3)), 1.5,
                9334, 0.699, 1.35, 847.3, 9),
}


D_ETA_RANGE = 0.1345      # [m] (Z_exp - Z_still) / 1211.8: the lab-frame run-up of 100 % of (13)


def d_eta(z):
    """The paper's error (13) in the lab frame [%]."""
    return 100.0 * abs(z - EXP_RUN_UP) / D_ETA_RANGE if math.isfinite(z) else math.nan


def d_eta_scale_mm():
    """Millimetres of lab-frame run-up per 1 % of the error (13)."""
    return D_ETA_RANGE * 1e3 / 100.0


# ---- runs and their results ----------------------------------------------------------------------


STAMP = "vajont_run.json"
STAMP_KEYS = ("run", "dx", "sets", "t_end", "case", "case_sha256")


@dataclass
class Result(campaign.RunResult):
    """A run's result: the campaign's fields (steps counted as an int), the run-up, the checks."""
    steps: int = 0
    particles: int = 0
    run_up: float = math.nan
    t_run_up: float = math.nan
    Z: float = math.nan
    d_eta: float = math.nan
    mass_drift: float = math.nan      # max |m - m0| / m0
    wall_corr: float = math.nan
    front_max: float = math.nan
    vmax_stop: float = math.nan       # max speed around the plate's stop [m/s]
    drho: float = math.nan            # max |rho / rho0 - 1| of mobile particles over the snapshots
    drho_t: float = math.nan          # its time [s]
    drho99: float = math.nan          # max over the snapshots of the 99th percentile of |rho / rho0 - 1|
    crossed: int = -1                 # most particles found below the bed or behind the plate in a snapshot
    tension: float = math.nan         # largest fraction of the grains with a negative pressure in a snapshot
    tension_t: float = math.nan       # its time [s]
    profiles: dict = field(default_factory=dict)   # name -> mt.Profile at the max run-up


PROFILE_NAMES = ("water_surface", "landslide_surface_above", "landslide_surface_below")


def reference_densities(case_json, sets):
    """rho0 [kg/m3] per medium index: fluids rho, granular media the mixture density (5)
    (saturated n rho_f + (1 - n) rho_s, dry (1 - n) rho_s), "$parameters" resolved with the run's
    overrides."""
    params = dict(case_json.get("parameters", {}))
    for key, val in sets:
        if key.startswith("parameters."):
            params[key.split(".", 1)[1]] = val

    def val(v):
        if isinstance(v, str) and v.startswith("$"):
            return params.get(v[1:], math.nan)
        return float(v) if isinstance(v, (int, float)) else math.nan

    media = case_json.get("media", {})
    rho = []
    for m in media.values():
        if m.get("type") == "granular":
            n, rs = val(m.get("porosity")), val(m.get("rho"))
            sat = val(m.get("saturated", False)) if not isinstance(m.get("saturated"), bool) else float(m["saturated"])
            rf = val(media.get(m.get("pore_fluid"), {}).get("rho", math.nan)) if sat else 0.0
            rho.append(n * rf + (1 - n) * rs)
        else:
            rho.append(val(m.get("rho")))
    return np.array(rho)


def read_snapshots(outdir):
    """[(t, snapshot)] of every snapshot in outdir, in time order, read once for all the checks."""
    return [(t, mt.read_snapshot(path)[1]) for t, path in mt.list_snapshots(outdir)]


def density_variation(snaps, rho0):
    """(max |rho / rho0 - 1| of the mobile particles over the snapshots [(t, snapshot)], its
    time, the largest 99th percentile of |rho / rho0 - 1| over the snapshots)."""
    best, t_best, p99 = math.nan, math.nan, math.nan
    if rho0.size == 0 or not np.all(np.isfinite(rho0)):
        return best, t_best, p99
    for t, snap in snaps:
        live = snap["state"] <= mt.STATE_FIXED
        med = snap["medium"][live].astype(int)
        if med.size == 0 or med.max() >= rho0.size:
            continue
        dev = np.abs(snap["rho"][live] / rho0[med] - 1.0)
        d = float(np.max(dev))
        if not math.isfinite(best) or d > best:
            best, t_best = d, t
        q = float(np.percentile(dev, 99))
        p99 = q if not math.isfinite(p99) else max(p99, q)
    return best, t_best, p99


def granular_media(case_json):
    """Indices (the case's order) of its granular media."""
    return [k for k, m in enumerate(case_json.get("media", {}).values())
            if isinstance(m, dict) and m.get("type") == "granular"]


def grains_in_tension(snaps, granular):
    """(largest fraction, over the snapshots [(t, snapshot)] after t = 0, of the grains (the particles of the
    media indices in granular, mobile or fixed) whose pressure is negative, its time). Their
    effective stress, max(p - p_w, 0), is then zero and so is their frictional viscosity (10):
    a grain in tension flows with the pore fluid's viscosity alone."""
    best, t_best = math.nan, math.nan
    if not granular:
        return best, t_best
    for t, snap in snaps:
        if not t > 0:
            continue
        grain = (snap["state"] <= mt.STATE_FIXED) & np.isin(snap["medium"].astype(int), granular)
        if not grain.any():
            continue
        f = float(np.mean(snap["p"][grain] < 0.0))
        if not math.isfinite(best) or f > best:
            best, t_best = f, t
    return best, t_best


CROSS_TOL = 1e-6  # [m] the CSV snapshots' 7 significant digits move a position by up to ~5e-7 m


def crossed_walls(outdir, bed, plate_index, dx, snaps=None):
    """Most fluid and granular particles, over the snapshots, whose centre lies below the bed
    polyline (0 <= x <= its end) or behind the plate's face (x < face, within its z span; the face
    is half a spacing ahead of the plate's first layer of wall particles), by more than CROSS_TOL
    (a particle the crossing guard put back sits 0.1 dx in front of the wall; one on the line
    may read as below it after the CSV's rounding). -1 without snapshots. snaps: the snapshots
    as read_snapshots(outdir) gives them, when already read."""
    worst = -1
    for _, snap in (read_snapshots(outdir) if snaps is None else snaps):
        live = snap["state"] <= mt.STATE_FIXED
        x, z = snap["x"][live], snap["z"][live]
        n = 0
        if bed is not None:
            inside = (x >= bed[0, 0]) & (x <= bed[-1, 0])
            n += int(np.sum(inside & (z < np.interp(x, bed[:, 0], bed[:, 1]) - CROSS_TOL)))
        if plate_index is not None:
            pw = (snap["state"] == mt.STATE_WALL) & (snap["medium"] == plate_index)
            if pw.any():
                face = snap["x"][pw].max() + 0.5 * dx
                n += int(np.sum((x < face - CROSS_TOL) & (z > snap["z"][pw].min()) & (z < snap["z"][pw].max())))
        worst = max(worst, n)
    return worst


def load_result(job, rho0=None, walls=None, granular=()):
    """The Result of a job's run folder; rho0 (reference_densities), walls ((bed polyline, index of
    the plate wall)) and granular (granular_media) for the checks on its snapshots."""
    r = Result(job.paper, job.dx, job.outdir, job.source)
    s = campaign.read_run_summary(job, r)
    if s is None:
        return r
    r.particles = int(s.get("particles") or 0)
    r.steps = int(s.get("steps") or 0)
    r.run_up = mt.summary_value(s, "run_up", "max")
    r.t_run_up = mt.summary_value(s, "run_up", "t_max")
    r.Z = mt.summary_value(s, "run_up_Z", "max")
    r.d_eta = mt.summary_value(s, "run_up_d_eta", "final")
    if not math.isfinite(r.d_eta):
        r.d_eta = d_eta(r.run_up)
    r.wall_corr = mt.summary_value(s, "wall_corrections", "final")
    r.front_max = mt.summary_value(s, "landslide_front", "max")
    mon = campaign.read_run_monitors(job.outdir)
    if mon is not None:
        m = mon.get("mass")
        if m is not None and m.size and m[0] > 0:
            r.mass_drift = float(np.nanmax(np.abs(m - m[0])) / m[0])
        v = mon.get("max_speed")
        sel = (mon["t"] >= PLATE_STOP - 0.1) & (mon["t"] <= PLATE_STOP + 0.1)
        if v is not None and sel.any():
            r.vmax_stop = float(np.nanmax(v[sel]))
    snaps = read_snapshots(job.outdir)
    if rho0 is not None:
        r.drho, r.drho_t, r.drho99 = density_variation(snaps, rho0)
    r.tension, r.tension_t = grains_in_tension(snaps, list(granular))
    if walls is not None:
        r.crossed = crossed_walls(job.outdir, walls[0], walls[1], job.dx, snaps)
    for name in PROFILE_NAMES:
        path = os.path.join(job.outdir, f"profile_{name}_atmax.csv")
        if os.path.isfile(path):
            r.profiles[name] = mt.read_profile(path)
    return r


def load_results(case_json, jobs):
    """The Results of the jobs, checked against the case's bed, plate and media."""
    wall_defs = case_json.get("walls", {})
    bed = wall_defs.get("bed", {}).get("polyline")
    bed = np.array(bed, dtype=float) if bed else None
    plate = list(wall_defs).index("plate") if "plate" in wall_defs else None
    granular = granular_media(case_json)
    return [load_result(job, reference_densities(case_json, job.stamp["sets"]), (bed, plate), granular)
            for job in jobs]


# ---- table ----------------------------------------------------------------------------------------


COLUMNS = [("", name, align) for name, align in (
    ("run", "<"), ("change", "<"), ("status", "<"), ("dx [m]", ">"), ("particles", ">"), ("steps", ">"),
    ("wall s", ">"), ("paper s", ">"), ("run-up [m]", ">"), ("paper", ">"), ("t [s]", ">"), ("paper ", ">"),
    ("Z [m asl]", ">"), ("paper  ", ">"), ("d_eta %", ">"), ("paper   ", ">"), ("lost", ">"), ("mass drift", ">"),
)]


def rows_of(results):
    rows = []
    for r in results:
        p = r.paper
        paper = fmt if not p.twin else (lambda v, spec: "-")   # a twin has no paper values
        rows.append([
            p.label, p.change, campaign.status_cell(r, CASE_T_END, T_TOL), fmt(r.dx, "g"),
            str(r.particles) if r.particles else "n/a",
            str(r.steps) if r.steps else "n/a", fmt(r.wall, ".0f"), paper(p.elapsed_s, ",.0f"),
            fmt(r.run_up, ".3f"), paper(p.run_up, ".3f"), fmt(r.t_run_up, ".2f"), paper(p.t_run_up, ".2f"),
            fmt(r.Z, ".1f"), paper(p.Z, ".1f"), fmt(r.d_eta, ".1f"), paper(p.d_eta, "g"),
            fmt(r.lost, ".0f"), fmt(r.mass_drift, ".1e"),
        ])
    rows.append(["exp.", "test No. 48", "", "", "", "", "", "", f"{EXP_RUN_UP:.3f}", "", "", "",
                 f"{EXP_Z:.1f}", "", "", "", "", ""])
    return rows


def print_table(rows):
    mt.print_table(COLUMNS, rows[:-1], rows[-1:])


ORDER_TOL = 0.001  # [m] run-up differences below this are no ordering (paper's: 15 and 17 mm)


def twin_floor(results):
    """|run-up of V1 twin - run-up of V1| [m], when both finished (else nan): the floor under
    the differences between runs (--twin)."""
    ok = {r.paper.twin: r for r in results if r.ok and r.paper.run == 1 and math.isfinite(r.run_up)}
    return abs(ok[True].run_up - ok[False].run_up) if len(ok) == 2 else math.nan


def ordering(results):
    """The paper's ordering: V2 (lower phi) above V1, V4 (saturated) below V1. Each check is
    (what, verdict, detail), verdict True (holds), False (does not) or None (undecided: the two
    run-ups differ by less than ORDER_TOL, or, with a V1 twin, by no more than the twin's floor)."""
    by = {r.paper.run: r for r in results if r.ok and math.isfinite(r.run_up) and not r.paper.twin}
    floor = twin_floor(results)
    note = f"; twin floor {floor * 1000:.1f} mm" if math.isfinite(floor) else ""
    out = []

    def verdict(d, sign):
        return None if abs(d) < ORDER_TOL or abs(d) <= floor else d * sign > 0   # (nan <= : False)

    if 1 in by and 2 in by:
        d = by[2].run_up - by[1].run_up
        out.append(("lower phi (V2) raises the run-up", verdict(d, +1),
                    f"V2 - V1 = {d * 1000:+.1f} mm (paper +15 mm){note}"))
    if 1 in by and 4 in by:
        d = by[4].run_up - by[1].run_up
        out.append(("saturation (V4) lowers the run-up", verdict(d, -1),
                    f"V4 - V1 = {d * 1000:+.1f} mm (paper -17 mm){note}"))
    return out


def criterion_check(results, deta_limit, known_band):
    """(passed, message) of --check: issue 59's criterion 6 (V1 within deta_limit % d_eta, V2 above
    V1, V4 below V1) met, or, with known_band (lo, hi), not met with V1's d_eta in [lo, hi] %."""
    by = {r.paper.run: r for r in results if r.ok and math.isfinite(r.run_up) and not r.paper.twin}
    missing = [f"V{k}" for k in (1, 2, 4) if k not in by]
    if missing:
        return False, f"--check: {', '.join(missing)}: not finished, or not among --runs"
    deta = by[1].d_eta
    holds = dict((what, verdict) for what, verdict, _ in ordering(results))
    met = deta <= deta_limit and all(v is True for v in holds.values())
    what = (f"V1 d_eta {deta:.1f} % (limit {deta_limit:g} %), V2 - V1 "
            f"{(by[2].run_up - by[1].run_up) * 1000:+.1f} mm, V4 - V1 {(by[4].run_up - by[1].run_up) * 1000:+.1f} mm")
    if known_band is None:
        return met, f"criterion 6 {'met' if met else 'NOT met'}: {what}"
    lo, hi = known_band
    if met:
        return False, f"known failure: the criterion is met now ({what}): make --check a plain check"
    if not lo <= deta <= hi:
        return False, (f"known failure: V1 d_eta {deta:.1f} % outside today's band [{lo:g}, {hi:g}] % and the "
                       f"criterion still not met ({what}): a regression, or measure the band again")
    return True, f"known failure, in today's band [{lo:g}, {hi:g}] %: {what}"


def verdict_text(holds):
    if holds is None:
        return (f"undecided, the run-ups differ by less than {ORDER_TOL * 1000:g} mm or by no more than the "
                "V1 twin's floor")
    return "holds" if holds else "does NOT hold"



CSV_FIELDS = [
    "run", "change", "dx_m", "status", "source", "threads", "particles", "steps", "simulated_time_s", "wall_time_s",
    "particle_steps_per_s", "paper_elapsed_s", "run_up_m", "paper_run_up_m", "t_run_up_s", "paper_t_run_up_s",
    "Z_m_asl", "paper_Z_m_asl", "d_eta_percent", "paper_d_eta_percent", "lost_particles", "mass_drift",
    "wall_corrections", "landslide_front_max_m", "max_speed_at_plate_stop", "max_density_variation",
    "max_density_variation_t_s", "density_variation_p99", "crossed_walls", "grains_in_tension",
    "grains_in_tension_t_s", "outdir", "twin"]


def write_csv(path, results):
    mt.write_csv(path, CSV_FIELDS, [[
        f"V{r.paper.run}", r.paper.change, r.dx, r.status, r.source, r.threads, r.particles, r.steps, r.sim_time,
        r.wall, r.psteps, float(r.paper.elapsed_s), r.run_up, r.paper.run_up, r.t_run_up, r.paper.t_run_up, r.Z,
        r.paper.Z, r.d_eta, float(r.paper.d_eta), r.lost, r.mass_drift, r.wall_corr, r.front_max, r.vmax_stop,
        r.drho, r.drho_t, r.drho99, r.crossed, r.tension, r.tension_t, r.outdir, int(r.paper.twin)]
        for r in results])


def write_md(path, results, header_lines, checks):
    with open(path, "w") as f:
        for line in header_lines:
            f.write(line + "\n\n")
        f.write("\n".join(mt.markdown_table(COLUMNS, rows_of(results))) + "\n")
        if checks:
            f.write("\n")
            for what, holds, detail in checks:
                f.write(f"- {what}: {verdict_text(holds)} ({detail})\n")


# ---- figure ---------------------------------------------------------------------------------------


BED = np.array([[0.0, 0.28], [0.66, 0.22], [0.72, 0.0], [0.75, 0.0], [1.02, 0.46], [1.81, 0.878]])


def landslide_top(r):
    """Top of the landslide per x bin: the higher of its dry (above) and wet (below) parts."""
    a, b = r.profiles.get("landslide_surface_above"), r.profiles.get("landslide_surface_below")
    if a is None and b is None:
        return None
    if a is None or b is None:
        p = a or b
        return p.x, p.z
    with np.errstate(invalid="ignore"):
        z = np.fmax(a.z, b.z)
    return a.x, z


def bed_at(x):
    return np.interp(x, BED[:, 0], BED[:, 1])


def draw_profiles(ax, r):
    ax.fill_between(BED[:, 0], BED[:, 1], -0.05, color="0.85", lw=0)
    ax.plot(BED[:, 0], BED[:, 1], color="0.3", lw=1.2)
    ax.axhline(EXP_RUN_UP, color="r", ls="--", lw=1.0, label=f"experiment: max run-up {EXP_RUN_UP} m")
    ax.axhline(STILL_LEVEL, color="0.5", ls=":", lw=0.8, label=f"still water {STILL_LEVEL} m")
    ls = landslide_top(r)
    if ls is not None:
        x, z = ls
        m = np.isfinite(z)
        ax.fill_between(x[m], bed_at(x[m]), z[m], color="tan", alpha=0.7, step="mid", lw=0)
        ax.plot(x[m], z[m], ".-", color="saddlebrown", ms=2, lw=1.2, label="landslide surface")
    w = r.profiles.get("water_surface")
    if w is not None:
        m = np.isfinite(w.z)
        if ls is not None and ls[0].shape == w.x.shape:
            # a bin whose highest water lies below the landslide surface holds only water trapped
            # under or inside the landslide: not the free surface
            with np.errstate(invalid="ignore"):
                m &= ~(np.isfinite(ls[1]) & (w.z < ls[1]))
        ax.plot(w.x[m], w.z[m], ".-", color="tab:blue", ms=2, lw=1.2, label="water surface")
    t = next((p.t for p in r.profiles.values()), math.nan)
    ax.plot([], [], " ", label=f"max run-up {fmt(r.run_up, '.3f')} m (d_eta {fmt(r.d_eta, '.1f')} %)")
    ax.set_title(f"V{r.paper.run} ({r.paper.change}), dx = {r.dx:g} m, t = {fmt(t, '.3f')} s (max run-up)",
                 fontsize=9)
    ax.set_xlim(-0.05, 1.85)
    ax.set_ylim(-0.05, 1.0)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=7)


def draw_snapshot(fig, ax, r, t_want, label, granular):
    near = mt.nearest_snapshot(r.outdir, t_want)
    if near is None:
        ax.text(0.5, 0.5, "no snapshots", transform=ax.transAxes, ha="center")
        return
    t, s = mt.read_snapshot(near[1])
    wall = s["state"] == mt.STATE_WALL
    live = s["state"] <= mt.STATE_FIXED
    fixed = s["state"] == mt.STATE_FIXED
    ax.scatter(s["x"][wall], s["z"][wall], s=1, c="0.6", lw=0)
    speed = np.hypot(s["vx"], s["vz"])
    size = max(1.0, 4.0 * (r.dx / 0.01) ** 2)
    sc = ax.scatter(s["x"][live], s["z"][live], s=size, c=speed[live], cmap="jet", vmin=0.0, vmax=1.2, lw=0)
    if fixed.any():
        ax.scatter(s["x"][fixed], s["z"][fixed], s=size, facecolors="none", edgecolors="k", lw=0.3)
    # the landslide surface: top of the granular particles per x bin of 2 dx
    gr = live & np.isin(s["medium"], granular)
    if gr.any():
        b = np.floor(s["x"][gr] / (2 * r.dx)).astype(int)
        tops = {}
        for k, z in zip(b, s["z"][gr]):
            tops[k] = max(tops.get(k, -np.inf), z)
        ks = sorted(tops)
        ax.plot([(k + 0.5) * 2 * r.dx for k in ks], [tops[k] + 0.5 * r.dx for k in ks], "k-", lw=1.0,
                label="landslide surface")
        ax.legend(loc="upper left", fontsize=7)
    ax.axhline(EXP_RUN_UP, color="r", ls="--", lw=0.8)
    ax.set_title(f"V{r.paper.run}: |u| at t = {t:.2f} s ({label}); black rings: fixed grains", fontsize=9)
    ax.set_xlim(-0.1, 1.85)
    ax.set_ylim(-0.08, 1.0)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    fig.colorbar(sc, ax=ax, label="|u| [m/s]", shrink=0.8)


def plot(path, results, plot_runs, granular):
    shown = [r for r in results if r.paper.run in plot_runs and r.profiles and not r.paper.twin]
    first = next((r for r in results if r.paper.run in plot_runs and r.ok and not r.paper.twin), None)
    n = len(shown) + (2 if first else 0)
    if n == 0:
        return False
    fig, axes = plt.subplots(n, 1, figsize=(9, 4.0 * n), squeeze=False, constrained_layout=True)
    axes = axes[:, 0]
    for ax, r in zip(axes, shown):
        draw_profiles(ax, r)
    if first:
        draw_snapshot(fig, axes[len(shown)], first, PLATE_STOP, "the plate stops", granular)
        draw_snapshot(fig, axes[len(shown) + 1], first, first.t_run_up, "nearest snapshot to the max run-up",
                      granular)
    fig.suptitle("Vajont, Padua 1968 test No. 48: profiles at the maximum run-up (paper Figs 7-9) "
                 "and velocity magnitude (Fig. 10)", fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True



# ---- main -----------------------------------------------------------------------------------------


OPTIONS = campaign.CaseOptions(
    description="Vajont (Manenti et al. 2018, Section 3.2): run V1-V6 with mixsph and compare with the paper's "
                "Tables 4-5.",
    own=(("--plot-runs", dict(default="1,2,4", help="runs whose profiles are plotted (default 1,2,4)")),
         ("--check", dict(action="store_true", help="exit status 1 unless issue 59's criterion 6 holds (V1 within "
                          "--deta-limit %% d_eta, V2 above V1, V4 below V1; runs 1,2,4)")),
         ("--deta-limit", dict(type=float, default=10.0, help="--check: V1's largest d_eta [%%] (default 10)")),
         ("--known-band", dict(type=float, nargs=2, metavar=("LO", "HI"),
                               help="--check of a known failure: passes only while the criterion is not met and "
                                    "V1's d_eta [%%] is in [LO, HI]"))),
    runs="all", known=tuple(PAPER), dx=0.02, out="vajont", case="vajont_padua.json", t_end="1.6 s",
    dx_help="particle spacing of V1-V4 [m] (default 0.02; the paper's is 0.005; V5, V6: x1.25, x1.5)",
    set_example="parameters.tension_cutoff=1", sphera=SPHERA_OPTIONS, progress=60.0,
    twin_help="also run V1 again with gravity x (1 + REL), e.g. 1e-6, into V1_dx<D>_twin, and compare it with V1: "
              "the floor under the differences between runs")


def plan_jobs(s, runs, dx):
    """The Jobs of the runs (V5, V6 at their ratios to dx) and, with --twin, of V1's twin."""
    plan = [(PAPER[k], list(PAPER[k].sets) + s.extra) for k in runs]
    if s.twin is not None:
        nan = math.nan
        plan.append((dataclasses.replace(PAPER[1], twin=True, change=f"V1, gravity x (1 + {s.twin:g})",
                                         elapsed_s=nan, run_up=nan, t_run_up=nan, Z=nan, d_eta=nan),
                     list(PAPER[1].sets) + campaign.twin_sets(s)))
    jobs = []
    for p, sets in plan:
        d = round(dx * p.dx_ratio, 12)
        head = {"run": p.run, "twin": p.twin, "dx": d, "sets": [list(x) for x in sets]}
        jobs.append(campaign.make_job(s, p, p.label, d, f"V{p.run}_dx{d:g}" + ("_twin" if p.twin else ""), sets,
                                      head))
    return jobs


def print_runs(results):
    """One line per finished run: its run-up beside the paper's (a twin's beside V1's)."""
    by_run = {r.paper.run: r for r in results if r.ok and not r.paper.twin}
    for r in results:
        if r.ok and r.paper.twin:
            v1 = by_run.get(1)
            diff = (f"{(r.run_up - v1.run_up) * 1000:+.1f} mm and {r.t_run_up - v1.t_run_up:+.3f} s from V1's"
                    if v1 else "V1 not finished")
            print(f"{r.paper.label}: max run-up {fmt(r.run_up, '.3f')} m at t = {fmt(r.t_run_up, '.3f')} s, "
                  f"{diff} (the floor under the differences between runs at dx = {r.dx:g} m); wall time "
                  f"{fmt(r.wall, '.0f')} s on {r.threads} thread(s)")
        elif r.ok:
            p = r.paper
            print(f"V{p.run}: max run-up {fmt(r.run_up, '.3f')} m at t = {fmt(r.t_run_up, '.3f')} s, "
                  f"Z = {fmt(r.Z, '.1f')} m a.m.s.l., d_eta = {fmt(r.d_eta, '.1f')} % at dx = {r.dx:g} m "
                  f"(paper V{p.run}: {p.run_up:.3f} m at {p.t_run_up:.2f} s, Z = {p.Z:.1f}, d_eta {p.d_eta:g} %; "
                  f"experiment {EXP_RUN_UP} m); wall time {fmt(r.wall, '.0f')} s on {r.threads} thread(s)")


def print_stability(results):
    print("stability (plate starts at t = 0, stops at t = 0.8 s):")
    for r in results:
        if r.status in ("not run", "missing", "no summary"):
            continue
        crossed = str(r.crossed) if r.crossed >= 0 else "n/a (no snapshots)"
        print(f"  {r.paper.label}: status {r.status}, lost particles {fmt(r.lost, '.0f')}, particles below the bed "
              f"or behind the plate (most in a snapshot) {crossed}, mass drift "
              f"{fmt(r.mass_drift, '.1e')}, wall-crossing corrections {fmt(r.wall_corr, '.0f')}, "
              f"max speed over t = 0.7-0.9 s {fmt(r.vmax_stop, '.2f')} m/s, max |rho/rho0 - 1| over the "
              f"snapshots {fmt(100 * r.drho, '.2f')} % (t = {fmt(r.drho_t, '.1f')} s; 99th percentile <= "
              f"{fmt(100 * r.drho99, '.2f')} %), grains with p < 0 (most in a snapshot) "
              f"{fmt(100 * r.tension, '.1f')} % (t = {fmt(r.tension_t, '.1f')} s), landslide front max "
              f"{fmt(r.front_max, '.3f')} m")


def report(s, dx, results, plot_runs):
    """Print the comparison with the paper and write the table (CSV, Markdown) and the plot."""
    head = (f"Vajont (Padua 1968, test No. 48), mixsph versus Manenti et al. (2018) Tables 4-5: V1-V4 at dx = "
            f"{dx:g} m (paper {PAPER_DX:g} m), t_end = {s.t_end:g} s, threads "
            f"{campaign.threads_used(results, s.threads)}; paper: SPHERA on 16 cores at 2.3 GHz"
            + "".join(f"; with {k}={num(v)}" for k, v in s.extra))
    print(f"\n{head}\n")
    print_table(rows_of(results))
    print("run-up: highest water particle centre (>= 3 water neighbours within 2h) over the opposite slope, "
          "x in [0.75, 1.81] m, every 0.005 s;")
    print("        Z = 1211.8 z + 0.3 m a.m.s.l.; d_eta% = |Z - 863.0| / (863.0 - 700.0) * 100 "
          "(= 100 |z - 0.712| / 0.1345), the paper's error (13).")
    print("lost: particles that left the domain; mass drift: max |M(t) - M(0)| / M(0) of the fluid and granular "
          "particles.")
    print()
    print_runs(results)
    checks = ordering(results)
    if checks:
        print()
        for what, holds, detail in checks:
            print(f"ordering: {what}: {verdict_text(holds)} ({detail})")
    print()
    print_stability(results)
    csv_path, md_path, png_path = (os.path.join(s.out, n) for n in ("vajont_table.csv", "vajont_table.md",
                                                                     "vajont_profiles.png"))
    write_csv(csv_path, results)
    write_md(md_path, results, [head], checks)
    drew = plot(png_path, results, plot_runs, granular_media(s.case_json))
    print()
    print(f"table: {mt.show(csv_path)}, {mt.show(md_path)}")
    print(f"plot:  {mt.show(png_path)}" if drew else "plot:  none (no profiles of the plotted runs)")


def run(argv=None, prog=PROG):
    args = campaign.parse_args(prog, OPTIONS, argv)
    runs = campaign.parse_runs(args.runs, "--runs", PAPER, "1,2,4", prefix="V")
    plot_runs = campaign.parse_runs(args.plot_runs, "--plot-runs", PAPER, "1,2,4", prefix="V")
    if args.twin is not None and 1 not in runs:
        raise mt.ToolError("--twin: V1, the run it repeats, is not among --runs")
    if args.known_band and not args.check:
        raise mt.ToolError("--known-band: only with --check")
    s = campaign.settings(args, prog, OPTIONS, len(runs))
    jobs = plan_jobs(s, runs, args.dx)
    failed = campaign.run(s, jobs, STAMP, STAMP_KEYS, T_TOL)
    results = load_results(s.case_json, jobs)
    report(s, args.dx, results, plot_runs)
    campaign.check_failed(failed)
    if args.check:
        passed, message = criterion_check(results, args.deta_limit, args.known_band)
        print(f"check: {message}")
        if not passed:
            raise mt.ToolError(f"check failed: {message}", code=1)


def main(argv=None, prog=PROG):
    """The script; argv None: sys.argv; prog: how its help and its messages name it."""
    campaign.main(prog, lambda: run(argv, prog))


if __name__ == "__main__":
    main()
