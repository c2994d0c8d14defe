"""Readers of the files a ``mixsph run`` writes into its output folder (docs/output.md).

    import mixsph_tools as mt
    mon = mt.read_monitors("out/x/monitors.csv")        # {"t": array, "water_front": array, ...}
    summ = mt.read_summary("out/x/summary.json")        # dict; JSON null -> nan in "outputs"
    prof = mt.find_profile("out/x", "interface", 0.5)   # Profile or None (not written)
    t, snap = mt.read_snapshot("out/x/snap_0003.csv")  # (time, {"x": array, ...}); list_snapshots
                                                        # gives run.h5 snapshots of --no-csv runs;
                                                        # snapshot_dim(snap): 2, or 3 (with "y")

Every reader raises ``ToolError`` with a message naming the file and what is wrong; the scripts
catch it and print it (no traceback for a user's mistake).

File formats (cli/main.c, lib/src/io/monitors.c):

- ``monitors.csv``: header ``t,step,<output>...``, one row per monitor interval, ``nan`` where a
  monitor has no value (e.g. no particle in its window);
- ``summary.json``: ``status`` ("ok" or the failure), ``wall_time_s`` (this process),
  ``run_wall_time_s`` (the run over all its pieces, see ``run_wall_time``), ``particle_steps_per_s``,
  ``simulated_time_s``, ``threads``, ``outputs{name: {final, max, t_max, min, t_min}}`` (null when
  the output never had a value);
- ``profile_<name>_<k>.csv``: first line ``# profile <name> of <medium> at t = <t> s (requested
  <t_req> s): ...``, then ``x,z_top`` per x bin (``nan`` where the bin holds no particle).
"""

import glob
import json
import math
import os
import re
from dataclasses import dataclass

import numpy as np


class ToolError(Exception):
    """A readable problem with an input file or an option (the message names it); ``code`` is the
    exit status a script ends with on it (2: bad usage or input)."""

    def __init__(self, message, code=2):
        super().__init__(message)
        self.code = code


def read_monitors(path):
    """Columns of monitors.csv as a dict of float arrays (at least 't')."""
    if not os.path.isfile(path):
        raise ToolError(f"{path} not found")
    with open(path) as f:
        lines = f.read().splitlines()
    if not lines:
        raise ToolError(f"{path}: empty")
    header = lines[0].strip().split(",")
    body = [(n, ln.strip()) for n, ln in enumerate(lines[1:], start=2) if ln.strip()]
    rows = []
    for k, (lineno, line) in enumerate(body):
        parts = line.split(",")
        if len(parts) != len(header):
            if k == len(body) - 1:
                break  # a run still writing (or killed) may leave a partial last line
            raise ToolError(f"{path}:{lineno}: {len(parts)} fields but {len(header)} names in the header")
        try:
            rows.append([float(v) for v in parts])
        except ValueError as e:
            if k == len(body) - 1:
                break
            raise ToolError(f"{path}:{lineno}: not a number: {e}") from None
    if "t" not in header:
        raise ToolError(f"{path}: no column 't' (header: {','.join(header)})")
    data = np.array(rows, dtype=float).reshape(len(rows), len(header))
    return {name: data[:, k] for k, name in enumerate(header)}


def read_summary(path):
    """summary.json as a dict; the numbers of 'outputs' that are null become nan."""
    if not os.path.isfile(path):
        raise ToolError(f"{path} not found")
    try:
        with open(path) as f:
            s = json.load(f)
    except (OSError, ValueError) as e:
        raise ToolError(f"{path}: cannot read: {e}") from None
    if not isinstance(s, dict) or "status" not in s:
        raise ToolError(f"{path}: not a mixsph summary (no 'status')")
    outs = s.get("outputs") or {}
    for name, rec in outs.items():
        if isinstance(rec, dict):
            for k, v in rec.items():
                if v is None:
                    rec[k] = math.nan
    s["outputs"] = outs
    return s


def summary_value(summary, output, field):
    """summary['outputs'][output][field] as float, nan when absent."""
    rec = summary.get("outputs", {}).get(output)
    if not isinstance(rec, dict):
        return math.nan
    v = rec.get(field)
    return float(v) if isinstance(v, (int, float)) else math.nan


@dataclass
class Profile:
    path: str
    name: str
    t: float            # time the profile was taken [s]
    t_requested: float  # time the case asked for [s]
    x: np.ndarray       # bin centres [m]
    z: np.ndarray       # top of the medium per bin [m], nan where empty


_PROFILE_HEAD = re.compile(r"#\s*profile\s+(\S+).*?\bat t\s*=\s*([-+0-9.eE]+)\s*s\s*\(requested\s+([-+0-9.eE]+)\s*s\)")


def read_profile(path):
    """One profile_<name>_<k>.csv."""
    if not os.path.isfile(path):
        raise ToolError(f"{path} not found")
    with open(path) as f:
        first = f.readline()
        header = f.readline().strip()
    m = _PROFILE_HEAD.match(first)
    if not m:
        raise ToolError(f"{path}: first line '{first.strip()}' is not "
                        "'# profile NAME of MEDIUM at t = T s (requested T s) ...'")
    if header != "x,z_top":
        raise ToolError(f"{path}: second line '{header}' is not 'x,z_top'")
    try:
        data = np.loadtxt(path, delimiter=",", skiprows=2, ndmin=2)
    except ValueError as e:
        raise ToolError(f"{path}: cannot read: {e}") from None
    if data.size == 0:
        data = np.zeros((0, 2))
    if data.shape[1] != 2:
        raise ToolError(f"{path}: {data.shape[1]} columns, expected 2 (x,z_top)")
    return Profile(path, m.group(1), float(m.group(2)), float(m.group(3)), data[:, 0], data[:, 1])


def find_profile(outdir, name, t_requested, tol=1e-9):
    """The profile <name> that the case requested at t_requested, or None if it was not written."""
    for path in sorted(glob.glob(os.path.join(outdir, f"profile_{glob.escape(name)}_*.csv"))):
        if not re.fullmatch(rf"profile_{re.escape(name)}_\d+\.csv", os.path.basename(path)):
            continue
        p = read_profile(path)
        if abs(p.t_requested - t_requested) <= tol * max(1.0, abs(t_requested)):
            return p
    return None


def first_time_below(t, v, threshold):
    """First t at which v < threshold (nan values never count), nan if never."""
    idx = np.flatnonzero(np.isfinite(v) & (v < threshold))
    return float(t[idx[0]]) if idx.size else math.nan


_SNAP_HEAD = re.compile(r"#\s*t\s*=\s*([-+0-9.eE]+)\s*s")
# The columns every snapshot has, in this order in 2D (the core fields of the particle-field table,
# lib/src/core/particle_fields.c; a 3D snapshot also has y after x and vy after vx); a snapshot of
# a simulation whose material law or scheme declares fields of its own has more, named by its
# header. tests/python/test_particle_fields.py checks this against the C table.
SNAP_COLUMNS = ("id", "x", "z", "vx", "vz", "rho", "p", "mu", "medium", "state")
# The axes of a vector's components by dimension, the vertical last (lib/src/core/dim.h): a run's
# dimension is the number of components of its positions (snapshot_dim).
AXES = {2: ("x", "z"), 3: ("x", "y", "z")}
# The components of a symmetric tensor (the deviatoric stress) in the order of dim.h: the 2D
# (plane strain) ones, the out-of-plane yy included, then the two that vanish in 2D.
SYM_AXES = ("xx", "xz", "zz", "yy", "xy", "yz")
SYM_N = {2: 4, 3: 6}
# run.h5 datasets whose columns are not the dataset's own name (a scalar dataset named as its
# column, e.g. a law's "tau_y", needs no entry; another dataset of several components gives NAME_0,
# NAME_1, ...): scalars by their column, vectors (DIM components) and symmetric tensors (SYM_N)
# by the prefix of their columns. tests/python/test_particle_fields.py checks every row of the C
# table against them. A run.h5 of format 1 held the stress as the scalars sxx, sxz, szz, syy:
# they are read as the columns of the same names.
H5_SCALARS = {"density": "rho", "pressure": "p", "viscosity": "mu", "mass": "m"}
H5_VECTORS = {"position": "", "velocity": "v"}
H5_TENSORS = {"stress": "s"}


def h5_columns(name, components, dim=2):
    """The snapshot columns of a run.h5 dataset `name` of `components` components (1: scalar) in a
    run of dimension `dim` (snapshot_dim)."""
    if components == 1 and name in H5_SCALARS:
        return (H5_SCALARS[name],)
    if name in H5_VECTORS and components == dim:
        return tuple(H5_VECTORS[name] + a for a in AXES[dim])
    if name in H5_TENSORS and components == SYM_N[dim]:
        return tuple(H5_TENSORS[name] + a for a in SYM_AXES[:components])
    return (name,) if components == 1 else tuple(f"{name}_{k}" for k in range(components))


def snapshot_dim(snap):
    """The dimension (2 or 3) of a snapshot as read_snapshot returns it: 3 when it has y."""
    return 3 if "y" in snap else 2


STATE_MOBILE, STATE_FIXED, STATE_WALL, STATE_LOST = 0, 1, 2, 3


def snapshot_time(path):
    """Simulated time [s] of a snap_NNNN.csv (its first line '# t = <t> s')."""
    try:
        with open(path) as f:
            first = f.readline()
    except OSError as e:
        raise ToolError(f"{path}: cannot read: {e}") from None
    m = _SNAP_HEAD.match(first)
    if not m:
        raise ToolError(f"{path}: first line '{first.strip()}' is not '# t = T s'")
    return float(m.group(1))


H5_REF = "::"   # a snapshot in run.h5: "<folder>/run.h5::<group name under /snapshots>"


def list_snapshots(outdir):
    """[(t, ref)] of the snapshots of an output folder, by time: its snap_NNNN.csv files (ref: the
    path), or, when it has none (a run with ``--no-csv``), the complete snapshots of its run.h5
    (ref: ``<folder>/run.h5::<group>``). ``read_snapshot`` reads either."""
    snaps = []
    for path in glob.glob(os.path.join(glob.escape(outdir), "snap_*.csv")):
        if re.fullmatch(r"snap_\d+\.csv", os.path.basename(path)):
            snaps.append((snapshot_time(path), path))
    if not snaps and os.path.isfile(os.path.join(outdir, "run.h5")):
        snaps = _h5_snapshots(os.path.join(outdir, "run.h5"))
    return sorted(snaps)


def _h5_snapshots(path):
    """[(t, ref)] of the complete snapshots of a run.h5 (a group with its time and positions)."""
    import h5py
    try:
        with h5py.File(path, "r", locking=False) as f:
            groups = f.get("snapshots")
            if groups is None:
                return []
            return [(float(g.attrs["time"]), f"{path}{H5_REF}{name}") for name, g in groups.items()
                    if "time" in g.attrs and all(d in g for d in ("position", "velocity", "state"))]
    except (OSError, KeyError) as e:
        raise ToolError(f"{path}: cannot read its snapshots: {e}") from None


def _read_h5_snapshot(ref):
    """(t, {column: array}) of a run.h5 snapshot: every dataset of its group, split into the
    columns of the CSV snapshots (h5_columns), rows by id."""
    import h5py
    path, name = ref.split(H5_REF, 1)
    try:
        with h5py.File(path, "r", locking=False) as f:
            g = f["snapshots"][name]
            dim = g["position"].shape[1] if g["position"].ndim == 2 else 0
            if dim not in AXES:
                raise ToolError(f"{path}: snapshot {name}: positions of shape {g['position'].shape}, "
                                f"expected (n, 2) or (n, 3)")
            cols = {}
            for dname, d in g.items():
                if not isinstance(d, h5py.Dataset) or d.ndim not in (1, 2):
                    continue
                v = d[()]
                if d.ndim == 1:
                    v = v[:, None]
                for k, col in enumerate(h5_columns(dname, v.shape[1], dim)):
                    cols[col] = v[:, k]
            t = float(g.attrs["time"])
    except (OSError, KeyError) as e:
        raise ToolError(f"{path}: cannot read snapshot {name}: {e}") from None
    missing = [c for c in SNAP_COLUMNS if c not in cols]
    if missing:
        raise ToolError(f"{path}: snapshot {name} has no column {', '.join(missing)}")
    return t, {k: np.asarray(v, dtype=float) for k, v in cols.items()}


def read_snapshot(path):
    """(t, {column: array}) of one snapshot of list_snapshots: a snap_NNNN.csv (the columns its
    header names: SNAP_COLUMNS and any a material law or scheme adds) or a run.h5 snapshot (the
    same columns, and the fields run.h5 has beyond the CSV, such as the mass m)."""
    if H5_REF in path:
        return _read_h5_snapshot(path)
    t = snapshot_time(path)
    with open(path) as f:
        f.readline()
        header = f.readline().strip().split(",")
    missing = [c for c in SNAP_COLUMNS if c not in header]
    if missing or len(set(header)) != len(header) or not all(header):
        raise ToolError(f"{path}: second line '{','.join(header)}' is not a header of distinct names with "
                        f"the columns {','.join(SNAP_COLUMNS)}")
    try:
        data = np.loadtxt(path, delimiter=",", skiprows=2, ndmin=2)
    except ValueError as e:
        raise ToolError(f"{path}: cannot read: {e}") from None
    if data.size and data.shape[1] != len(header):
        raise ToolError(f"{path}: {data.shape[1]} columns, the header names {len(header)}")
    data = data.reshape(-1, len(header))
    return t, {name: data[:, k] for k, name in enumerate(header)}


def nearest_snapshot(outdir, t):
    """(t_snap, path) of the snapshot closest in time to t, or None when there is none."""
    snaps = list_snapshots(outdir)
    if not snaps:
        return None
    return min(snaps, key=lambda s: abs(s[0] - t))


def checkpoint_time(path):
    """Simulated time [s] of a checkpoint file (its ``time`` attribute); nan if unreadable."""
    try:
        import h5py
        with h5py.File(path, "r") as f:
            return float(f.attrs["time"])
    except Exception:   # noqa: BLE001 - only for a progress estimate
        return math.nan


def run_particle_steps_per_s(summary):
    """Particle-steps per second of a whole run (all its pieces, see ``run_wall_time``)."""
    if "restarted_from" not in summary:
        v = summary.get("particle_steps_per_s")
        return float(v) if isinstance(v, (int, float)) else math.nan
    try:
        return float(summary["particles"]) * float(summary["steps"]) / run_wall_time(summary)
    except (KeyError, TypeError, ValueError, ZeroDivisionError):
        return math.nan


def run_wall_time(summary):
    """The wall time of a whole run from its summary.json: ``run_wall_time_s`` (the time spent
    stepping, over all its pieces when it was continued from checkpoints), else ``wall_time_s``
    for a run made in one piece; nan for a continued run whose first pieces' time is unknown
    (a checkpoint of a build that did not record it)."""
    w = summary.get("run_wall_time_s")
    if isinstance(w, (int, float)) and math.isfinite(w):
        return float(w)
    if "restarted_from" in summary:
        return math.nan
    w = summary.get("wall_time_s")
    return float(w) if isinstance(w, (int, float)) else math.nan


def last_time(monitors_csv):
    """Simulated time of the last complete line of a growing monitors.csv (nan if none)."""
    try:
        with open(monitors_csv, "rb") as f:
            f.seek(0, os.SEEK_END)
            n = f.tell()
            f.seek(max(0, n - 4096))
            raw = f.read()
    except OSError:
        return math.nan
    lines = raw.decode(errors="replace").split("\n")
    lines = lines[1:-1] if n > 4096 else lines[:-1]   # drop a cut first line and the unfinished last one
    for line in reversed(lines):
        try:
            return float(line.split(",", 1)[0])
        except ValueError:
            continue
    return math.nan


def tail(path, n=8):
    """The last n lines of a text file ([] if it cannot be read)."""
    try:
        with open(path, errors="replace") as f:
            return f.read().splitlines()[-n:]
    except OSError:
        return []
