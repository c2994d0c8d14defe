"""A host process for tests/python/test_fmu_unload.py: loads the LandslideWave FMU's binary with
fmpy, runs it on two OpenMP threads and unloads it (dlclose / FreeLibrary), in the way the
scenario given on the command line says, then loads and runs it again. Exits 0 when every run
gave the same outputs; a crash while unloading (the libgomp workers of a multi-threaded run
outliving the code they wait in) kills it with a signal instead.

    python fmu_unload_host.py FMU {freed|after_error|not_freed}

  freed        instantiate, run, terminate, freeInstance, unload; twice (from two unpacked copies)
  after_error  run a case that blows up (the Vajont case with time-step coefficients far too
               large) into the error state, freeInstance, unload; then run again
  not_freed    run, unload without terminate or freeInstance; then run again
"""
import json
import os
import sys
import tempfile
import zipfile

from fmpy import read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi1 import FMICallException

FMU, SCENARIO = sys.argv[1], sys.argv[2]
MD = read_model_description(FMU)
VR = {v.name: v.valueReference for v in MD.modelVariables}


def unpack():
    d = tempfile.mkdtemp(prefix="landslidewave_unload_")
    with zipfile.ZipFile(FMU) as z:
        z.extractall(d)
    return d


def load(unzipdir, case_file=None):
    """An instance of a fresh load of the binary, initialised to run on two threads."""
    fmu = FMU2Slave(guid=MD.guid, unzipDirectory=unzipdir, modelIdentifier=MD.coSimulation.modelIdentifier,
                    instanceName="unload")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setReal([VR["dx"], VR["mu0"]], [0.03, 1000.0])
    fmu.setInteger([VR["threads"]], [2])
    if case_file:
        fmu.setString([VR["case_file"]], [case_file])
    fmu.exitInitializationMode()
    return fmu


def run(fmu):
    """Step the instance to 0.05 s; its max run-up."""
    for k in range(5):
        fmu.doStep(currentCommunicationPoint=0.01 * k, communicationStepSize=0.01)
    return fmu.getReal([VR["max_run_up"]])[0]


first = unpack()
if SCENARIO == "after_error":
    case = json.load(open(os.path.join(first, "resources", "vajont_padua.json")))
    case["numerics"].update({"cfl": 1.0, "cfl_visc": 1.0})
    unstable = os.path.join(first, "vajont_unstable.json")
    json.dump(case, open(unstable, "w"))
    fmu = load(first, unstable)
    try:
        fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.5)
        sys.exit("the unstable case ran without an error")
    except FMICallException as e:
        print(f"the unstable case: {e}")
    fmu.freeInstance()  # from the error state; fmpy then unloads the library
    fmu = load(first)
    a = run(fmu)
    fmu.terminate()
    fmu.freeInstance()
else:
    fmu = load(first)
    a = run(fmu)
    if SCENARIO == "freed":
        fmu.terminate()
        fmu.freeInstance()  # fmpy: fmi2FreeInstance, then the library is unloaded
    elif SCENARIO == "not_freed":
        fmu.freeLibrary()
    else:
        sys.exit(f"unknown scenario {SCENARIO}")
fmu = load(unpack())  # another copy of the binary, as fmpy's simulate_fmu unpacks each time
b = run(fmu)
fmu.terminate()
fmu.freeInstance()
fmu = load(first)  # the first copy loaded again
c = run(fmu)
fmu.terminate()
fmu.freeInstance()
if not (a == b == c):
    sys.exit(f"the runs differ: max_run_up {a}, {b}, {c}")
print(f"{SCENARIO}: loaded three times, max_run_up {a}")
