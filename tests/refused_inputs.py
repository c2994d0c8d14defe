#!/usr/bin/env python3
"""Inputs the mixsph executable must refuse at once (issue 26): each mutant of a bundled case is
run as `mixsph run`, and must exit with code 2 within a second of CPU time, with a message on stderr naming
the key (and, for the resource budget, the limit's key), using bounded memory: under an address-
space limit (RLIMIT_AS) in a normal build, under AddressSanitizer's RSS limit in the sanitizer
build (ASan reserves terabytes of address space, so RLIMIT_AS cannot bound it).

    refused_inputs.py MIXSPH [--asan] NAME     one mutant (CTest runs one test per mutant)
    refused_inputs.py MIXSPH [--asan] --list   the mutants' names

Each mutant reproduces an input that crashed, hung or ate memory before it was refused, or one
the reader accepted while it should not (the issue's list), or one the fuzzer found
(tests/fuzz/fuzz_case.c). Only the standard library: it runs with any python3.
"""
import json
import os
import pathlib
import resource
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
SECONDS = 1.0                 # the "within a second"
MEMORY_BYTES = 1 << 30        # 1 GiB of address space (a normal build)
ASAN_RSS_MB = 1024            # the same bound as resident memory under ASan


def case(name):
    return json.loads((ROOT / "cases" / name).read_text())


def vajont():
    return case("vajont_padua.json")


def with_wall_to_1e6():
    c = vajont()
    line = c["walls"]["bed"]["polyline"]
    line.append([1.0e6, line[-1][1]])
    return c


def with_wide_profile():
    c = vajont()
    c["monitors"]["water_surface"].update(x_min=-50.0, x_max=50.0, bin=1e-7)
    return c


def renamed(section, old, new, fix=None):
    def make():
        c = vajont()
        c[section] = {new if k == old else k: v for k, v in c[section].items()}
        if fix:
            fix(c, new)
        return c
    return make


def fix_run_up(c, new):
    c["full_scale"]["reference"]["monitor"] = new


def fix_water(c, new):
    for b in c["bodies"].values():
        if b["medium"] == "water":
            b["medium"] = new
    for m in c["monitors"].values():
        if m.get("medium") == "water":
            m["medium"] = new
    for m in c["media"].values():
        if m.get("pore_fluid") == "water":
            m["pore_fluid"] = new


def outside_domain():
    c = vajont()
    c["bodies"]["reservoir"]["polygon"] = [[x + 10.0, z] for x, z in c["bodies"]["reservoir"]["polygon"]]
    return c


def behind_wall():
    c = vajont()  # under the bed (its fluid side is above it), inside the domain
    c["bodies"]["buried"] = {"medium": "water", "polygon": [[0.1, -0.05], [0.3, -0.05], [0.3, 0.0], [0.1, 0.0]]}
    return c


def text_duplicate_parameter():
    # the second "gravity" is a "$g" reference: the substitution looped forever (cJSON's replace
    # by name finds the first "gravity")
    c = vajont()
    c["parameters"]["g"] = 9.81
    return json.dumps(c, indent=1).replace('"name": "vajont_padua",',
                                           '"name": "vajont_padua", "gravity": 9.81, "gravity": "$g",', 1)


def text_duplicate_medium():
    # a bogus first "water" was the one the bodies used
    return json.dumps(vajont(), indent=1).replace(
        '"media": {', '"media": {"water": {"type": "fluid", "rho": 1, "c": 10},', 1)


# name: (the case (a function giving its JSON object or text), overrides, what stderr must contain)
MUTANTS = {
    "profile_bin_1e-300": (vajont, ["monitors.water_surface.bin=1e-300"],
                           ["monitors.water_surface.bin", "output.max_profile_bins"]),
    "profile_bin_1e-25": (vajont, ["monitors.water_surface.bin=1e-25"],
                          ["monitors.water_surface.bin", "output.max_profile_bins"]),
    "profile_100m_bin_1e-7": (with_wide_profile, [], ["monitors.water_surface.bin", "1e9 bins",
                                                      "output.max_profile_bins"]),
    "monitor_interval_1e-17": (vajont, ["numerics.t_end=1e-3", "output.monitor_interval=1e-17"],
                               ["output.monitor_interval", "output.max_monitor_rows"]),
    "monitor_interval_1e-300": (vajont, ["numerics.t_end=1e-3", "output.monitor_interval=1e-300"],
                                ["output.monitor_interval", "output.max_monitor_rows"]),
    "snapshot_interval_1e-17": (vajont, ["numerics.t_end=1e-3", "output.snapshot_interval=1e-17"],
                                ["output.snapshot_interval", "output.max_snapshot_bytes"]),
    "snapshot_interval_1e-300": (vajont, ["numerics.t_end=1e-3", "output.snapshot_interval=1e-300"],
                                 ["output.snapshot_interval", "output.max_snapshot_bytes"]),
    "dx_1e-6": (vajont, ["numerics.dx=1e-6"], ["numerics.dx", "particles", "numerics.max_particles"]),
    "dx_1e-5": (vajont, ["numerics.dx=1e-5"], ["numerics.dx", "particles", "numerics.max_particles"]),
    "wall_to_1e6_m": (with_wall_to_1e6, [], ["walls.bed.polyline", "6e8 wall particles",
                                             "numerics.max_particles"]),
    "t_end_1e4": (vajont, ["numerics.t_end=1e4", "output.monitor_interval=1", "output.snapshot_interval=0"],
                  ["numerics.t_end", "time steps", "numerics.max_steps"]),
    "duplicate_key_parameter": (text_duplicate_parameter, [], ['"gravity" is given twice']),
    "duplicate_medium": (text_duplicate_medium, [], ['media: the key "water" is given twice']),
    "monitor_name_comma": (renamed("monitors", "run_up", "run,up", fix_run_up), [],
                           ['monitors: the name "run,up" is not a plain identifier']),
    "monitor_name_quote": (renamed("monitors", "run_up", 'run"up', fix_run_up), [],
                           ['monitors: the name "run\\"up" is not a plain identifier']),
    "monitor_name_newline": (renamed("monitors", "run_up", "run\nup", fix_run_up), [],
                             ['monitors: the name "run\\nup" is not a plain identifier']),
    "medium_name_comma": (renamed("media", "water", "wat,er", fix_water), [],
                          ['media: the name "wat,er" is not a plain identifier']),
    "wall_name_slash": (renamed("walls", "bed", "../bed"), [], ['walls: the name "../bed" is not a plain identifier']),
    "body_outside_domain": (outside_domain, [], ["bodies.reservoir", "outside the domain"]),
    "body_behind_wall": (behind_wall, [], ["bodies.buried", "fluid side of the walls"]),
}


def limit_memory():
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_BYTES, MEMORY_BYTES))


def run(mixsph, asan, name):
    make, sets, expected = MUTANTS[name]
    made = make()
    text = made if isinstance(made, str) else json.dumps(made, indent=1)
    with tempfile.TemporaryDirectory(prefix="mixsph_refused_") as d:
        path = pathlib.Path(d) / f"{name}.json"
        path.write_text(text)
        cmd = [mixsph, "run", str(path), "--quiet", "--threads", "1", "--out", str(pathlib.Path(d) / "out")]
        for s in sets:
            cmd += ["--set", s]
        env = dict(os.environ, OMP_NUM_THREADS="1")
        if asan:
            env["ASAN_OPTIONS"] = f"hard_rss_limit_mb={ASAN_RSS_MB}:max_allocation_size_mb={ASAN_RSS_MB}:" \
                                  "allocator_may_return_null=0:" + env.get("ASAN_OPTIONS", "")
        t0 = time.monotonic()
        cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=10 * SECONDS,
                               preexec_fn=None if asan else limit_memory)
        except subprocess.TimeoutExpired:
            print(f"{name}: FAILED: still running after {10 * SECONDS:g} s (accepted?)")
            return 1
        took = time.monotonic() - t0
        cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    # the bound is on the child's CPU time: a refusal that works through a huge input, or
    # allocates it, spends CPU time; wall time also counts the waits of a loaded machine
    # (a sanitizer build beside other jobs took 1.1-1.4 s of wall time for these)
    cpu = (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)
    print(f"{name}: exit {p.returncode} in {took:.3f} s ({cpu:.3f} s of CPU): {p.stderr.strip()}")
    bad = []
    if p.returncode != 2:
        bad.append(f"exit code {p.returncode}, expected 2")
    if cpu > SECONDS:
        bad.append(f"took {cpu:.3f} s of CPU time, over {SECONDS:g} s")
    bad += [f"stderr does not name {e!r}" for e in expected if e not in p.stderr]
    for b in bad:
        print(f"{name}: FAILED: {b}")
    return 1 if bad else 0


def main(argv):
    args = [a for a in argv[1:] if a != "--asan"]
    asan = "--asan" in argv
    if len(args) != 2:
        print(__doc__)
        return 2
    if args[1] == "--list":
        print("\n".join(MUTANTS))
        return 0
    return run(args[0], asan, args[1])


if __name__ == "__main__":
    sys.exit(main(sys.argv))
