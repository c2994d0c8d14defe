"""Run one scenario of an FMI 2.0 co-simulation FMU (LandslideWave.fmu) through fmpy.

This module is what the Dask workers execute. Each worker process unzips a given FMU once
(keyed by the SHA-256 of its bytes) and reuses the extracted folder and the parsed model
description for every later scenario; only the FMU instance is created per scenario.

Variable names are never hard-coded here: parameters and outputs are looked up in the FMU's
modelDescription.xml, so the module works with any co-simulation FMU.
"""

from __future__ import annotations

import hashlib
import math
import os
import shutil
import tempfile
import time
from ctypes import byref
from dataclasses import dataclass, field

# Process-wide cache: FMU sha256 -> (unzip folder, model description). Lives as long as the
# worker process; every scenario of that FMU on that worker reuses the entry.
_CACHE: dict[str, "FmuFiles"] = {}
# How many times this process has unzipped an FMU (checked by the tests: once per worker).
UNZIP_COUNT = 0


@dataclass
class FmuFiles:
    sha256: str
    unzipdir: str
    md: object                                   # fmpy ModelDescription
    variables: dict = field(default_factory=dict)  # name -> ScalarVariable


def fmu_sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def read_fmu_bytes(path: str) -> dict:
    """The FMU as {'sha256', 'name', 'data'}: what the client ships to the workers once."""
    with open(path, "rb") as f:
        data = f.read()
    return {"sha256": fmu_sha256(data), "name": os.path.basename(path), "data": data}


def _cache_root() -> str:
    try:  # a Dask worker has its own scratch folder; use it so the cluster cleans up
        from distributed import get_worker
        return get_worker().local_directory
    except Exception:
        return tempfile.gettempdir()


def unzipped(fmu: dict) -> FmuFiles:
    """The extracted FMU of this process (unzipping it on the first call only)."""
    global UNZIP_COUNT
    sha = fmu["sha256"]
    hit = _CACHE.get(sha)
    if hit is not None and os.path.isdir(hit.unzipdir):
        return hit
    import fmpy
    from fmpy import read_model_description

    folder = os.path.join(_cache_root(), f"dss-fmu-{sha[:16]}-{os.getpid()}")
    tmp = folder + ".part"
    shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(tmp)
    zpath = os.path.join(tmp, "model.fmu")
    with open(zpath, "wb") as f:
        f.write(fmu["data"])
    fmpy.extract(zpath, os.path.join(tmp, "x"))
    shutil.rmtree(folder, ignore_errors=True)
    os.replace(tmp, folder)
    unzipdir = os.path.join(folder, "x")
    md = read_model_description(unzipdir)
    if md.coSimulation is None:
        raise ValueError(f"{fmu.get('name', 'FMU')} has no co-simulation interface")
    UNZIP_COUNT += 1
    entry = FmuFiles(sha, unzipdir, md, {v.name: v for v in md.modelVariables})
    _CACHE[sha] = entry
    return entry


def enumeration_items_of(v) -> dict:
    """An Enumeration variable's items, name -> value ({} for another type)."""
    if v.type != "Enumeration" or v.declaredType is None:
        return {}
    return {it.name: int(it.value) for it in v.declaredType.items}


def _check_value(v, value):
    """The value converted for the variable's type; ValueError if it cannot be."""
    t = v.type
    if t == "Real":
        x = float(value)
        lo = float(v.min) if v.min is not None else -math.inf
        hi = float(v.max) if v.max is not None else math.inf
        if not (lo <= x <= hi):  # also rejects NaN
            raise ValueError(f"{v.name} = {value!r} outside [{v.min}, {v.max}] of the model description")
        return x
    if t in ("Integer", "Enumeration"):
        items = enumeration_items_of(v)
        if isinstance(value, str) and value.strip() in items:  # an item by name: its value
            return items[value.strip()]
        x = float(value)
        if not x.is_integer():
            raise ValueError(f"{v.name} = {value!r} is not an integer")
        x = int(x)
        if (v.min is not None and x < int(v.min)) or (v.max is not None and x > int(v.max)):
            raise ValueError(f"{v.name} = {value!r} outside [{v.min}, {v.max}] of the model description")
        if items and x not in items.values():
            raise ValueError(f"{v.name} = {value!r} is not one of its items: "
                             + ", ".join(f"{k} ({i})" for k, i in items.items()))
        return x
    if t == "Boolean":
        if isinstance(value, str):
            s = value.strip().lower()
            if s in ("1", "true", "yes", "1.0"):
                return True
            if s in ("0", "false", "no", "0.0"):
                return False
            raise ValueError(f"{v.name} = {value!r} is not a Boolean")
        x = float(value)
        if x not in (0.0, 1.0):
            raise ValueError(f"{v.name} = {value!r} is not a Boolean (0 or 1)")
        return bool(x)
    if t == "String":
        return str(value)
    raise ValueError(f"{v.name}: unsupported type {t}")


def _set(fmu_inst, v, value):
    vr = [v.valueReference]
    if v.type == "Real":
        fmu_inst.setReal(vr, [value])
    elif v.type in ("Integer", "Enumeration"):
        fmu_inst.setInteger(vr, [value])
    elif v.type == "Boolean":
        fmu_inst.setBoolean(vr, [value])
    else:
        fmu_inst.setString(vr, [value])


def _get(fmu_inst, v):
    vr = [v.valueReference]
    if v.type == "Real":
        return float(fmu_inst.getReal(vr)[0])
    if v.type in ("Integer", "Enumeration"):
        return int(fmu_inst.getInteger(vr)[0])
    if v.type == "Boolean":
        return bool(fmu_inst.getBoolean(vr)[0])
    x = fmu_inst.getString(vr)[0]
    return x.decode() if isinstance(x, bytes) else str(x)


def run_scenario(fmu: dict, params: dict, opts: dict) -> dict:
    """Run the FMU once with the given parameter values.

    fmu:    {'sha256', 'name', 'data'} (read_fmu_bytes)
    params: variable name -> value (parameters of the FMU; unknown names are an error)
    opts:   stop_time (default: the model's DefaultExperiment), step (communication step, s),
            threads (set on a parameter named 'threads' when the FMU has one and params does
            not set it), outputs (names; default all outputs), series (names recorded at
            every communication point), timeout (wall s; 0 = none)

    Returns a dict: status ('ok' or 'failed'), error (message, '' if ok), wall_time_s,
    the outputs' final values, series (name -> list) if asked, worker_pid, unzip_count.
    Never raises for a scenario's own failure: a bad parameter, an FMU error or a timeout
    is returned as status 'failed' with the message.
    """
    t_wall0 = time.perf_counter()
    t_cpu0 = time.process_time()
    res = {"status": "failed", "error": "", "wall_time_s": math.nan, "cpu_time_s": math.nan,
           "worker_pid": os.getpid(), "unzip_count": UNZIP_COUNT, "host": os.uname().nodename}
    messages: list[str] = []
    inst = None
    instantiated = False
    try:
        files = unzipped(fmu)
        res["unzip_count"] = UNZIP_COUNT
        md = files.md
        var = files.variables
        values = {}
        for name, value in params.items():
            v = var.get(name)
            if v is None or v.causality != "parameter":
                known = ", ".join(x.name for x in md.modelVariables if x.causality == "parameter")
                raise ValueError(f"unknown parameter {name!r} (the FMU's parameters: {known})")
            values[name] = (v, _check_value(v, value))
        threads = opts.get("threads")
        if threads is not None and "threads" in var and "threads" not in values \
                and var["threads"].causality == "parameter":
            values["threads"] = (var["threads"], _check_value(var["threads"], threads))

        de = md.defaultExperiment
        stop = opts.get("stop_time") or (de.stopTime if de is not None and de.stopTime else None)
        if stop is None:
            raise ValueError("no stop time: give one (the FMU has no DefaultExperiment stopTime)")
        stop = float(stop)
        step = float(opts.get("step") or (de.stepSize if de is not None and de.stepSize else stop))
        step = min(step, stop)
        out_names = opts.get("outputs") or [v.name for v in md.modelVariables if v.causality == "output"]
        for n in out_names:
            if n not in var:
                raise ValueError(f"unknown output {n!r}")
        series_names = list(opts.get("series") or [])
        for n in series_names:
            if n not in var:
                raise ValueError(f"unknown series output {n!r}")
        timeout = float(opts.get("timeout") or 0.0)

        from fmpy.fmi2 import (FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE,
                               fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE)
        from fmpy import calloc, free

        def logger(_env, _inst, status, category, message):
            if status >= 1:  # warning and worse
                m = message.decode(errors="replace") if isinstance(message, bytes) else str(message)
                messages.append(m)

        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(logger)
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        try:
            from fmpy.logging import addLoggerProxy
            addLoggerProxy(byref(callbacks))
        except Exception:
            pass

        t_wall0 = time.perf_counter()
        t_cpu0 = time.process_time()
        inst = FMU2Slave(guid=md.guid, unzipDirectory=files.unzipdir,
                         modelIdentifier=md.coSimulation.modelIdentifier,
                         instanceName=f"dss{os.getpid()}")
        inst.instantiate(callbacks=callbacks, loggingOn=False)
        instantiated = True
        for v, x in values.values():
            _set(inst, v, x)
        inst.setupExperiment(startTime=0.0, stopTime=stop)
        inst.enterInitializationMode()
        inst.exitInitializationMode()
        series = {n: [] for n in series_names}
        times = []
        t = 0.0
        k = 0
        while t < stop - 1e-12 * max(1.0, stop):
            k += 1
            t_next = min(stop, k * step)
            inst.doStep(currentCommunicationPoint=t, communicationStepSize=t_next - t)
            t = t_next
            if series_names:
                times.append(t)
                for n in series_names:
                    series[n].append(_get(inst, var[n]))
            if timeout > 0 and time.perf_counter() - t_wall0 > timeout:
                raise TimeoutError(f"timeout: {timeout:g} s wall reached at t = {t:g} s of {stop:g}")
        for n in out_names:
            res[n] = _get(inst, var[n])
        # the values of every parameter the run used (those the scenario did not set too)
        for v in md.modelVariables:
            if v.causality == "parameter" and v.name not in params:
                try:
                    res[v.name] = _get(inst, v)
                except Exception:
                    pass
        if series_names:
            res["series"] = {"time": times, **series}
        inst.terminate()
        res["status"] = "ok"
    except Exception as e:  # the scenario failed; the sweep goes on
        msg = f"{type(e).__name__}: {e}"
        if messages:
            msg += " | FMU: " + " | ".join(messages[-5:])
        res["error"] = msg
    finally:
        res["wall_time_s"] = time.perf_counter() - t_wall0
        res["cpu_time_s"] = time.process_time() - t_cpu0
        if inst is not None:
            try:
                if instantiated:
                    inst.freeInstance()       # also unloads the library
                else:
                    inst.freeLibrary()
            except Exception:
                pass
    return res
