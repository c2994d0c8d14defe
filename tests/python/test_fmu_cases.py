"""The LandslideWave FMU on a landslide case other than the Vajont one: its physical parameters
reach any case through the case's `parameters` block, not through the keys of one case.

cases/slope_tank.json (a gravel heap shoved by a ram into a tank; bundled in the FMU's
resources) names its media, bodies, walls and motion otherwise than cases/vajont_padua.json and
declares reservoir_level, phi, porosity, grain_density, saturated and the plate scales, but not
mu0, mu_thr or tension_cutoff. Each parameter set through the FMU must change the run exactly as
`mixsph run --set parameters.NAME=...` changes it (one thread: bit-identical, both go through the
library); a parameter the case does not declare is an fmi2Error whose logged message names it.
The Vajont case declares porosity, grain_density and the plate scales too (they were keys of its
media and motion before): the same comparison for those. About 20 s on an idle core.
"""
import json
import math

import pytest

import fmu_helpers as H
from fmpy.fmi1 import FMICallException

SLOPE = H.ROOT / "cases" / "slope_tank.json"
SLOPE_T_END = 1.2  # the case's numerics.t_end: the executable runs to it


@pytest.fixture(scope="module", autouse=True)
def _cleanup():
    yield
    H.cleanup()


def _simulate(params, stop):
    from fmpy import simulate_fmu
    return simulate_fmu(H.fmu_path(), start_values=params, stop_time=stop, output_interval=0.05)


def _same_outputs(res, summary):
    """The FMU run and the executable's: same steps, same maximum run-up and its time, same
    final landslide front (NaN equal to NaN), compared exactly."""
    cli = summary["outputs"]
    assert res["steps"][-1] == summary["steps"]
    assert res["max_run_up"][-1] == cli["run_up"]["max"]
    assert res["time_of_max_run_up"][-1] == cli["run_up"]["t_max"]
    front = cli["landslide_front"]["final"]
    assert (res["landslide_front"][-1] == front) or (front is None and math.isnan(res["landslide_front"][-1]))


def _names(case, section):
    return set(case.get(section, {}))


def test_slope_case_is_another_case_that_declares_the_parameters():
    # the point of the case: nothing of it is named as in the Vajont case, so a binding that
    # still used the Vajont keys (media.slide.porosity, motions.plate...) could not reach it
    slope, vajont = json.loads(SLOPE.read_text()), json.loads(H.CASE.read_text())
    for section in ("media", "bodies", "walls", "motions"):
        assert not _names(slope, section) & _names(vajont, section), section
    declared = set(slope["parameters"])
    assert {"reservoir_level", "phi", "porosity", "grain_density", "saturated", "plate_duration_scale",
            "plate_stroke_scale"} <= declared
    assert not {"mu0", "mu_thr", "tension_cutoff"} & declared  # left out for the error test below


@pytest.fixture(scope="module")
def slope_default():
    return _simulate({"case_file": "slope_tank.json"}, SLOPE_T_END)


def test_slope_case_with_no_parameter_set_is_the_executables_run(slope_default, tmp_path):
    summary = H.run_mixsph({}, tmp_path / "cli", case=SLOPE)
    _same_outputs(slope_default, summary)
    # a wave ran up the shore (still water at 0.24 m) and the landslide front moved
    assert slope_default["max_run_up"][-1] > 0.24 + 0.05
    assert slope_default["landslide_front"][-1] != slope_default["landslide_front"][0]


@pytest.mark.parametrize("params", [
    {"reservoir_level": 0.27},
    {"phi": 25.0},
    {"porosity": 0.45},
    {"grain_density": 2300.0},
    {"saturated": True},
    {"plate_duration_scale": 1.3},
    {"plate_stroke_scale": 0.7},
], ids=lambda p: next(iter(p)))
def test_slope_case_parameter_changes_the_run_as_the_executables_override(params, slope_default, tmp_path):
    res = _simulate({"case_file": "slope_tank.json", **params}, SLOPE_T_END)
    summary = H.run_mixsph(params, tmp_path / "cli", case=SLOPE)
    _same_outputs(res, summary)
    # and the parameter did reach the case: the run is not the default one
    assert (res["max_run_up"][-1], res["steps"][-1]) != (slope_default["max_run_up"][-1], slope_default["steps"][-1])


def test_pushing_the_slope_cases_ram():
    # the moving wall of this case is "ram" (motion "shove"): found through the library, pushed
    # along its direction of travel
    v = H.vrs()

    def front(push):
        f = H.instance("push")
        H.start(f, {"case_file": "slope_tank.json"})
        if push is not None:
            f.setBoolean([v["push_external"]], [True])
            f.setReal([v["push_velocity"]], [push])
        t = 0.0
        while t < 0.6 - 1e-12:
            f.doStep(currentCommunicationPoint=t, communicationStepSize=0.05)
            t += 0.05
        x = f.getReal([v["landslide_front"]])[0]
        f.freeInstance()
        return x

    still, law, fast = front(0.0), front(None), front(1.5)
    assert still < law < fast


@pytest.mark.parametrize("name,value", [("mu_thr", 1.0e5), ("mu0", 100.0), ("tension_cutoff", True)])
def test_a_parameter_the_case_does_not_declare_is_an_error_naming_it(name, value):
    log = H.Logger()
    f = H.instance("undeclared", logger=log)
    f.setupExperiment(startTime=0.0)
    f.enterInitializationMode()
    H.set_params(f, {"case_file": "slope_tank.json", "phi": 30.0, name: value})
    with pytest.raises(FMICallException) as e:
        f.exitInitializationMode()
    assert e.value.status == 3  # fmi2Error
    errors = log.errors()
    assert len(errors) == 1, errors
    assert errors[0].startswith(f"{name} was set"), errors
    assert f"parameters.{name}" in errors[0] and "slope_tank.json" in errors[0], errors
    assert "phi" in errors[0]  # it lists what the case does declare
    f.freeInstance()


def test_a_declared_parameter_left_alone_keeps_the_case_value_while_another_is_set(slope_default):
    # setting only mu-free parameters on the slope case works: the check concerns what is set
    res = _simulate({"case_file": "slope_tank.json", "phi": 32.0}, SLOPE_T_END)  # the case's own value
    assert res["max_run_up"][-1] == slope_default["max_run_up"][-1]
    assert res["steps"][-1] == slope_default["steps"][-1]


# ---- the Vajont case's newly declared parameters ---------------------------------------------

VAJONT_STOP = 1.6  # its t_end


@pytest.fixture(scope="module")
def vajont_default():
    """The Vajont case at the coarse dx with none of these parameters set, run once for the three
    comparisons below."""
    return _simulate(H.COARSE, VAJONT_STOP)


@pytest.mark.parametrize("params", [
    {"porosity": 0.42},
    {"grain_density": 2400.0},
    {"plate_duration_scale": 1.3, "plate_stroke_scale": 0.8},
], ids=lambda p: "+".join(p))
def test_vajont_parameters_reach_the_case_as_the_executables_override(params, vajont_default, tmp_path):
    res = _simulate({**H.COARSE, **params}, VAJONT_STOP)
    summary = H.run_mixsph({**H.COARSE, **params}, tmp_path / "cli")
    _same_outputs(res, summary)
    assert res["max_run_up"][-1] != vajont_default["max_run_up"][-1]
