"""The Python readers against the particle-field table of the C library
(lib/src/core/particle_fields.c) and against files with fields the readers were not told of.

- every row of the C table that run.h5 holds gets, from mixsph_tools.h5_columns, exactly the
  columns the C row names (its struct members), and SNAP_COLUMNS are the first columns of every
  CSV snapshot, in the C writer's order (key rows first, then table order);
- a CSV snapshot and a run.h5 snapshot with a field a material law declares (a scalar "tau_y", a
  field "tau" of 4 components) are read with it, from what the file declares; the stress dataset
  (n, 4) and a format-1 run.h5's scalars sxx, sxz, szz, syy give the same columns; a 3D run.h5
  (positions (n, 3)) gives x, y, z.

The C table is read from its source: its rows are `{.name = "...", COMPONENTS1(a) | VECTOR(v,
"prefix") | STRESS(s, "prefix"), ..., .where = ...}` initialisers (the test fails, naming the file,
if that form changes); a VECTOR's columns are the prefix and each axis of the dimension, a
STRESS's the prefix and each component of a symmetric tensor (lib/src/core/dim.h).
"""
import os
import re
import sys

import h5py
import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import mixsph_tools as mt  # noqa: E402
from mixsph_tools import readers  # noqa: E402

TABLE = os.path.join(ROOT, "lib", "src", "core", "particle_fields.c")
ROW = re.compile(r'\{\s*\.name\s*=\s*"(\w+)",\s*(COMPONENTS1|VECTOR|STRESS)\(([^)]*)\)(.*?)\},?\s*$', re.S | re.M)


def row_columns(kind, args, dim):
    """The columns of a C table row's COMPONENTS1(a), VECTOR(v, "prefix") or STRESS(s, "prefix")
    in a build of dimension dim."""
    args = [a.strip() for a in args.split(",")]
    if kind == "COMPONENTS1":
        assert len(args) == 1, f"{TABLE}: COMPONENTS1({args})"
        return (args[0],)
    assert len(args) == 2 and args[1].startswith('"') and args[1].endswith('"'), f"{TABLE}: {kind}({args})"
    prefix = args[1][1:-1]
    axes = readers.AXES[dim] if kind == "VECTOR" else readers.SYM_AXES[:readers.SYM_N[dim]]
    return tuple(prefix + a for a in axes)


def c_rows(dim=2):
    """[(name, columns, where flags, needs)] of the C table in a build of dimension dim, in order."""
    with open(TABLE) as f:
        text = f.read()
    body = text[text.index("particle_fields[] = {"):]
    body = body[:body.index("\n};")]
    rows = []
    for m in ROW.finditer(body):
        cols = row_columns(m.group(2), m.group(3), dim)
        rest = m.group(4)
        where = re.search(r"\.where\s*=\s*([^,}]+)", rest)
        assert where, f"{TABLE}: row {m.group(1)} has no .where"
        flags = set(re.findall(r"\w+", where.group(1)))
        if "OUT" in flags:   # the table's own shorthand for a snapshot field
            flags |= {"PF_STATE", "PF_HDF5", "PF_CSV", "PF_VIEW"}
        rows.append((m.group(1), cols, flags, ".needs" in rest))
    assert len(rows) == body.count(".name"), f"{TABLE}: {body.count('.name')} rows, {len(rows)} parsed"
    return rows


@pytest.mark.parametrize("dim", [2, 3])
def test_h5_columns_match_the_c_table(dim):
    rows = c_rows(dim)
    assert len(rows) >= 9
    for name, cols, flags, _ in rows:
        if "PF_HDF5" in flags:
            assert mt.h5_columns(name, len(cols), dim) == cols, name
    # no stale entry: every name the readers know is a run.h5 row of the table
    h5 = {name for name, cols, flags, _ in rows if "PF_HDF5" in flags}
    for name in (*readers.H5_SCALARS, *readers.H5_VECTORS, *readers.H5_TENSORS):
        assert name in h5, name


def test_snap_columns_are_the_core_csv_columns_in_writer_order():
    # the first columns of every CSV snapshot (rows needing no feature; a field every simulation
    # has may be added after them)
    rows = [r for r in c_rows() if "PF_CSV" in r[2] and not r[3]]
    order = [r for r in rows if "PF_KEY" in r[2]] + [r for r in rows if "PF_KEY" not in r[2]]
    assert mt.SNAP_COLUMNS == tuple(c for r in order for c in r[1])[:len(mt.SNAP_COLUMNS)]


def write_csv(path, t, cols):
    names = list(cols)
    with open(path, "w") as f:
        f.write(f"# t = {t:.9g} s\n" + ",".join(names) + "\n")
        for i in range(len(cols[names[0]])):
            f.write(",".join(f"{cols[k][i]:.9g}" for k in names) + "\n")


def core_columns(n):
    rng = np.random.default_rng(3)
    cols = {c: rng.uniform(0, 1, n) for c in mt.SNAP_COLUMNS}
    cols["id"] = np.arange(n, dtype=float)
    cols["medium"] = np.zeros(n)
    cols["state"] = np.zeros(n)
    return cols


def test_csv_snapshot_with_a_law_field(tmp_path):
    cols = core_columns(5)
    cols["tau_y"] = np.linspace(-1e3, 1e3, 5)
    path = tmp_path / "snap_0000.csv"
    write_csv(path, 0.25, cols)
    t, snap = mt.read_snapshot(str(path))
    assert t == 0.25 and set(snap) == set(cols)
    np.testing.assert_allclose(snap["tau_y"], cols["tau_y"], rtol=1e-8)
    assert mt.snapshot_dim(snap) == 2
    # a header without a core column, or with a repeated name, is refused naming the file
    del cols["rho"]
    write_csv(path, 0.25, cols)
    with pytest.raises(mt.ToolError, match="snap_0000.csv.*rho"):
        mt.read_snapshot(str(path))


def write_h5_snapshot(path, n, dim, fields):
    """A run.h5 of one snapshot at t = 0.5 with the core datasets of a run of dimension dim
    (positions: x = k, the vertical -k, y = 10 k) and `fields` {name: array} besides."""
    with h5py.File(path, "w") as f:
        g = f.create_group("snapshots/000000")
        g.attrs["time"] = 0.5
        k = np.arange(n, dtype=float)
        g["position"] = np.c_[k, -k] if dim == 2 else np.c_[k, 10 * k, -k]
        g["velocity"] = np.zeros((n, dim))
        for d in ("density", "pressure", "viscosity", "mass"):
            g[d] = np.ones(n)
        for d in ("medium", "state"):
            g[d] = np.zeros(n, np.uint8)
        g["id"] = np.arange(n, dtype=np.uint32)
        for name, v in fields.items():
            g[name] = v


def test_h5_snapshot_with_law_fields(tmp_path):
    n = 4
    tau = np.arange(4 * n, dtype=float).reshape(n, 4)
    write_h5_snapshot(tmp_path / "run.h5", n, 2, {"tau_y": np.full(n, 7.0), "tau": tau})
    (t, ref), = mt.list_snapshots(str(tmp_path))
    t2, snap = mt.read_snapshot(ref)
    assert t == t2 == 0.5
    assert set(mt.SNAP_COLUMNS) | {"m", "tau_y", "tau_0", "tau_1", "tau_2", "tau_3"} == set(snap)
    np.testing.assert_array_equal(snap["z"], -np.arange(n))
    np.testing.assert_array_equal(snap["tau_y"], 7.0)
    np.testing.assert_array_equal(snap["tau_2"], tau[:, 2])
    assert mt.snapshot_dim(snap) == 2


def test_h5_stress_now_and_in_format_1(tmp_path):
    # format 2: one dataset "stress" (n, 4) in 2D; format 1: the scalars sxx, sxz, szz, syy
    n = 3
    stress = np.arange(4 * n, dtype=float).reshape(n, 4)
    names = ("sxx", "sxz", "szz", "syy")
    (tmp_path / "new").mkdir()
    (tmp_path / "old").mkdir()
    write_h5_snapshot(tmp_path / "new" / "run.h5", n, 2, {"stress": stress})
    write_h5_snapshot(tmp_path / "old" / "run.h5", n, 2, {c: stress[:, k] for k, c in enumerate(names)})
    snaps = [mt.read_snapshot(mt.list_snapshots(str(tmp_path / d))[0][1])[1] for d in ("new", "old")]
    for snap in snaps:
        for k, c in enumerate(names):
            np.testing.assert_array_equal(snap[c], stress[:, k])
        assert "stress_0" not in snap


def test_h5_snapshot_of_a_3d_run(tmp_path):
    n = 3
    write_h5_snapshot(tmp_path / "run.h5", n, 3, {"stress": np.ones((n, 6))})
    _, snap = mt.read_snapshot(mt.list_snapshots(str(tmp_path))[0][1])
    assert mt.snapshot_dim(snap) == 3
    assert {"x", "y", "z", "vx", "vy", "vz", "sxx", "sxz", "szz", "syy", "sxy", "syz"} <= set(snap)
    np.testing.assert_array_equal(snap["y"], 10 * np.arange(n))
    np.testing.assert_array_equal(snap["z"], -np.arange(n))
