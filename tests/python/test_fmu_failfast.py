"""The FMU refuses a case over the resource budget at once (issue 26): a case file with a tiny dx
given through `case_file` makes fmi2ExitInitializationMode return fmi2Error within a second, with
the library's message (the key, the estimate, the limit and its key) through the FMI logger.
Before the budget it did not return for over 60 s, filling the lattice."""
import json
import time

import pytest
from fmpy.fmi1 import FMICallException

import fmu_helpers as H


def test_a_case_with_a_tiny_dx_is_refused_within_a_second(tmp_path):
    case = json.loads(H.CASE.read_text())
    case["numerics"]["dx"] = 1e-6
    path = tmp_path / "vajont_tiny_dx.json"
    path.write_text(json.dumps(case))
    log = H.Logger()
    f = H.instance("tiny_dx", logger=log)
    f.setupExperiment(startTime=0.0)
    f.enterInitializationMode()
    v = H.vrs()
    f.setString([v["case_file"]], [str(path)])
    t0 = time.monotonic()
    with pytest.raises(FMICallException) as e:
        f.exitInitializationMode()
    took = time.monotonic() - t0
    assert e.value.status == 3  # fmi2Error
    assert took < 1.0, f"fmi2ExitInitializationMode took {took:.2f} s"
    errors = log.errors()
    assert len(errors) == 1, errors
    assert "numerics.dx" in errors[0] and "numerics.max_particles" in errors[0], errors
    assert str(path) in errors[0], errors
    f.freeInstance()
