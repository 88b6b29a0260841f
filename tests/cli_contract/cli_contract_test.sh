#!/usr/bin/env bash
# The command line's contract (issue 38): for every subcommand, a bad option value or an output
# that cannot be written ends with a non-zero exit (never a signal) and ONE line on standard
# error that names the option or the path, and nothing claims success on standard output.
#
#   cli_contract_test.sh AUTOSHOVEL SOURCE_DIR
#
# Each case is `refuses NAME EXPECTED -- ARGS...`: EXPECTED is a fixed string the error line must
# contain. Run by ctest, and under ASan/UBSan by scripts/sanitize (a sanitizer report is a
# non-zero exit with more than one line, so it fails here too).
set -uo pipefail
autoshovel=$1 source_dir=$2
models=(--models "$source_dir/models")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0 failed=0

# A case passes when: exit status in 1..125 (not a signal, not 0); standard error is exactly one
# line containing EXPECTED, without a doubled command prefix; standard output does not say that
# anything was written.
refuses() {
  local name=$1 expected=$2
  shift 3
  # A reader that opens a named pipe blocks: the time limit turns a hang into a failure.
  timeout 300 "$autoshovel" "$@" >"$tmp/out" 2>"$tmp/err" </dev/null
  local status=$? problem=""
  local lines
  lines=$(grep -c '' "$tmp/err")
  if [ "$status" -eq 0 ]; then
    problem="exit 0"
  elif [ "$status" -eq 124 ]; then
    problem="timed out (a hang)"
  elif [ "$status" -gt 125 ]; then
    problem="exit $status (signal or sanitizer abort)"
  elif [ "$lines" -ne 1 ]; then
    problem="$lines lines on stderr"
  elif [ -n "$(tail -c1 "$tmp/err")" ]; then
    problem="the error line has no final newline"
  elif ! grep -qF -- "$expected" "$tmp/err"; then
    problem="stderr lacks '$expected'"
  elif grep -qE '(autoshovel [a-z -]+: )\1' "$tmp/err"; then
    problem="doubled command prefix"
  elif grep -qiE '\b(wrote|written to)\b' "$tmp/out"; then
    problem="stdout claims a write: $(head -c 200 "$tmp/out")"
  fi
  if [ -z "$problem" ]; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL $name: $problem"
    echo "  command: autoshovel $*"
    sed 's/^/  stderr: /' "$tmp/err" | head -5
  fi
}

# Outputs that cannot be written. Root ignores permission bits, so these use what even root
# cannot write: a full device, a path under a regular file, a missing folder, a folder.
full=/dev/full
under_file="$tmp/plain_file/out"
touch "$tmp/plain_file"
missing_dir="$tmp/no_such_folder/out"
mkdir -p "$tmp/a_folder"
mkdir -p "$tmp/nonempty_run" && touch "$tmp/nonempty_run/x"
echo "not sqlite" >"$tmp/text.sqlite"
mkfifo "$tmp/fifo.yaml" "$tmp/fifo.model" "$tmp/fifo.scale"

# describe
refuses describe-unknown "unknown machine 'no_such_machine'" -- "${models[@]}" describe no_such_machine
refuses describe-overlay-missing "missing_overlay.yaml" -- "${models[@]}" describe xcmg_968ev --overlay "$tmp/missing_overlay.yaml"
refuses describe-folder "is a folder" -- "${models[@]}" describe "$tmp/a_folder"
refuses describe-fifo "is a named pipe" -- "${models[@]}" describe "$tmp/fifo.yaml"
# gen
refuses gen-output-under-file "plain_file" -- gen "$source_dir/models/loaders/xcmg_968ev.yaml" -o "$under_file"
refuses gen-missing-description "no_such.yaml" -- gen "$tmp/no_such.yaml" -o "$tmp/gen"
# plant step
refuses step-amplitude-nan "--amplitude" -- "${models[@]}" plant step --machine xcmg_968ev --amplitude nan
refuses step-rate-zero "--rate" -- "${models[@]}" plant step --machine xcmg_968ev --rate 0
refuses step-seed-negative "--seed" -- "${models[@]}" plant step --machine xcmg_968ev --seed -1
refuses step-seed-2to64 "--seed" -- "${models[@]}" plant step --machine xcmg_968ev --seed 18446744073709551616
refuses step-full-disk "/dev/full" -- "${models[@]}" plant step --machine xcmg_968ev --duration 0.5 -o "$full"
refuses step-missing-folder "no_such_folder" -- "${models[@]}" plant step --machine xcmg_968ev --duration 0.5 -o "$missing_dir"
refuses step-into-folder "a_folder" -- "${models[@]}" plant step --machine xcmg_968ev --duration 0.5 -o "$tmp/a_folder"
# plant step to a full standard output
"$autoshovel" "${models[@]}" plant step --machine xcmg_968ev --duration 0.5 >/dev/full 2>"$tmp/err"
status=$?
if [ "$status" -ne 0 ] && [ "$status" -le 125 ] && grep -q "standard output" "$tmp/err" &&
  [ "$(grep -c '' "$tmp/err")" -eq 1 ]; then
  passed=$((passed + 1))
else
  failed=$((failed + 1))
  echo "FAIL step-stdout-full: exit $status, stderr: $(cat "$tmp/err")"
fi
# scenario
refuses scenario-unknown "unknown scenario" -- "${models[@]}" scenario no_such_yard
refuses scenario-mpp-nan "--mpp" -- "${models[@]}" scenario cone_pile --mpp nan
refuses scenario-png-missing-folder "no_such_folder" -- "${models[@]}" scenario cone_pile -o "$missing_dir.png"
refuses scenario-png-full "/dev/full" -- "${models[@]}" scenario cone_pile -o "$full"
refuses scenario-fifo "fifo.yaml: is a named pipe" -- "${models[@]}" scenario "$tmp/fifo.yaml"
# map
refuses map-frames-zero "--frames" -- "${models[@]}" map cone_pile --frames 0
refuses map-advance-inf "--advance" -- "${models[@]}" map cone_pile --advance inf
balls="$source_dir/tests/data/pile_scans/balls_25.pcd"
empty_box="$source_dir/tests/data/pile_scans/empty_box.pcd"
refuses map-cloud-floor-three "--floor" -- map --cloud "$balls" --floor 0,0,1 --output-dir "$tmp/m1"
refuses map-cloud-floor-nan "--floor" -- map --cloud "$balls" --floor 0,0,nan,1 --output-dir "$tmp/m2"
refuses map-cloud-floor-and-reference "--floor or --reference" -- map --cloud "$balls" --floor 0,0,1,0 --reference "$empty_box" --output-dir "$tmp/m3"
refuses map-cloud-register-alone "--register" -- map --cloud "$balls" --register --output-dir "$tmp/m4"
refuses map-cloud-floor-zero "--floor" -- map --cloud "$balls" --floor 0,0,0,1 --output-dir "$tmp/m5"
# select
refuses select-top-zero "--top" -- "${models[@]}" select cone_pile --top 0
refuses select-safety-nan "--safety-distance" -- "${models[@]}" select cone_pile --safety-distance nan
refuses select-angles-nan "--angles" -- "${models[@]}" select cone_pile --angles 0,nan
refuses select-png-under-file "plain_file" -- "${models[@]}" select cone_pile --truth-map --png "$under_file.png"
# calibrate arm
refuses arm-simulate-full "/dev/full" -- "${models[@]}" calibrate arm --machine xcmg_968ev --simulate "$full"
refuses arm-simulate-missing-folder "no_such_folder" -- "${models[@]}" calibrate arm --machine xcmg_968ev --simulate "$missing_dir.csv"
refuses arm-seed-2to64 "--seed" -- "${models[@]}" calibrate arm --machine xcmg_968ev --simulate "$tmp/arm.csv" --seed 18446744073709551615
refuses arm-initial-nan "--initial" -- "${models[@]}" calibrate arm "$tmp/arm.csv" --machine xcmg_968ev --initial 1,nan,0,0
refuses arm-data-missing "no_such.csv" -- "${models[@]}" calibrate arm "$tmp/no_such.csv" --machine xcmg_968ev
refuses arm-data-folder "a_folder: cannot open: is a folder" -- "${models[@]}" calibrate arm "$tmp/a_folder" --machine xcmg_968ev
refuses arm-data-fifo "cannot open: is a named pipe" -- "${models[@]}" calibrate arm "$tmp/fifo.yaml" --machine xcmg_968ev
refuses run-predictor-fifo "is a named pipe" -- "${models[@]}" run --predictor "$tmp/fifo" -o "$tmp/r9"
# calibrate camera-lidar
refuses camlidar-max-points "--max-points" -- "${models[@]}" calibrate camera-lidar --machine xcmg_968ev --frames "$tmp" --max-points -5
refuses camlidar-simulate-under-file "plain_file" -- "${models[@]}" calibrate camera-lidar --machine xcmg_968ev --simulate "$under_file"
refuses camlidar-seed "--seed" -- "${models[@]}" calibrate camera-lidar --machine xcmg_968ev --simulate "$tmp/cl" --seed -3
# identify hydraulics
refuses hydraulics-simulate-under-file "plain_file" -- "${models[@]}" identify hydraulics --machine xcmg_968ev --simulate "$under_file"
refuses hydraulics-header-lines "--header-lines" -- "${models[@]}" identify hydraulics "$tmp/x.csv" --machine xcmg_968ev --header-lines -1
refuses hydraulics-log-missing "no_such.csv" -- "${models[@]}" identify hydraulics "$tmp/no_such.csv" --machine xcmg_968ev
# train
refuses weights-threads "--threads" -- "${models[@]}" train weights --threads -1
refuses weights-evaluations "--evaluations" -- "${models[@]}" train weights --evaluations 5
refuses weights-demos-fifo "is a named pipe" -- "${models[@]}" train weights --demos "$tmp/fifo.yaml" --out "$tmp/w.yaml"
refuses predictor-threads "--threads" -- "${models[@]}" train predictor "$tmp/text.sqlite" -o "$tmp/svr" --threads -2
refuses predictor-database-missing "no_such.sqlite" -- "${models[@]}" train predictor "$tmp/no_such.sqlite" -o "$tmp/svr"
refuses segmentation-lr "--lr" -- "${models[@]}" train segmentation cone_pile -o "$tmp/n.onnx" --lr nan
refuses segmentation-jobs "--jobs" -- "${models[@]}" train segmentation cone_pile -o "$tmp/n.onnx" --jobs 0
# campaign and its report
refuses campaign-workers "--workers" -- "${models[@]}" campaign "$source_dir/examples/campaigns/faults.yaml" --workers -1
refuses campaign-spec-missing "no_such.yaml" -- "${models[@]}" campaign "$tmp/no_such.yaml"
refuses campaign-out-under-file "plain_file" -- "${models[@]}" campaign "$source_dir/examples/campaigns/faults.yaml" -o "$under_file"
refuses report-missing "no_such.sqlite" -- "${models[@]}" report production "$tmp/no_such.sqlite"
refuses report-text-file "text.sqlite" -- "${models[@]}" report production "$tmp/text.sqlite"
refuses report-folder "a_folder: not a regular file" -- "${models[@]}" report production "$tmp/a_folder"
refuses report-fifo "not a regular file" -- "${models[@]}" report production "$tmp/fifo.yaml"
# run
refuses run-attack-nan "--attack-speed" -- "${models[@]}" run --attack-speed nan -o "$tmp/r1"
refuses run-attack-huge "--attack-speed" -- "${models[@]}" run --attack-speed 1e308 -o "$tmp/r2"
refuses run-pressure-negative "--pressure-bar" -- "${models[@]}" run --pressure-bar -1 -o "$tmp/r3"
refuses run-safety-nan "--safety-distance" -- "${models[@]}" run --safety-distance nan -o "$tmp/r4"
refuses run-d-res-negative "--d-res" -- "${models[@]}" run --d-res -1 -o "$tmp/r5"
refuses run-seed-negative "--seed" -- "${models[@]}" run --seed -1 -o "$tmp/r6"
refuses run-cycles-zero "--cycles" -- "${models[@]}" run --cycles 0 -o "$tmp/r7"
refuses run-out-under-file "plain_file" -- "${models[@]}" run cone_pile --cycles 1 -o "$under_file"
refuses run-out-not-empty "nonempty_run" -- "${models[@]}" run cone_pile --cycles 1 -o "$tmp/nonempty_run"
if grep -q "resume" "$tmp/err"; then  # `run` has no --resume: it must not suggest one
  failed=$((failed + 1))
  echo "FAIL run-out-not-empty: suggests resuming: $(cat "$tmp/err")"
fi
refuses run-faults-missing "--faults" -- "${models[@]}" run --faults "$tmp/no_such.yaml" -o "$tmp/r8"
refuses run-record-not-empty "nonempty_run" -- "${models[@]}" run cone_pile --cycles 1 --record "$tmp/nonempty_run" -o "$tmp/r10"
refuses truck-record-not-empty "nonempty_run" -- "${models[@]}" run truck_loading --cycles 1 --record "$tmp/nonempty_run" -o "$tmp/r11"
for d in r1 r2 r3 r4 r5 r6 r7 r8 r9 r10 r11; do
  if [ -e "$tmp/$d" ]; then
    failed=$((failed + 1))
    echo "FAIL run-refused-leaves-no-folder: $d was created"
  fi
done
# replay
refuses replay-missing "no_such_recording: not a folder" -- "${models[@]}" replay "$tmp/no_such_recording" -o "$tmp/rp1"
mkdir -p "$tmp/unfinished_recording"
refuses replay-unfinished "did not finish" -- "${models[@]}" replay "$tmp/unfinished_recording" -o "$tmp/rp2"
refuses replay-scale "--segmentation-scale" -- "${models[@]}" replay "$tmp/unfinished_recording" --segmentation-scale 5 -o "$tmp/rp3"
refuses run-scale "--segmentation-scale" -- "${models[@]}" run --segmentation-scale nan -o "$tmp/rp4"
for d in rp1 rp2 rp3 rp4; do
  if [ -e "$tmp/$d" ]; then
    failed=$((failed + 1))
    echo "FAIL replay-refused-leaves-no-folder: $d was created"
  fi
done
# compare
refuses compare-trials "--trials" -- "${models[@]}" compare table5 --trials 0
refuses compare-attack "--attack-speed" -- "${models[@]}" compare table5 --attack-speed -1

echo "cli_contract: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
