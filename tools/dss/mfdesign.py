"""A cost-aware sequential design of FMU runs over a ladder of spacings dx (emulate mf-design).

Start: nested Latin hypercubes, n_1 runs at the coarsest level (scenarios.sample's Latin
hypercube), of those the n_2 most spread (greedy maximin in the unit box) also at the next
level, and so on: the runs of a level are a subset of those of the level below, which the
recursive co-kriging of multifidelity.py needs.

Then, until the CPU seconds spent reach the budget: fit the multi-fidelity emulator, draw
random candidates in the box and a reference sample, and pick a batch of as many picks as
there are workers. A pick is a point x AND a level l; it runs x at every level up to l (the
design stays nested). Its value is the expected reduction of the target's posterior variance
(the finest level, or the dx -> 0 extrapolation) integrated over the reference sample, per CPU
second of the runs it needs:

    gain(x, l) = sum_{k <= l} w_k sum_{r in R} cov_k(r, x)^2 / (var_k(x) + noise_k) / |R|
    cost(l)    = sum_{k <= l} cost_k

with cov_k the latent posterior covariance of level k's discrepancy GP, w_k the squared
coefficient of delta_k in the target (the product of the rho's above it; for the
extrapolation the Richardson weights), and cost_k the median CPU time of the level's runs so
far (measured, not assumed: the start has runs at every level). Within a batch each pick
conditions the levels it runs on a run at x (a rank-1 update, as design.imse_pick does).

State: OUT/mfdesign.json (settings, the batches' scenario ids, the history), OUT/scenarios.csv,
OUT/results.parquet (one file per finished run). A batch is recorded before it is submitted,
so a killed design re-run completes the recorded batches first and repeats no run.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time

import numpy as np
import pandas as pd

from . import multifidelity as M
from . import scenarios as S
from .design import DesignError, _dist_spec, _draw, _fmt_t, _save, box_of
from .scenarios import ID
from .store import open_store

N_REF = 400              # the reference sample of the integrated variance
N_CAND = 1000            # candidates per batch
TARGETS = ("finest", M.EXTRAPOLATED)


def nested_start(dists, fixed, levels, counts, seed):
    """Scenarios of the start: counts[i] runs at levels[i] (coarse to fine, counts not
    increasing), each level's points a subset of the coarser level's (module doc)."""
    if any(counts[i] < counts[i + 1] for i in range(len(counts) - 1)):
        raise DesignError(f"--init {','.join(map(str, counts))}: the counts must not increase "
                          f"from the coarsest level to the finest (the design is nested)")
    if counts[-1] < 3:
        raise DesignError("--init: at least 3 runs at the finest level")
    base = S.sample(dists, counts[0], "lhs", seed, {})
    U = np.array([[(float(s[d.name]) - box_of(d)[0]) / (box_of(d)[1] - box_of(d)[0])
                   for d in dists] for s in base])
    keep = list(range(len(base)))
    members = [keep]
    for n in counts[1:]:
        keep = _maximin_subset(U, keep, n)
        members.append(keep)
    out = []
    for dx, idx in zip(levels, members):
        for i in idx:
            out.append({**fixed, **base[i], "dx": float(dx)})
    return out


def _maximin_subset(U, idx, n):
    """n of the rows idx of U, greedily the farthest from those chosen (the first: the one
    nearest the box's centre)."""
    idx = list(idx)
    if n >= len(idx):
        return idx
    P = U[idx]
    chosen = [int(np.argmin(((P - 0.5) ** 2).sum(axis=1)))]
    dmin = ((P - P[chosen[0]]) ** 2).sum(axis=1)
    while len(chosen) < n:
        j = int(np.argmax(dmin))
        chosen.append(j)
        dmin = np.minimum(dmin, ((P - P[j]) ** 2).sum(axis=1))
    return [idx[j] for j in sorted(chosen)]


def target_weights(m: M.OutputMF, target: str) -> np.ndarray:
    """w_k: the squared coefficient of delta_k in the target (module doc)."""
    level = M.EXTRAPOLATED if target == M.EXTRAPOLATED and m.order else len(m.levels) - 1
    return np.asarray(m.linear_form(level, latent=True)["coef"], float) ** 2


def pick_batch(m: M.OutputMF, Uc, Ur, costs, k, target="finest", max_cost=math.inf):
    """Up to k picks (candidate index, level index, gain, cost) at the largest integrated
    variance reduction per CPU second (module doc), with rank-1 updates within the batch; the
    picks together cost at most max_cost."""
    L = len(m.levels)
    w = target_weights(m, target)
    cRC = [g.cov(Ur, Uc) for g in m.levels]
    vC = [g.predict(Uc)[1] for g in m.levels]
    nz = [g.noise_var() for g in m.levels]
    W = [[] for _ in range(L)]
    cum_cost = np.cumsum(costs)
    picks, used, spent = [], set(), 0.0
    for _ in range(k):
        per_level = [w[q] * (cRC[q] ** 2).sum(axis=0) / (np.maximum(vC[q], 0.0) + nz[q])
                     / len(Ur) for q in range(L)]
        gain = np.cumsum(per_level, axis=0)               # level l: the sum over q <= l
        score = gain / cum_cost[:, None]
        score[:, list(used)] = -np.inf
        score[cum_cost > max_cost - spent, :] = -np.inf
        li, ci = np.unravel_index(int(np.argmax(score)), score.shape)
        if not np.isfinite(score[li, ci]) or score[li, ci] <= 0:
            break
        picks.append((int(ci), int(li), float(gain[li, ci]), float(cum_cost[li])))
        spent += float(cum_cost[li])
        used.add(int(ci))
        for q in range(li + 1):
            col = m.levels[q].cov(Uc, Uc[ci:ci + 1])[:, 0]
            for wv in W[q]:
                col -= wv * wv[ci]
            s = math.sqrt(max(vC[q][ci], 0.0) + nz[q])
            wC, wR = col / s, cRC[q][:, ci] / s
            cRC[q] -= np.outer(wR, wC)
            vC[q] = vC[q] - wC ** 2
            W[q].append(wC)
    return picks


class MFDesign:
    """The cost-aware multi-fidelity design in OUT (module doc). evaluate(scenarios,
    on_result) runs a list of scenarios and calls on_result(row) per finished run."""

    def __init__(self, out, dists, fixed, stop_time, levels, budget_cpu, output="max_run_up",
                 init=None, seed=0, n_workers=2, restarts=0, target="finest", fmu=None,
                 settings=None, progress=True, stream=None, n_candidates=N_CAND,
                 jitter_floor=True):
        self.out = out
        self.dists = list(dists)
        self.names = [d.name for d in self.dists]
        self.fixed = {k: v for k, v in dict(fixed).items() if k != "dx"}
        self.stop_time = stop_time
        self.levels = sorted((float(x) for x in levels), reverse=True)
        if len(self.levels) < 2 or len(set(self.levels)) != len(self.levels):
            raise DesignError(f"--levels: two or more distinct spacings dx (got {levels})")
        self.budget = float(budget_cpu)
        self.output, self.seed = output, int(seed)
        self.n_workers = max(1, int(n_workers))
        self.restarts = restarts
        if target not in TARGETS:
            raise DesignError(f"unknown target {target!r} ({', '.join(TARGETS)})")
        self.target = target
        d = len(self.dists)
        L = len(self.levels)
        # the start: (d + 1) runs at the finest level, doubling per coarser level
        self.init = [int(x) for x in init] if init else [(d + 1) * 2 ** (L - 1 - i)
                                                         for i in range(L)]
        if len(self.init) != L:
            raise DesignError(f"--init has {len(self.init)} counts for {L} levels")
        self.box = {dd.name: box_of(dd) for dd in self.dists}
        self.n_cand = int(n_candidates)
        self.jitter_floor = bool(jitter_floor)
        self.fmu = dict(fmu or {})
        self.settings = dict(settings or {})
        self.progress, self.stream = progress, stream or sys.stderr
        self.state_path = os.path.join(out, "mfdesign.json")
        self.table_path = os.path.join(out, "scenarios.csv")
        os.makedirs(out, exist_ok=True)
        self.store = open_store(out, "parquet")
        self.t0 = time.monotonic()
        self.state = self._load_state()
        self._warm = None          # the last fit's thetas and rhos: the next fit's start

    # ---- state ----------------------------------------------------------------------------------

    def _spec(self):
        return {"dists": {d.name: _dist_spec(d) for d in self.dists}, "fixed": self.fixed,
                "stop_time": self.stop_time, "levels": self.levels, "output": self.output,
                "seed": self.seed, "init": self.init, "target": self.target,
                "jitter_floor": self.jitter_floor}

    def _load_state(self):
        now = json.loads(json.dumps(self._spec()))
        if os.path.isfile(self.state_path):
            with open(self.state_path) as f:
                st = json.load(f)
            if st["spec"] != now:
                diff = [k for k in sorted(set(now) | set(st["spec"]))
                        if st["spec"].get(k) != now.get(k)]
                raise DesignError(f"{self.out} holds a design with other settings "
                                  f"({', '.join(diff)}): use another folder, or the same "
                                  f"settings to continue it")
            if st.get("fmu", {}).get("guid") and self.fmu.get("guid") and \
                    st["fmu"]["guid"] != self.fmu["guid"]:
                raise DesignError(f"{self.out} holds the runs of the FMU with GUID "
                                  f"{st['fmu']['guid']}, not {self.fmu['guid']}: use another "
                                  f"folder")
            return st
        return {"spec": now, "batches": [], "history": [], "fmu": self.fmu,
                "settings": self.settings}

    def _write_state(self):
        self.state["budget_cpu_s"] = self.budget
        _save(self.state_path, self.state)

    def _add(self, scen):
        tab = S.table(scen, self.stop_time)
        if os.path.isfile(self.table_path):
            old = pd.read_csv(self.table_path, dtype={ID: str})
            tab = pd.concat([old, tab[~tab[ID].isin(set(old[ID]))]], ignore_index=True)
        tab.to_csv(self.table_path + ".tmp", index=False)
        os.replace(self.table_path + ".tmp", self.table_path)
        return [S.scenario_id(s, self.stop_time) for s in scen]

    def _scenarios(self, ids):
        tab = pd.read_csv(self.table_path, dtype={ID: str}).set_index(ID)
        return [{ID: i, **{k: S._plain(v) for k, v in tab.loc[i].to_dict().items()
                           if not (isinstance(v, float) and v != v)}} for i in ids]

    def results(self) -> pd.DataFrame:
        df = self.store.latest()
        if df.empty:
            return df
        return df[df[ID].isin({i for b in self.state["batches"] for i in b["ids"]})]

    def _say(self, text):
        if self.progress:
            print(text, file=self.stream, flush=True)

    def _complete(self, evaluate):
        df = self.store.latest()
        have = set(df[ID]) if not df.empty else set()
        todo = [i for b in self.state["batches"] for i in b["ids"] if i not in have]
        if todo:
            evaluate(self._scenarios(todo), self.store.append)

    # ---- measurements ---------------------------------------------------------------------------

    def level_of(self, dx):
        for i, d in enumerate(self.levels):
            if math.isclose(float(dx), d, rel_tol=1e-9):
                return i
        return None

    def costs(self, df) -> list[float]:
        """The median CPU seconds of the ok runs of each level."""
        out = []
        for dx in self.levels:
            c = df.loc[np.isclose(df["dx"].astype(float), dx) & (df["status"] == "ok"),
                       "cpu_time_s"].astype(float)
            c = c[np.isfinite(c)]
            if c.empty:
                raise DesignError(f"no ok run at dx = {dx:g} after the start: its cost is not "
                                  f"measured (see the failed runs in the results)")
            out.append(float(np.median(c)))
        return out

    def spent(self, df) -> float:
        c = df["cpu_time_s"].astype(float) if not df.empty else pd.Series([], dtype=float)
        return float(c[np.isfinite(c)].sum())

    def fit(self, df, outputs=None, restarts=None):
        ok = df[df["status"] == "ok"]
        em = M.from_results(ok, self.names, self.levels, outputs or [self.output],
                            box=self.box, fmu=self.fmu,
                            settings={**self.settings, "design": os.path.abspath(self.state_path)})
        for o in outputs or [self.output]:
            warm = self._warm if o == self.output else None
            m = em.fit_output(o, restarts=self.restarts if restarts is None else restarts,
                              seed=self.seed, thetas=warm and warm[0], rhos=warm and warm[1],
                              jitter_floor=self.jitter_floor)
            if o == self.output:
                self._warm = ([g.theta for g in m.levels], [g.rho for g in m.levels])
        return em

    # ---- the loop -------------------------------------------------------------------------------

    def run(self, evaluate) -> dict:
        if not self.state["batches"]:
            scen = nested_start(self.dists, self.fixed, self.levels, self.init, self.seed)
            self.state["batches"].append({"kind": "start", "ids": self._add(scen),
                                          "levels": [float(s["dx"]) for s in scen]})
            self._write_state()
            self._say(f"mf-design: start: nested Latin hypercube, runs per level "
                      + ", ".join(f"dx {dx:g}: {n}" for dx, n in zip(self.levels, self.init)))
        reason = None
        while True:
            self._complete(evaluate)
            df = self.results()
            spent = self.spent(df)
            costs = self.costs(df)
            n_lv = [int(((np.isclose(df["dx"].astype(float), dx)) & (df["status"] == "ok")).sum())
                    for dx in self.levels]
            t_fit = time.monotonic()
            em = self.fit(df)
            m = em.models[self.output]
            cal = m.calibration[-1]
            hist = {"batches": len(self.state["batches"]), "runs_per_level": n_lv,
                    "cpu_spent_s": spent, "cost_per_level_s": costs,
                    "rho": [g.rho for g in m.levels[1:]], "order": m.order.get("p"),
                    "loo_rmse_finest": cal["loo_rmse"], "loo_rms_z_finest": cal["loo_rms_z"],
                    "fit_s": time.monotonic() - t_fit,
                    "elapsed_s": time.monotonic() - self.t0}
            if not self.state["history"] or \
                    self.state["history"][-1]["runs_per_level"] != n_lv:
                self.state["history"].append(hist)
                self._write_state()
            self._say(f"mf-design: runs per level {n_lv} (dx {', '.join(f'{d:g}' for d in self.levels)}), "
                      f"CPU {spent:.0f}/{self.budget:.0f} s, cost per run "
                      + "/".join(f"{c:.1f}" for c in costs) + " s, rho "
                      + "/".join(f"{g.rho:.3f}" for g in m.levels[1:])
                      + (f", order {m.order['p']:.2f}" if m.order else "")
                      + f", LOO RMSE at the finest {cal['loo_rmse']:.4g} (rms z "
                      f"{cal['loo_rms_z']:.2f}), elapsed {_fmt_t(time.monotonic() - self.t0)}")
            left = self.budget - spent
            if left < costs[0]:
                reason = "budget"
                break
            bi = len(self.state["batches"])
            rng = np.random.default_rng([self.seed, bi])
            cand = _draw(self.dists, {}, self.n_cand, rng)
            ref = _draw(self.dists, {}, N_REF, rng)
            Uc = em.unit(np.array([[c[n] for n in em.inputs] for c in cand], float))
            Ur = em.unit(np.array([[c[n] for n in em.inputs] for c in ref], float))
            picks = pick_batch(m, Uc, Ur, costs, self.n_workers, self.target, max_cost=left)
            scen, lv, batch_cost = [], [], 0.0
            for ci, li, gain, cost in picks:
                batch_cost += cost
                for q in range(li + 1):
                    scen.append({**self.fixed, **cand[ci], "dx": self.levels[q]})
                    lv.append(self.levels[q])
            if not scen:
                reason = "no new point"
                break
            self.state["batches"].append({"kind": f"cost-aware ({self.target})",
                                          "ids": self._add(scen), "levels": lv,
                                          "expected_cpu_s": batch_cost})
            self._write_state()
        self.state["stopped"] = reason
        self._write_state()
        return {"runs": len(self.results()), "reason": reason, "history": self.state["history"]}
