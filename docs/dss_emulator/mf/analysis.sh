#!/bin/sh
# The analysis of the multi-fidelity campaign (docs/dss.md): the emulators against the hold-out,
# the single-fidelity emulator of the same compute, the extrapolation's check, risk, speed.
set -e
cd "$(dirname "$0")/../../.."
OUT=${OUT:-out/mf}
FMU=${FMU:-build/LandslideWave.fmu}
PY=".venv/bin/python"
PLOTS=docs/dss_emulator/mf
BOX="--dist reservoir_level=uniform:0.40:0.52 --dist phi=uniform:25:40 --dist plate_duration_scale=uniform:0.8:1.2"
INBOX="--box reservoir_level=0.40:0.52 --box phi=25:40 --box plate_duration_scale=0.8:1.2"
R=0.1682             # the run-up's range over the 20 hold-out runs at dx = 0.02 (m)
# the study's emulator (as its design fitted it), the same runs refitted, the nested hypercube's
$PY -m tools.dss emulate mf-validate $OUT/study/mf_emulator.json $OUT/holdout02 --level 0.02 --range $R --fmu $FMU --plot $PLOTS/holdout_mf_design_nofloor.png
$PY -m tools.dss emulate mf-fit $OUT/study --levels 0.04,0.03,0.02 --inputs reservoir_level,phi,plate_duration_scale $INBOX -o $OUT/study/mf_refit.json --fmu $FMU
$PY -m tools.dss emulate mf-validate $OUT/study/mf_refit.json $OUT/holdout02 --level 0.02 --range $R --fmu $FMU
$PY -m tools.dss emulate mf-validate $OUT/mflhs/mf_emulator.json $OUT/holdout02 --level 0.02 --range $R --fmu $FMU --plot $PLOTS/holdout_mf_lhs.png --json $OUT/mflhs/mf_emulator_holdout.json
$PY -m tools.dss emulate mf-validate $OUT/study2/mf_emulator.json $OUT/holdout02 --level 0.02 --range $R --fmu $FMU --plot $PLOTS/holdout_mf_design.png --json $OUT/study2/mf_emulator_holdout.json
# the model comparison (docs/dss.md, "Choosing the model by cross-validation"): the CV on the
# training runs first, then the ARD and isotropic refits of study2's and mflhs's runs against the hold-out
MF_RUNS=$OUT $PY docs/dss_emulator/mf/mf_cv.py 2
MF_RUNS=$OUT $PY docs/dss_emulator/mf/mf_cv.py 1
for S in study2 mflhs; do
  for K in ard iso; do
    $PY -m tools.dss emulate mf-fit $OUT/$S --levels 0.04,0.03,0.02 --inputs reservoir_level,phi,plate_duration_scale $INBOX --output max_run_up --kernel $K -o $OUT/$S/mf_$K.json --fmu $FMU
    $PY -m tools.dss emulate mf-validate $OUT/$S/mf_$K.json $OUT/holdout02 --level 0.02 --range $R --fmu $FMU --json $OUT/$S/mf_${K}_holdout.json
  done
done
# the single-fidelity emulators (10 runs: the same compute; 15 runs)
for S in sf02_10 sf02; do
  $PY -m tools.dss emulate fit $OUT/$S --output max_run_up --output max_run_up_Z $INBOX -o $OUT/$S/emulator_box.json --fmu $FMU --no-plots
done
$PY -m tools.dss emulate validate $OUT/sf02_10/emulator_box.json $OUT/holdout02 --range $R --fmu $FMU --plot $PLOTS/holdout_sf.png --json $OUT/sf02_10/holdout.json
$PY -m tools.dss emulate validate $OUT/sf02/emulator_box.json $OUT/holdout02 --range $R --fmu $FMU
# the jitter, the discrepancy and the ratio's bootstrap (uses all runs, chooses nothing)
MF_RUNS=$OUT $PY docs/dss_emulator/mf/mf_bound.py
# the extrapolation: to dx = 0.015 against the runs there, and the limit
for E in study/mf_emulator.json study/mf_refit.json study2/mf_emulator.json; do
  $PY -m tools.dss emulate mf-validate $OUT/$E $OUT/check015 --level 0.015 --range $R --fmu $FMU
  $PY -m tools.dss emulate mf-validate $OUT/$E $OUT/check015 --level extrapolated --range $R --fmu $FMU
done
# risk at the limit and at the finest level; speed
$PY -m tools.dss emulate mf-risk $OUT/study/mf_emulator.json $BOX --crest 850 --level finest --fmu $FMU
$PY -m tools.dss emulate mf-risk $OUT/study2/mf_emulator.json $BOX --crest 850 --fmu $FMU --plots $PLOTS
$PY -m tools.dss.bench_mf $OUT/study/mf_emulator.json
