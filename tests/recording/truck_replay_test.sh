#!/usr/bin/env bash
# `autoshovel run truck_loading --record` then `autoshovel replay --check`: recognising the truck
# from the recorded first-pass scan and building the bed map from the recorded swing-back scans
# reproduce what the machine computed, byte for byte; the run's results are the same with and
# without --record; a recording with a scan's readings moved does not reproduce (the check can fail).
#
#   truck_replay_test.sh AUTOSHOVEL SOURCE_DIR
set -uo pipefail
autoshovel=$1 source_dir=$2
models=(--models "$source_dir/models")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() {
  echo "FAIL: $*"
  exit 1
}

"$autoshovel" "${models[@]}" run truck_loading --cycles 1 --no-figures --record "$tmp/rec" \
  -o "$tmp/run" >"$tmp/run.out" 2>&1 || { cat "$tmp/run.out"; fail "run exited $?"; }
for f in recording.yaml machine.yaml scans.csv scanlines.csv scan_points.csv \
  reference/truck.csv reference/bed_maps.csv; do
  [ -s "$tmp/rec/$f" ] || fail "the recording has no $f"
done
grep -q "^job: truck_loading" "$tmp/rec/recording.yaml" || fail "no job in the manifest"
scans=$(($(wc -l <"$tmp/rec/scans.csv") - 1))
[ "$scans" -eq 2 ] || fail "expected the recognition scan and one swing-back scan, got $scans"
grep -q "^1," "$tmp/rec/reference/truck.csv" || fail "the run recognised no truck"

# The recording changes nothing of the run.
"$autoshovel" "${models[@]}" run truck_loading --cycles 1 --no-figures -o "$tmp/plain" \
  >"$tmp/plain.out" 2>&1 || { cat "$tmp/plain.out"; fail "plain run exited $?"; }
diff <(grep "^\[pass" "$tmp/run.out" | sed 's/(.* elapsed)//') \
  <(grep "^\[pass" "$tmp/plain.out" | sed 's/(.* elapsed)//') || fail "--record changed the run"

"$autoshovel" "${models[@]}" replay "$tmp/rec" --check -o "$tmp/replay" >"$tmp/replay.out" 2>&1 ||
  { cat "$tmp/replay.out"; fail "replay --check exited $?"; }
cmp "$tmp/rec/reference/truck.csv" "$tmp/replay/truck.csv" || fail "the truck differs"
cmp "$tmp/rec/reference/bed_maps.csv" "$tmp/replay/bed_maps.csv" || fail "the bed maps differ"
grep -q "truck 1/1 identical, bed maps $scans/$scans identical" "$tmp/replay.out" ||
  { cat "$tmp/replay.out"; fail "replay does not report $scans identical bed maps"; }
[ -s "$tmp/replay/figures/bed_map.png" ] || fail "no bed map picture"

# The loader's camera options do not apply to a truck recording: refused, no run folder.
"$autoshovel" "${models[@]}" replay "$tmp/rec" --truth -o "$tmp/replay_truth" >"$tmp/truth.out" 2>&1
status=$?
[ "$status" -eq 2 ] || { cat "$tmp/truth.out"; fail "--truth on a truck recording: exit $status"; }
grep -q "is a truck-loading recording" "$tmp/truth.out" || { cat "$tmp/truth.out"; fail "no reason given"; }
[ ! -e "$tmp/replay_truth" ] || fail "a refused replay left a run folder"

# The swing-back scan's readings 0.2 m higher: its bed map must differ, the truck not.
awk -F, 'BEGIN { OFS = "," } $1 == 1 && $6 == 1 { $5 = $5 + 0.2 } { print }' \
  "$tmp/rec/scan_points.csv" >"$tmp/points.csv" && mv "$tmp/points.csv" "$tmp/rec/scan_points.csv"
"$autoshovel" "${models[@]}" replay "$tmp/rec" --check -o "$tmp/replay2" >"$tmp/replay2.out" 2>&1
status=$?
[ "$status" -eq 1 ] || { cat "$tmp/replay2.out"; fail "moved readings were not found (exit $status)"; }
grep -q "truck 1/1 identical" "$tmp/replay2.out" || fail "the truck changed with a bed scan"
grep -q "first difference: bed_maps.csv line 3" "$tmp/replay2.out" ||
  { cat "$tmp/replay2.out"; fail "the difference is not in the swing-back scan's bed map"; }
echo "truck_replay_test: truck and $scans bed maps reproduced; a moved scan detected"
