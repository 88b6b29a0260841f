#!/usr/bin/env bash
# The CLI as a user meets it: describe works for every shipped machine; a malformed
# description gives exactly one line `file:line:column: ...` and a non-zero exit.
# usage: cli_test.sh AUTOSHOVEL SOURCE_DIR
set -uo pipefail
autoshovel=$1 source_dir=$2
fail() { echo "FAIL: $*"; exit 1; }
for machine in xcmg_968ev sdlg_l955he excavator_25t; do
  out=$("$autoshovel" --models "$source_dir/models" describe "$machine") || fail "describe $machine"
  grep -q "max reach" <<<"$out" || fail "describe $machine: no reach"
  grep -q "generated     up to date" <<<"$out" || fail "describe $machine: generated code not up to date"
done
for level in "" describe gen plant "plant step" scenario map calibrate "calibrate arm" \
  "calibrate camera-lidar" identify "identify hydraulics" select run compare; do
  "$autoshovel" $level --help >/dev/null || fail "--help at '$level'"
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/models/loaders"
cp -r "$source_dir/models/materials" "$tmp/models/"
sed 's/^  track_width: 2.25 /  track_width: -2.25 /' "$source_dir/models/loaders/xcmg_968ev.yaml" \
  > "$tmp/models/loaders/broken.yaml"
"$autoshovel" gen "$tmp/models/loaders/broken.yaml" -o "$tmp/out" 2>"$tmp/err" >/dev/null
status=$?
[ "$status" -ne 0 ] || fail "malformed description accepted"
[ "$(wc -l <"$tmp/err")" -eq 1 ] || fail "expected one line, got: $(cat "$tmp/err")"
grep -qE "broken.yaml:[0-9]+:[0-9]+: chassis.track_width: must be > 0 m, got -2.25 m" "$tmp/err" \
  || fail "unexpected message: $(cat "$tmp/err")"
[ ! -e "$tmp/out" ] || fail "output written for a malformed description"
"$autoshovel" --models "$source_dir/models" describe no_such_machine 2>/dev/null && fail "unknown machine accepted"
# The Z-bar candidate of docs/energy_audit.md stays a valid description that reaches the SAE dump.
out=$("$autoshovel" --models "$source_dir/models" describe \
  "$source_dir/examples/xcmg_968ev_zbar/xcmg_968ev.yaml") || fail "describe the Z-bar candidate"
grep -q "dump clearance at 45 deg" <<<"$out" || fail "Z-bar candidate: SAE J732 dump not reached"
# plant step: a CSV with the documented columns; the same seed gives the same bytes.
"$autoshovel" --models "$source_dir/models" plant step --machine xcmg_968ev --actuator boom \
  --amplitude 0.6 --duration 1.5 --noise --seed 7 -o "$tmp/step.csv" || fail "plant step"
grep -q "^t,command,spool,pressure,joint_angle,joint_rate$" "$tmp/step.csv" || fail "step header"
[ "$(grep -cv '^[#t]' "$tmp/step.csv")" -eq 151 ] || fail "expected 151 samples"
"$autoshovel" --models "$source_dir/models" plant step --machine xcmg_968ev --actuator boom \
  --amplitude 0.6 --duration 1.5 --noise --seed 7 >"$tmp/step2.csv" || fail "plant step to stdout"
cmp -s "$tmp/step.csv" "$tmp/step2.csv" || fail "plant step is not deterministic"
"$autoshovel" --models "$source_dir/models" plant step --machine xcmg_968ev --actuator stick \
  2>"$tmp/err" >/dev/null && fail "unknown actuator accepted"
grep -q "has no actuator 'stick'; it has: boom_cylinders (joint boom)" "$tmp/err" \
  || fail "unexpected message: $(cat "$tmp/err")"
"$autoshovel" --models "$source_dir/models" plant step --machine xcmg_968ev --amplitude 1.5 \
  2>"$tmp/err" >/dev/null && fail "amplitude 1.5 accepted"
grep -q -- "--amplitude: must be in \[-1, 1\], got 1.5" "$tmp/err" || fail "unexpected message: $(cat "$tmp/err")"
# scenario: lists the yard, draws the top view, suggests the nearest name for a typo.
"$autoshovel" --models "$source_dir/models" scenario cone_pile -o "$tmp/cone.png" >"$tmp/out" \
  || fail "scenario cone_pile"
grep -q "gravel_cone .*cone .*big_gravel" "$tmp/out" || fail "scenario listing: $(cat "$tmp/out")"
[ -s "$tmp/cone.png" ] || fail "no top view written"
"$autoshovel" --models "$source_dir/models" scenario cone_pil 2>"$tmp/err" >/dev/null \
  && fail "unknown scenario accepted"
grep -q "did you mean 'cone_pile'" "$tmp/err" || fail "unexpected message: $(cat "$tmp/err")"
# map: the six-layer picture of the semantic elevation map from a scenario's start pose.
"$autoshovel" --models "$source_dir/models" map cone_pile --advance 4 --frames 2 \
  -o "$tmp/map.png" >"$tmp/out" || fail "map cone_pile: $(cat "$tmp/out")"
grep -q "pile at" "$tmp/out" || fail "map found no pile: $(cat "$tmp/out")"
[ -s "$tmp/map.png" ] || fail "no map picture written"
"$autoshovel" --models "$source_dir/models" map cone_pile --lighting dusk 2>"$tmp/err" \
  >/dev/null && fail "lighting dusk accepted"
grep -q "lighting must be normal, bright or dim" "$tmp/err" || fail "unexpected: $(cat "$tmp/err")"
# calibrate arm: simulate a measurement file, calibrate, get an overlay; bad files are located.
"$autoshovel" --models "$source_dir/models" calibrate arm --machine xcmg_968ev \
  --simulate "$tmp/arm.csv" >/dev/null || fail "calibrate arm --simulate"
"$autoshovel" --models "$source_dir/models" calibrate arm "$tmp/arm.csv" --machine xcmg_968ev \
  --initial 1,1,0,0 -o "$tmp/arm.yaml" >"$tmp/out" || fail "calibrate arm: $(cat "$tmp/out")"
grep -q "l_1 (boom" "$tmp/out" || fail "calibration table: $(cat "$tmp/out")"
grep -q "^    - name: bucket" "$tmp/arm.yaml" || fail "overlay: $(cat "$tmp/arm.yaml")"
sed '4s/^\([^,]*\),[^,]*,/\1,abc,/' "$tmp/arm.csv" >"$tmp/bad_arm.csv"
"$autoshovel" --models "$source_dir/models" calibrate arm "$tmp/bad_arm.csv" \
  --machine xcmg_968ev -o "$tmp/bad.yaml" 2>"$tmp/err" >/dev/null && fail "bad csv accepted"
grep -q "bad_arm.csv:4:2: theta_boom_deg: expected a finite number, got 'abc'" "$tmp/err" \
  || fail "unexpected: $(cat "$tmp/err")"
[ ! -e "$tmp/bad.yaml" ] || fail "overlay written for a bad file"
"$autoshovel" --models "$source_dir/models" describe xcmg_968ev --overlay "$tmp/arm.yaml" \
  >/dev/null || fail "describe with the calibration overlay"
head -4 "$tmp/arm.csv" >"$tmp/two.csv"
"$autoshovel" --models "$source_dir/models" calibrate arm "$tmp/two.csv" --machine xcmg_968ev \
  2>"$tmp/err" >/dev/null && fail "two poses accepted"
[ -s "$tmp/arm.yaml.png" ] || fail "no residual chart"

# identify hydraulics: simulate logs, fit the boom, get an overlay that describe accepts.
"$autoshovel" --models "$source_dir/models" identify hydraulics --machine xcmg_968ev \
  --simulate "$tmp/hyd" >/dev/null || fail "identify hydraulics --simulate"
"$autoshovel" --models "$source_dir/models" identify hydraulics "$tmp"/hyd/boom_cylinders_step_*.csv \
  --machine xcmg_968ev -o "$tmp/hyd.yaml" --png "$tmp/hyd.png" >"$tmp/out" \
  || fail "identify hydraulics: $(cat "$tmp/out")"
grep -q "motion delay" "$tmp/out" || fail "hydraulics table: $(cat "$tmp/out")"
grep -q "^    - name: boom_cylinders" "$tmp/hyd.yaml" || fail "overlay: $(cat "$tmp/hyd.yaml")"
[ -s "$tmp/hyd.png" ] || fail "no hydraulics residual figure"
"$autoshovel" --models "$source_dir/models" describe xcmg_968ev --overlay "$tmp/hyd.yaml" \
  >/dev/null || fail "describe with the hydraulics overlay"
"$autoshovel" --models "$source_dir/models" identify hydraulics --machine xcmg_968ev \
  2>"$tmp/err" >/dev/null && fail "identify hydraulics without logs accepted"
grep -q "give one or more logs" "$tmp/err" || fail "unexpected: $(cat "$tmp/err")"
"$autoshovel" --models "$source_dir/models" calibrate camera-lidar --machine xcmg_968ev \
  2>"$tmp/err" >/dev/null && fail "calibrate camera-lidar without frames accepted"
grep -q "give --frames" "$tmp/err" || fail "unexpected: $(cat "$tmp/err")"
# select: candidates on the simulator's cone, a PNG.
"$autoshovel" --models "$source_dir/models" select cone_pile --truth-map --png "$tmp/sel.png" \
  >"$tmp/out" || fail "select: $(cat "$tmp/out")"
[ -s "$tmp/sel.png" ] || fail "select wrote no PNG"
"$autoshovel" --models "$source_dir/models" select no_such_yard 2>"$tmp/err" >/dev/null \
  && fail "select accepted an unknown scenario"
echo "cli ok"

# run: one closed-loop cycle on the cone, simulator labels; the run folder holds what it says.
"$autoshovel" --models "$source_dir/models" run cone_pile --cycles 1 --truth -o "$tmp/run" \
  >"$tmp/out" 2>&1 || fail "run: $(cat "$tmp/out")"
grep -q "1/1 cycles completed" "$tmp/out" || fail "run: $(cat "$tmp/out")"
for f in config.yaml results.sqlite log.txt report.html figures/fill_rate.png \
  figures/map_cycle_0.png figures/candidates_cycle_0.png figures/volume_cycle_0.png \
  figures/tip_path_cycle_0.png; do
  [ -s "$tmp/run/$f" ] || fail "run wrote no $f"
done
grep -q "^scenario: cone_pile" "$tmp/run/config.yaml" || fail "run: config.yaml lacks the scenario"
"$autoshovel" --models "$source_dir/models" run cone_pile --cycles 1 -o "$tmp/run" \
  >/dev/null 2>"$tmp/err" && fail "run overwrote an existing run folder"
"$autoshovel" --models "$source_dir/models" run mixing_station --bins bin_42 -o "$tmp/run2" \
  >/dev/null 2>"$tmp/err" && fail "run accepted an unknown bin"
grep -q "no bin 'bin_42'" "$tmp/err" || fail "run: unexpected message: $(cat "$tmp/err")"
exit 0
