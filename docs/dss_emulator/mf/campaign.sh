#!/bin/sh
# The multi-fidelity campaign of docs/dss.md (section "Multi-fidelity emulator: the Vajont
# campaign"), as run: every FMU job under the shared CPU lock, niced. OUT and FMU may be set.
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
# 1. the hold-out: 20 Latin-hypercube runs at the ladder's finest dx, 4 at the next finer one
$RUN $PY -m tools.dss sweep $OUT/holdout02 --fmu $FMU $BOX -n 20 --seed 101 --dx 0.02 --workers 2 --no-report --quiet
$RUN $PY -m tools.dss sweep $OUT/check015 --fmu $FMU $BOX -n 4 --seed 102 --dx 0.015 --workers 2 --no-report --quiet
# 2. the study: the cost-aware design (450 CPU s), the fit, P(run-up Z > 850 m) at dx -> 0
$RUN $PY -m tools.dss emulate study $OUT/study --fmu $FMU $BOX --levels $LEVELS --budget-cpu 450 --seed 1 --crest 850 --workers 2
# 3. the single-fidelity emulator of the same compute: a Latin hypercube at dx = 0.02 alone
$RUN $PY -m tools.dss sweep $OUT/sf02 --fmu $FMU $BOX -n 13 --seed 11 --dx 0.02 --workers 2 --no-report --quiet
# 4. the nested Latin hypercube of the same compute (the start only: --budget-cpu 1)
$RUN $PY -m tools.dss emulate mf-design $OUT/mflhs --fmu $FMU $BOX --levels $LEVELS --budget-cpu 1 --init 36,16,8 --seed 11 --workers 2
