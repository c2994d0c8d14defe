"""Bit-identity of two builds of mixsph: run a set of cases with both on one thread and compare
every output byte for byte.

    python tools/bit_identity.py --ref-bin REF/build/mixsph [--new-bin build/mixsph]
                                 [--set-name full|quick] [--cases a,b] [--out out/bitid] [--jobs 2]

A refactoring that must not change results (docs/development.md) is checked with this against the
commit before it. Compared for every case: the step count and status of summary.json, monitors.csv,
every profile_*.csv and snap_*.csv byte for byte, and every dataset of every snapshot of run.h5
value for value (the files' own bytes differ by HDF5's creation metadata). Exit status 0 when every
case is identical, 1 otherwise (the first difference of each case is printed).

The full set is the one of issue 56: Vajont V1 at dx 0.02, explicit and implicit, V1 under the
elastic-plastic law, erosive Run 6 at dx 0.02, the water dam break, the column collapse, the elastic
column and the slide flume at dx 0.01, to their case's t_end. The quick set runs the same cases to
short end times (a minute in all): a development check, not the evidence.
"""
import argparse
import concurrent.futures as futures
import glob
import json
import os
import subprocess
import sys

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# name: (case file, overrides, t_end of the quick set [s])
CASES = {
    "v1_explicit": ("vajont_padua.json", [("numerics.dx", 0.02)], 0.3),
    "v1_implicit": ("vajont_padua.json", [("numerics.dx", 0.02), ("numerics.viscosity", 1)], 0.3),
    "v1_elastic_plastic": ("vajont_padua.json", [("numerics.dx", 0.02), ("parameters.rheology", 1)], 0.3),
    "erosive_run6": ("erosive_dambreak.json", [("numerics.dx", 0.02), ("media.sediment.mu_thr", 20e3),
                                               ("media.sediment.mu0", 5e3)], 0.15),
    "dambreak_water": ("dambreak_water.json", [], 0.1),
    "column_collapse": ("column_collapse.json", [], 0.2),
    "elastic_column": ("elastic_column.json", [], 0.1),
    "slide_flume": ("slide_flume.json", [("numerics.dx", 0.01)], 0.2),
}


def run(binary, cases_dir, name, out, quick):
    case, sets, t_quick = CASES[name]
    args = [binary, "run", os.path.join(cases_dir, case), "--out", out, "--threads", "1", "--quiet"]
    for k, v in sets + ([("numerics.t_end", t_quick)] if quick else []):
        args += ["--set", f"{k}={v}"]
    with open(os.path.join(os.path.dirname(out), os.path.basename(out) + ".log"), "w") as log:
        rc = subprocess.call(args, stdout=log, stderr=subprocess.STDOUT)
    return rc


def first_text_difference(a, b):
    with open(a, "rb") as fa, open(b, "rb") as fb:
        for k, (la, lb) in enumerate(zip(fa, fb), 1):
            if la != lb:
                return f"line {k}: {la.decode().strip()[:120]!r} vs {lb.decode().strip()[:120]!r}"
    return "different lengths"


# Fields stored under another layout since the reference (new name: the reference's datasets, one
# per component, in the new field's component order): compared component by component.
REGROUPED = {"stress": ("sxx", "sxz", "szz", "syy")}


def datasets(f):
    """{path: values} of every dataset of an open HDF5 file, with REGROUPED fields split into the
    reference's datasets."""
    out = {}

    def visit(name, obj):
        if not isinstance(obj, h5py.Dataset):
            return
        head, _, leaf = name.rpartition("/")
        if leaf in REGROUPED and obj.ndim == 2:
            for c, part in enumerate(REGROUPED[leaf]):
                out[f"{head}/{part}" if head else part] = np.ascontiguousarray(obj[()][:, c])
        else:
            out[name] = np.asarray(obj[()])
    f.visititems(visit)
    return out


# The text of the case file a run.h5 keeps: not a result, and it differs when the reference runs
# its own tree's case files (--ref-cases).
CASE_TEXT = "metadata/case_json"


def compare_h5(a, b, skip=()):
    """The first dataset of run.h5 whose values differ, or None."""
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        va, vb = ({k: v for k, v in datasets(f).items() if k not in skip} for f in (fa, fb))
        if sorted(va) != sorted(vb):
            return f"datasets differ: {sorted(set(va) ^ set(vb))[:5]}"
        for n in sorted(va):
            da, db = va[n], vb[n]
            if da.shape != db.shape or da.dtype != db.dtype:
                return f"{n}: shape/type {da.shape} {da.dtype} vs {db.shape} {db.dtype}"
            if da.tobytes() != db.tobytes():
                k = int(np.argmax(da.reshape(-1) != db.reshape(-1))) if da.size else 0
                return f"{n}: first difference at element {k}"
    return None


def compare(ref_dir, new_dir, skip=()):
    """A list of differences between two output folders (empty: identical)."""
    diffs = []
    sa = json.load(open(os.path.join(ref_dir, "summary.json")))
    sb = json.load(open(os.path.join(new_dir, "summary.json")))
    for key in ("status", "steps", "particles", "wall_particles"):
        if sa.get(key) != sb.get(key):
            diffs.append(f"summary.json {key}: {sa.get(key)} vs {sb.get(key)}")
    names = sorted({os.path.basename(p) for d in (ref_dir, new_dir)
                    for pat in ("monitors.csv", "profile_*.csv", "snap_*.csv") for p in glob.glob(os.path.join(d, pat))})
    for n in names:
        a, b = os.path.join(ref_dir, n), os.path.join(new_dir, n)
        if not (os.path.exists(a) and os.path.exists(b)):
            diffs.append(f"{n}: only in {'new' if os.path.exists(b) else 'ref'}")
        elif open(a, "rb").read() != open(b, "rb").read():
            diffs.append(f"{n}: {first_text_difference(a, b)}")
    ha, hb = os.path.join(ref_dir, "run.h5"), os.path.join(new_dir, "run.h5")
    if os.path.exists(ha) or os.path.exists(hb):
        d = compare_h5(ha, hb, skip) if os.path.exists(ha) and os.path.exists(hb) else "run.h5 missing in one"
        if d:
            diffs.append(f"run.h5 {d}")
    return diffs, sa.get("steps"), len(names)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ref-bin", required=True, help="the reference build's mixsph")
    ap.add_argument("--new-bin", default=os.path.join(ROOT, "build", "mixsph"))
    ap.add_argument("--ref-cases", default=os.path.join(ROOT, "cases"),
                    help="the case files the reference runs (default this tree's; the reference tree's cases/ "
                         "when a case file gained a key the reference does not know)")
    ap.add_argument("--set-name", choices=("full", "quick"), default="quick")
    ap.add_argument("--cases", default=",".join(CASES), help="comma-separated subset of: " + ", ".join(CASES))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bitid"))
    ap.add_argument("--jobs", type=int, default=2, help="runs at once (each on one thread)")
    a = ap.parse_args(argv)
    names = [n for n in a.cases.split(",") if n]
    unknown = [n for n in names if n not in CASES]
    if unknown:
        ap.error(f"unknown case(s) {unknown}: the cases are {', '.join(CASES)}")
    quick = a.set_name == "quick"
    jobs = []
    with futures.ThreadPoolExecutor(a.jobs) as pool:
        for n in names:
            for which, binary, cases_dir in (("ref", a.ref_bin, a.ref_cases), ("new", a.new_bin, os.path.join(ROOT, "cases"))):
                out = os.path.join(a.out, a.set_name, which, n)
                os.makedirs(os.path.dirname(out), exist_ok=True)
                jobs.append((n, which, pool.submit(run, os.path.abspath(binary), cases_dir, n, out, quick)))
        rcs = {(n, w): f.result() for n, w, f in jobs}
    failed = 0
    for n in names:
        ref_dir, new_dir = (os.path.join(a.out, a.set_name, w, n) for w in ("ref", "new"))
        if rcs[(n, "ref")] != rcs[(n, "new")]:
            print(f"{n}: exit codes differ: ref {rcs[(n, 'ref')]}, new {rcs[(n, 'new')]}")
            failed += 1
            continue
        same_cases = os.path.realpath(a.ref_cases) == os.path.realpath(os.path.join(ROOT, "cases"))
        diffs, steps, files = compare(ref_dir, new_dir, () if same_cases else (CASE_TEXT,))
        if diffs:
            failed += 1
            print(f"{n}: DIFFERENT ({len(diffs)}): " + "; ".join(diffs[:3]))
        else:
            print(f"{n}: identical ({steps} steps, exit {rcs[(n, 'new')]}, {files} CSV files and run.h5)")
    print(f"{len(names) - failed} of {len(names)} cases bit-identical ({a.set_name} set)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
