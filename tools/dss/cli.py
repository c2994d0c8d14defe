"""The command-line pieces tools/dss's commands share: the FMU's default path, NAME=VALUE
parsing, the run and cluster options, the run settings resolved from the arguments (and a
folder's saved sweep.json), and the usage error every command reports with exit code 2.

A module of its own so that the commands (__main__.py, sweep.py, emulate.py) import it and not
each other.
"""

from __future__ import annotations

import json
import os

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_FMU_CANDIDATES = ("build/LandslideWave.fmu", "build-dss/LandslideWave.fmu")
DEFAULT_DX = 0.03          # the default coarse resolution of a sweep (m); --dx to change
# outputs recorded over time in every run (results' column series; the runs on the page)
MONITOR_SERIES = ("run_up", "landslide_front", "kinetic_energy", "water_kinetic_energy", "dt")


class UsageError(Exception):
    """Bad usage or input: the commands print it and exit with 2."""


def default_fmu() -> str:
    env = os.environ.get("DSS_FMU")
    if env:
        return env
    for c in DEFAULT_FMU_CANDIDATES:
        p = os.path.join(ROOT, c)
        if os.path.isfile(p):
            return p
    return os.path.join(ROOT, DEFAULT_FMU_CANDIDATES[0])


def parse_value(s: str):
    from .scenarios import _num
    return _num(s)


def parse_sets(items) -> dict:
    from .scenarios import split_assignment
    out = {}
    for it in items or []:
        k, v = split_assignment(it)
        out[k] = parse_value(v)
    return out


def parse_box(items) -> dict:
    """--box NAME=lo:hi items -> {name: (lo, hi)}."""
    from .scenarios import split_assignment
    out = {}
    for it in items or []:
        k, v = split_assignment(it)
        parts = v.split(":")
        if len(parts) != 2:
            raise UsageError(f"--box {it}: expected NAME=lo:hi")
        out[k] = (float(parts[0]), float(parts[1]))
    return out


def parse_dists(items) -> dict:
    """--dist NAME=SPEC items -> {name: scenarios.Distribution}."""
    from .scenarios import Distribution, split_assignment
    return {k: Distribution(k, v) for k, v in (split_assignment(it) for it in items or [])}


def model_params(fmu_path: str):
    from fmpy import read_model_description
    md = read_model_description(fmu_path)
    return md, {v.name: v for v in md.modelVariables}


def enumeration_items(var) -> dict:
    """The FMU's Enumeration parameters: name -> {item name: value} (LandslideWave's rheology:
    paper 0, elastic_plastic 1)."""
    from .fmu_run import enumeration_items_of
    return {n: items for n, v in var.items() if v.causality == "parameter" and (items := enumeration_items_of(v))}


def item_value(name: str, value, items: dict):
    """value of parameter `name` with an Enumeration's item name replaced by its value (a sweep's
    tables, its scenario ids and the emulator hold numbers); other values as they are."""
    its = items.get(name)
    if its is None or not isinstance(value, str):
        return value
    if value in its:
        return its[value]
    try:
        return int(float(value)) if float(value).is_integer() else value
    except ValueError:
        raise UsageError(f"{name} = {value!r} is not one of its items: "
                         + ", ".join(f"{k} ({v})" for k, v in its.items())) from None


def item_values(params: dict, items: dict) -> dict:
    """params with item names replaced by their values (item_value)."""
    return {k: item_value(k, v, items) for k, v in params.items()}


def item_choices(dists, items: dict):
    """The choices of choice distributions of Enumeration parameters as their items' values (in
    place); the distributions."""
    for d in dists:
        if getattr(d, "kind", None) == "choice":
            d.choices = [item_value(d.name, c, items) for c in d.choices]
    return dists


def fmu_items(fmu_path: str | None) -> dict:
    """enumeration_items of the FMU at fmu_path; {} when it cannot be read (numbers only then)."""
    try:
        return enumeration_items(model_params(fmu_path)[1]) if fmu_path and os.path.isfile(fmu_path) else {}
    except Exception:
        return {}


def common_cluster_args(p):
    g = p.add_argument_group("cluster")
    g.add_argument("--scheduler", metavar="ADDR",
                   help="address of an existing Dask scheduler (tcp://host:8786) or a scheduler "
                        "JSON file; default: an embedded local cluster")
    g.add_argument("--workers", type=int, metavar="N",
                   help="workers of the local cluster (default: the machine's cores)")
    g.add_argument("--upload-code", action="store_true",
                   help="upload the worker module to the scheduler and the workers "
                        "(Client.upload_file): workers need fmpy and distributed, not this repository")


def common_run_args(p):
    p.add_argument("--fmu", help="the FMU (default: $DSS_FMU, else build/LandslideWave.fmu)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a parameter fixed in every scenario (repeatable)")
    p.add_argument("--stop-time", type=float, metavar="T",
                   help="simulated time (s; default the FMU's DefaultExperiment stopTime)")
    p.add_argument("--step", type=float, metavar="H",
                   help="communication step (s; default 0.05)")
    p.add_argument("--dx", type=float, metavar="DX",
                   help=f"particle spacing when the FMU has a dx parameter and no --set/axis gives "
                        f"it (default {DEFAULT_DX}, the coarse sweep resolution)")
    p.add_argument("--threads", type=int, default=1, metavar="N",
                   help="OpenMP threads per scenario, set on the FMU's 'threads' parameter (default 1)")
    p.add_argument("--timeout", type=float, default=0.0, metavar="S",
                   help="wall seconds after which a scenario is stopped and recorded as failed")
    p.add_argument("--format", choices=("parquet", "csv"), help="results table format (default parquet)")
    p.add_argument("--quiet", action="store_true", help="no progress display")


def load_settings(out):
    p = os.path.join(out, "sweep.json")
    if os.path.isfile(p):
        with open(p) as f:
            return json.load(f)
    return {}


def save_json(path, obj):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(obj, f, indent=2)
    os.replace(tmp, path)


def resolve_run(args, saved=None):
    """fmu path, fixed params, opts, format from the arguments (and a previous sweep's settings)."""
    saved = saved or {}
    fmu = args.fmu or saved.get("fmu") or default_fmu()
    if not os.path.isfile(fmu):
        raise UsageError(f"FMU {fmu} not found: build it (cmake --build build --target fmu) "
                         f"or give --fmu / DSS_FMU")
    stop = args.stop_time if args.stop_time is not None else saved.get("stop_time")
    step = args.step if args.step is not None else saved.get("step", 0.05)
    dx = args.dx if args.dx is not None else saved.get("dx", DEFAULT_DX)
    fixed = dict(saved.get("fixed", {})) if not args.set else {}
    fixed.update(parse_sets(args.set))
    md, var = model_params(fmu)
    fixed = item_values(fixed, enumeration_items(var))
    if stop is None:
        de = md.defaultExperiment
        stop = float(de.stopTime) if de is not None and de.stopTime else None
        if stop is None:
            raise UsageError("the FMU has no default stop time: give --stop-time")
    # the monitors over time the FMU has, recorded at every communication point for the runs'
    # page (tools/dss/html_report.py)
    series = [n for n in MONITOR_SERIES if n in var and var[n].causality == "output"]
    opts = {"stop_time": float(stop), "step": float(step), "threads": args.threads,
            "timeout": args.timeout, "series": series}
    return fmu, fixed, opts, md, var, dx
