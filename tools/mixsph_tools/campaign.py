"""The campaign runner of the validation scripts (tools/vajont_validate.py, tools/erosive_dambreak.py):
the options they share, their runs of ``mixsph run`` (at most --jobs at once; with --reuse a
finished run of the same settings is kept and an unfinished one continued from its checkpoint),
and the fields every run's result has. A script keeps what is particular to its case: the paper's
runs and the overrides that make each, what it reads from a run folder, and how it compares,
tabulates and plots the results.

    args = campaign.parse_args(PROG, OPTIONS, argv)     # OPTIONS: the script's CaseOptions
    s = campaign.settings(args, PROG, OPTIONS, n_runs)  # checks everything; raises ToolError
    jobs = [campaign.make_job(s, paper, "V1", dx, "V1_dx0.02", sets, {"run": 1, ...}), ...]
    failed = campaign.run(s, jobs, STAMP, STAMP_KEYS, T_TOL)
    results = [my_load_result(job) for job in jobs]     # on campaign.read_run_summary
    campaign.check_failed(failed)                       # ToolError (exit 1) when a run failed

``campaign.main(PROG, body)`` runs a script's body and turns a ToolError into its message and
exit status (2 bad usage or input, 1 a run failed; 130 when interrupted).
"""

import argparse
import json
import math
import os
import signal
import subprocess
import sys
import time
from dataclasses import dataclass

from .readers import ToolError, checkpoint_time, last_time, read_monitors, read_summary, run_particle_steps_per_s, \
    run_wall_time, summary_value, tail
from .report import fmt, fmt_duration, num, show
from .runs import GRANULAR_LAWS, case_digest, launch, parse_sets, plan_reuse, twin_gravity, with_law

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))   # the repository
EXIT_MEANINGS = {2: "bad usage or input", 3: "unstable run", 4: "out of memory or output failure"}


def main(prog, body):
    """Run body(); a ToolError it raises ends the script with its message and exit status."""
    try:
        body()
    except ToolError as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        sys.exit(e.code)


# ---- options --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CaseOptions:
    """A script's command line: what its shared options default to and say, and its own options."""
    description: str
    runs: str              # default of --runs
    known: tuple           # the paper's run numbers
    dx: float              # default of --dx [m]
    dx_help: str
    out: str               # default output folder, under out/
    case: str              # default case file, under cases/
    t_end: str             # the case's end time, as --t-end's help names it
    set_example: str       # a --set KEY=VALUE for the help and the error message
    twin_help: str
    sphera: tuple          # --sphera: (key, value) overrides, SPHERA's own numerical options
    progress: float        # default of --progress [s]
    own: tuple = ()        # the script's own options: (name, add_argument keywords) each


def parse_args(prog, o, argv=None):
    """The parsed command line of a script with the CaseOptions o (argv None: sys.argv)."""
    ap = argparse.ArgumentParser(prog=prog, description=o.description)
    add_options(ap, o)
    for name, kw in o.own:
        ap.add_argument(name, **kw)
    return ap.parse_args(argv)


def add_options(ap, o):
    """The options every validation script has, with o's defaults (a CaseOptions)."""
    if o.known:   # a script of the paper's numbered runs
        known = f"{min(o.known)}-{max(o.known)}"
        ap.add_argument("--runs", default=o.runs, help=f"paper runs to do, {known}, comma-separated or 'all' "
                        f"(default {o.runs})")
    ap.add_argument("--dx", type=float, default=o.dx, help=o.dx_help)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", o.out), help=f"output folder (default out/{o.out})")
    ap.add_argument("--threads", type=int, help="OpenMP threads of each run (default max(1, cores // jobs))")
    ap.add_argument("--jobs", type=int, default=1, help="runs at once (default 1)")
    ap.add_argument("--reuse", action="store_true", help="keep runs already done (summary.json ok, same settings) "
                    "and continue unfinished ones from their checkpoints")
    ap.add_argument("--checkpoint-every", type=float, default=600.0, metavar="SECONDS",
                    help="each run writes a checkpoint every SECONDS of wall time (default 600; 0: none), "
                    "from which --reuse continues it after an interruption")
    ap.add_argument("--mixsph", default=os.path.join(ROOT, "build", "mixsph"),
                    help="mixsph executable (default build/mixsph)")
    ap.add_argument("--case", default=os.path.join(ROOT, "cases", o.case), help=f"case file (default cases/{o.case})")
    ap.add_argument("--law", choices=GRANULAR_LAWS, help="the material law of the case's granular media (default: "
                    "the case's); the run's case is then OUT/case_LAW.json, the case with that law (the other law's "
                    "keys kept, unused; the law's own keys not in the case at their defaults)")
    ap.add_argument("--t-end", type=float, help=f"end time [s] of every run (default: the case's, {o.t_end}); "
                    "for short tests")
    ap.add_argument("--progress", type=float, default=o.progress, help="print the simulated time of the running "
                    f"runs every this many seconds (default {o.progress:g}, 0: never)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="sets",
                    help=f"an override passed to every run after the run's own (repeatable), e.g. {o.set_example}")
    if o.sphera:
        ap.add_argument("--sphera", action="store_true", help="run with the numerical options of SPHERA's own "
                        "input for this test (" + ", ".join(f"{k}={num(v)}" for k, v in o.sphera) + "), before any "
                        "--set")
    if o.twin_help:
        ap.add_argument("--twin", type=float, metavar="REL", help=o.twin_help)


def parse_runs(text, what, known, example, prefix=""):
    """The runs of an option like --runs ("all" or numbers of ``known``, comma-separated, each
    may start with ``prefix``) as a sorted list; ToolError naming the option otherwise."""
    if text.strip().lower() == "all":
        return sorted(known)
    runs = []
    for part in text.split(","):
        part = part.strip().upper()
        part = part[len(prefix):] if prefix and part.startswith(prefix) else part
        if not part:
            continue
        if not part.isdigit() or int(part) not in known:
            raise ToolError(f"{what}: '{part}' is not a run {min(known)}-{max(known)} "
                            f"(e.g. {what} {example} or {what} all)")
        if int(part) not in runs:
            runs.append(int(part))
    if not runs:
        raise ToolError(f"{what}: no run given")
    return sorted(runs)


@dataclass
class Settings:
    """The checked options of a campaign and what they imply."""
    prog: str
    mixsph: str            # absolute path of the executable
    case: str              # absolute path of the case file
    case_json: dict
    case_sha: str          # SHA-256 of the case file (recorded in every stamp)
    t_end: float           # end time of every run [s]: --t-end or the case's
    t_end_option: float    # --t-end (None: the case's, not passed to the runs)
    extra: list            # (key, value): --sphera's, then --set's, after each run's own overrides
    twin: float            # --twin REL (None without)
    g_twin: float          # gravity of the twin runs (None without --twin)
    cores: int
    jobs: int              # runs at once
    threads: int           # OpenMP threads of each run
    out: str               # absolute path of the output folder (made by run)
    reuse: bool
    checkpoint_every: float
    progress: float


def _check_numbers(args):
    if not (args.dx > 0 and math.isfinite(args.dx)):
        raise ToolError("--dx must be a positive number of metres")
    if args.jobs < 1:
        raise ToolError("--jobs must be at least 1")
    if args.threads is not None and args.threads < 1:
        raise ToolError("--threads must be at least 1")
    if args.t_end is not None and not (args.t_end > 0 and math.isfinite(args.t_end)):
        raise ToolError("--t-end must be a positive number of seconds")
    if not (args.checkpoint_every >= 0 and math.isfinite(args.checkpoint_every)):
        raise ToolError("--checkpoint-every must be a number of seconds >= 0 (0: no checkpoints)")


def _read_case(path):
    try:
        with open(path) as f:
            return json.load(f), case_digest(path)
    except (OSError, ValueError) as e:
        raise ToolError(f"{show(path)}: cannot read the case: {e}") from None


def usable_cores():
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def settings(args, prog, o, n_runs):
    """Settings of the parsed shared options (add_options); n_runs: the campaign's runs besides
    twins (--jobs more than that gain nothing). Raises ToolError on a bad option or input;
    creates nothing but, with --law, the output folder and the case of that law in it."""
    _check_numbers(args)
    twin = getattr(args, "twin", None)
    extra = (list(o.sphera) if getattr(args, "sphera", False) else []) + parse_sets(args.sets, o.set_example)
    mixsph = os.path.abspath(args.mixsph)
    if not (os.path.isfile(mixsph) and os.access(mixsph, os.X_OK)):
        raise ToolError(f"{show(mixsph)}: no mixsph executable there (build it: ./tools/do build)")
    case = os.path.abspath(args.case)
    case_json, case_sha = _read_case(case)
    if getattr(args, "law", None):
        case_json = with_law(case_json, args.law, show(case))
        case = os.path.join(os.path.abspath(args.out), f"case_{args.law}.json")
        os.makedirs(os.path.dirname(case), exist_ok=True)
        with open(case, "w") as f:
            json.dump(case_json, f, indent=2)
            f.write("\n")
        case_sha = case_digest(case)
    t_end = args.t_end if args.t_end is not None else float(case_json.get("numerics", {}).get("t_end", math.nan))
    if not math.isfinite(t_end):
        raise ToolError(f"{show(case)}: no numerics.t_end (give --t-end)")
    g_twin = twin_gravity(case_json, extra, twin, show(case)) if twin is not None else None
    cores = usable_cores()
    jobs = min(args.jobs, max(1, n_runs))
    threads = args.threads if args.threads is not None else max(1, cores // jobs)
    return Settings(prog, mixsph, case, case_json, case_sha, t_end, args.t_end, extra, twin, g_twin, cores,
                    jobs, threads, os.path.abspath(args.out), args.reuse, args.checkpoint_every, args.progress)


# ---- runs -----------------------------------------------------------------------------------------


@dataclass
class Job:
    """One run of a campaign: the paper's run it stands for, its folder, command and stamp."""
    paper: object
    dx: float
    outdir: str
    cmd: list
    stamp: dict
    label: str = ""          # how the messages name it: "V1", "run 6"
    threads: int = 0
    source: str = ""         # "ran", "reused", "FAILED", "not run"
    message: str = ""        # why it failed
    checkpoint: str = None   # continue this unfinished run's checkpoint (cmd is then its restart)
    proc: object = None
    log: object = None
    t0: float = 0.0          # wall clock at its start [s]
    ts0: float = 0.0         # simulated time at its start [s] (the checkpoint's when continued)


def run_command(s, outdir, dx, sets):
    """``mixsph run CASE --out OUTDIR --set numerics.dx=DX --set KEY=VALUE... [--set
    numerics.t_end=T] --threads N --quiet [--checkpoint-every S]``."""
    cmd = [s.mixsph, "run", s.case, "--out", outdir, "--set", f"numerics.dx={num(dx)}"]
    for key, val in sets:
        cmd += ["--set", f"{key}={num(val)}"]
    if s.t_end_option is not None:
        cmd += ["--set", f"numerics.t_end={num(s.t_end_option)}"]
    cmd += ["--threads", str(s.threads), "--quiet"]
    if s.checkpoint_every > 0:
        cmd += ["--checkpoint-every", num(s.checkpoint_every)]
    return cmd


def make_job(s, paper, label, dx, dirname, sets, head, tail=None):
    """The Job of a run into OUT/dirname with the overrides ``sets`` (the run's own, then
    s.extra): its stamp is ``head`` (what tells the run apart), then t_end, the case, its SHA-256,
    the threads and the command, then ``tail``."""
    outdir = os.path.join(s.out, dirname)
    cmd = run_command(s, outdir, dx, sets)
    stamp = dict(head, t_end=s.t_end, case=s.case, case_sha256=s.case_sha, threads=s.threads, command=cmd)
    stamp.update(tail or {})
    return Job(paper, dx, outdir, cmd, stamp, label=label, threads=s.threads)


def twin_sets(s):
    """The overrides of a --twin run besides its run's own: s.extra, then the perturbed gravity."""
    return list(s.extra) + [("gravity", s.g_twin)]


def on_sigterm(signum, frame):
    """SIGTERM like Ctrl-C: the campaign then stops its own mixsph runs instead of leaving them running."""
    raise KeyboardInterrupt


def run(s, jobs, stamp_name, stamp_keys, t_tol, what=""):
    """Make the campaign's runs: with --reuse, keep the finished ones and continue the unfinished
    ones (mt.plan_reuse); run the rest, s.jobs at once. ``what`` (e.g. " at dx = 0.01 m") goes
    into the line that announces them. Returns the failed jobs."""
    os.makedirs(s.out, exist_ok=True)
    to_run = [job for job in jobs if not s.reuse or plan_reuse(job, job.label, stamp_name, stamp_keys, s.t_end,
                                                                   t_tol, s.mixsph, s.threads, s.checkpoint_every)]
    if to_run:
        print(f"{len(to_run)} run(s) of {show(s.case)}{what} to t = {s.t_end:g} s, {min(s.jobs, len(to_run))} "
              f"at a time, {s.threads} thread(s) each, {s.cores} core(s)", flush=True)
    signal.signal(signal.SIGTERM, on_sigterm)
    return run_jobs(s, to_run, stamp_name)


def run_jobs(s, jobs, stamp_name):
    """Run the jobs, at most s.jobs at once; a failed run does not stop the others, except for
    bad usage or input (exit 2), which would repeat: the runs not started then are "not run".
    Ctrl-C or SIGTERM stops the running ones (exit 130). Returns the failed jobs."""
    pending, running, failed = list(jobs), [], []
    t_start = last = time.monotonic()
    try:
        while pending or running:
            halted = any(j.proc.returncode == 2 for j in failed)   # bad usage or input: would repeat
            while pending and len(running) < s.jobs and not halted:
                running.append(start(pending.pop(0), stamp_name))
            if not running:
                print(f"{s.prog}: not starting the remaining runs ({', '.join(j.label for j in pending)})",
                      flush=True)
                break
            time.sleep(0.5)
            for job in [j for j in running if j.proc.poll() is not None]:
                running.remove(job)
                if not finish(job):
                    failed.append(job)
            now = time.monotonic()
            if s.progress > 0 and running and now - last >= s.progress:
                last = now
                print(progress_line(running, now - t_start, s.t_end), flush=True)
    except KeyboardInterrupt:
        stop(running)
        print(f"\n{s.prog}: interrupted; stopped {', '.join(j.label for j in running)}", file=sys.stderr)
        sys.exit(130)
    except ToolError:
        stop(running)
        raise
    for job in pending:
        job.source = "not run"
    return failed


def start(job, stamp_name):
    """Start a job's mixsph (mt.launch) and say so."""
    job.t0 = time.monotonic()
    job.ts0 = checkpoint_time(job.checkpoint) if job.checkpoint else 0.0
    try:
        job.proc, job.log = launch(job.outdir, stamp_name, job.stamp, job.cmd, job.checkpoint)
    except OSError as e:
        raise ToolError(f"cannot start {job.cmd[0]}: {e}") from None
    how = f"continued from {show(job.checkpoint)}" if job.checkpoint else "started"
    print(f"{job.label}: {how}, dx = {job.dx:g} m, {job.threads} thread{'s' if job.threads > 1 else ''} "
          f"-> {show(job.outdir)}/  (log: mixsph.log)", flush=True)
    return job


def finish(job):
    """Close a job whose mixsph ended and say how it went (the log's tail when it failed).
    Returns True when it succeeded."""
    job.log.close()
    rc = job.proc.returncode
    took = fmt_duration(time.monotonic() - job.t0)
    if rc == 0:
        job.source = "ran"
        print(f"{job.label}: done in {took}", flush=True)
        return True
    job.source = "FAILED"
    job.message = f"mixsph exited with {rc} ({EXIT_MEANINGS.get(rc, 'error')})" if rc > 0 else \
        f"mixsph was killed by signal {-rc}"
    log = os.path.join(job.outdir, "mixsph.log")
    print(f"{job.label}: FAILED after {took}: {job.message}; log {show(log)}:", flush=True)
    for line in tail(log):
        print(f"    | {line}", flush=True)
    return False


def progress_line(running, elapsed, t_end):
    """'  [3m07s] V1 t = 0.412/1.6 s (ETA 9m05s), ...': the simulated time of each running job
    (its monitors.csv) and the wall time left at its pace so far."""
    parts = []
    now = time.monotonic()
    for job in running:
        ts = last_time(os.path.join(job.outdir, "monitors.csv"))
        eta = (now - job.t0) * (t_end - ts) / (ts - job.ts0) if math.isfinite(ts) and ts > job.ts0 else math.nan
        parts.append(f"{job.label} t = {fmt(ts, '.3f', '--')}/{t_end:g} s (ETA {fmt_duration(eta)})")
    return f"  [{fmt_duration(elapsed)}] " + ", ".join(parts)


def stop(running):
    """Terminate the running jobs' mixsph (SIGTERM, then SIGKILL after 10 s)."""
    for job in running:
        job.proc.terminate()
    for job in running:
        try:
            job.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            job.proc.kill()
            job.proc.wait()


def check_failed(failed):
    """ToolError (exit status 1) naming the failed jobs, if any."""
    if failed:
        raise ToolError("mixsph failed for " + "; ".join(
            f"{j.label}: {j.message} (log {show(os.path.join(j.outdir, 'mixsph.log'))})" for j in failed), code=1)


# ---- results --------------------------------------------------------------------------------------


@dataclass
class RunResult:
    """What every run's result has; a script's Result adds its case's measures."""
    paper: object
    dx: float = math.nan
    outdir: str = ""
    source: str = ""
    status: str = "missing"      # summary.json's status, or "not run", "no summary"
    threads: int = 0
    sim_time: float = math.nan   # [s]
    wall: float = math.nan       # wall time of the whole run (all its pieces) [s]
    steps: float = math.nan      # time steps of the whole run
    psteps: float = math.nan     # particle-steps per second
    lost: float = math.nan       # particles that left the case's domain (most over the run)

    @property
    def ok(self):
        return self.status == "ok"


def read_run_summary(job, r):
    """Fill the RunResult fields of r from the job's summary.json and return the summary; None
    (r.status "not run" or "no summary") when there is none."""
    if job.source == "not run":
        r.status = "not run"
        return None
    path = os.path.join(job.outdir, "summary.json")
    if not os.path.isfile(path):
        r.status = "no summary"
        return None
    summ = read_summary(path)
    r.status = str(summ.get("status"))
    r.threads = int(summ.get("threads") or 0)
    r.sim_time = float(summ.get("simulated_time_s") or math.nan)
    r.wall = run_wall_time(summ)
    r.steps = float(summ.get("steps") or math.nan)
    r.psteps = run_particle_steps_per_s(summ)
    r.lost = summary_value(summ, "lost_particles", "max")
    return summ


def read_run_monitors(outdir):
    """The columns of a run's monitors.csv (mt.read_monitors), None when it has none."""
    path = os.path.join(outdir, "monitors.csv")
    return read_monitors(path) if os.path.isfile(path) else None


def status_cell(r, t_expected, t_tol):
    """A result's status as the tables show it: how it came ("ran", "reused"), or why it failed,
    with the time it ended when that is not t_expected."""
    status = r.source if r.ok else (r.status if r.source != "FAILED" else f"FAILED ({r.status})")
    if r.ok and math.isfinite(r.sim_time) and abs(r.sim_time - t_expected) > t_tol:
        status += f", t={r.sim_time:.3g} s"
    return status


def threads_used(results, default):
    """'1,2': the thread counts of the finished runs (``default`` when none finished)."""
    used = sorted({r.threads for r in results if r.ok})
    return ",".join(str(t) for t in used) or str(default)
