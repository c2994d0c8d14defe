"""Helpers of the LandslideWave FMU tests (tests/python/test_fmu*.py).

The FMU and the mixsph executable are taken from the build folder (MIXSPH_BUILD_DIR, default
build/, which ./tools/do test builds with the FMU). A missing FMU fails the tests rather than
skipping them: the FMU is part of what ./tools/do test must check.

Runs are small: the Vajont case at dx = 0.03 m (296 particles) with mu0 = 1 kPa s (the time step
is then the acoustic one, about 1.9e-4 s), one OpenMP thread.
"""
import os
import pathlib
import shutil
import subprocess
import tempfile
import zipfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("MIXSPH_BUILD_DIR", ROOT / "build"))
FMU = BUILD / "LandslideWave.fmu"
MIXSPH = BUILD / "mixsph"
CASE = ROOT / "cases" / "vajont_padua.json"

# The coarse test setting: parameters of the FMU and the same as case overrides of mixsph.
COARSE = {"dx": 0.03, "mu0": 1000.0}
# The FMU's physical parameters reach a case through its `parameters` block (override
# "parameters.NAME"), the numerical ones through keys every case has (fmu/landslide_model.c).
PHYSICAL = ["reservoir_level", "phi", "mu0", "mu_thr", "saturated", "tension_cutoff", "porosity", "grain_density",
            "plate_duration_scale", "plate_stroke_scale", "rheology", "grain_bulk_modulus", "nu", "cohesion",
            "bed_friction"]
CASE_KEYS = {
    **{name: f"parameters.{name}" for name in PHYSICAL},
    "dx": "numerics.dx",
    "output_interval": "output.monitor_interval",
    "pressure_smoothing": "numerics.pressure_smoothing",
    "av_wall": "numerics.av_wall",
    "implicit_viscosity": "numerics.viscosity",
}

ENV = {"OMP_NUM_THREADS": "1", "OMP_WAIT_POLICY": "PASSIVE"}
for _k, _v in ENV.items():
    os.environ[_k] = _v


def fmu_path():
    if not FMU.is_file():
        pytest.fail(f"{FMU} not found: build it with `cmake --build {BUILD} --target fmu` "
                    "(./tools/do build does it when fmpy is in .venv)")
    return str(FMU)


_unzipped = {}


def unzipped():
    """The FMU unpacked once per session (fmpy instances share it)."""
    path = fmu_path()
    if path not in _unzipped:
        d = tempfile.mkdtemp(prefix="landslidewave_")
        with zipfile.ZipFile(path) as z:
            z.extractall(d)
        _unzipped[path] = d
    return _unzipped[path]


def model_description():
    from fmpy import read_model_description
    return read_model_description(fmu_path())


def vrs():
    return {v.name: v.valueReference for v in model_description().modelVariables}


class Logger:
    """Collects the FMI logger's messages of the instances that use it."""

    def __init__(self):
        self.messages = []

    def __call__(self, env, instance_name, status, category, message):
        self.messages.append((status, category.decode() if category else "",
                              message.decode(errors="replace") if message else ""))

    def errors(self):
        return [m for s, c, m in self.messages if s >= 3]


def instance(name="lw", logger=None, logging_on=False, unzipdir=None):
    """An instantiated FMU2Slave of the unpacked FMU (with a logger if given)."""
    from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, \
        fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE
    from fmpy import calloc, free  # noqa: F401  (C allocation functions for the callbacks)
    md = model_description()
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir or unzipped(),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
    fmu._logger_ref = logger
    if logger is None:
        fmu.instantiate(loggingOn=logging_on)
    else:
        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(logger)
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        fmu._cb_ref = cb
        fmu.instantiate(callbacks=cb, loggingOn=logging_on)
    return fmu


def set_params(fmu, params):
    v = vrs()
    types = {x.name: x.type for x in model_description().modelVariables}
    for name, value in params.items():
        t = types[name]
        if t == "Real":
            fmu.setReal([v[name]], [float(value)])
        elif t in ("Integer", "Enumeration"):
            fmu.setInteger([v[name]], [int(value)])
        elif t == "Boolean":
            fmu.setBoolean([v[name]], [bool(value)])
        else:
            fmu.setString([v[name]], [str(value)])


def start(fmu, params):
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    set_params(fmu, params)
    fmu.exitInitializationMode()


OUT_REAL = ["run_up", "max_run_up", "time_of_max_run_up", "landslide_front", "kinetic_energy", "dt",
            "max_run_up_Z"]
OUT_INT = ["fixed_particles", "lost_particles", "excluded_particles", "steps"]


def outputs(fmu):
    v = vrs()
    r = fmu.getReal([v[n] for n in OUT_REAL])
    i = fmu.getInteger([v[n] for n in OUT_INT])
    return tuple(r) + tuple(i)


def run_mixsph(overrides, out_dir, t_end=None, case=CASE):
    """Run the mixsph executable on a case (the Vajont one by default) with the FMU parameters
    `overrides` given as the case keys they map onto (CASE_KEYS); returns summary.json."""
    import json
    if not MIXSPH.is_file():
        pytest.fail(f"{MIXSPH} not found (./tools/do build)")
    cmd = [str(MIXSPH), "run", str(case), "--threads", "1", "--quiet", "--out", str(out_dir)]
    for name, value in overrides.items():
        cmd += ["--set", f"{CASE_KEYS[name]}={int(value) if isinstance(value, bool) else value!r}"]
    if t_end is not None:
        cmd += ["--set", f"numerics.t_end={t_end!r}"]
    subprocess.run(cmd, check=True, env={**os.environ, **ENV}, stdout=subprocess.DEVNULL)
    with open(pathlib.Path(out_dir) / "summary.json") as f:
        return json.load(f)


def cleanup():
    for d in _unzipped.values():
        shutil.rmtree(d, ignore_errors=True)
    _unzipped.clear()
