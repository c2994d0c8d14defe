#!/usr/bin/env python3
"""Erosive dam break: compare ensembles of runs, so that a difference between two schemes can be
told from the drift of one scheme's runs under a perturbation of round-off size.

    python tools/erosive_ensemble.py --group NAME RUN_DIR... --group NAME RUN_DIR... [--at 0.5]
                                     [--out DIR]
    mixsph-validate erosive-ensemble ...   (the same, installed by ./tools/do setup)

Each RUN_DIR is a finished run folder of tools/erosive_dambreak.py (OUT/run<k>_dx<D>, with its
erosive_run.json, summary.json, interface profile and snapshot at ``--at``). The members of a
group are the same run with a perturbation far below any physical or numerical error (e.g.
``--set gravity=9.81``, ``9.81001``, ... : 1 part in 10^6); the first group is the reference.

Why: at t = 0.5 s the plunging wave of this case amplifies differences of round-off size, so two
runs of one scheme that differ by 1 part in 10^6 in gravity end 0.5-13 % apart at the interface
(docs/validation/erosive_dambreak.md, "Noise floor"). A single run of another scheme against a
single reference run then measures that drift as much as the scheme. With an ensemble per scheme:

- **within** a group: the interface error (the paper's measure, erosive_dambreak.interface_error:
  mean over the 0.01 m bins with centre x <= 0.25 m of |z - z_ref| / z_ref * 100) of every ordered
  pair of its members, mean and largest: the floor;
- **between** a group and the reference group: every member against every reference member;
- **mean profiles**: the interface error of the group's mean profile (the bin-wise mean over its
  members, where every member has the bin) against the reference group's. Two means of N members
  drawn from one scheme differ by about the within-pair distance / sqrt(N) (independent members),
  the floor of this row.

Both interface measures of tools/erosive_dambreak.py: the top grain (profile monitor
``interface``) and f = 0.5 (the 0.5 iso-line of the sediment fraction, from the snapshot). Also
per group: the bed-load rise at the left wall (mean and range), the steps and the wall time.

Prints the table and writes OUT/erosive_ensemble.csv (default OUT: the current folder) and
OUT/erosive_ensemble.png: per measure, each group's mean interface and the band between its
members' lowest and highest (bins where every member has a value), and their difference.

Exit status: 0 ok; 2 bad usage or input (a folder that is not a finished run, a group of one
member, runs of different dx or case).
"""

import argparse
import itertools
import json
import math
import os
import sys

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after choosing the backend)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mixsph_tools as mt  # noqa: E402
from mixsph_tools import campaign, fmt, show  # noqa: E402
import erosive_dambreak as ed  # noqa: E402

PROG = "erosive_ensemble.py"


class Member:
    """One finished run: its profiles at the comparison time and its summary's measures."""

    def __init__(self, run_dir, at):
        stamp_path = os.path.join(run_dir, ed.STAMP)
        summary_path = os.path.join(run_dir, "summary.json")
        for p in (stamp_path, summary_path):
            if not os.path.isfile(p):
                raise mt.ToolError(f"{show(run_dir)}: no {os.path.basename(p)} (not a finished run of "
                                   "tools/erosive_dambreak.py)")
        with open(stamp_path) as f:
            stamp = json.load(f)
        summ = mt.read_summary(summary_path)
        if summ.get("status") != "ok":
            raise mt.ToolError(f"{show(run_dir)}: run status '{summ.get('status')}', not ok")
        self.dir = run_dir
        self.dx = float(stamp["dx"])
        self.case = stamp["case"]
        self.steps = float(summ.get("steps") or math.nan)
        self.wall = mt.run_wall_time(summ)
        self.rise = mt.summary_value(summ, "bedload_rise_left_wall", "max")
        self.top = mt.find_profile(run_dir, "interface", at)
        if self.top is None:
            raise mt.ToolError(f"{show(run_dir)}: no interface profile at t = {at:g} s")
        self.frac = ed.fraction_interface(run_dir, at, self.dx, sediment_index(self.case))
        if self.frac is None:
            raise mt.ToolError(f"{show(run_dir)}: no snapshot at t = {at:g} s")


def sediment_index(case_path):
    """The index of the medium 'sediment' in the case file's order (the library's numbering)."""
    with open(case_path) as f:
        media = list(json.load(f).get("media", {}))
    if "sediment" not in media:
        raise mt.ToolError(f"{show(case_path)}: no medium 'sediment'")
    return media.index("sediment")


def mean_profile(profiles):
    """The bin-wise mean of profiles on the same bins; nan where any member has no value."""
    z = np.vstack([p.z for p in profiles])
    base = profiles[0]
    for p in profiles[1:]:
        if len(p.x) != len(base.x) or not np.allclose(p.x, base.x):
            raise mt.ToolError(f"{show(p.path)}: other bins than {show(base.path)}")
    return mt.Profile(base.path, base.name + " (mean)", base.t, base.t_requested, base.x,
                      np.where(np.all(np.isfinite(z), axis=0), z.mean(axis=0), math.nan))


def pair_errors(pairs, measure):
    """Interface errors (%) of (run, reference) member pairs by the profile attribute ``measure``."""
    out = [ed.interface_error(getattr(a, measure), getattr(b, measure))[0] for a, b in pairs]
    return [e for e in out if math.isfinite(e)]


def stats(errors):
    return (float(np.mean(errors)), float(np.max(errors))) if errors else (math.nan, math.nan)


def compare(groups):
    """Rows of the comparison: per group its floor and, for the groups after the first, the
    distance to the first (member pairs and mean profiles)."""
    ref_name, ref = groups[0]
    rows = []
    for name, members in groups:
        within = list(itertools.permutations(members, 2))
        row = {"group": name, "members": len(members), "dx": members[0].dx,
               "rise_mean": float(np.mean([m.rise for m in members])),
               "rise_min": min(m.rise for m in members), "rise_max": max(m.rise for m in members),
               "steps_mean": float(np.mean([m.steps for m in members])),
               "wall_mean": float(np.mean([m.wall for m in members]))}
        for measure in ("top", "frac"):
            row[f"within_{measure}_mean"], row[f"within_{measure}_max"] = stats(pair_errors(within, measure))
            if name == ref_name:
                row[f"between_{measure}_mean"] = row[f"between_{measure}_max"] = math.nan
                row[f"means_{measure}"] = math.nan
            else:
                between = list(itertools.product(members, ref))
                row[f"between_{measure}_mean"], row[f"between_{measure}_max"] = stats(pair_errors(between, measure))
                row[f"means_{measure}"] = ed.interface_error(mean_profile([getattr(m, measure) for m in members]),
                                                             mean_profile([getattr(m, measure) for m in ref]))[0]
            row[f"means_floor_{measure}"] = row[f"within_{measure}_mean"] / math.sqrt(len(members))
        rows.append(row)
    return rows


def print_rows(rows, ref_name, at):
    print(f"interface error [%] at t = {at:g} s (top grain / f = 0.5), reference group: {ref_name}")
    head = (f"{'group':<12} {'n':>2} {'within: mean (max)':>26} {'vs ' + ref_name + ': mean (max)':>28} "
            f"{'mean profiles':>15} {'floor of means':>15} {'rise [m] mean (range)':>24} {'steps':>9} {'wall s':>7}")
    print(head)

    def pair(r, key):
        return (f"{fmt(r[key + '_top_mean'], '.1f')} ({fmt(r[key + '_top_max'], '.1f')}) / "
                f"{fmt(r[key + '_frac_mean'], '.1f')} ({fmt(r[key + '_frac_max'], '.1f')})")

    for r in rows:
        is_ref = r["group"] == ref_name
        means = "-" if is_ref else f"{fmt(r['means_top'], '.1f')} / {fmt(r['means_frac'], '.1f')}"
        floor = f"{fmt(r['means_floor_top'], '.1f')} / {fmt(r['means_floor_frac'], '.1f')}"
        rise = f"{fmt(r['rise_mean'], '.3f')} ({fmt(r['rise_min'], '.3f')}-{fmt(r['rise_max'], '.3f')})"
        print(f"{r['group']:<12} {r['members']:>2} {pair(r, 'within'):>26} "
              f"{'(reference)' if is_ref else pair(r, 'between'):>28} {means:>15} {floor:>15} {rise:>24} "
              f"{fmt(r['steps_mean'], ',.0f'):>9} {fmt(r['wall_mean'], '.0f'):>7}")


def plot(path, groups, at):
    fig, axes = plt.subplots(2, 2, figsize=(12, 7), sharex=True, constrained_layout=True,
                             gridspec_kw={"height_ratios": [3, 1.4]})
    ref_name, ref = groups[0]
    for col, (measure, title) in enumerate((("top", "top grain"), ("frac", "f = 0.5 (sediment fraction)"))):
        ax, dax = axes[0][col], axes[1][col]
        ref_mean = mean_profile([getattr(m, measure) for m in ref])
        for k, (name, members) in enumerate(groups):
            z = np.vstack([getattr(m, measure).z for m in members])
            ok = np.all(np.isfinite(z), axis=0) & (members[0].top.x <= ed.PLOT_X_MAX)
            x = getattr(members[0], measure).x
            mean = mean_profile([getattr(m, measure) for m in members])
            ax.fill_between(x[ok], z[:, ok].min(axis=0), z[:, ok].max(axis=0), color=f"C{k}", alpha=0.25, lw=0)
            ax.plot(x[ok], mean.z[ok], "-", color=f"C{k}", lw=1.6, label=f"{name}: mean of {len(members)}, "
                    "band = members' range")
            if k:
                d = mean.z - ref_mean.z
                good = np.isfinite(d) & (x <= ed.PLOT_X_MAX)
                dax.plot(x[good], 100 * d[good] / ref_mean.z[good], ".-", color=f"C{k}", label=f"{name} - {ref_name}")
        ax.axvline(ed.ERR_X_MAX, color="0.6", lw=0.8, ls=":")
        ax.set_ylabel("interface z [m]")
        ax.set_title(f"interface at t = {at:g} s, {title}")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
        dax.axhline(0, color="0.5", lw=0.8)
        dax.axvline(ed.ERR_X_MAX, color="0.6", lw=0.8, ls=":")
        dax.set_xlabel("x [m] (the error is over x <= 0.25 m, dotted)")
        dax.set_ylabel("mean - reference mean [%]")
        dax.grid(True, alpha=0.3)
        dax.legend(fontsize=8)
    dx = groups[0][1][0].dx
    fig.suptitle(f"Erosive dam break, dx = {dx:g} m: ensembles of runs perturbed at round-off size")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def parse_args(argv):
    ap = argparse.ArgumentParser(prog=PROG, description="Compare ensembles of erosive dam break runs "
                                 "(docs/validation/erosive_dambreak.md).")
    ap.add_argument("--group", nargs="+", action="append", required=True, metavar=("NAME", "RUN_DIR"),
                    help="a group's name and its member run folders (at least 2); the first group is the reference")
    ap.add_argument("--at", type=float, default=ed.PAPER_T_END, help="comparison time [s] (default 0.5)")
    ap.add_argument("--out", default=".", help="folder of erosive_ensemble.csv (default: the current one)")
    args = ap.parse_args(argv)
    for g in args.group:
        if len(g) < 3:
            ap.error(f"--group {g[0]}: needs at least 2 run folders (got {len(g) - 1})")
    names = [g[0] for g in args.group]
    if len(set(names)) != len(names):
        ap.error("--group: two groups have the same name")
    return args


def run(argv=None):
    args = parse_args(argv)
    groups = [(g[0], [Member(d, args.at) for d in g[1:]]) for g in args.group]
    members = [m for _, ms in groups for m in ms]
    if len({m.dx for m in members}) > 1 or len({m.case for m in members}) > 1:
        raise mt.ToolError("the runs differ in dx or case: "
                           + ", ".join(sorted({f'dx {m.dx:g} {show(m.case)}' for m in members})))
    rows = compare(groups)
    print_rows(rows, groups[0][0], args.at)
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, "erosive_ensemble.csv")
    mt.write_csv(path, list(rows[0]), [[r[k] for k in rows[0]] for r in rows])
    png = os.path.join(args.out, "erosive_ensemble.png")
    plot(png, groups, args.at)
    print(f"table: {show(path)}")
    print(f"plot:  {show(png)}")


def main(argv=None, prog=PROG):
    campaign.main(prog, lambda: run(argv))


if __name__ == "__main__":
    main()
