"""The optimisation procedure of Manenti et al. (2018), Section 2.2, on the sweep machinery.

For a case and a permitted error E (%) on a chosen output:

1. Threshold viscosity. With mu0 switched off (mu0 = MU0_OFF >= mu_thr), raise mu_thr along a
   geometric ladder start, start*f, start*f^2, ... and stop at the first mu_thr_k whose output
   differs from that of the next rung by at most E: mu_thr_min = mu_thr_k and that run is the
   converged reference (the paper's Table 1, Runs 1-4, reference Run 2).
2. Limiting viscosity. At mu_thr_min, lower mu0 below it (mu_thr_min*g, mu_thr_min*g^2, ...)
   until the error against the reference exceeds E; mu0_min is the smallest mu0 still within E
   (optionally refined by geometric bisection between the last good and the first bad value).
   The ladder also stops when the solver's step count no longer falls (the time step is then
   bound by the acoustic CFL, not by mu0, so a lower mu0 saves nothing).
   The saving is 1 - wall(mu0_min) / wall(reference) (the paper's Table 2, Runs 5-7), and the
   same from the FMU's step count when it has a 'steps' output.

Error of a run y against a reference r: 100 |y - r| / |r - offset| for the output's final value
(e.g. max_run_up; offset lets it be measured above the still-water level, like the paper's
error (13)); with series=True the mean of that over the communication points of the run (an
output's history, e.g. the landslide front, like the paper's interface comparison).

Each rung's runs are submitted together, as many as there are workers, so a cluster evaluates
several mu values at once; every run is also stored in OUT's results table, so an interrupted
optimisation re-run does only what is missing.
"""

from __future__ import annotations

import json
import math
import os

import numpy as np
import pandas as pd

from . import runner, scenarios as sc_mod
from .scenarios import ID
from .store import ResultStore

MU0_OFF = 1.0e12


class OptimiseError(RuntimeError):
    pass


def rel_error(y, ref, offset: float = 0.0, series: bool = False) -> float:
    """Percentage error of y against ref (see the module doc)."""
    if series:
        y = np.asarray(y, dtype=float)
        ref = np.asarray(ref, dtype=float)
        n = min(len(y), len(ref))
        y, ref = y[:n], ref[:n]
        den = np.abs(ref - offset)
        ok = den > 1e-12
        if not ok.any():
            return math.nan
        return float(np.mean(np.abs(y[ok] - ref[ok]) / den[ok]) * 100.0)
    den = abs(float(ref) - offset)
    if den <= 1e-300:
        return math.nan
    return abs(float(y) - float(ref)) / den * 100.0


class Evaluator:
    """Runs (mu_thr, mu0) points on the cluster, reusing stored results."""

    def __init__(self, client, fmu_path, fixed, opts, store: ResultStore, output, series, progress):
        self.client, self.fmu_path, self.fixed, self.opts = client, fmu_path, fixed, opts
        self.store, self.output, self.series, self.progress = store, output, series, progress
        self.cache: dict[str, dict] = {}
        prev = store.latest()
        if not prev.empty:
            for rec in prev.to_dict(orient="records"):
                if rec.get("status") == "ok":
                    self.cache[rec[ID]] = rec

    def value(self, row):
        if self.series:
            s = row.get("series")
            if isinstance(s, str):
                s = json.loads(s)
            return s[self.output]
        return row[self.output]

    def run(self, points: list[tuple[float, float]]) -> list[dict]:
        scen = []
        for mu_thr, mu0 in points:
            p = dict(self.fixed)
            p["mu_thr"], p["mu0"] = float(mu_thr), float(mu0)
            scen.append({ID: sc_mod.scenario_id(p, self.opts.get("stop_time")), **p})
        todo = [s for s in scen if s[ID] not in self.cache]
        if todo:
            if self.progress:
                self.progress.total += len(todo)
            for row in runner.run_scenarios(self.client, self.fmu_path, todo, self.opts,
                                            on_result=self.store.append, progress=self.progress):
                if row["status"] == "ok":
                    self.cache[row[ID]] = row
                else:
                    self.cache.setdefault("failed:" + row[ID], row)
        out = []
        for s in scen:
            row = self.cache.get(s[ID]) or self.cache.get("failed:" + s[ID])
            out.append(row)
        return out


def optimise(client, fmu_path: str, out_dir: str, output: str, error: float, fixed: dict,
             opts: dict, series: bool = False, offset: float = 0.0,
             mu_thr_start: float = 10e3, mu_thr_factor: float = 2.0, mu_thr_max: float = 1.28e6,
             mu0_factor: float = 0.5, mu0_min_bound: float = 1.0, refine: int = 1,
             fmt: str = "parquet", progress: bool = True, log=print) -> dict:
    if not (error > 0):
        raise OptimiseError("the permitted error must be > 0 (%)")
    if not (mu_thr_factor > 1.0) or not (0.0 < mu0_factor < 1.0):
        raise OptimiseError("need --mu-thr-factor > 1 and 0 < --mu0-factor < 1")
    for k in ("mu_thr", "mu0"):
        if k in fixed:
            raise OptimiseError(f"{k} is what the procedure varies: do not fix it")
    opts = dict(opts)
    opts.setdefault("outputs", None)
    if series:
        opts["series"] = sorted(set(opts.get("series") or []) | {output})
    store = ResultStore(out_dir, fmt)
    prog = runner.Progress(0, label="optimise", enabled=progress)
    ev = Evaluator(client, fmu_path, fixed, opts, store, output, series, prog)
    W = runner.n_workers(client)
    runs = []  # every evaluated point, for the table

    def check(row, what):
        if row is None or row.get("status") != "ok":
            raise OptimiseError(f"{what} failed: {row.get('error') if row else 'no result'}")

    # ---- stage 1: raise mu_thr with mu0 switched off ---------------------------------------
    ladder = []
    m = mu_thr_start
    while m <= mu_thr_max * (1 + 1e-9):
        ladder.append(m)
        m *= mu_thr_factor
    if len(ladder) < 2:
        raise OptimiseError("the mu_thr ladder needs at least two rungs (start <= max / factor)")
    rows1: list[dict] = []
    k_conv = None
    i = 0
    while k_conv is None and i < len(ladder):
        n = max(W, 2 if not rows1 else 1)
        batch = ladder[i:i + n]
        res = ev.run([(mt, max(MU0_OFF, mt)) for mt in batch])
        for mt, row in zip(batch, res):
            check(row, f"mu_thr = {mt:g} (mu0 off)")
            rows1.append(row)
        i += len(batch)
        for k in range(len(rows1) - 1):
            e = rel_error(ev.value(rows1[k]), ev.value(rows1[k + 1]), offset, series)
            rows1[k]["_err_next"] = e
            if e <= error:
                k_conv = k
                break
    if k_conv is None:
        raise OptimiseError(f"{output} did not converge within {error:g} % up to mu_thr = "
                            f"{ladder[-1]:g} (raise --mu-thr-max)")
    mu_thr_min = ladder[k_conv]
    ref = rows1[k_conv]
    y_ref = ev.value(ref)
    for k, row in enumerate(rows1):
        runs.append({"stage": "mu_thr", "mu_thr": row["mu_thr"], "mu0": row["mu0"],
                     "value": _scalar(ev.value(row)), "error_vs_next_pct": row.get("_err_next", math.nan),
                     "error_vs_ref_pct": rel_error(ev.value(row), y_ref, offset, series),
                     "wall_time_s": row["wall_time_s"], "cpu_time_s": row.get("cpu_time_s", math.nan),
                     "steps": row.get("steps", math.nan),
                     "role": "reference (mu_thr_min)" if k == k_conv else ""})

    # ---- stage 2: lower mu0 below mu_thr_min -----------------------------------------------
    good: list[tuple[float, dict, float]] = []   # (mu0, row, err), descending mu0
    bad = None
    stop_reason = ""
    j = 1
    last_steps = ref.get("steps", math.nan)
    while bad is None and not stop_reason:
        mus = []
        while len(mus) < W:
            m0 = mu_thr_min * mu0_factor ** (j + len(mus))
            if m0 < mu0_min_bound:
                break
            mus.append(m0)
        if not mus:
            stop_reason = f"reached the lower bound mu0 >= {mu0_min_bound:g}"
            break
        j += len(mus)
        res = ev.run([(mu_thr_min, m0) for m0 in mus])
        for m0, row in zip(mus, res):
            if row is None or row.get("status") != "ok":
                bad = (m0, row, math.nan)
                break
            e = rel_error(ev.value(row), y_ref, offset, series)
            if e > error:
                bad = (m0, row, e)
                break
            steps = row.get("steps", math.nan)
            if good and math.isfinite(last_steps) and math.isfinite(steps) \
                    and steps >= 0.98 * last_steps:
                # no cheaper than the rung above: the time step is the acoustic one; a lower
                # mu0 would only add error, so mu0_min stays the rung above
                runs.append(_row2(row, m0, mu_thr_min, ev, e, "no further saving"))
                stop_reason = (f"steps no longer fall below mu0 = {good[-1][0]:g} (the time "
                               f"step is bound by the acoustic CFL there)")
                break
            good.append((m0, row, e))
            last_steps = steps
    # refinement between the last good and the first bad mu0 (geometric)
    if bad is not None and refine > 0:
        lo_ok = good[-1][0] if good else mu_thr_min
        hi_bad = bad[0]
        for _ in range(refine):
            ratios = [(i + 1) / (W + 1) for i in range(W)]
            mus = [math.exp(math.log(lo_ok) + r * (math.log(hi_bad) - math.log(lo_ok))) for r in ratios]
            res = ev.run([(mu_thr_min, m0) for m0 in mus])
            for m0, row in zip(mus, res):   # descending mu0
                ok = row is not None and row.get("status") == "ok"
                e = rel_error(ev.value(row), y_ref, offset, series) if ok else math.nan
                if ok and e <= error:
                    good.append((m0, row, e))
                    lo_ok = m0
                else:
                    runs.append(_row2(row, m0, mu_thr_min, ev, e, "over the error" if ok else "failed"))
                    hi_bad = m0
                    break
    good.sort(key=lambda t: -t[0])
    for m0, row, e in good:
        runs.append(_row2(row, m0, mu_thr_min, ev, e, ""))
    if bad is not None:
        runs.append(_row2(bad[1], bad[0], mu_thr_min, ev, bad[2],
                          "over the error" if bad[1] is not None and bad[1].get("status") == "ok" else "failed"))

    result = {"output": output, "series": series, "permitted_error_pct": error, "offset": offset,
              "fixed": fixed, "stop_time": opts.get("stop_time"), "mu_thr_min": mu_thr_min,
              "reference_value": _scalar(y_ref), "reference_wall_time_s": ref["wall_time_s"],
              "reference_steps": ref.get("steps"), "reference_cpu_time_s": ref.get("cpu_time_s"),
              "mu0_min": None, "error_pct": None, "wall_time_s": None, "cpu_time_s": None,
              "wall_time_saved_pct": None, "cpu_time_saved_pct": None, "steps_saved_pct": None,
              "stop_reason": stop_reason or ("error above the permitted one below mu0_min" if bad else "")}
    if good:
        m0, row, e = min(good, key=lambda t: t[0])
        result.update({"mu0_min": m0, "error_pct": e, "wall_time_s": row["wall_time_s"],
                       "value": _scalar(ev.value(row)),
                       "cpu_time_s": row.get("cpu_time_s"),
                       "wall_time_saved_pct": 100.0 * (1.0 - row["wall_time_s"] / ref["wall_time_s"])})
        if row.get("cpu_time_s") and ref.get("cpu_time_s"):
            result["cpu_time_saved_pct"] = 100.0 * (1.0 - row["cpu_time_s"] / ref["cpu_time_s"])
        if row.get("steps") is not None and ref.get("steps"):
            result["steps_saved_pct"] = 100.0 * (1.0 - float(row["steps"]) / float(ref["steps"]))
        for r in runs:
            if r["stage"] == "mu0" and r["mu0"] == m0:
                r["role"] = "mu0_min"
    else:
        result["stop_reason"] = "even mu0 = mu_thr_min * factor exceeds the permitted error"
    prog.update(force=True) if progress and prog.total else None
    table = pd.DataFrame(runs)
    table["_k"] = np.where(table["stage"] == "mu_thr", table["mu_thr"], -table["mu0"])
    table["_s"] = (table["stage"] == "mu0").astype(int)
    table = table.sort_values(["_s", "_k"]).drop(columns=["_k", "_s"]).reset_index(drop=True)
    table["wall_time_saved_pct"] = 100.0 * (1.0 - table["wall_time_s"] / ref["wall_time_s"])
    table.to_csv(os.path.join(out_dir, "optimise_runs.csv"), index=False)
    with open(os.path.join(out_dir, "optimise.json"), "w") as f:
        json.dump(_jsonable(result), f, indent=2)
    store.compact()
    result["table"] = table
    return result


def _row2(row, m0, mu_thr, ev, e, role):
    ok = row is not None and row.get("status") == "ok"
    return {"stage": "mu0", "mu_thr": mu_thr, "mu0": m0,
            "value": _scalar(ev.value(row)) if ok else math.nan, "error_vs_next_pct": math.nan,
            "error_vs_ref_pct": e, "wall_time_s": row["wall_time_s"] if row else math.nan,
            "cpu_time_s": row.get("cpu_time_s", math.nan) if row else math.nan,
            "steps": row.get("steps", math.nan) if ok else math.nan, "role": role}


def _scalar(v):
    if isinstance(v, (list, tuple, np.ndarray)):
        return float(v[-1]) if len(v) else math.nan   # a series: its last value
    return float(v)


def _jsonable(d):
    out = {}
    for k, v in d.items():
        if isinstance(v, (np.floating, np.integer)):
            v = v.item()
        if isinstance(v, float) and not math.isfinite(v):
            v = None
        out[k] = v
    return out


def format_result(res: dict) -> str:
    t = res["table"]
    lines = [f"optimisation of {res['output']}{' (history)' if res['series'] else ''}, permitted "
             f"error {res['permitted_error_pct']:g} %, stop time {res['stop_time']}",
             f"{'stage':<7} {'mu_thr':>10} {'mu0':>10} {'value':>10} {'err next %':>10} "
             f"{'err ref %':>9} {'wall s':>8} {'cpu s':>8} {'steps':>9} {'saved %':>8}  role"]
    for r in t.to_dict(orient="records"):
        mu0 = "off" if r["mu0"] >= MU0_OFF else f"{r['mu0']:.4g}"
        lines.append(f"{r['stage']:<7} {r['mu_thr']:>10.4g} {mu0:>10} {r['value']:>10.4f} "
                     f"{r['error_vs_next_pct']:>10.2f} {r['error_vs_ref_pct']:>9.2f} "
                     f"{r['wall_time_s']:>8.1f} {r['cpu_time_s']:>8.1f} {r['steps']:>9.0f} {r['wall_time_saved_pct']:>8.1f}  {r['role']}")
    lines.append(f"mu_thr_min = {res['mu_thr_min']:g} Pa s (reference run: {res['output']} = "
                 f"{res['reference_value']:.4f}, wall {res['reference_wall_time_s']:.1f} s)")
    if res["mu0_min"] is not None:
        s = f"mu0_min = {res['mu0_min']:g} Pa s: error {res['error_pct']:.2f} % <= " \
            f"{res['permitted_error_pct']:g} %, wall {res['wall_time_s']:.1f} s, " \
            f"wall time saved {res['wall_time_saved_pct']:.1f} %"
        extra = []
        if res.get("cpu_time_saved_pct") is not None:
            extra.append(f"CPU time saved {res['cpu_time_saved_pct']:.1f} %")
        if res.get("steps_saved_pct") is not None:
            extra.append(f"steps saved {res['steps_saved_pct']:.1f} %")
        if extra:
            s += " (" + ", ".join(extra) + ")"
        lines.append(s)
    else:
        lines.append("mu0_min: none below mu_thr_min within the permitted error")
    if res.get("stop_reason"):
        lines.append(f"mu0 ladder stopped: {res['stop_reason']}")
    return "\n".join(lines)
