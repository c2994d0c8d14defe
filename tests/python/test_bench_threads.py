"""tools/bench_threads.py: one tiny pair of each kind through build/mixsph, and its refusals. The
speed-ups it prints are not checked (they are the machine's); what is checked is that every run
it reports was made and recorded."""

import json
import os
import subprocess
import sys

from tool_helpers import BUILD, ENV, ROOT, built


def bench(*opts):
    return [sys.executable, os.path.join(ROOT, "tools", "bench_threads.py"), "--build", BUILD, *opts]


def test_one_pair_with_the_ceiling(tmp_path):
    built("mixsph")
    record = tmp_path / "bench.json"
    done = subprocess.run(bench("--runs", "dambreak10k", "--modes", "exe", "--pairs", "1",
                                         "--t-end", "0.002", "--ceiling", "--json", str(record)),
                          env=ENV, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "dambreak10k exe pair 1: 1 thread" in done.stdout
    assert "dambreak10k ceiling (two independent 1-thread processes at once)" in done.stdout
    runs = json.loads(record.read_text())["runs"]
    # one 1-thread and one 2-thread run, then one record of the two 1-thread processes run at once
    assert sorted(r.get("threads", 0) for r in runs) == [0, 1, 2]
    both = [r for r in runs if r["mode"] == "two_1_thread_processes"]
    assert len(both) == 1 and len(both[0]["wall_s"]) == 2 and min(both[0]["wall_s"]) > 0


def test_refused():
    for args, says in ((["--runs", "nosuch"], "unknown run"), (["--modes", "gpu"], "unknown mode")):
        done = subprocess.run(bench(*args), env=ENV, capture_output=True, text=True, timeout=60)
        assert done.returncode != 0 and says in done.stderr, done.stderr
