"""Scenario tables: a grid, random or Latin-hypercube samples of parameter distributions, or a CSV.

A scenario is a dict parameter name -> value. Its id is a hash of its values (and the stop
time of the sweep), so the same scenario always gets the same id: that is what makes a sweep
resumable (a re-run skips the ids that already have a result).

Specifications (command line):
  grid      NAME=v1,v2,...        explicit values
            NAME=lo:hi:n          n values evenly spaced from lo to hi
  sampled   NAME=uniform:lo:hi    (random, lhs)
            NAME=loguniform:lo:hi
            NAME=normal:mean:sd   (optionally :lo:hi to truncate by clipping)
            NAME=choice:a,b,c     equal probability
  fixed     NAME=value            the same in every scenario
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math

import numpy as np
import pandas as pd

ID = "scenario_id"


def _num(s: str):
    s = s.strip()
    try:
        x = float(s)
    except ValueError:
        return s
    return int(x) if x.is_integer() and "." not in s and "e" not in s.lower() else x


def split_assignment(text: str) -> tuple[str, str]:
    if "=" not in text:
        raise ValueError(f"expected NAME=SPEC, got {text!r}")
    name, spec = text.split("=", 1)
    name = name.strip()
    if not name:
        raise ValueError(f"empty parameter name in {text!r}")
    return name, spec.strip()


def grid_values(spec: str) -> list:
    """Values of one grid axis: 'a,b,c' or 'lo:hi:n'."""
    if ":" in spec and "," not in spec:
        parts = spec.split(":")
        if len(parts) != 3:
            raise ValueError(f"grid range must be lo:hi:n, got {spec!r}")
        lo, hi, n = float(parts[0]), float(parts[1]), int(parts[2])
        if n < 1:
            raise ValueError(f"grid range {spec!r}: n must be >= 1")
        return [float(x) for x in np.linspace(lo, hi, n)] if n > 1 else [lo]
    vals = [_num(x) for x in spec.split(",") if x.strip() != ""]
    if not vals:
        raise ValueError(f"empty grid axis {spec!r}")
    return vals


class Distribution:
    """One parameter's distribution; ppf maps u in (0,1) to a value."""

    def __init__(self, name: str, spec: str):
        self.name = name
        kind, _, rest = spec.partition(":")
        self.kind = kind.strip().lower()
        if self.kind == "choice":
            self.choices = [_num(x) for x in rest.split(",") if x.strip() != ""]
            if not self.choices:
                raise ValueError(f"{name}: choice needs values")
            return
        try:
            args = [float(x) for x in rest.split(":")] if rest else []
        except ValueError:
            raise ValueError(f"{name}: bad numbers in {spec!r}") from None
        if self.kind in ("uniform", "loguniform"):
            if len(args) != 2 or not args[0] < args[1]:
                raise ValueError(f"{name}: {self.kind} needs lo:hi with lo < hi, got {spec!r}")
            if self.kind == "loguniform" and args[0] <= 0:
                raise ValueError(f"{name}: loguniform needs lo > 0")
        elif self.kind == "normal":
            if len(args) not in (2, 4) or args[1] <= 0:
                raise ValueError(f"{name}: normal needs mean:sd[:lo:hi] with sd > 0, got {spec!r}")
        else:
            raise ValueError(f"{name}: unknown distribution {kind!r} (uniform, loguniform, normal, choice)")
        self.args = args

    def ppf(self, u: np.ndarray) -> list:
        u = np.asarray(u, dtype=float)
        if self.kind == "choice":
            idx = np.minimum((u * len(self.choices)).astype(int), len(self.choices) - 1)
            return [self.choices[i] for i in idx]
        a = self.args
        if self.kind == "uniform":
            x = a[0] + u * (a[1] - a[0])
        elif self.kind == "loguniform":
            x = np.exp(math.log(a[0]) + u * (math.log(a[1]) - math.log(a[0])))
        else:
            from scipy.stats import norm
            x = norm.ppf(u, loc=a[0], scale=a[1])
            if len(a) == 4:
                x = np.clip(x, a[2], a[3])
        return [float(v) for v in x]


def grid(axes: dict[str, list], fixed: dict | None = None) -> list[dict]:
    """Every combination of the axes (the first axis varies slowest)."""
    names = list(axes)
    out = []
    for combo in itertools.product(*(axes[n] for n in names)):
        s = dict(fixed or {})
        s.update(dict(zip(names, combo)))
        out.append(s)
    return out


def sample(dists: list[Distribution], n: int, method: str = "lhs", seed: int = 0,
           fixed: dict | None = None) -> list[dict]:
    """n scenarios drawn from the distributions: 'random' (independent uniforms) or 'lhs'
    (Latin hypercube, scipy.stats.qmc) mapped through each distribution's quantile function."""
    if n < 1:
        raise ValueError("the number of samples must be >= 1")
    d = len(dists)
    if d == 0:
        raise ValueError("sampling needs at least one distribution (--dist NAME=SPEC)")
    if method == "lhs":
        from scipy.stats import qmc
        u = qmc.LatinHypercube(d=d, seed=seed).random(n)
    elif method == "random":
        u = np.random.default_rng(seed).random((n, d))
    else:
        raise ValueError(f"unknown sampling method {method!r} (random, lhs)")
    cols = [dist.ppf(u[:, j]) for j, dist in enumerate(dists)]
    out = []
    for i in range(n):
        s = dict(fixed or {})
        s.update({dist.name: cols[j][i] for j, dist in enumerate(dists)})
        out.append(s)
    return out


def from_csv(path: str, fixed: dict | None = None) -> list[dict]:
    """One scenario per row; every column is a parameter (a scenario_id column is ignored)."""
    df = pd.read_csv(path)
    df = df.drop(columns=[c for c in df.columns if c == ID])
    if df.empty:
        raise ValueError(f"{path}: no scenarios")
    out = []
    for rec in df.to_dict(orient="records"):
        s = dict(fixed or {})
        s.update({k: _plain(v) for k, v in rec.items()})
        out.append(s)
    return out


def _plain(v):
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (np.floating,)):
        return float(v)
    if isinstance(v, (np.bool_,)):
        return bool(v)
    return v


def _canon(v):
    v = _plain(v)
    if isinstance(v, bool):
        return int(v)
    if isinstance(v, (int, float)):
        return float(repr(float(v))) if not float(v).is_integer() else int(v)
    return str(v)


def scenario_id(params: dict, stop_time: float | None) -> str:
    """A stable id of the scenario: the same values (and stop time) give the same id."""
    key = {k: _canon(params[k]) for k in sorted(params)}
    key["__stop_time"] = None if stop_time is None else _canon(stop_time)
    h = hashlib.sha1(json.dumps(key, sort_keys=True).encode()).hexdigest()
    return h[:12]


def table(scenarios: list[dict], stop_time: float | None) -> pd.DataFrame:
    """The scenario table: scenario_id first, then the parameters; duplicates dropped."""
    rows = []
    seen = set()
    for s in scenarios:
        sid = scenario_id(s, stop_time)
        if sid in seen:
            continue
        seen.add(sid)
        rows.append({ID: sid, **s})
    return pd.DataFrame(rows)
