"""Helpers for the tests of the tools/ validation scripts that run mixsph."""

import os
import signal
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import mixsph_tools as mt  # noqa: E402

ENV = dict(os.environ, OMP_WAIT_POLICY="passive")   # the tests share the cores
BUILD = os.environ.get("MIXSPH_BUILD_DIR", os.path.join(ROOT, "build"))


def built(name, how="./tools/do build"):
    """The path of ``name`` (e.g. "mixsph") in the build folder (MIXSPH_BUILD_DIR, default
    build/). When it is not there the test cannot run: in CI (environment CI=true) that is a
    broken pipeline, so the test fails; elsewhere it is skipped. Either way the message names
    what is missing and how to build it."""
    import pytest
    path = os.path.join(BUILD, name)
    if os.path.isfile(path):
        return path
    message = f"{path} is not built (build it with {how})"
    if os.environ.get("CI", "").lower() in ("true", "1"):
        pytest.fail(f"{message}; CI=true, so a missing build fails the test instead of skipping it", pytrace=False)
    pytest.skip(message)


def script_command(script, *opts):
    """[python, tools/<script>, --mixsph build/mixsph, *opts]; the test fails in CI and is skipped
    elsewhere when build/mixsph is not built (built())."""
    return [sys.executable, os.path.join(ROOT, "tools", script), "--mixsph", built("mixsph"), *opts]


def assert_refused(tool, cases, out, timeout=120):
    """Each (options, message) of ``cases``: the script ``tool`` + options + --out ``out``
    exits 2 with the message on stderr and creates nothing at ``out``."""
    for opts, message in cases:
        r = subprocess.run(tool + opts + ["--out", str(out)], capture_output=True, text=True, env=ENV,
                           timeout=timeout)
        assert r.returncode == 2 and message in r.stderr, r.stderr
        assert not os.path.exists(out)


def cut_off(cmd, run_dir, t_min, timeout=240):
    """Start a script (cmd) and kill it and its mixsph with SIGKILL, as the end of a session does,
    once run_dir holds a checkpoint and monitors.csv has reached t_min. Returns the run's
    time up to its last checkpoint (the checkpoint's ``run_wall_time_s``)."""
    import h5py
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=ENV, start_new_session=True)
    ckpt = os.path.join(run_dir, "checkpoint.h5")
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and p.poll() is None and not (
            os.path.exists(ckpt) and mt.last_time(os.path.join(run_dir, "monitors.csv")) >= t_min):
        time.sleep(0.05)
    os.killpg(p.pid, signal.SIGKILL)
    p.wait()
    assert p.returncode == -signal.SIGKILL, "the run ended before it could be cut off"
    assert not os.path.exists(os.path.join(run_dir, "summary.json"))
    with h5py.File(ckpt, "r") as f:
        return float(f.attrs["run_wall_time_s"])
