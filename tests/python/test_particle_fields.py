"""The Python readers against the particle-field table of the C library
(lib/src/core/particle_fields.c) and against files with fields the readers were not told of.

- every row of the C table that run.h5 holds gets, from mixsph_tools.h5_columns, exactly the
  columns the C row names (its struct members), and SNAP_COLUMNS are the first columns of every
  CSV snapshot, in the C writer's order (key rows first, then table order);
- a CSV snapshot and a run.h5 snapshot with a field a material law declares (a scalar "sxx", a
  vector "tau" of 4 components) are read with it, from what the file declares.

The C table is read from its source: its rows are `{.name = "...", COMPONENTSn(a, b, ...), ...,
.where = ...}` initialisers (the test fails, naming the file, if that form changes).
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
ROW = re.compile(r'\{\s*\.name\s*=\s*"(\w+)",\s*COMPONENTS(\d)\(([^)]*)\)(.*?)\},?\s*$', re.S | re.M)


def c_rows():
    """[(name, columns, where flags, needs)] of the C table, in order."""
    with open(TABLE) as f:
        text = f.read()
    body = text[text.index("particle_fields[] = {"):]
    body = body[:body.index("\n};")]
    rows = []
    for m in ROW.finditer(body):
        cols = tuple(c.strip() for c in m.group(3).split(","))
        assert len(cols) == int(m.group(2)), f"{TABLE}: row {m.group(1)}: COMPONENTS{m.group(2)} of {cols}"
        rest = m.group(4)
        where = re.search(r"\.where\s*=\s*([^,}]+)", rest)
        assert where, f"{TABLE}: row {m.group(1)} has no .where"
        flags = set(re.findall(r"\w+", where.group(1)))
        if "OUT" in flags:   # the table's own shorthand for a snapshot field
            flags |= {"PF_STATE", "PF_HDF5", "PF_CSV", "PF_VIEW"}
        rows.append((m.group(1), cols, flags, ".needs" in rest))
    assert len(rows) == body.count(".name"), f"{TABLE}: {body.count('.name')} rows, {len(rows)} parsed"
    return rows


def test_h5_columns_match_the_c_table():
    rows = c_rows()
    assert len(rows) >= 9
    for name, cols, flags, _ in rows:
        if "PF_HDF5" in flags:
            assert mt.h5_columns(name, len(cols)) == cols, name
    # no stale entry: every alias names a run.h5 row of the table with those columns
    h5 = {name: cols for name, cols, flags, _ in rows if "PF_HDF5" in flags}
    for name, cols in readers.H5_COLUMNS.items():
        assert h5.get(name) == cols, name


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
    cols["sxx"] = np.linspace(-1e3, 1e3, 5)
    path = tmp_path / "snap_0000.csv"
    write_csv(path, 0.25, cols)
    t, snap = mt.read_snapshot(str(path))
    assert t == 0.25 and set(snap) == set(cols)
    np.testing.assert_allclose(snap["sxx"], cols["sxx"], rtol=1e-8)
    # a header without a core column, or with a repeated name, is refused naming the file
    del cols["rho"]
    write_csv(path, 0.25, cols)
    with pytest.raises(mt.ToolError, match="snap_0000.csv.*rho"):
        mt.read_snapshot(str(path))


def test_h5_snapshot_with_law_fields(tmp_path):
    n = 4
    path = tmp_path / "run.h5"
    with h5py.File(path, "w") as f:
        g = f.create_group("snapshots/000000")
        g.attrs["time"] = 0.5
        g["position"] = np.c_[np.arange(n), -np.arange(n)].astype(float)
        g["velocity"] = np.zeros((n, 2))
        for d in ("density", "pressure", "viscosity", "mass"):
            g[d] = np.ones(n)
        for d in ("medium", "state"):
            g[d] = np.zeros(n, np.uint8)
        g["id"] = np.arange(n, dtype=np.uint32)
        g["sxx"] = np.full(n, 7.0)
        g["tau"] = np.arange(4 * n, dtype=float).reshape(n, 4)
    (t, ref), = mt.list_snapshots(str(tmp_path))
    t2, snap = mt.read_snapshot(ref)
    assert t == t2 == 0.5
    assert set(mt.SNAP_COLUMNS) | {"m", "sxx", "tau_0", "tau_1", "tau_2", "tau_3"} == set(snap)
    np.testing.assert_array_equal(snap["z"], -np.arange(n))
    np.testing.assert_array_equal(snap["sxx"], 7.0)
    np.testing.assert_array_equal(snap["tau_2"], np.arange(4 * n).reshape(n, 4)[:, 2])
