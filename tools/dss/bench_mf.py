"""python -m tools.dss.bench_mf EMU.json [--repeat 5] : the multi-fidelity emulator's speed.

Times (wall, best and median of --repeat) 1,000 predictions at the finest level and at the
dx -> 0 extrapolation, and the risk (P(output > crest) with 1e5 samples and 200 joint
posterior draws at 1,000 of them) with the inputs uniform over the emulator's box, and prints
the machine's load. The FMU is not needed (the GUID check is the commands' business).
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")     # as python -m tools.dss (its __main__)

import numpy as np  # noqa: E402

from . import multifidelity as M  # noqa: E402
from .scenarios import Distribution  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m tools.dss.bench_mf", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("emulator")
    ap.add_argument("--output", default="max_run_up")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--crest", type=float, help="default: the middle of the finest runs' range")
    a = ap.parse_args(argv)
    em = M.load(a.emulator, check_fmu=False)
    rng = np.random.default_rng(0)
    X = em.box[:, 0] + rng.random((1000, len(em.inputs))) * (em.box[:, 1] - em.box[:, 0])
    print(f"load average {os.getloadavg()[0]:.2f} (1 min), {os.cpu_count()} cores")
    for level in ("finest", M.EXTRAPOLATED):
        t = []
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            em.predict(X, a.output, level)
            t.append(time.perf_counter() - t0)
        print(f"1000 predictions at {level}: best {1e3 * min(t):.1f} ms, median "
              f"{1e3 * float(np.median(t)):.1f} ms")
    y = em.Y[-1][a.output]
    crest = a.crest if a.crest is not None else float(np.nanmedian(y))
    dists = {n: Distribution(n, f"uniform:{float(lo)!r}:{float(hi)!r}") for n, (lo, hi) in zip(em.inputs, em.box)}
    for level in ("finest", M.EXTRAPOLATED):
        t = []
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            r = M.exceedance(em, a.output, dists, {}, crest, level=level)
            t.append(time.perf_counter() - t0)
        print(f"risk at {level} (1e5 samples, 200 joint draws at 1000): best {min(t):.2f} s, "
              f"median {float(np.median(t)):.2f} s (P = {r['p']:.3f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
