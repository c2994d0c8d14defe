#!/bin/sh
# The analysis of the multi-fidelity campaign (docs/dss.md): the emulators against the hold-out,
# the single-fidelity emulator of the same compute, the extrapolation's check, speed, risk.
set -e
cd "$(dirname "$0")/../../.."
OUT=${OUT:-out/mf}
FMU=${FMU:-build/LandslideWave.fmu}
PY=".venv/bin/python"
PLOTS=docs/dss_emulator/mf
BOX="--dist reservoir_level=uniform:0.40:0.52 --dist phi=uniform:25:40 --dist plate_duration_scale=uniform:0.8:1.2"
R=${R:-0.1682}       # the run-up's range over the 20 hold-out runs at dx = 0.02 (m)
# the multi-fidelity design's emulator at the finest level, and the nested hypercube's
$PY -m tools.dss emulate mf-validate $OUT/study/mf_emulator.json $OUT/holdout02 --level 0.02 --range $R --fmu $FMU --plot $PLOTS/holdout_mf_design.png --json $OUT/v_design.json
$PY -m tools.dss emulate mf-fit $OUT/mflhs --levels 0.04,0.03,0.02 --inputs reservoir_level,phi,plate_duration_scale --box reservoir_level=0.40:0.52 --box phi=25:40 --box plate_duration_scale=0.8:1.2 -o $OUT/mflhs/mf_emulator.json --fmu $FMU
$PY -m tools.dss emulate mf-validate $OUT/mflhs/mf_emulator.json $OUT/holdout02 --level 0.02 --range $R --fmu $FMU --plot $PLOTS/holdout_mf_lhs.png --json $OUT/v_lhs.json
# the single-fidelity emulator of the same compute (a Latin hypercube at dx = 0.02 alone)
$PY -m tools.dss emulate fit $OUT/sf02 --output max_run_up --output max_run_up_Z --box reservoir_level=0.40:0.52 --box phi=25:40 --box plate_duration_scale=0.8:1.2 -o $OUT/sf02/emulator_box.json --fmu $FMU --no-plots
$PY -m tools.dss emulate validate $OUT/sf02/emulator_box.json $OUT/holdout02 --range $R --fmu $FMU --plot $PLOTS/holdout_sf.png --json $OUT/v_sf.json
# the extrapolation: to dx = 0.015 against the runs there, and the limit
$PY -m tools.dss emulate mf-validate $OUT/study/mf_emulator.json $OUT/check015 --level 0.015 --range $R --fmu $FMU --plot $PLOTS/check015.png --json $OUT/v_015.json
$PY -m tools.dss emulate mf-validate $OUT/study/mf_emulator.json $OUT/check015 --level extrapolated --range $R --fmu $FMU --json $OUT/v_dx0.json
# risk at the limit and at the finest level, speed
$PY -m tools.dss emulate mf-risk $OUT/study/mf_emulator.json $BOX --crest 850 --fmu $FMU --plots $PLOTS --json $OUT/risk_dx0.json
$PY -m tools.dss emulate mf-risk $OUT/study/mf_emulator.json $BOX --crest 850 --level finest --fmu $FMU --json $OUT/risk_finest.json
$PY -m tools.dss.bench_mf $OUT/study/mf_emulator.json
