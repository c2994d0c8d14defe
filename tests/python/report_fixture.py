"""A small DSS study made without the FMU, for the tests of the study page: the multi-fidelity
design of tools/dss (mfdesign.MFDesign, its folder, store and state) on a stand-in of the FMU (a
smooth response of reservoir level, phi and saturated over a ladder of three spacings that
converges at order 1.5, with monitors over time), its final fit and emulate study's ending
(emulate_mf.finish_study: study.json and the page). Also a run folder with the files a mixsph
run writes (monitors.csv, summary.json, a profile, snapshots) for the run page."""

import json
import math
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, ROOT)

from tools.dss import emulate_mf as EMF  # noqa: E402
from tools.dss import mfdesign as MD  # noqa: E402
from tools.dss import scenarios as S  # noqa: E402

DISTS = ["reservoir_level=uniform:0.40:0.52", "phi=uniform:25:40", "saturated=choice:0,1"]
LEVELS = [0.04, 0.03, 0.02]
CREST = 850.0


def cost(dx):
    """CPU seconds of a stand-in run: dx^-4, as the FMU's (particles x steps)."""
    return 1e-6 * dx ** -4


def runup(s):
    """The stand-in's max run-up [m, model scale]: a smooth response plus an O(dx^1.5) error."""
    a = (s["reservoir_level"] - 0.40) / 0.12
    b = (s["phi"] - 25.0) / 15.0
    g = 0.62 + 0.16 * a + 0.03 * np.sin(3 * b) + 0.02 * s["saturated"]
    return float(g - 8.0 * (1 + 0.3 * a) * s["dx"] ** 1.5)


def run_result(s):
    """What the runner stores for a stand-in run, monitors over time included."""
    y = runup(s)
    t = np.arange(1, 33) * 0.05
    r = y * np.clip(t / 1.2, 0, 1) ** 2
    series = {"time": t.tolist(), "run_up": r.tolist(),
              "landslide_front": (0.3 + 0.5 * np.tanh(t)).tolist(),
              "kinetic_energy": (50 * t * np.exp(-t)).tolist()}
    return {**s, "status": "ok", "error": "", "max_run_up": y, "max_run_up_Z": 700.0 + 200.0 * y,
            "time_of_max_run_up": 1.2, "cpu_time_s": cost(s["dx"]), "wall_time_s": cost(s["dx"]),
            "series": series, "finished_at": f"{time.time():.6f}"}


def make_study(out, init=(8, 4, 3), n_risk=20_000):
    """The study folder OUT (design, fit, study.json, report.html); returns the emulator."""
    dists = [S.Distribution(*S.split_assignment(d)) for d in DISTS]
    budget = sum(n * cost(dx) for n, dx in zip(init, LEVELS)) * 1.001
    settings = {"fmu": None, "stop_time": 1.6, "step": 0.05, "fixed": {}, "threads": 1,
                "levels": LEVELS}
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "sweep.json"), "w") as f:
        json.dump(settings, f)
    des = MD.MFDesign(out, dists, {}, 1.6, LEVELS, budget, init=list(init), n_workers=2,
                      progress=False, n_candidates=200, settings=settings)

    def evaluate(scen, on_result):
        for s in scen:
            on_result(run_result(s))
    t0 = time.monotonic()
    des.run(evaluate)
    em = des.fit(des.results(), outputs=["max_run_up", "max_run_up_Z"], restarts=0)
    em.save(os.path.join(out, "mf_emulator.json"))
    EMF.finish_study(out, em, {d.name: d for d in dists}, "max_run_up_Z", CREST, "extrapolated",
                     n_risk, 0, t0)
    return em


def make_run_dir(out, n_snap=5, n_particles=600):
    """A folder with the files of a mixsph run (docs/output.md), made up."""
    os.makedirs(out, exist_ok=True)
    t = np.linspace(0, 1.6, 81)
    with open(os.path.join(out, "monitors.csv"), "w") as f:
        f.write("t,step,kinetic_energy,run_up\n")
        for k, tt in enumerate(t):
            f.write(f"{tt:.6g},{10 * k},{50 * tt * math.exp(-tt):.6g},{0.7 * min(tt / 1.2, 1) ** 2:.6g}\n")
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump({"status": "ok", "wall_time_s": 1.0, "simulated_time_s": 1.6, "threads": 1,
                   "outputs": {"run_up": {"final": 0.7, "max": 0.7, "t_max": 1.2, "min": 0.0,
                                          "t_min": 0.0}}}, f)
    with open(os.path.join(out, "profile_surface_0.csv"), "w") as f:
        f.write("# profile surface of water at t = 0.8 s (requested 0.8 s): top per x bin\nx,z_top\n")
        for x in np.linspace(0, 1, 21):
            f.write(f"{x:.4g},{0.4 + 0.05 * math.sin(6 * x):.4g}\n")
    rng = np.random.default_rng(0)
    x0 = rng.random(n_particles)
    z0 = 0.4 * rng.random(n_particles)
    for k in range(n_snap):
        with open(os.path.join(out, f"snap_{k:04d}.csv"), "w") as f:
            f.write(f"# t = {0.4 * k:.6g} s\n")
            f.write("id,x,z,vx,vz,rho,p,mu,medium,state\n")
            for i in range(n_particles):
                f.write(f"{i},{x0[i] + 0.02 * k:.5g},{z0[i]:.5g},0,0,1000,0,0.001,{i % 2},"
                        f"{2 if i < 20 else 0}\n")
    return out
