"""Reports of a sweep (PNG + CSV), from its results table.

- runup_vs_level.png: the run-up of every scenario against the reservoir level, with the
  median and the 5-95 % band over the other sampled parameters in each level bin;
- exceedance.png: the exceedance probability P(run-up > z) over the scenarios (each scenario
  weighted equally, i.e. over the sampled parameter distributions; for a grid: over its
  points), with the given elevation (e.g. a dam crest) marked and its probability;
- scenario_table.png and scenario_table.csv: the scenarios with their parameters, run-up, its
  time, full-scale elevation, wall time and status (the PNG shows the first rows).
"""

from __future__ import annotations

import math
import os

import numpy as np
import pandas as pd

from .scenarios import ID

META = {"error", "worker_pid", "unzip_count", "host", "run_id", "submitted_at", "finished_at",
        "series"}


def varied_params(df: pd.DataFrame) -> list[str]:
    """Columns (other than outputs we know of) that take more than one value."""
    skip = META | {"status", "wall_time_s", "cpu_time_s", "stop_time", "max_run_up", "max_run_up_Z",
                   "time_of_max_run_up", "run_up", "landslide_front", "kinetic_energy",
                   "fixed_particles", "dt", "lost_particles", "steps", ID}
    return [c for c in df.columns if c not in skip and df[c].nunique(dropna=True) > 1]


def pick_runup(df: pd.DataFrame, prefer: str | None = None) -> tuple[str, str]:
    """(column, label) of the run-up to report: full scale if the FMU gives it (finite)."""
    if prefer:
        if prefer not in df.columns:
            raise ValueError(f"no column {prefer!r} in the results")
        return prefer, prefer
    if "max_run_up_Z" in df.columns and np.isfinite(pd.to_numeric(df["max_run_up_Z"], errors="coerce")).any():
        return "max_run_up_Z", "max run-up Z [m a.m.s.l.]"
    if "max_run_up" in df.columns:
        return "max_run_up", "max run-up z [m, model]"
    raise ValueError("the results have no max_run_up column (give --y)")


def exceedance(values: np.ndarray, z: float) -> tuple[float, int, int]:
    """(fraction of values > z, count above, count)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return math.nan, 0, 0
    above = int((v > z).sum())
    return above / v.size, above, int(v.size)


def make_report(df: pd.DataFrame, out_dir: str, crest: float | None = None, x: str = "reservoir_level",
                y: str | None = None, max_table_rows: int = 40, title: str = "") -> dict:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(out_dir, exist_ok=True)
    info: dict = {"files": []}
    ok = df[df["status"] == "ok"].copy() if "status" in df.columns else df.copy()
    info["n_ok"], info["n_failed"] = len(ok), len(df) - len(ok)

    # ---- the scenario table ----------------------------------------------------------------
    cols = [c for c in df.columns if c not in META or c == "error"]
    table = df[cols].copy()
    csv_path = os.path.join(out_dir, "scenario_table.csv")
    table.to_csv(csv_path, index=False)
    info["files"].append(csv_path)
    # the PNG: the parameters that vary between scenarios, the run-up results and the status
    outs = [c for c in ("max_run_up", "time_of_max_run_up", "max_run_up_Z", "wall_time_s", "status")
            if c in df.columns]
    pretty = [ID] + [c for c in varied_params(df) if c not in outs] + outs
    sub = table[pretty].head(max_table_rows)
    cells = [[_fmt(v) for v in r] for r in sub.itertuples(index=False)]
    fig_h = 0.6 + 0.25 * (len(cells) + 1)
    fig, ax = plt.subplots(figsize=(max(8, 1.25 * len(pretty)), fig_h))
    ax.axis("off")
    if cells:
        t = ax.table(cellText=cells, colLabels=pretty, loc="upper center", cellLoc="right")
        t.auto_set_font_size(False)
        t.set_fontsize(7)
        t.scale(1, 1.1)
        t.auto_set_column_width(list(range(len(pretty))))
    note = f"{len(df)} scenarios ({info['n_ok']} ok, {info['n_failed']} failed)"
    if len(df) > max_table_rows:
        note += f"; first {max_table_rows} shown, all in scenario_table.csv"
    ax.set_title((title + ": " if title else "") + note, fontsize=9)
    p = os.path.join(out_dir, "scenario_table.png")
    fig.savefig(p, dpi=130, bbox_inches="tight")
    plt.close(fig)
    info["files"].append(p)

    if ok.empty:
        return info
    ycol, ylabel = pick_runup(ok, y)
    yv = pd.to_numeric(ok[ycol], errors="coerce").to_numpy(dtype=float)

    # ---- run-up versus reservoir level -----------------------------------------------------
    if x in ok.columns:
        xv = pd.to_numeric(ok[x], errors="coerce").to_numpy(dtype=float)
        fig, ax = plt.subplots(figsize=(7, 4.5))
        # colour the points by the other parameter that varies most (the spread's main source)
        others = [c for c in ok.columns if c not in META and c not in (ID, x, ycol, "status")
                  and c in varied_params(ok)]
        if others:
            cname = max(others, key=lambda c: ok[c].nunique())
            sc = ax.scatter(xv, yv, s=16, alpha=0.8, c=pd.to_numeric(ok[cname], errors="coerce"),
                            cmap="viridis", label="scenarios", zorder=3)
            fig.colorbar(sc, ax=ax, label=cname)
        else:
            ax.scatter(xv, yv, s=16, alpha=0.8, label="scenarios", zorder=3)
        levels = np.unique(xv[np.isfinite(xv)])
        if len(levels) <= max(1, len(xv) // 2):   # a grid of levels: one group per level
            centres = levels
            groups = [yv[xv == lv] for lv in levels]
        else:   # sampled levels: quantile bins
            nb = min(10, max(2, len(xv) // 4))
            edges = np.unique(np.nanquantile(xv, np.linspace(0, 1, nb + 1)))
            idx = np.clip(np.searchsorted(edges, xv, side="right") - 1, 0, len(edges) - 2)
            centres = np.array([np.nanmean(xv[idx == i]) for i in range(len(edges) - 1)])
            groups = [yv[idx == i] for i in range(len(edges) - 1)]
        med = np.array([np.nanmedian(g) if len(g) else np.nan for g in groups])
        lo = np.array([np.nanquantile(g, 0.05) if len(g) else np.nan for g in groups])
        hi = np.array([np.nanquantile(g, 0.95) if len(g) else np.nan for g in groups])
        ax.plot(centres, med, "-o", color="C3", label="median")
        if any(len(g) > 1 for g in groups):
            ax.fill_between(centres, lo, hi, color="C3", alpha=0.2,
                            label="5-95 % over the other parameters")
        if crest is not None:
            ax.axhline(crest, color="k", ls="--", lw=1, label=f"elevation {crest:g}")
        ax.set_xlabel(x)
        ax.set_ylabel(ylabel)
        ax.set_title((title + ": " if title else "") + f"run-up vs {x} ({len(ok)} scenarios)", fontsize=10)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        p = os.path.join(out_dir, "runup_vs_level.png")
        fig.savefig(p, dpi=130, bbox_inches="tight")
        plt.close(fig)
        info["files"].append(p)
        info["runup_vs_level"] = pd.DataFrame({x: centres, "median": med, "p05": lo, "p95": hi})

    # ---- exceedance probability ------------------------------------------------------------
    v = np.sort(yv[np.isfinite(yv)])
    if v.size:
        fig, ax = plt.subplots(figsize=(7, 4.5))
        # empirical P(Y > z): 1 below the smallest value, (n-1-i)/n from v_i on, 0 from the largest
        xs = np.concatenate([[v[0] - 0.02 * (v[-1] - v[0] + 1e-9)], v])
        ps = np.concatenate([[1.0], (v.size - 1 - np.arange(v.size)) / v.size])
        ax.step(xs, ps, where="post", label="P(run-up > z)")
        if crest is not None:
            pc, na, n = exceedance(v, crest)
            info["crest"] = crest
            info["p_exceed"] = pc
            info["n_exceed"] = na
            ax.axvline(crest, color="k", ls="--", lw=1)
            ax.annotate(f"P(> {crest:g}) = {pc:.2f} ({na}/{n})", (crest, 0.5),
                        xytext=(5, 0), textcoords="offset points", fontsize=9)
        ax.set_xlabel(ylabel)
        ax.set_ylabel("exceedance probability")
        ax.set_ylim(0, 1.05)
        ax.grid(alpha=0.3)
        ax.set_title((title + ": " if title else "") + f"exceedance over {v.size} scenarios", fontsize=10)
        p = os.path.join(out_dir, "exceedance.png")
        fig.savefig(p, dpi=130, bbox_inches="tight")
        plt.close(fig)
        info["files"].append(p)
    info["y"] = ycol
    return info


def _fmt(v):
    if isinstance(v, float):
        return "nan" if not math.isfinite(v) else f"{v:.4g}"
    s = str(v)
    return s if len(s) <= 40 else s[:37] + "..."
