"""LandslideWave FMU (FMI 2.0 co-simulation) driven by fmpy: validation, the same result as the
mixsph executable, a parameter effect, FMU state save/restore and serialisation, independent
instances, and errors instead of crashes.

Coarse runs (fmu_helpers.COARSE: the Vajont case at dx = 0.03 m, mu0 = 1 kPa s, one thread); the
whole file takes about a minute on an idle core.
"""
import math

import numpy as np
import pytest

import fmu_helpers as H
from fmpy.fmi1 import FMICallException


@pytest.fixture(scope="module", autouse=True)
def _cleanup():
    yield
    H.cleanup()


# ---- the model description --------------------------------------------------------------------

def test_validate_fmu_finds_no_problem():
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu, validate_model_description
    assert validate_fmu(H.fmu_path()) == []
    md = read_model_description(H.fmu_path())
    assert validate_model_description(md, validate_variable_names=True, validate_model_structure=True) == []
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    assert md.guid.startswith("{") and "@" not in md.guid and "@" not in (md.version or "")
    names = {v.name: v for v in md.modelVariables}
    for p in ["reservoir_level", "phi", "mu0", "mu_thr", "saturated", "dx", "plate_duration_scale",
              "plate_stroke_scale", "porosity", "grain_density", "output_interval", "case_file", "tension_cutoff",
              "pressure_smoothing", "av_wall", "rheology", "grain_bulk_modulus", "nu", "cohesion", "bed_friction"]:
        assert names[p].causality == "parameter", p
    for o in H.OUT_REAL + H.OUT_INT:
        assert names[o].causality == "output" and names[o].start is None, o
    assert names["push_velocity"].causality == "input"


def _case_value(case, key):
    """The value of a dotted case key, a "$name" resolved through the case's parameters."""
    node = case
    for part in key.split("."):
        node = node[part]
    if isinstance(node, str) and node.startswith("$"):
        node = case["parameters"][node[1:]]
    if node in ("explicit", "implicit"):  # numerics.viscosity: implicit_viscosity's false, true
        node = node == "implicit"
    return float(node)


def test_parameter_starts_are_the_bundled_case_values():
    # a parameter the host leaves alone keeps the case file's value, so its declared start must
    # be that value, or a tool reading the starts shows a run that is not the one made
    import json
    from fmpy import read_model_description
    names = {v.name: v for v in read_model_description(H.fmu_path()).modelVariables}
    case = json.loads(H.CASE.read_text())
    for name, key in H.CASE_KEYS.items():
        start = names[name].start
        start = float(start in (True, "true", "1", 1)) if names[name].type == "Boolean" else float(start)
        assert start == _case_value(case, key), f"{name}: start {start} but {key} = {_case_value(case, key)}"


def test_zip_layout():
    import zipfile
    with zipfile.ZipFile(H.fmu_path()) as z:
        files = set(z.namelist())
    assert {"modelDescription.xml", "binaries/linux64/LandslideWave.so",
            "resources/vajont_padua.json", "resources/slope_tank.json"} <= files


# ---- the same run as the executable -----------------------------------------------------------

RUN = {"reservoir_level": 0.46, "phi": 35.0, **H.COARSE}
STOP = 1.6  # the case's t_end: the executable runs to it


@pytest.fixture(scope="module")
def fmu_run_phi35():
    from fmpy import simulate_fmu
    return simulate_fmu(H.fmu_path(), start_values=RUN, stop_time=STOP, output_interval=0.02)


def test_simulate_fmu_matches_the_executable(fmu_run_phi35, tmp_path):
    res = fmu_run_phi35
    summary = H.run_mixsph(RUN, tmp_path / "cli")
    cli = summary["outputs"]["run_up"]
    # The same trajectory (steps are never shortened to land on a communication point) and the
    # same monitor samples: identical with one thread (summary.json is written with 17
    # significant digits, which round-trip a double exactly), and the same number of steps.
    assert res["max_run_up"][-1] == cli["max"]
    assert res["time_of_max_run_up"][-1] == cli["t_max"]
    assert res["steps"][-1] == summary["steps"]
    assert 0.5 < cli["max"] < 0.9  # a run-up, not an empty monitor (the experiment: 0.712 m)
    # max_run_up is the running maximum of the samples
    assert np.all(np.diff(res["max_run_up"]) >= 0)
    assert np.nanmax(res["run_up"]) <= res["max_run_up"][-1] + 1e-12
    # the water's own kinetic energy (monitor of the case): part of the total, nonzero once the
    # landslide has hit the reservoir
    assert np.all(res["water_kinetic_energy"] <= res["kinetic_energy"] * (1 + 1e-12))
    assert np.nanmax(res["water_kinetic_energy"]) > 0.0
    assert np.nanmax(res["water_kinetic_energy"]) < np.nanmax(res["kinetic_energy"])
    # full-scale map of the case: Z = 1211.8 z + 0.3
    assert res["max_run_up_Z"][-1] == pytest.approx(1211.8 * res["max_run_up"][-1] + 0.3, rel=1e-12)


def test_reservoir_level_sets_the_still_water():
    v = H.vrs()
    levels = {}
    for level in (0.40, 0.46, 0.52):
        f = H.instance("level")
        H.start(f, {**H.COARSE, "reservoir_level": level})
        levels[level] = f.getReal([v["run_up"]])[0]  # the highest water particle at t = 0
        f.freeInstance()
    # the top row of the lattice (spacing dx = 0.03) lies within dx below the level
    for level, z in levels.items():
        assert level - H.COARSE["dx"] <= z <= level, levels


def test_resource_location_with_escaped_characters(tmp_path):
    # fmpy passes the resources folder as a file:/// URI with %-escapes (here a space and a '%')
    import shutil
    d = tmp_path / "unpacked 100% here"
    shutil.copytree(H.unzipped(), d)
    log = H.Logger()
    f = H.instance("escaped", logger=log, unzipdir=str(d))
    H.start(f, H.COARSE)
    f.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)
    assert H.outputs(f)[-1] > 0 and not log.errors()  # steps taken, no error
    f.freeInstance()


def test_lower_friction_angle_raises_the_run_up(fmu_run_phi35):
    from fmpy import simulate_fmu
    res25 = simulate_fmu(H.fmu_path(), start_values={**RUN, "phi": 25.0}, stop_time=STOP, output_interval=0.02)
    assert res25["max_run_up"][-1] > fmu_run_phi35["max_run_up"][-1]


def test_tension_cutoff_parameter_matches_the_executable(fmu_run_phi35, tmp_path):
    # the Boolean parameter reaches the case as parameters.tension_cutoff = 1: the FMU's run is
    # the executable's with that override (identical with one thread), and not the default run
    from fmpy import simulate_fmu
    res = simulate_fmu(H.fmu_path(), start_values={**RUN, "tension_cutoff": True}, stop_time=STOP,
                       output_interval=0.02)
    cli = H.run_mixsph({**RUN, "tension_cutoff": True}, tmp_path / "cli")["outputs"]["run_up"]
    assert res["max_run_up"][-1] == cli["max"]
    assert res["max_run_up"][-1] != fmu_run_phi35["max_run_up"][-1]


def test_av_wall_parameter_matches_the_executable(fmu_run_phi35, tmp_path):
    # the Boolean parameter (default true) reaches the case as numerics.av_wall = 0 when set
    # false: the FMU's run is the executable's with that override (identical with one thread),
    # and not the default run
    from fmpy import simulate_fmu
    res = simulate_fmu(H.fmu_path(), start_values={**RUN, "av_wall": False}, stop_time=STOP, output_interval=0.02)
    cli = H.run_mixsph({**RUN, "av_wall": False}, tmp_path / "cli")["outputs"]["run_up"]
    assert res["max_run_up"][-1] == cli["max"]
    assert res["max_run_up"][-1] != fmu_run_phi35["max_run_up"][-1]


def test_implicit_viscosity_parameter_matches_the_executable(fmu_run_phi35, tmp_path):
    # the Boolean parameter (default false, the case's "explicit") reaches the case as
    # numerics.viscosity = 1 ("implicit"): the FMU's run is the executable's with that override
    # (identical with one thread), and not the explicit run (at this coarse dx both take the
    # acoustic time step, so the steps agree; the schemes differ)
    from fmpy import simulate_fmu
    res = simulate_fmu(H.fmu_path(), start_values={**RUN, "implicit_viscosity": True}, stop_time=STOP,
                       output_interval=0.02)
    cli = H.run_mixsph({**RUN, "implicit_viscosity": True}, tmp_path / "cli")
    assert res["max_run_up"][-1] == cli["outputs"]["run_up"]["max"]
    assert res["steps"][-1] == cli["steps"]
    assert res["max_run_up"][-1] != fmu_run_phi35["max_run_up"][-1]


def test_pressure_smoothing_parameter_matches_the_executable(fmu_run_phi35, tmp_path):
    # the real parameter (default 0.4, the case file's) reaches the case as
    # numerics.pressure_smoothing: switched off, the FMU's run is the executable's with that
    # override (identical with one thread), and not the default run
    from fmpy import simulate_fmu
    res = simulate_fmu(H.fmu_path(), start_values={**RUN, "pressure_smoothing": 0.0}, stop_time=STOP,
                       output_interval=0.02)
    cli = H.run_mixsph({**RUN, "pressure_smoothing": 0.0}, tmp_path / "cli")["outputs"]["run_up"]
    assert res["max_run_up"][-1] == cli["max"]
    assert res["max_run_up"][-1] != fmu_run_phi35["max_run_up"][-1]


# ---- FMU state ---------------------------------------------------------------------------------

def _trajectory(fmu, t0, t1, h):
    rows = []
    t = t0
    while t < t1 - 1e-12:
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
        rows.append(H.outputs(fmu))
    return rows


def _same(a, b):
    """Identical rows, NaN equal to NaN."""
    assert len(a) == len(b)
    for ra, rb in zip(a, b):
        for x, y in zip(ra, rb):
            assert (x == y) or (isinstance(x, float) and math.isnan(x) and math.isnan(y)), (ra, rb)


def test_state_save_continue_restore_continue_and_serialize():
    params = {**H.COARSE, "phi": 30.0}
    fmu = H.instance("a")
    H.start(fmu, params)
    h = 0.02
    _trajectory(fmu, 0.0, 0.3, h)
    state = fmu.getFMUstate()
    first = _trajectory(fmu, 0.3, 0.6, h)
    assert first[-1][H.OUT_REAL.index("landslide_front")] > first[0][H.OUT_REAL.index("landslide_front")]
    fmu.setFMUstate(state)
    again = _trajectory(fmu, 0.3, 0.6, h)
    _same(first, again)

    blob = fmu.serializeFMUstate(state)
    fmu.freeFMUstate(state)
    # a second instance with other (default) parameters takes the state's parameters and case
    other = H.instance("b")
    H.start(other, {"dx": 0.02})
    restored = other.deSerializeFMUstate(blob)
    other.setFMUstate(restored)
    other.freeFMUstate(restored)
    v = H.vrs()
    assert other.getReal([v["phi"], v["dx"]]) == [30.0, 0.03]
    third = _trajectory(other, 0.3, 0.6, h)
    _same(first, third)
    # a corrupted blob is an error, not a crash
    with pytest.raises(FMICallException):
        other.deSerializeFMUstate(blob[: len(blob) // 2])
    bad = bytearray(blob)
    bad[-100] ^= 0xFF
    st = other.deSerializeFMUstate(bytes(bad))
    before = H.outputs(other)
    with pytest.raises(FMICallException):
        other.setFMUstate(st)
    other.freeFMUstate(st)
    assert H.outputs(other) == before  # a refused state leaves the instance as it was
    other.doStep(currentCommunicationPoint=0.6, communicationStepSize=0.02)
    for f in (fmu, other):
        f.freeInstance()


# ---- independent instances -------------------------------------------------------------------

def test_two_instances_stepped_alternately_match_their_solo_runs():
    pa = {**H.COARSE, "phi": 35.0}
    pb = {**H.COARSE, "phi": 25.0, "reservoir_level": 0.44}
    h, t1 = 0.05, 0.5

    def solo(params):
        f = H.instance("solo")
        H.start(f, params)
        rows = _trajectory(f, 0.0, t1, h)
        f.freeInstance()
        return rows

    a, b = H.instance("A"), H.instance("B")
    H.start(a, pa)
    H.start(b, pb)
    ra, rb = [], []
    t = 0.0
    while t < t1 - 1e-12:
        a.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        b.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        ra.append(H.outputs(a))
        rb.append(H.outputs(b))
        t += h
    a.freeInstance()
    b.freeInstance()
    _same(ra, solo(pa))
    _same(rb, solo(pb))
    assert ra[-1] != rb[-1]  # the parameters do matter


# ---- the co-simulation input -------------------------------------------------------------------

def test_external_push_velocity_replaces_the_law():
    v = H.vrs()
    h, t1 = 0.05, 0.4

    def front(push):
        f = H.instance("push")
        H.start(f, H.COARSE)
        if push is not None:
            f.setBoolean([v["push_external"]], [True])
            f.setReal([v["push_velocity"]], [push])
        _trajectory(f, 0.0, t1, h)
        x = f.getReal([v["landslide_front"]])[0]
        f.freeInstance()
        return x

    law, still, fast = front(None), front(0.0), front(1.2)
    # no push: the toe barely moves; the law (0.62 m/s at most) moves it; 1.2 m/s moves it more
    assert still < law < fast


# ---- errors, not crashes -----------------------------------------------------------------------

def _expect_error(logger, fn, *args, text=None, **kw):
    n = len(logger.errors())
    with pytest.raises(FMICallException) as e:
        fn(*args, **kw)
    assert e.value.status == 3  # fmi2Error
    new = logger.errors()[n:]
    assert new, "no message through the FMI logger"
    if text:
        assert any(text in m for m in new), new


def test_invalid_parameters_give_fmi2error_and_a_logged_message(tmp_path):
    v = H.vrs()
    log = H.Logger()

    # out of range (the model description's min/max) and non-finite values
    f = H.instance("range", logger=log)
    _expect_error(log, f.setReal, [v["phi"]], [95.0], text="phi = 95 is out of range")
    _expect_error(log, f.setReal, [v["mu0"]], [-1.0], text="mu0")
    _expect_error(log, f.setReal, [v["dx"]], [float("nan")], text="dx")
    _expect_error(log, f.setReal, [v["pressure_smoothing"]], [1.5], text="pressure_smoothing = 1.5 is out of range")
    _expect_error(log, f.setInteger, [v["threads"]], [-2], text="threads")
    # the instance stays usable after a rejected value
    H.start(f, H.COARSE)
    f.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)
    # fixed parameters cannot change once running; inputs must be finite
    _expect_error(log, f.setReal, [v["phi"]], [30.0], text="fixed parameter")
    _expect_error(log, f.setReal, [v["push_velocity"]], [float("inf")], text="push_velocity")
    f.freeInstance()

    # inconsistent parameters: each value in range, but not for the chosen case (the water dam
    # break, by absolute path, has no friction angle and no moving wall to push)
    dambreak = str(H.ROOT / "cases" / "dambreak_water.json")
    f = H.instance("inconsistent", logger=log)
    f.setupExperiment(startTime=0.0)
    f.enterInitializationMode()
    H.set_params(f, {"case_file": dambreak, "phi": 30.0})
    _expect_error(log, f.exitInitializationMode, text="parameters.phi")
    f.freeInstance()
    f = H.instance("inconsistent2", logger=log)
    f.setupExperiment(startTime=0.0)
    f.enterInitializationMode()
    H.set_params(f, {"case_file": dambreak, "push_external": True})
    _expect_error(log, f.exitInitializationMode, text="no moving wall")
    f.freeInstance()

    # a missing resource
    f = H.instance("missing", logger=log)
    f.setupExperiment(startTime=0.0)
    f.enterInitializationMode()
    H.set_params(f, {"case_file": "no_such_case.json"})
    _expect_error(log, f.exitInitializationMode, text="no_such_case.json")
    f.freeInstance()

    # a non-finite state: the Vajont case with time-step coefficients far too large (a copy
    # written for the test, given by absolute path) blows up within a few steps
    import json
    case = json.loads(H.CASE.read_text())
    case["numerics"].update({"cfl": 1.0, "cfl_visc": 1.0})
    unstable = tmp_path / "vajont_unstable.json"
    unstable.write_text(json.dumps(case))
    f = H.instance("unstable", logger=log)
    H.start(f, {**H.COARSE, "case_file": str(unstable)})
    _expect_error(log, f.doStep, currentCommunicationPoint=0.0, communicationStepSize=0.5, text="unstable")
    # the instance is in the error state: it refuses to step on, and can be freed
    with pytest.raises(FMICallException):
        f.doStep(currentCommunicationPoint=0.5, communicationStepSize=0.1)
    f.freeInstance()

    # model exchange functions exist (fmpy resolves them) and refuse
    import ctypes
    f = H.instance("me", logger=log)
    n = len(log.errors())
    for name in ["fmi2EnterEventMode", "fmi2EnterContinuousTimeMode"]:
        fn = getattr(f.dll, name)
        fn.argtypes, fn.restype = [ctypes.c_void_p], ctypes.c_int
        assert fn(f.component) == 3
    assert len(log.errors()) == n + 2 and "co-simulation" in log.errors()[-1]
    f.freeInstance()


# ---- the granular law: rheology and the elastic-plastic law's parameters -----------------------

def test_rheology_is_an_enumeration_of_the_case_laws_numbers():
    # the items' values are the numbers by which a case chooses a granular medium's law
    # (media.NAME.law: "paper" or "elastic_plastic" (or 0, 1), docs/cases.md, generated from the
    # key tables), so the FMU passes the value through unchanged
    import re
    md = H.model_description()
    v = {x.name: x for x in md.modelVariables}["rheology"]
    assert v.type == "Enumeration" and v.causality == "parameter" and v.variability == "fixed"
    items = {it.name: int(it.value) for it in v.declaredType.items}
    assert items == {"paper": 0, "elastic_plastic": 1}
    assert int(v.start) == items["paper"]  # the default: the paper's law
    docs = (H.ROOT / "docs" / "cases.md").read_text()
    row = re.search(r'^\| `law` \| string \| no \| this law when the medium gives mu_thr or mu1, else '
                    r'elastic_plastic \| ([^|]*)\|', docs, re.M)
    assert row and row.group(1).strip() == '`"paper"` or `"elastic_plastic"` (or 0, 1)', row
    # the paper law's parameters say that the elastic-plastic law ignores them, and conversely
    for name in ("mu0", "mu_thr", "tension_cutoff"):
        d = {x.name: x for x in md.modelVariables}[name].description
        assert "ignored with elastic_plastic" in d, name
    for name in ("nu", "cohesion"):
        d = {x.name: x for x in md.modelVariables}[name].description
        assert "ignored with paper" in d, name


EP_STOP = 0.6  # the slide has entered the reservoir and the wave runs (run-up 0.50-0.55 m)


@pytest.fixture(scope="module")
def fmu_run_ep():
    from fmpy import simulate_fmu
    return simulate_fmu(H.fmu_path(), start_values={**RUN, "rheology": 1}, stop_time=EP_STOP, output_interval=0.02)


def test_elastic_plastic_rheology_matches_the_executable_and_differs_from_paper(fmu_run_ep, fmu_run_phi35,
                                                                                  tmp_path):
    # rheology = elastic_plastic reaches the case as parameters.rheology = 1: the FMU's run is the
    # executable's with that override (identical with one thread), with the P-wave time step of
    # the elastic law (more steps than the paper law's acoustic one) and no held grains
    res = fmu_run_ep
    cli = H.run_mixsph({**RUN, "rheology": 1}, tmp_path / "cli", t_end=EP_STOP)
    assert res["max_run_up"][-1] == cli["outputs"]["run_up"]["max"]
    assert res["steps"][-1] == cli["steps"]
    assert np.all(res["fixed_particles"] == 0)
    paper = H.run_mixsph(RUN, tmp_path / "paper", t_end=EP_STOP)
    assert res["max_run_up"][-1] != paper["outputs"]["run_up"]["max"]
    assert res["steps"][-1] > paper["steps"]
    assert np.isfinite(res["landslide_front"][-1]) and res["lost_particles"][-1] == 0


def test_elastic_plastic_parameters_act_on_their_law_only(fmu_run_ep, fmu_run_phi35):
    from fmpy import simulate_fmu
    # with the paper's law (the default) nu, cohesion are ignored: the default run bit for bit
    paper = simulate_fmu(H.fmu_path(), start_values={**RUN, "nu": 0.45, "cohesion": 500.0}, stop_time=STOP,
                         output_interval=0.02)
    assert paper["max_run_up"][-1] == fmu_run_phi35["max_run_up"][-1]
    assert paper["steps"][-1] == fmu_run_phi35["steps"][-1]
    # with elastic_plastic they change the run, and mu_thr, mu0 do not
    ep = dict(RUN, rheology=1)
    soft = simulate_fmu(H.fmu_path(), start_values={**ep, "nu": 0.45}, stop_time=EP_STOP, output_interval=0.02)
    assert soft["max_run_up"][-1] != fmu_run_ep["max_run_up"][-1]
    assert soft["steps"][-1] < fmu_run_ep["steps"][-1]  # nu -> 0.5: G -> 0, a slower P wave
    cohesive = simulate_fmu(H.fmu_path(), start_values={**ep, "cohesion": 500.0}, stop_time=EP_STOP,
                            output_interval=0.02)
    assert cohesive["landslide_front"][-1] != fmu_run_ep["landslide_front"][-1]
    viscous = simulate_fmu(H.fmu_path(), start_values={**ep, "mu_thr": 1e4, "mu0": 10.0}, stop_time=EP_STOP,
                           output_interval=0.02)
    assert viscous["max_run_up"][-1] == fmu_run_ep["max_run_up"][-1]
    assert viscous["steps"][-1] == fmu_run_ep["steps"][-1]


def test_bed_friction_reaches_the_bed_wall(fmu_run_phi35, tmp_path):
    from fmpy import simulate_fmu
    # bed_friction reaches the case as parameters.bed_friction, the Vajont bed wall's friction: the
    # FMU's run is the executable's with that override, and a Coulomb bed (delta = 20 degrees, the
    # paper law's grains then slide on it) moves the slide's front from the default's (90: the
    # paper's no-slip bed); an angle out of [0, 90] is an fmi2Error naming it
    res = simulate_fmu(H.fmu_path(), start_values={**RUN, "bed_friction": 20.0}, stop_time=EP_STOP,
                       output_interval=0.02)
    cli = H.run_mixsph({**RUN, "bed_friction": 20.0}, tmp_path / "cli", t_end=EP_STOP)
    assert res["max_run_up"][-1] == cli["outputs"]["run_up"]["max"]
    assert res["steps"][-1] == cli["steps"]
    default = fmu_run_phi35[fmu_run_phi35["time"] <= EP_STOP + 1e-9]
    assert res["landslide_front"][-1] != default["landslide_front"][-1]
    v = H.vrs()
    log = H.Logger()
    f = H.instance("bed_friction", logger=log)
    _expect_error(log, f.setReal, [v["bed_friction"]], [95.0], text="bed_friction = 95 is out of range [0, 90]")
    assert f.getReal([v["bed_friction"]]) == [90.0]  # the instance keeps the value it had
    f.freeInstance()


def test_bad_rheology_values_give_fmi2error_and_a_logged_message():
    v = H.vrs()
    log = H.Logger()
    f = H.instance("rheology", logger=log)
    _expect_error(log, f.setInteger, [v["rheology"]], [2],
                  text="rheology = 2 is not one of its items: 0 (paper), 1 (elastic_plastic)")
    _expect_error(log, f.setInteger, [v["rheology"]], [-1], text="rheology = -1")
    _expect_error(log, f.setReal, [v["nu"]], [0.5], text="nu = 0.5 is out of range [0, 0.49]")
    _expect_error(log, f.setReal, [v["cohesion"]], [-1.0], text="cohesion = -1 is out of range")
    _expect_error(log, f.setReal, [v["grain_bulk_modulus"]], [0.0], text="grain_bulk_modulus = 0 is out of range")
    # the instance stays usable, with the value it had
    assert f.getInteger([v["rheology"]]) == [0]
    H.start(f, {**H.COARSE, "rheology": 1})
    assert f.getInteger([v["rheology"]]) == [1]
    f.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)
    _expect_error(log, f.setInteger, [v["rheology"]], [0], text="fixed parameter")
    f.freeInstance()
    # a case that does not declare rheology (slope_tank.json, a resource): an error naming it
    f = H.instance("rheology_case", logger=log)
    f.setupExperiment(startTime=0.0)
    f.enterInitializationMode()
    H.set_params(f, {"case_file": "slope_tank.json", "rheology": 1})
    _expect_error(log, f.exitInitializationMode, text="rheology")
    f.freeInstance()
