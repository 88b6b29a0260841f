#!/usr/bin/env bash
# `autoshovel run --record` then `autoshovel replay --check`: replaying the recorded frames
# reproduces the run's map after every update, every selection and the scoop's V1 and V2 at every
# trigger decision, byte for byte; a recording with one pose changed does not (the check can
# fail).
#
#   replay_test.sh AUTOSHOVEL SOURCE_DIR
set -uo pipefail
autoshovel=$1 source_dir=$2
models=(--models "$source_dir/models")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() {
  echo "FAIL: $*"
  exit 1
}

"$autoshovel" "${models[@]}" run cone_pile --cycles 1 --seed 3 --truth --no-figures \
  --record "$tmp/rec" -o "$tmp/run" >"$tmp/run.out" 2>&1
status=$?
[ "$status" -le 1 ] || { cat "$tmp/run.out"; fail "run exited $status"; }
for f in recording.yaml machine.yaml updates.csv frames.csv scoop.csv tip_path.csv \
  reference/map_digests.csv reference/selections.csv reference/predictions.csv; do
  [ -s "$tmp/rec/$f" ] || fail "the recording has no $f"
done
updates=$(($(wc -l <"$tmp/rec/updates.csv") - 1))
[ "$updates" -ge 5 ] || fail "only $updates updates recorded"
selected=$(awk -F, 'NR > 1 && $5 != ""' "$tmp/rec/reference/selections.csv" | wc -l)
[ "$selected" -ge 1 ] || fail "no selection found a shovel point"
ls "$tmp/rec"/lidar/*/*.pcd >/dev/null 2>&1 || fail "no LiDAR frames"
ls "$tmp/rec"/camera/*.png >/dev/null 2>&1 || fail "no camera frames"

# No --truth: replay takes the recording machine's semantics (its manifest's perception).
grep -q "perception: {semantics: labels" "$tmp/rec/recording.yaml" || fail "no perception in the manifest"
"$autoshovel" "${models[@]}" replay "$tmp/rec" --check -o "$tmp/replay" \
  >"$tmp/replay.out" 2>&1 || { cat "$tmp/replay.out"; fail "replay --check exited $?"; }
cmp "$tmp/rec/reference/map_digests.csv" "$tmp/replay/map_digests.csv" || fail "maps differ"
cmp "$tmp/rec/reference/selections.csv" "$tmp/replay/selections.csv" || fail "selections differ"
cmp "$tmp/rec/reference/predictions.csv" "$tmp/replay/predictions.csv" || fail "V1/V2 differ"
predicted=$(awk -F, 'NR > 1 && $4 != ""' "$tmp/rec/reference/predictions.csv" | wc -l)
[ "$predicted" -ge 1 ] || fail "no decision predicted V2"
grep -q "maps identical after $updates of $updates updates" "$tmp/replay.out" ||
  { cat "$tmp/replay.out"; fail "replay does not report $updates identical maps"; }
[ -s "$tmp/replay/figures/map_cycle_0.png" ] || fail "no map picture"
[ -s "$tmp/replay/figures/candidates_cycle_0.png" ] || fail "no candidates picture"
grep -q "maps identical after $updates of $updates" "$tmp/replay/report.html" || fail "no report"

# An identification overlay in the recording (a real machine's calibrated arm): replay applies
# it. The bucket 1 cm longer (pin to tooth tip) moves the tip path, so V1 changes while the maps stay the same; an
# overlay identified against another description is refused with its place.
machine_name=$(sed -n 's/^name: *\([A-Za-z0-9_]*\).*/\1/p' "$tmp/rec/machine.yaml" | head -1)
machine_sha=$(sha256sum "$tmp/rec/machine.yaml" | cut -d' ' -f1)
bucket_length=$(awk '/- name: bucket/ { b = 1 } b && /length:/ { print $2; exit }' "$tmp/rec/machine.yaml")
cp -r "$tmp/rec" "$tmp/rec_overlay"
printf 'machine: %s\nbase_sha256: %s\narm:\n  links:\n    - name: bucket\n      length: %s\n' \
  "$machine_name" "$machine_sha" "$(awk -v l="$bucket_length" 'BEGIN { print l + 0.01 }')" \
  >"$tmp/rec_overlay/arm.overlay.yaml"
sed -i 's/^machine: \(.*\)$/machine: \1\noverlays: ["arm.overlay.yaml"]/' "$tmp/rec_overlay/recording.yaml"
"$autoshovel" "${models[@]}" replay "$tmp/rec_overlay" --check --no-figures -o "$tmp/replay_overlay" \
  >"$tmp/replay_overlay.out" 2>&1
status=$?
[ "$status" -eq 1 ] || { cat "$tmp/replay_overlay.out"; fail "the overlay changed nothing (exit $status)"; }
grep -q "maps identical after $updates of $updates updates" "$tmp/replay_overlay.out" ||
  { cat "$tmp/replay_overlay.out"; fail "the arm overlay changed the maps"; }
grep -q "first difference: predictions.csv" "$tmp/replay_overlay.out" ||
  { cat "$tmp/replay_overlay.out"; fail "the arm overlay did not change V1"; }
sed -i 's/^base_sha256: .*/base_sha256: 0123/' "$tmp/rec_overlay/arm.overlay.yaml"
"$autoshovel" "${models[@]}" replay "$tmp/rec_overlay" --no-figures -o "$tmp/replay_stale" \
  >"$tmp/replay_stale.out" 2>&1
status=$?
[ "$status" -eq 2 ] || { cat "$tmp/replay_stale.out"; fail "a stale overlay was accepted (exit $status)"; }
grep -q "arm.overlay.yaml:2:14: base_sha256" "$tmp/replay_stale.out" ||
  { cat "$tmp/replay_stale.out"; fail "the stale overlay's refusal does not say where"; }
[ ! -e "$tmp/replay_stale" ] || fail "a refused replay left a run folder"

# One LiDAR frame's pose moved by 0.2 m: the maps from that update on must differ.
awk -F, 'BEGIN { OFS = "," } NR == 2 { $8 = $8 + 0.2 } { print }' "$tmp/rec/frames.csv" \
  >"$tmp/frames.csv" && mv "$tmp/frames.csv" "$tmp/rec/frames.csv"
"$autoshovel" "${models[@]}" replay "$tmp/rec" --truth --check --no-figures -o "$tmp/replay2" \
  >"$tmp/replay2.out" 2>&1
status=$?
[ "$status" -eq 1 ] || { cat "$tmp/replay2.out"; fail "a moved frame was not found (exit $status)"; }
grep -q "first difference: map_digests.csv line 2" "$tmp/replay2.out" ||
  { cat "$tmp/replay2.out"; fail "the difference is not at the first update"; }
echo "replay_test: $updates updates, $selected selections, $predicted V2 predictions reproduced;" \
  "an arm overlay applied, a stale one refused; a moved frame detected"
