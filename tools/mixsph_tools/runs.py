"""The run folders of the validation scripts: the command of a run, the stamp that records its
settings (the script's ``<case>_run.json`` beside the run's summary.json), and the --reuse
decision made from both (a finished run of the same settings is kept, an unfinished one that left
a checkpoint is continued with ``mixsph run --restart``, anything else runs afresh).
"""

import hashlib
import json
import math
import os
import subprocess

from .readers import ToolError, read_summary
from .report import num, show


def parse_sets(texts, example):
    """The --set KEY=VALUE options of a script as [(key, value)]; raises ToolError naming the
    option on one that is not KEY=VALUE with a finite number (``example`` shows a good one)."""
    out = []
    for text in texts:
        key, eq, value = text.partition("=")
        try:
            v = float(value)
        except ValueError:
            v = math.nan
        if not eq or not key or not math.isfinite(v):
            raise ToolError(f"--set {text}: expected KEY=VALUE with a finite number, e.g. {example}")
        out.append((key, v))
    return out


# The material laws of a granular medium, in the order whose place a case's "law" may give instead
# of the name (docs/cases.md): so chosen, the medium may keep the other law's keys, unused.
GRANULAR_LAWS = ("paper", "elastic_plastic")


def with_law(case_json, law, case_name):
    """A copy of a case whose granular media all use the material law ``law`` ("paper" or
    "elastic_plastic"), given by its number so that the keys of the other law stay (unused; the
    law's own keys not in the case take their defaults). Raises ToolError for another law or a
    case without a granular medium."""
    if law not in GRANULAR_LAWS:
        raise ToolError(f"--law {law}: expected one of {', '.join(GRANULAR_LAWS)}")
    out = json.loads(json.dumps(case_json))
    granular = [m for m in out.get("media", {}).values() if isinstance(m, dict) and m.get("type") == "granular"]
    if not granular:
        raise ToolError(f"{case_name}: --law {law}: the case has no granular medium")
    for m in granular:
        m["law"] = GRANULAR_LAWS.index(law)
    return out


def twin_gravity(case_json, sets, rel, case_name):
    """The gravity of a --twin REL run: the case's ``gravity`` (or the last --set gravity=... of
    ``sets``) x (1 + REL). Raises ToolError when REL is not a relative change between 0 and 1e-3
    in size or the case has no numeric gravity."""
    if not (isinstance(rel, (int, float)) and 0 < abs(rel) < 1e-3):
        raise ToolError("--twin REL: a relative change of gravity between 0 and 1e-3 in size, e.g. 1e-6")
    g = case_json.get("gravity")
    g = next((v for k, v in reversed(sets) if k == "gravity"), g)   # a --set gravity=... counts
    if not isinstance(g, (int, float)) or isinstance(g, bool):
        raise ToolError(f"{case_name}: no numeric 'gravity' to perturb for --twin")
    return g * (1.0 + rel)


def clean_outdir(d, stamp_name):
    """Remove the files an earlier run left in folder d (a shorter run must not show stale
    profiles or snapshots, a fresh run must not be continued from an old checkpoint); stamp_name
    is the script's record of the run's settings."""
    if not os.path.isdir(d):
        return
    for name in os.listdir(d):
        if name in ("summary.json", "monitors.csv", "mixsph.log", "checkpoint.h5", stamp_name) or \
                (name.endswith(".csv") and name.startswith(("profile_", "snap_"))):
            os.remove(os.path.join(d, name))


def case_digest(path):
    """SHA-256 (hex) of a case file's bytes: a run's stamp records it, so a run made before the
    case file was edited is not reused for the edited case (the path alone would not tell)."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        h.update(f.read())
    return h.hexdigest()


def _stamp_differs(outdir, stamp, stamp_name, keys):
    """Why the stamp file in outdir does not record the same values of ``keys`` as ``stamp``
    (None when it does; a missing stamp counts as the same, for folders of older scripts)."""
    stamp_path = os.path.join(outdir, stamp_name)
    if not os.path.isfile(stamp_path):
        return None
    try:
        with open(stamp_path) as f:
            old = json.load(f)
    except (OSError, ValueError):
        return f"{show(stamp_path)} records other settings (unreadable)"
    if not isinstance(old, dict):
        return f"{show(stamp_path)} records other settings (not a JSON object)"
    differ = [k for k in keys if old.get(k) != stamp.get(k)]
    if differ:
        return f"{show(stamp_path)} records other settings ({', '.join(differ)})"
    return None


def reusable(outdir, stamp, stamp_name, keys, t_end, t_tol):
    """(True, why) when outdir already holds a finished run (summary status ok, simulated to t_end
    within t_tol) whose stamp file records the same values of ``keys`` as ``stamp``; else
    (False, why not)."""
    summ_path = os.path.join(outdir, "summary.json")
    if not os.path.isfile(summ_path):
        return False, "no summary.json"
    try:
        summ = read_summary(summ_path)
    except ToolError as e:
        return False, str(e)
    if summ.get("status") != "ok":
        return False, f"its summary.json says status '{summ.get('status')}'"
    st = summ.get("simulated_time_s")
    if not isinstance(st, (int, float)) or abs(st - t_end) > t_tol:
        return False, f"it ran to t = {st} s, not t_end = {t_end:g} s"
    why = _stamp_differs(outdir, stamp, stamp_name, keys)
    if why:
        return False, why
    return True, f"summary ok, t = {st:.4g} s"


def resumable(outdir, stamp, stamp_name, keys):
    """(checkpoint path, why) when outdir holds an unfinished run of the same settings (its stamp
    file records the same ``keys``, t_end included) that left a checkpoint (``mixsph run
    --checkpoint-every``, or one stopped by SIGTERM): ``mixsph run --restart`` continues it
    bit-identically. (None, why not) otherwise. Call it for a run that is not reusable."""
    ckpt = os.path.join(outdir, "checkpoint.h5")
    if not os.path.isfile(ckpt):
        return None, "no checkpoint.h5"
    if not os.path.isfile(os.path.join(outdir, stamp_name)):
        return None, f"no {stamp_name} to tell which run it is"
    why = _stamp_differs(outdir, stamp, stamp_name, keys)
    if why:
        return None, why
    return ckpt, "an unfinished run of the same settings left a checkpoint"


def plan_reuse(job, label, stamp_name, keys, t_end, t_tol, mixsph, threads, checkpoint_every):
    """The --reuse decision of a script's run ``job`` (with outdir, stamp, cmd, source,
    checkpoint), printed under ``label``: a finished run of the same settings is kept
    (job.source = "reused"; returns False, nothing to run); an unfinished one that left a
    checkpoint is continued (job.checkpoint set, job.cmd its ``mixsph run --restart``); else the
    run starts afresh. Returns True when the job is to be run."""
    ok, why = reusable(job.outdir, job.stamp, stamp_name, keys, t_end, t_tol)
    if ok:
        job.source = "reused"
        print(f"{label}: reused {show(job.outdir)}/ ({why})")
        return False
    ckpt, why_not = resumable(job.outdir, job.stamp, stamp_name, keys)
    if ckpt:
        job.checkpoint = ckpt
        job.cmd = restart_command(mixsph, ckpt, threads, checkpoint_every)
        print(f"{label}: not finished ({why}): continuing it from {show(ckpt)}")
    elif os.path.isdir(job.outdir):
        print(f"{label}: not reused ({why}; not continued: {why_not}): running it again")
    return True


def launch(outdir, stamp_name, stamp, cmd, checkpoint=None):
    """Start ``mixsph run`` for a script's run in outdir, its output in outdir/mixsph.log.
    Fresh (checkpoint None): the folder is cleaned and the stamp written, then ``cmd`` runs.
    Continued: ``cmd`` is a ``mixsph run --restart`` of ``checkpoint``; the folder is kept (the
    run's files go on from the checkpoint), the log is appended to. Returns (process, log file);
    raises OSError when the process cannot start."""
    os.makedirs(outdir, exist_ok=True)
    if checkpoint is None:
        clean_outdir(outdir, stamp_name)
        with open(os.path.join(outdir, stamp_name), "w") as f:
            json.dump(stamp, f, indent=2)
            f.write("\n")
    log = open(os.path.join(outdir, "mixsph.log"), "a" if checkpoint else "w")
    log.write("$ " + " ".join(cmd) + "\n")
    log.flush()
    try:
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
    except OSError:
        log.close()
        raise
    return proc, log


def restart_command(mixsph, checkpoint, threads, checkpoint_every):
    """The ``mixsph run --restart`` command continuing a checkpoint in its own folder."""
    cmd = [mixsph, "run", "--restart", checkpoint, "--threads", str(threads), "--quiet"]
    if checkpoint_every > 0:
        cmd += ["--checkpoint-every", num(checkpoint_every)]
    return cmd
