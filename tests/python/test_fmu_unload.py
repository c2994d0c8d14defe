"""Unloading the FMU is safe in every state (docs/fmu.md, "Unloading"): a fresh Python process
(tests/python/fmu_unload_host.py) loads the binary, runs it on two OpenMP threads, unloads it
after freeInstance, after an error, or without freeInstance, loads it again and runs it again,
and exits with status 0. Before the binary was marked not unloadable, each of these died with
SIGSEGV in the unload: libgomp's idle workers outlived the code they were waiting in.

The hosts run with OpenMP's default wait policy (the workers spin for a while before they
sleep), not the tests' passive one, as a user's process would.
"""
import os
import re
import shlex
import subprocess
import sys

import pytest

import fmu_helpers as H

HOST = H.ROOT / "tests" / "python" / "fmu_unload_host.py"


def _user_env():
    env = dict(os.environ)
    for k in H.ENV:
        env.pop(k, None)
    return env


@pytest.mark.parametrize("scenario", ["freed", "after_error", "not_freed"])
def test_unload_reload_in_a_fresh_process_exits_cleanly(scenario):
    p = subprocess.run([sys.executable, str(HOST), H.fmu_path(), scenario], env=_user_env(),
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, f"{scenario}: exit status {p.returncode}\n{p.stdout}\n{p.stderr}"
    assert "loaded three times" in p.stdout


def test_the_readmes_fmpy_simulate_command_exits_0(tmp_path):
    """The command of README.md's FMU section, as written there (all cores: threads 0), with its
    CSV written into a temporary folder and its stop time cut to 0.1 s (the unload that crashed
    comes after the run, whatever its length)."""
    readme = (H.ROOT / "README.md").read_text()
    m = re.search(r"^\.venv/bin/fmpy simulate build/LandslideWave\.fmu(.*?)(?<!\\)$", readme, re.M | re.S)
    assert m, "README.md has no `.venv/bin/fmpy simulate build/LandslideWave.fmu ...` command"
    args = shlex.split(m.group(1).replace("\\\n", " "))
    out = args.index("--output-file")
    args[out + 1] = str(tmp_path / os.path.basename(args[out + 1]))
    args[args.index("--stop-time") + 1] = "0.1"
    fmpy = os.path.join(os.path.dirname(sys.executable), "fmpy")
    p = subprocess.run([fmpy, "simulate", H.fmu_path(), *args], env=_user_env(), capture_output=True,
                       text=True, timeout=600)
    assert p.returncode == 0, f"exit status {p.returncode}\n{p.stdout}\n{p.stderr}"
    rows = (tmp_path / os.path.basename(args[out + 1])).read_text().splitlines()
    assert len(rows) == 12  # the header, 0 to 0.1 s every 0.01 s
