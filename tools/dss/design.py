"""Sequential design of FMU runs for an emulator (emulate design).

Start: a Latin hypercube of n_init runs over the box of the distributions (the sweep's LHS,
scenarios.sample). Then, until the emulator's cross-validated RMSE (in % of the output's range
over the runs) is at most the target or the budget is spent: fit the emulator, draw a large
random candidate set in the box, and pick a batch of as many runs as there are workers among
them by a criterion:

  imse   (default) the largest reduction of the posterior variance integrated over a random
         reference sample of the box (imse_pick); within a batch each pick conditions the
         covariances on a run there (a rank-1 update). The largest sd alone sits on the box's
         faces when the length scales are long (the Vajont campaign: all 48 picks within 5 % of
         a face), which leaves the interior to the start.
  sd     the largest predictive sd
  crest  (with a crest) the largest p(1-p), p = P(output > crest) at the candidate: where the
         exceedance is most uncertain

With sd and crest each pick multiplies the others' scores by 1 - r(x, x_picked)^2, r the fitted
kernel's correlation (without the noise): a simple distance penalty in the GP's own length
scales, so a batch is not clustered.

State: OUT/design.json (settings, the batches' scenario ids in order, the history of the CV
error), OUT/scenarios.csv (every scenario's parameters, as a sweep's) and the results store
OUT/results.parquet (one file per finished run, written as it finishes). A batch is written
to design.json before it is submitted, so a killed design re-run first completes the recorded
batches (only the scenarios without a result) and then goes on: no run is repeated.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time

import numpy as np
import pandas as pd

from . import emulator as E
from . import scenarios as S
from .scenarios import ID
from .store import open_store


class DesignError(RuntimeError):
    pass


def box_of(dist: S.Distribution) -> tuple[float, float]:
    if dist.kind == "choice":
        v = [float(x) for x in dist.choices]
        return min(v), max(v)
    if dist.kind in ("uniform", "loguniform"):
        return float(dist.args[0]), float(dist.args[1])
    if dist.kind == "normal" and len(dist.args) == 4:
        return float(dist.args[2]), float(dist.args[3])
    raise DesignError(f"{dist.name}: a design needs a bounded distribution (uniform, loguniform, "
                      f"choice or normal:mean:sd:lo:hi)")


def _save(path, obj):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(obj, f, indent=1)
    os.replace(tmp, path)


def _fmt_t(s):
    if not math.isfinite(s):
        return "?"
    s = int(round(s))
    return f"{s // 3600}h{s // 60 % 60:02d}m" if s >= 3600 else f"{s // 60}m{s % 60:02d}s"


CRITERIA = ("imse", "sd")
N_REF = 500              # the reference sample of the integrated variance
IMSE_CANDIDATES = 2000   # imse's default candidates at most (1000 per input below it)


def _draw(dists, fixed, n, rng):
    """n random scenarios (dicts) from the distributions (uniform u through each ppf)."""
    u = rng.random((n, len(dists)))
    out = [dict(fixed) for _ in range(n)]
    for j, d in enumerate(dists):
        col = d.ppf(u[:, j])
        for i in range(n):
            out[i][d.name] = col[i]
    return out


def pick_batch(em: E.Emulator, output: str, dists: list[S.Distribution], fixed: dict, k: int,
               rng, n_cand: int, crest: float | None = None, exclude=None,
               criterion: str = "imse", n_ref: int = N_REF):
    """k scenarios (dicts) from n_cand random candidates in the box.

    With a crest: largest p(1-p), p = P(output > crest); criterion 'sd': largest predictive
    sd; with either, each pick damps the others' scores by 1 - r^2 (r: the fitted correlation).
    criterion 'imse' (without a crest): largest integrated-variance reduction over a reference
    sample R of n_ref scenarios drawn (after the candidates, from the same rng) from the same
    distributions (imse_pick)."""
    from scipy.stats import norm
    if crest is None and criterion not in CRITERIA:
        raise DesignError(f"unknown criterion {criterion!r} ({', '.join(CRITERIA)})")
    cand = _draw(dists, fixed, n_cand, rng)
    X = em.matrix(cand)
    U = em.unit(X)
    m = em.models[output]
    if crest is None and criterion == "imse":
        Ur = em.unit(em.matrix(_draw(dists, fixed, n_ref, rng)))
        return [cand[i] for i in imse_pick(m, U, Ur, k)]
    mu, sd = m.predict(U)
    if crest is None:
        score = sd.copy()
    else:
        p = norm.sf((crest - mu) / np.maximum(sd, 1e-300))
        score = p * (1 - p)
    picked = []
    for _ in range(k):
        i = int(np.argmax(score))
        if not np.isfinite(score[i]) or score[i] <= 0:
            break
        picked.append(i)
        r = m.correlation(U, U[i:i + 1])[:, 0]
        score = score * (1 - r ** 2)
        score[i] = -np.inf
    return [cand[i] for i in picked]


def imse_pick(m: E.OutputModel, Uc, Ur, k: int) -> list[int]:
    """Indices of k candidates (rows of Uc, unit box) picked one by one at the largest
    reduction of the posterior variance integrated over the reference points Ur (IMSE, Sacks
    et al. 1989; the ALC criterion of Gramacy's laGP):

        score(c) = sum_{x in R} cov(x, c)^2 / (var(c) + noise(c))

    cov the posterior covariance of the latent response (OutputModel.posterior_cov), var(c) =
    cov(c, c), noise the fitted WhiteKernel variance at c. After each pick p, the covariances
    over R and the candidates are those of the GP with a run at p (fitted noise) added, a rank-1
    update: cov(a, b) -= cov(a, p) cov(p, b) / (var(p) + noise(p)), with cov(C, p) from one
    fresh column of posterior_cov and the previous picks' updates. Cost: one |R| x |C| matrix
    (the kernel against the training runs and a product of n_train), then O(|R| |C|) per pick."""
    cRC = m.posterior_cov(Ur, Uc)                       # R x C, updated in place
    vC = m.posterior_var(Uc)
    nz = m.noise_at(Uc)
    W = []                                              # the updates' vectors over C
    picked = []
    for _ in range(k):
        score = (cRC ** 2).sum(axis=0) / (np.maximum(vC, 0.0) + nz)
        score[~np.isfinite(score)] = -np.inf
        score[picked] = -np.inf
        i = int(np.argmax(score))
        if not np.isfinite(score[i]) or score[i] <= 0:
            break
        picked.append(i)
        cCp = m.posterior_cov(Uc, Uc[i:i + 1])[:, 0]
        for w in W:
            cCp -= w * w[i]
        s = math.sqrt(max(vC[i], 0.0) + nz[i])
        wC, wR = cCp / s, cRC[:, i] / s
        cRC -= np.outer(wR, wC)
        vC = vC - wC ** 2
        W.append(wC)
    return picked


class Design:
    """A sequential design in OUT (see the module doc). evaluate(scenarios, on_result) runs a
    list of scenarios ({'scenario_id', params...}) and calls on_result(row) per finished run."""

    def __init__(self, out, dists, fixed, stop_time, output="max_run_up", budget=60,
                 target_error=2.0, n_init=None, crest=None, seed=0, n_workers=2, mode="product",
                 folds=5, restarts=2, n_candidates=None, fmu=None, settings=None, progress=True,
                 stream=None, min_runs=None, noise=None, criterion=None):
        self.out = out
        self.dists = list(dists)
        self.names = [d.name for d in self.dists]
        self.fixed = dict(fixed)
        self.stop_time = stop_time
        self.output, self.budget, self.target = output, int(budget), float(target_error)
        self.crest, self.seed, self.n_workers = crest, int(seed), max(1, int(n_workers))
        self.mode, self.folds, self.restarts = mode, folds, restarts
        d = len(self.dists)
        # the start: 10 runs per input is the usual rule for GP emulators, at most a third of
        # the budget, at least one batch
        self.n_init = int(n_init) if n_init else max(self.n_workers, min(self.budget // 3, 10 * d))
        # the acquisition: 'crest' with a crest (p(1-p)), else 'imse' (default) or 'sd'
        if crest is not None and criterion not in (None, "crest"):
            raise DesignError(f"--criterion {criterion} applies without --crest only (with a "
                              f"crest the picks are at the largest p(1-p))")
        self.criterion = "crest" if crest is not None else (criterion or "imse")
        if self.criterion not in CRITERIA + ("crest",):
            raise DesignError(f"unknown criterion {self.criterion!r} ({', '.join(CRITERIA)})")
        # imse costs a reference-by-candidates matrix per batch: at most IMSE_CANDIDATES
        self.n_cand = int(n_candidates) if n_candidates else (
            min(1000 * d, IMSE_CANDIDATES) if self.criterion == "imse" else 1000 * d)
        # the CV target may stop the design only from this many runs on: a CV of a few runs is
        # no estimate (the first campaign stopped at 10 runs on a CV RMSE of 1.7 % and missed
        # on the hold-out); default 10 runs per input (Loeppky, Sacks & Welch 2009), at most
        # the budget
        self.min_runs = int(min_runs) if min_runs is not None else min(10 * d, self.budget)
        self.box = {dd.name: box_of(dd) for dd in self.dists}
        # the measured noise term per output (emulator.noise_from_file), or None
        self.noise = dict(noise) if noise else None
        self.fmu = dict(fmu or {})
        self.settings = dict(settings or {})
        self.progress, self.stream = progress, stream or sys.stderr
        self.state_path = os.path.join(out, "design.json")
        self.table_path = os.path.join(out, "scenarios.csv")
        os.makedirs(out, exist_ok=True)
        self.store = open_store(out, "parquet")
        self.t0 = time.monotonic()
        self.run_seconds = []          # wall time of the runs this process did
        self.state = self._load_state()

    # ---- state --------------------------------------------------------------------------------

    def _spec(self):
        return {"dists": {d.name: _dist_spec(d) for d in self.dists}, "fixed": self.fixed,
                "stop_time": self.stop_time, "output": self.output, "crest": self.crest,
                "seed": self.seed, "n_init": self.n_init, "mode": self.mode,
                "criterion": self.criterion,
                # the measured noise floor changes the picks: part of the settings (absent
                # without one, so designs of before it continue)
                **({"noise": {k: {"variance": v["variance"], "mode": v["mode"]}
                              for k, v in self.noise.items() if k == self.output}}
                   if self.noise else {})}

    def _load_state(self):
        if os.path.isfile(self.state_path):
            with open(self.state_path) as f:
                st = json.load(f)
            # a design of before the criterion setting picked at the largest sd (or p(1-p))
            st["spec"].setdefault("criterion", "sd" if st["spec"].get("crest") is None
                                  else "crest")
            if st["spec"] != json.loads(json.dumps(self._spec())):
                now = json.loads(json.dumps(self._spec()))
                diff = [k for k in sorted(set(now) | set(st["spec"])) if st["spec"].get(k) != now.get(k)]
                raise DesignError(f"{self.out} holds a design with other settings ({', '.join(diff)}"
                                  f"): use another folder, or the same settings to continue it")
            return st
        return {"spec": json.loads(json.dumps(self._spec())), "batches": [], "history": [],
                "fmu": self.fmu, "settings": self.settings}

    def _write_state(self):
        self.state["budget"], self.state["target_error_pct"] = self.budget, self.target
        _save(self.state_path, self.state)

    def _add_scenarios(self, scen: list[dict]) -> list[str]:
        tab = S.table(scen, self.stop_time)
        old = pd.read_csv(self.table_path, dtype={ID: str}) if os.path.isfile(self.table_path) \
            else None
        if old is not None and not old.empty:
            tab = pd.concat([old, tab[~tab[ID].isin(set(old[ID]))]], ignore_index=True)
        tab.to_csv(self.table_path + ".tmp", index=False)
        os.replace(self.table_path + ".tmp", self.table_path)
        return [S.scenario_id(s, self.stop_time) for s in scen]

    def _scenarios(self, ids) -> list[dict]:
        tab = pd.read_csv(self.table_path, dtype={ID: str}).set_index(ID)
        out = []
        for i in ids:
            rec = {k: S._plain(v) for k, v in tab.loc[i].to_dict().items()
                   if not (isinstance(v, float) and v != v)}
            out.append({ID: i, **rec})
        return out

    def results(self) -> pd.DataFrame:
        df = self.store.latest()
        ids = [i for b in self.state["batches"] for i in b["ids"]]
        if df.empty:
            return df
        return df[df[ID].isin(set(ids))]

    def n_runs(self) -> int:
        return len(self.results())

    # ---- the loop -----------------------------------------------------------------------------

    def _say(self, text):
        if self.progress:
            print(text, file=self.stream, flush=True)

    def _complete_batches(self, evaluate):
        """Run every recorded scenario that has no result yet (the resumption)."""
        have = set(self.store.latest()[ID]) if not self.store.latest().empty else set()
        todo = [i for b in self.state["batches"] for i in b["ids"] if i not in have]
        if not todo:
            return
        def on_result(row):
            self.store.append(row)
            if math.isfinite(row.get("wall_time_s", math.nan)):
                self.run_seconds.append(float(row["wall_time_s"]))
        evaluate(self._scenarios(todo), on_result)

    def fit(self, restarts=None, folds=None, mode=None):
        """The emulator of the runs so far; the hyperparameters start from the previous fit's,
        and the CV keeps them in every fold (cheap; the final fit of `emulate design` refits
        them per fold)."""
        df = self.results()
        ok = df[df["status"] == "ok"] if not df.empty else df
        if len(ok) < 3:
            return None
        em = E.from_results(ok, outputs=[self.output], inputs=self.names, box=self.box,
                            fmu=self.fmu, sweep={**self.settings, "design": self.state_path},
                            noise=self.noise)
        m = em.fit_output(self.output, mode=mode or self.mode,
                          restarts=self.restarts if restarts is None else restarts,
                          seed=self.seed, folds=folds or self.folds, cv=True, cv_refit=False,
                          init=getattr(self, "_thetas", None))
        self._thetas = m.thetas()
        return em

    def _eta(self, runs_left):
        if not self.run_seconds or runs_left <= 0:
            return math.nan if runs_left > 0 else 0.0
        return runs_left * float(np.mean(self.run_seconds)) / self.n_workers

    def run(self, evaluate) -> dict:
        """Run the design to its end; returns the final state's summary."""
        if not self.state["batches"]:
            if self.n_init > self.budget:
                raise DesignError(f"the start ({self.n_init} runs) is over the budget "
                                  f"({self.budget})")
            scen = S.sample(self.dists, self.n_init, "lhs", self.seed, self.fixed)
            ids = self._add_scenarios(scen)
            self.state["batches"].append({"kind": "lhs", "ids": ids})
            self._write_state()
            self._say(f"design: start: Latin hypercube of {len(ids)} runs")
        reason = None
        while True:
            self._complete_batches(evaluate)
            n = self.n_runs()
            t_fit = time.monotonic()
            em = self.fit()
            cv = em.cv[self.output] if em is not None else None
            hist = {"runs": n, "batches": len(self.state["batches"]),
                    "elapsed_s": time.monotonic() - self.t0}
            if cv:
                hist.update({k: cv[k] for k in ("rmse", "max_error", "coverage95", "range",
                                                "rmse_pct", "max_error_pct")})
                hist["fit_s"] = time.monotonic() - t_fit
            if not self.state["history"] or self.state["history"][-1]["runs"] != n:
                self.state["history"].append(hist)
                self._write_state()
            left = self.budget - n
            cvtxt = (f"CV RMSE {cv['rmse_pct']:.2f} % of range (max {cv['max_error_pct']:.2f} %, "
                     f"95 % coverage {100 * cv['coverage95']:.0f} %)" if cv else "CV: -")
            self._say(f"design: runs {n}/{self.budget}, {cvtxt}, target {self.target:g} %, "
                      f"elapsed {_fmt_t(time.monotonic() - self.t0)}, "
                      f"ETA {_fmt_t(self._eta(left))} (at most, the budget's)")
            if cv and cv["rmse_pct"] <= self.target and n >= self.min_runs:
                reason = "target"
                break
            if left <= 0:
                reason = "budget"
                break
            if em is None:
                raise DesignError("fewer than 3 ok runs after the start: nothing to fit "
                                  "(see the failed runs in the results)")
            k = min(self.n_workers, left)
            bi = len(self.state["batches"])
            rng = np.random.default_rng([self.seed, bi])
            have = set(self.results()[ID])
            batch = pick_batch(em, self.output, self.dists, self.fixed, k, rng, self.n_cand,
                               crest=self.crest, criterion=self.criterion)
            ids = self._add_scenarios(batch)
            ids = [i for i in ids if i not in have]
            if not ids:
                reason = "no new point"
                break
            self.state["batches"].append({"kind": self.criterion, "ids": ids})
            self._write_state()
        self.state["stopped"] = reason
        self._write_state()
        return {"runs": self.n_runs(), "reason": reason, "history": self.state["history"]}


def _dist_spec(d: S.Distribution) -> str:
    if d.kind == "choice":
        return "choice:" + ",".join(str(c) for c in d.choices)
    return d.kind + ":" + ":".join(repr(float(a)) for a in d.args)
