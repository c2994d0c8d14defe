"""Replay FMU runs with the mixsph executable, for their particles.

The FMU writes no files (its library variant has no HDF5, docs/fmu.md), so a study's runs have
their outputs and monitors over time but no particle snapshots. A replay runs the same scenario
with `mixsph run` (same case, same overrides, same library: the runs are deterministic and do not
depend on the thread count) with snapshots, into OUT/replays/<scenario_id>/, whose page data
(html_report.run_data) the study page animates.

The FMU's parameters map to the case's keys as the FMU documents it: each parameter's
description in modelDescription.xml names its key (parameters.phi, numerics.dx,
numerics.viscosity, ...); case_file is the case (a name in the FMU's resources/, which are the
repository's cases/, or a path); threads is mixsph's --threads.
"""

from __future__ import annotations

import math
import os
import re
import subprocess

from .cli import ROOT, UsageError

KEY = re.compile(r"\b((?:parameters|numerics|output)\.[A-Za-z_0-9]+)")
REPLAYS = "replays"
DEFAULT_MIXSPH = os.path.join(ROOT, "build", "mixsph")


def case_keys(fmu_path) -> dict:
    """FMU parameter name -> the case key its description names (those that name one)."""
    from fmpy import read_model_description
    md = read_model_description(fmu_path)
    out = {}
    for v in md.modelVariables:
        if v.causality != "parameter":
            continue
        m = KEY.search(v.description or "")
        if m:
            out[v.name] = m.group(1)
    return out


def command(mixsph, scenario: dict, keys: dict, stop_time: float, out_dir: str,
            snapshots: int) -> list[str]:
    """The mixsph command of a scenario (FMU parameter -> value)."""
    case = str(scenario.get("case_file") or "vajont_padua.json")
    if not os.path.isabs(case):
        case = os.path.join(ROOT, "cases", case)
    if not os.path.isfile(case):
        raise UsageError(f"replay: the case {case} of scenario {scenario.get('scenario_id')} is "
                         f"not there")
    cmd = [mixsph, "run", case, "--out", out_dir, "--threads", "1", "--quiet"]
    for name, value in scenario.items():
        if name in ("scenario_id", "case_file", "threads", "stop_time"):
            continue
        if value is None or (isinstance(value, float) and math.isnan(value)):
            continue
        key = keys.get(name)
        if key is None:
            raise UsageError(f"replay: the FMU parameter {name!r} names no case key in its "
                             f"description: cannot replay it with mixsph")
        try:
            x = float(value)
        except (TypeError, ValueError):
            raise UsageError(f"replay: {name} = {value!r} of scenario {scenario.get('scenario_id')}"
                             f" is not a number: mixsph --set takes numbers") from None
        cmd += ["--set", f"{key}={int(x)}" if x.is_integer() else f"{key}={x!r}"]
    cmd += ["--set", f"numerics.t_end={stop_time!r}",
            "--set", f"output.snapshot_interval={stop_time / max(1, snapshots)!r}"]
    return cmd


def replay(folder, scenarios: list[dict], fmu_path, stop_time, mixsph=None, snapshots=25,
           log=print) -> dict:
    """Run each scenario (its own parameters: the scenario table's row) with mixsph into
    FOLDER/replays/<scenario_id>/ unless a finished replay is there; {scenario_id: folder}."""
    mixsph = mixsph or DEFAULT_MIXSPH
    if not os.path.isfile(mixsph):
        raise UsageError(f"replay: {mixsph} is not built (./tools/do build)")
    if not fmu_path or not os.path.isfile(fmu_path):
        raise UsageError(f"replay: the FMU {fmu_path} is not there: its parameters' case keys "
                         f"are read from it")
    keys = case_keys(fmu_path)
    done = {}
    for s in scenarios:
        sid = str(s["scenario_id"])
        out = os.path.join(folder, REPLAYS, sid)
        summary = os.path.join(out, "summary.json")
        if not os.path.isfile(summary):
            cmd = command(mixsph, s, keys, stop_time, out, snapshots)
            log(f"dss page: replaying {sid} with mixsph for its particles ({' '.join(cmd[3:])})")
            r = subprocess.run(cmd, capture_output=True, text=True,
                               env=dict(os.environ, OMP_WAIT_POLICY="passive"))
            if r.returncode != 0:
                log(f"dss page: the replay of {sid} failed (exit {r.returncode}): "
                    f"{(r.stderr or r.stdout).strip()[-400:]}")
                continue
        done[sid] = out
    return done
