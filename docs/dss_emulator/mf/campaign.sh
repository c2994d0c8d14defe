#!/bin/sh
# The runs of the multi-fidelity campaign of docs/dss.md ("The Vajont campaign of the
# multi-fidelity emulator"), as run: every FMU job under the shared CPU lock, niced. OUT and FMU
# may be set. The runs are deterministic. Step 2 ran with the code of commit f1b8ac0 (before the
# finer levels' noise floor); step 6 is the same study with the code's current model.
set -e
cd "$(dirname "$0")/../../.."
OUT=${OUT:-out/mf}
FMU=${FMU:-build/LandslideWave.fmu}
PY=".venv/bin/python"
RUN="flock /tmp/mixsph-cpu.lock nice -n 5"
BOX="--dist reservoir_level=uniform:0.40:0.52 --dist phi=uniform:25:40 --dist plate_duration_scale=uniform:0.8:1.2"
LEVELS=0.04,0.03,0.02
export OMP_NUM_THREADS=1
# 0. the cost of a run per level (one run each at the box's centre)
$RUN $PY -m tools.dss sweep $OUT/cost --fmu $FMU --grid dx=0.03,0.02,0.015 --set reservoir_level=0.46 --set phi=32.5 --set plate_duration_scale=1.0 --workers 1 --no-report --quiet
# 1. the hold-out: 20 Latin-hypercube runs at the ladder's finest dx
$RUN $PY -m tools.dss sweep $OUT/holdout02 --fmu $FMU $BOX -n 20 --seed 101 --dx 0.02 --workers 2 --no-report --quiet
# 2. the study: the cost-aware design (350 CPU s), the fit, P(run-up Z > 850 m) at dx -> 0
$RUN $PY -m tools.dss emulate study $OUT/study --fmu $FMU $BOX --levels $LEVELS --budget-cpu 350 --seed 1 --crest 850 --workers 2
# 3. the single-fidelity emulator's runs: a Latin hypercube at dx = 0.02 alone (the same compute),
#    and 5 more (a second hypercube) for the 15-run row
$RUN $PY -m tools.dss sweep $OUT/sf02 --fmu $FMU $BOX -n 10 --seed 11 --dx 0.02 --workers 2 --no-report --quiet
cp -r $OUT/sf02 $OUT/sf02_10
$RUN $PY -m tools.dss sweep $OUT/sf02 --fmu $FMU $BOX -n 5 --seed 12 --dx 0.02 --workers 2 --no-report --quiet
# 4. the extrapolation's check: 3 runs one level finer than the ladder
$RUN $PY -m tools.dss sweep $OUT/check015 --fmu $FMU $BOX -n 3 --seed 102 --dx 0.015 --workers 2 --no-report --quiet
# 5. the nested Latin hypercube of the same compute (the start only: --budget-cpu 1)
$RUN $PY -m tools.dss emulate mf-design $OUT/mflhs --fmu $FMU $BOX --levels $LEVELS --budget-cpu 1 --init 28,12,6 --seed 11 --workers 2
# 6. the study again with the current model (as run: its start's 21 of 28 runs copied from step 2's
#    results, the same scenarios: the runs are deterministic)
$RUN $PY -m tools.dss emulate study $OUT/study2 --fmu $FMU $BOX --levels $LEVELS --budget-cpu 350 --seed 1 --crest 850 --workers 2
