"""The HDF5 run file, its XDMF sidecar, checkpoints and restart, through the mixsph executable
(lib/src/io/output.c, cli/main.c) and the plot tool (tools/plot_snapshot.py).

- h5py reads every field of every snapshot with its shape, dtype and units;
- meshio (a real XDMF reader) loads run.xdmf and gets the same points and fields;
- a run killed with SIGKILL mid-way leaves run.h5 readable with the snapshots written so far;
- `mixsph run --restart` from the checkpoint of a killed run ends bit for bit like an
  uninterrupted run (one thread): every snapshot dataset, the CSV snapshots and monitors.csv;
- an unwritable output folder or run file is an error before the run starts.

Runs are small: the water dam break at dx = 0.02 m (706 particles with the walls) and, where a
run must live long enough to be killed, dx = 0.01 m; one OpenMP thread, passive waiting.
"""
import json
import math
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import h5py
import meshio
import numpy as np
import pytest
from meshio.xdmf import TimeSeriesReader

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("MIXSPH_BUILD_DIR", ROOT / "build"))
MIXSPH = BUILD / "mixsph"
CASE = ROOT / "cases" / "dambreak_water.json"
PYTHON = sys.executable
ENV = dict(os.environ, OMP_NUM_THREADS="1", OMP_WAIT_POLICY="PASSIVE")

# name: (trailing shape after n, dtype, units)
FIELDS = {
    "position": ((2,), np.float64, "m"),
    "velocity": ((2,), np.float64, "m/s"),
    "density": ((), np.float64, "kg/m^3"),
    "pressure": ((), np.float64, "Pa"),
    "viscosity": ((), np.float64, "Pa s"),
    "mass": ((), np.float64, "kg"),
    "medium": ((), np.uint8, "1"),
    "state": ((), np.uint8, "1"),
    "id": ((), np.uint32, "1"),
}


def mixsph():
    if not MIXSPH.is_file():
        pytest.fail(f"{MIXSPH} not found: build it first (./tools/do build)")
    return str(MIXSPH)


def run(args, check=True):
    r = subprocess.run([mixsph(), "run", *args], env=ENV, capture_output=True, text=True, timeout=600)
    if check and r.returncode != 0:
        pytest.fail(f"mixsph {' '.join(args)} failed ({r.returncode}):\n{r.stderr}")
    return r


def case_args(dx, t_end, out, *extra):
    return [str(CASE), "--set", f"numerics.dx={dx}", "--set", f"numerics.t_end={t_end}", "--out", str(out),
            "--threads", "1", "--quiet", *extra]


def xdmf_count(path):
    """Number of snapshots listed in a run.xdmf (0 if not there yet)."""
    try:
        return path.read_text().count('<Grid Name="snapshot_')
    except FileNotFoundError:
        return 0


@pytest.fixture(scope="module")
def ref(tmp_path_factory):
    """An uninterrupted run: dx = 0.02, t_end = 0.2 s, snapshots every 0.05 s."""
    out = tmp_path_factory.mktemp("ref")
    run(case_args(0.02, 0.2, out))
    return out


def test_fields_shapes_dtypes_units(ref):
    with h5py.File(ref / "run.h5", "r") as f:
        assert f.attrs["format"] == "mixsph-run"
        meta = f["metadata"]
        n = int(meta.attrs["n_particles"] + meta.attrs["n_wall_particles"])
        assert json.loads(f["metadata/case_json"][()])["name"] == "dambreak_water"
        assert "numerics.dx=0.02" in meta.attrs["overrides"]
        assert list(meta.attrs["media"]) == ["water"] and list(meta.attrs["walls"]) == ["tank"]
        snaps = f["snapshots"]
        assert f.attrs["n_snapshots"] == len(snaps) == 5  # t = 0, 0.05, ..., 0.2
        times = []
        for k, name in enumerate(sorted(snaps)):
            g = snaps[name]
            assert g.attrs["index"] == k and g.attrs["n"] == n
            times.append(g.attrs["time"])
            for field, (shape, dtype, units) in FIELDS.items():
                d = g[field]
                assert d.shape == (n, *shape), field
                assert d.dtype == dtype, field
                assert d.attrs["units"] == units, field
                assert d.attrs["description"]
            assert np.array_equal(g["id"][()], np.arange(n))  # row k is particle k
            state = g["state"][()]
            assert set(np.unique(state)) <= {0, 1, 2, 3}
            assert int((state == 2).sum()) == meta.attrs["n_wall_particles"]
            assert np.all(g["density"][()] > 0) and np.all(g["mass"][()] > 0)
        # the snapshot times: the first step at or after k * 0.05 s (dt < 2e-4 s here)
        assert np.all(np.array(times) - 0.05 * np.arange(5) >= -1e-12)
        assert np.all(np.array(times) - 0.05 * np.arange(5) < 2e-4)
        # the same values as the CSV snapshot of the same index (written with 6-7 digits)
        last = snaps[sorted(snaps)[-1]]
        csv = np.genfromtxt(ref / "snap_0004.csv", delimiter=",", skip_header=2)
        csv = csv[np.argsort(csv[:, 0])]
        pos, vel = last["position"][()], last["velocity"][()]
        np.testing.assert_allclose(csv[:, 1], pos[:, 0], rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(csv[:, 2], pos[:, 1], rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(csv[:, 3], vel[:, 0], rtol=1e-5, atol=1e-9)
        np.testing.assert_allclose(csv[:, 6], last["pressure"][()], rtol=1e-5, atol=1e-3)
        np.testing.assert_array_equal(csv[:, 9], last["state"][()])


def test_xdmf_meshio_reads_same_points(ref, tmp_path):
    xdmf = ref / "run.xdmf"
    with h5py.File(ref / "run.h5", "r") as f:
        snaps = [f["snapshots"][name] for name in sorted(f["snapshots"])]
        # the time series: times and every node field of every step, the first step's points
        with TimeSeriesReader(str(xdmf)) as reader:
            points, cells = reader.read_points_cells()
            assert reader.num_steps == len(snaps) == 5
            np.testing.assert_array_equal(points, snaps[0]["position"][()])
            assert cells[0].type == "vertex" and len(cells[0].data) == len(points)
            for k, g in enumerate(snaps):
                t, point_data, _ = reader.read_data(k)
                assert t == g.attrs["time"]
                assert set(point_data) == set(FIELDS) - {"position"}
                for name, data in point_data.items():
                    np.testing.assert_array_equal(data, g[name][()])
        # every step's own grid (its points move): each grid of the collection as a document of
        # its own, beside run.h5, read by meshio.read
        root = ET.parse(xdmf).getroot()
        grids = root.find("Domain").find("Grid").findall("Grid")
        assert len(grids) == len(snaps)
        for k, grid in enumerate(grids):
            grid.remove(grid.find("Time"))
            doc = ET.Element("Xdmf", Version="3.0")
            ET.SubElement(doc, "Domain").append(grid)
            one = ref / f"one_step_{k}.xdmf"
            ET.ElementTree(doc).write(one)
            mesh = meshio.read(one, file_format="xdmf")
            np.testing.assert_array_equal(mesh.points, snaps[k]["position"][()])
            np.testing.assert_array_equal(mesh.point_data["velocity"], snaps[k]["velocity"][()])
            one.unlink()


@pytest.fixture(scope="module")
def killed(tmp_path_factory):
    """A run (dx = 0.01, t_end = 0.2 s, snapshots every 0.02 s, a checkpoint at every progress
    step) killed with SIGKILL once two snapshots are written and a checkpoint exists."""
    out = tmp_path_factory.mktemp("killed")
    args = case_args(0.01, 0.2, out, "--set", "output.snapshot_interval=0.02", "--checkpoint-every", "0")
    p = subprocess.Popen([mixsph(), "run", *args], env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and p.poll() is None:
        if xdmf_count(out / "run.xdmf") >= 2 and (out / "checkpoint.h5").exists():
            break
        time.sleep(0.02)
    p.send_signal(signal.SIGKILL)
    p.wait()
    assert p.returncode == -signal.SIGKILL, "the run ended before it could be killed"
    return out


def test_killed_run_leaves_readable_file(killed):
    listed = xdmf_count(killed / "run.xdmf")
    assert listed >= 2
    with h5py.File(killed / "run.h5", "r") as f:
        written = int(f.attrs["n_snapshots"])
        assert written >= listed  # the sidecar is rewritten after each flushed snapshot
        n = int(f["metadata"].attrs["n_particles"] + f["metadata"].attrs["n_wall_particles"])
        for k in range(written):
            g = f[f"snapshots/{k:06d}"]
            assert g.attrs["index"] == k
            for field, (shape, dtype, units) in FIELDS.items():
                data = g[field][()]
                assert data.shape == (n, *shape) and data.dtype == dtype
                assert g[field].attrs["units"] == units
            assert np.all(np.isfinite(g["position"][()]))
        t_end = f["metadata"].attrs["t_end"]
        assert f[f"snapshots/{written - 1:06d}"].attrs["time"] < t_end
    # and ParaView's view of it: the sidecar loads with the snapshots it lists
    with TimeSeriesReader(str(killed / "run.xdmf")) as reader:
        reader.read_points_cells()
        assert reader.num_steps == listed
        for k in range(listed):
            reader.read_data(k)


def same_run_files(a, b):
    with h5py.File(a / "run.h5", "r") as fa, h5py.File(b / "run.h5", "r") as fb:
        assert fa.attrs["n_snapshots"] == fb.attrs["n_snapshots"] == len(fa["snapshots"]) == len(fb["snapshots"])
        for name in fa["snapshots"]:
            ga, gb = fa["snapshots"][name], fb["snapshots"][name]
            assert ga.attrs["time"] == gb.attrs["time"] and ga.attrs["step"] == gb.attrs["step"]
            for field in FIELDS:
                x, y = ga[field][()], gb[field][()]
                assert x.dtype == y.dtype and x.shape == y.shape
                assert x.tobytes() == y.tobytes(), f"{name}/{field} differs"
    assert (a / "monitors.csv").read_bytes() == (b / "monitors.csv").read_bytes()
    csv_a = sorted(p.name for p in a.glob("snap_*.csv"))
    assert csv_a == sorted(p.name for p in b.glob("snap_*.csv"))
    for name in csv_a:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    assert (a / "run.xdmf").read_text() == (b / "run.xdmf").read_text()


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    """The killed run's settings, uninterrupted."""
    out = tmp_path_factory.mktemp("uninterrupted")
    run(case_args(0.01, 0.2, out, "--set", "output.snapshot_interval=0.02"))
    return out


def test_restart_equals_uninterrupted(killed, full, tmp_path):
    # continue a copy of the killed run's folder from its checkpoint (the default folder: the
    # checkpoint's)
    cont = tmp_path / "continued"
    shutil.copytree(killed, cont)
    with h5py.File(cont / "checkpoint.h5", "r") as c:
        t_ckpt = c.attrs["time"]
        wall_ckpt = c.attrs["run_wall_time_s"]
        assert c["state"].dtype == np.uint8 and c.attrs["format"] == "mixsph-checkpoint"
    assert 0 < t_ckpt < 0.2 and wall_ckpt > 0
    r = subprocess.run([mixsph(), "run", "--restart", str(cont / "checkpoint.h5"), "--threads", "1", "--quiet"],
                       env=ENV, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    same_run_files(full, cont)
    with h5py.File(cont / "run.h5", "r") as f:
        assert f.attrs["restarts"] == 1 and f.attrs["last_restart_time"] == t_ckpt
    # the summary's rates count the continuation's own work (from the checkpoint), not the
    # steps and simulated time of the whole run over the continuation's wall time
    summ = json.loads((cont / "summary.json").read_text())
    whole = json.loads((full / "summary.json").read_text())
    assert summ["status"] == "ok" and summ["steps"] == whole["steps"]
    assert summ["restarted_from"] == str(cont / "checkpoint.h5") and summ["restart_time_s"] == t_ckpt
    step_ckpt = summ["restart_step"]
    assert 0 < step_ckpt < summ["steps"]
    wall = summ["wall_time_s"]
    assert math.isclose(summ["particle_steps_per_s"], summ["particles"] * (summ["steps"] - step_ckpt) / wall, rel_tol=1e-12)
    assert math.isclose(summ["wall_s_per_simulated_s"], wall / (summ["simulated_time_s"] - t_ckpt), rel_tol=1e-12)
    assert "restarted_from" not in whole
    # the run's wall time adds the killed run's time up to its checkpoint to the continuation's
    # (both measured around the steps, so it is not the sum of the processes' wall times)
    assert summ["run_wall_time_s"] > wall_ckpt
    assert math.isclose(summ["run_wall_time_s"] - wall_ckpt, wall, rel_tol=0.5)
    assert 0 < whole["run_wall_time_s"] <= whole["wall_time_s"]


def test_sigterm_checkpoints_and_restart_equals_uninterrupted(full, tmp_path):
    """SIGTERM (as Ctrl-C's SIGINT) stops the run at the next progress step with a checkpoint
    (exit code 128 + 15); --restart then completes it as if it had never stopped."""
    out = tmp_path / "stopped"
    args = case_args(0.01, 0.2, out, "--set", "output.snapshot_interval=0.02")
    p = subprocess.Popen([mixsph(), "run", *args], env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and p.poll() is None and xdmf_count(out / "run.xdmf") < 2:
        time.sleep(0.02)
    p.send_signal(signal.SIGTERM)
    stdout, stderr = p.communicate(timeout=300)
    assert p.returncode == 128 + signal.SIGTERM, stderr
    assert "STOPPED" in stdout and "--restart" in stderr
    assert json.loads((out / "summary.json").read_text())["status"] == "stopped"
    r = subprocess.run([mixsph(), "run", "--restart", str(out / "checkpoint.h5"), "--threads", "1", "--quiet"],
                       env=ENV, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    same_run_files(full, out)


def test_restart_into_new_folder(killed, full, tmp_path):
    """--out to a fresh folder: new files holding the snapshots and monitor rows from the
    checkpoint on, equal to the uninterrupted run's."""
    new = tmp_path / "new"
    r = subprocess.run([mixsph(), "run", "--restart", str(killed / "checkpoint.h5"), "--out", str(new), "--threads",
                        "1", "--quiet"], env=ENV, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    with h5py.File(new / "run.h5", "r") as fn, h5py.File(full / "run.h5", "r") as ff:
        first = int(fn.attrs["first_snapshot"])
        assert fn.attrs["restarts"] == 1 and first >= 1
        names = sorted(fn["snapshots"])
        assert names == sorted(ff["snapshots"])[first:]
        for name in names:
            for field in FIELDS:
                assert fn["snapshots"][name][field][()].tobytes() == ff["snapshots"][name][field][()].tobytes()
    rows_new = (new / "monitors.csv").read_text().splitlines()
    rows_full = (full / "monitors.csv").read_text().splitlines()
    assert rows_new[0] == rows_full[0] and len(rows_new) > 1
    assert rows_new[1:] == rows_full[len(rows_full) - (len(rows_new) - 1):]
    # the XDMF lists them and the plot tool draws them
    with TimeSeriesReader(str(new / "run.xdmf")) as reader:
        assert reader.num_steps == len(names)
    png = tmp_path / "first.png"
    p = subprocess.run([PYTHON, str(ROOT / "tools" / "plot_snapshot.py"), str(new), "--index", "0", "-o", str(png)],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert png.stat().st_size > 5000


def test_restart_rejects_case_arguments(killed):
    r = run(["--restart", str(killed / "checkpoint.h5"), str(CASE)], check=False)
    assert r.returncode == 2 and "--restart" in r.stderr


def test_unwritable_output_fails_before_the_run(tmp_path):
    r = run(case_args(0.02, 0.2, "/dev/null/out"), check=False)
    assert r.returncode == 4
    assert "/dev/null/out" in r.stderr and "cannot create" in r.stderr
    assert r.stdout == ""  # no run, no summary
    # the run file cannot be created: a clear message, nothing printed by HDF5 itself
    out = tmp_path / "blocked"
    (out / "run.h5").mkdir(parents=True)
    r = run(case_args(0.02, 0.2, out), check=False)
    assert r.returncode == 4
    assert "run.h5" in r.stderr and "cannot create the HDF5 run file" in r.stderr
    assert "HDF5-DIAG" not in r.stderr
    assert not list(out.glob("snap_*.csv"))


def test_no_csv_writes_run_file_only(ref, tmp_path):
    out = tmp_path / "nocsv"
    run(case_args(0.02, 0.2, out, "--no-csv"))
    assert not list(out.glob("snap_*.csv"))
    with h5py.File(ref / "run.h5", "r") as fa, h5py.File(out / "run.h5", "r") as fb:
        assert sorted(fa["snapshots"]) == sorted(fb["snapshots"])
        for name in fa["snapshots"]:
            for field in FIELDS:
                assert fa["snapshots"][name][field][()].tobytes() == fb["snapshots"][name][field][()].tobytes()


def test_plot_snapshot_png_and_gif(ref, tmp_path):
    tool = ROOT / "tools" / "plot_snapshot.py"
    png = tmp_path / "snap.png"
    r = subprocess.run([PYTHON, str(tool), str(ref), "--color", "medium", "--time", "0.1", "-o", str(png)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert png.stat().st_size > 5000
    gif = tmp_path / "run.gif"
    r = subprocess.run([PYTHON, str(tool), str(ref / "run.h5"), "--color", "speed", "--animate", "-o", str(gif)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    from PIL import Image
    with Image.open(gif) as im:
        assert im.format == "GIF" and im.n_frames == 5


def test_tools_read_the_snapshots_of_a_run_without_csv(full, tmp_path):
    # tools/mixsph_tools.py: a folder without snap_NNNN.csv (a --no-csv run) gives its run.h5
    # snapshots, with the CSV snapshots' columns and values (the CSV prints 6-7 significant digits)
    # and the fields only run.h5 holds
    sys.path.insert(0, str(ROOT / "tools"))
    import mixsph_tools as mt
    h5only = tmp_path / "h5only"
    h5only.mkdir()
    shutil.copy(full / "run.h5", h5only / "run.h5")
    csv_snaps, h5_snaps = mt.list_snapshots(str(full)), mt.list_snapshots(str(h5only))
    assert len(csv_snaps) == len(h5_snaps) >= 10
    for (tc, refc), (th, refh) in zip(csv_snaps, h5_snaps):
        assert refh.endswith(".h5" + mt.H5_REF + refh.split(mt.H5_REF)[1]) and math.isclose(tc, th, rel_tol=1e-8)
        _, c = mt.read_snapshot(refc)
        _, h = mt.read_snapshot(refh)
        order = np.argsort(c["id"])    # CSV rows in memory order, run.h5 rows by id
        assert set(h) - set(c) == {"m"}    # run.h5 also holds the mass, the CSV not
        for k in c:
            assert np.allclose(c[k][order], h[k], rtol=1e-5, atol=1e-9), k


def test_3d_run_file_xdmf_csv_and_plots(tmp_path):
    """A 3D case (cases/falling_block_3d.json, 1000 particles, to 0.02 s) through the same
    executable: run.h5 holds 3-component positions and velocities, run.xdmf is read by meshio as
    3D points with every field, the CSV snapshots have y columns, and plot_snapshot draws the
    side view of a y band (only the particles in it) and the plan view."""
    out = tmp_path / "block"
    run([str(ROOT / "cases" / "falling_block_3d.json"), "--set", "numerics.t_end=0.02", "--set",
         "output.snapshot_interval=0.01", "--out", str(out), "--threads", "1", "--quiet"])
    with h5py.File(out / "run.h5", "r") as f:
        snaps = [f["snapshots"][name] for name in sorted(f["snapshots"])]
        assert len(snaps) == 3
        for g in snaps:
            assert g["position"].shape == (1000, 3) and g["velocity"].shape == (1000, 3)
        first = snaps[0]["position"][()]
        # the cube's lattice: x, y, z = (i + 1/2) dx, 10 sites a side
        np.testing.assert_allclose(np.unique(np.round(first[:, 1], 9)), 0.005 + 0.01 * np.arange(10), atol=1e-12)
        with TimeSeriesReader(str(out / "run.xdmf")) as reader:
            points, _ = reader.read_points_cells()
            np.testing.assert_array_equal(points, first)
            _, point_data, _ = reader.read_data(len(snaps) - 1)
            assert point_data["velocity"].shape == (1000, 3)
            for name in ("density", "pressure", "mass", "medium", "state", "id"):
                np.testing.assert_array_equal(point_data[name], snaps[-1][name][()])
    header = (out / "snap_0001.csv").read_text().splitlines()[1]
    assert header.startswith("id,x,y,z,vx,vy,vz,")
    tool = ROOT / "tools" / "plot_snapshot.py"
    for args in (["--view", "side", "--y-band", "0.04", "0.06"], ["--view", "plan", "--color", "speed"]):
        png = tmp_path / f"{args[1]}.png"
        r = subprocess.run([PYTHON, str(tool), str(out), *args, "-o", str(png)], capture_output=True, text=True,
                           timeout=300)
        assert r.returncode == 0, r.stderr
        assert png.stat().st_size > 5000
    sys.path.insert(0, str(ROOT / "tools"))
    import plot_snapshot
    band = plot_snapshot.Run(str(out))
    band.set_view("side", (0.04, 0.06))
    assert len(band.snapshot(0)["position"]) == 2 * 10 * 10  # two y layers of the cube
