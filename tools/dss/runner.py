"""Running scenarios on Dask distributed: an embedded local cluster, or an existing cluster.

The FMU file is read once by the client and broadcast to every worker (client.scatter), so the
workers need no shared file system; each worker unzips it once (fmu_run.unzipped). Results come
back as they finish (distributed.as_completed), go to the results store at once, and feed the
progress display. A scenario that fails (bad parameters, an FMU error, a timeout, a worker that
died) becomes a 'failed' row with its error; nothing aborts the sweep except the user.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import math
import os
import signal
import sys
import time
import uuid

from . import fmu_run
from .scenarios import ID


def utc_now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


@contextlib.contextmanager
def dask_client(scheduler: str | None = None, workers: int | None = None, quiet: bool = False,
                upload_code: bool = False):
    """A distributed.Client: connected to SCHEDULER (an address such as tcp://host:8786 or a
    scheduler file path ending in .json), or to a new local cluster of WORKERS processes
    (default: the machine's cores) with one thread each."""
    import logging
    from distributed import Client, LocalCluster

    cluster = None
    if scheduler:
        if scheduler.endswith(".json") and os.path.isfile(scheduler):
            client = Client(scheduler_file=scheduler)
        else:
            client = Client(scheduler)
    else:
        n = workers or os.cpu_count() or 1
        try:
            import bokeh  # noqa: F401  (the dashboard needs it)
            dash = True
        except ImportError:
            dash = False
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=":0", silence_logs=logging.ERROR,
                               env={"OMP_NUM_THREADS": "1", "OMP_WAIT_POLICY": "passive"})
        client = Client(cluster)
    global _TASK_MODULE
    _TASK_MODULE = fmu_run
    if upload_code:
        _TASK_MODULE = upload_worker_module(client)
    try:
        if not quiet:
            info = client.scheduler_info()
            nw = len(info.get("workers", {}))
            where = scheduler or "local cluster"
            print(f"dss: Dask {where}: {nw} worker(s)"
                  + (f", dashboard {client.dashboard_link}" if cluster is None or dash else ""),
                  file=sys.stderr)
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


# The module whose run_scenario the tasks call: tools.dss.fmu_run (workers that have this
# repository on their path), or its copy uploaded to the cluster (upload_worker_module).
_TASK_MODULE = fmu_run
WORKER_MODULE = "mixsph_dss_worker"


def upload_worker_module(client):
    """Send fmu_run.py to the scheduler and every worker (Client.upload_file) as the top-level
    module mixsph_dss_worker, and use that module for the tasks: the workers then need only
    fmpy (and distributed), not this repository."""
    import importlib.util
    import shutil
    import tempfile
    d = tempfile.mkdtemp(prefix="dss-upload-")
    path = os.path.join(d, WORKER_MODULE + ".py")
    shutil.copyfile(fmu_run.__file__, path)
    client.upload_file(path)
    spec = importlib.util.spec_from_file_location(WORKER_MODULE, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[WORKER_MODULE] = mod
    spec.loader.exec_module(mod)
    return mod


def n_workers(client) -> int:
    return max(1, len(client.scheduler_info().get("workers", {})))


class Progress:
    """One line: done/total, ok, failed, running, elapsed, ETA and throughput. Rewritten in
    place on a terminal; otherwise printed every 10 % or 30 s."""

    def __init__(self, total: int, label: str = "sweep", stream=None, enabled: bool = True):
        self.total, self.label = total, label
        self.stream = stream or sys.stderr
        self.enabled = enabled
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.ok = self.failed = 0
        self.t0 = time.monotonic()
        self.last_print = -1e9
        self.last_frac = -1.0

    @staticmethod
    def _fmt(s: float) -> str:
        if not math.isfinite(s):
            return "?"
        s = int(round(s))
        return f"{s // 3600}h{s // 60 % 60:02d}m" if s >= 3600 else f"{s // 60}m{s % 60:02d}s"

    def line(self, running: int = 0) -> str:
        done = self.ok + self.failed
        el = time.monotonic() - self.t0
        rate = done / el * 3600 if el > 0 and done else math.nan
        eta = (self.total - done) * el / done if done else math.nan
        return (f"{self.label}: {done}/{self.total} done (ok {self.ok}, failed {self.failed}), "
                f"{running} running, elapsed {self._fmt(el)}, ETA {self._fmt(eta)}, "
                f"{rate:.0f} scenarios/h" if done else
                f"{self.label}: 0/{self.total} done, {running} running, elapsed {self._fmt(el)}")

    def update(self, status: str | None = None, running: int = 0, force: bool = False):
        if status == "ok":
            self.ok += 1
        elif status is not None:
            self.failed += 1
        if not self.enabled:
            return
        done = self.ok + self.failed
        frac = done / self.total if self.total else 1.0
        now = time.monotonic()
        if self.tty:
            print("\r" + self.line(running).ljust(110), end="", file=self.stream, flush=True)
            if force:
                print(file=self.stream)
        elif force or frac - self.last_frac >= 0.1 or now - self.last_print >= 30:
            text = self.line(running)
            if text != getattr(self, "last_text", None):
                print(text, file=self.stream, flush=True)
            self.last_print, self.last_frac, self.last_text = now, frac, text


_SHIPPED: dict = {}


def shipped_fmu(client, fmu_path: str):
    """The FMU's bytes on every worker (one broadcast per client and FMU content)."""
    fmu = fmu_run.read_fmu_bytes(fmu_path)
    key = (id(client), fmu["sha256"])
    fut = _SHIPPED.get(key)
    if fut is None or fut.status != "finished":
        # a list, so that the dict travels as one object (scatter would split a dict)
        fut = client.scatter([fmu], broadcast=True, hash=False)[0]
        _SHIPPED.clear()
        _SHIPPED[key] = fut
    return fut


def run_scenarios(client, fmu_path: str, scenarios: list[dict], opts: dict, on_result=None,
                  progress: Progress | None = None, run_id: str | None = None) -> list[dict]:
    """Run every scenario ({'scenario_id': ..., params...}) on the cluster; call
    on_result(row) as each one finishes (in completion order) and return all rows.

    A row is: scenario_id, the parameters, status, error, wall_time_s, the outputs, stop_time,
    worker_pid, host, run_id, submitted_at, finished_at (and series if opts asks for it)."""
    from distributed import as_completed

    run_id = run_id or uuid.uuid4().hex[:10]
    fmu_future = shipped_fmu(client, fmu_path)
    futures = {}
    submitted = utc_now()
    for sc in scenarios:
        params = {k: v for k, v in sc.items() if k != ID}
        f = client.submit(_TASK_MODULE.run_scenario, fmu_future, params, opts,
                          key=f"dss-{sc[ID]}-{uuid.uuid4().hex[:6]}", pure=False, retries=0)
        futures[f] = sc
    rows = []
    pending = len(futures)
    if progress:
        progress.update(running=min(pending, n_workers(client)))
    try:
        for f in as_completed(list(futures)):
            sc = futures[f]
            try:
                res = f.result()
            except Exception as e:  # the worker died (e.g. a crash in the FMU) or was lost
                res = {"status": "failed", "error": f"{type(e).__name__}: {e}",
                       "wall_time_s": math.nan}
            pending -= 1
            row = {ID: sc[ID], **{k: v for k, v in sc.items() if k != ID}}
            row.update({k: v for k, v in res.items() if k not in row})
            row["stop_time"] = opts.get("stop_time")
            row["run_id"] = run_id
            row["submitted_at"] = submitted
            row["finished_at"] = utc_now()
            rows.append(row)
            if on_result:
                on_result(row)
            if progress:
                progress.update(row["status"], running=min(pending, n_workers(client)))
            f.release()
    finally:
        for f in futures:
            if not f.done():
                f.cancel()
    if progress:
        progress.update(running=0, force=True)
    return rows


@contextlib.contextmanager
def sigterm_as_interrupt():
    """SIGTERM ends a sweep like Ctrl-C: cancel, close the cluster, keep what is stored."""
    def handler(signum, frame):
        raise KeyboardInterrupt
    try:
        old = signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not the main thread
        old = None
    try:
        yield
    finally:
        if old is not None:
            signal.signal(signal.SIGTERM, old)
