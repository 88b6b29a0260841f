#!/usr/bin/env bash
# `autoshovel train segmentation` end to end, small (issue 8, item 5): 12 views of a site the
# shipped network never saw (examples/yards/ore_terminal.yaml, iron-ore piles), 3 steps. The
# network loaded into PyTorch computes what the ONNX file does (same validation mIoU from both),
# the new network scores higher on the held-out views, the shipped network is untouched, and an
# output into its folder is refused.
#   train_segmentation_test.sh AUTOSHOVEL SOURCE_DIR WORK_DIR
set -euo pipefail
autoshovel=$1 source=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
shipped=$source/models/segmentation/yard_segmenter.onnx
sum_before=$(sha256sum "$shipped" | cut -d' ' -f1)

"$autoshovel" train segmentation "$source/examples/yards/ore_terminal.yaml" -o "$work/ore.onnx" \
  --views 12 --heldout 4 --steps 3 --jobs 2 > "$work/out.txt"
cat "$work/out.txt"
test -s "$work/ore.onnx" || { echo "FAIL: no new network"; exit 1; }
line=$(grep '^mean IoU, all views:' "$work/out.txt")
before=$(echo "$line" | sed -E 's/.*: ([0-9.]+) % before, ([0-9.]+) % after/\1/')
after=$(echo "$line" | sed -E 's/.*: ([0-9.]+) % before, ([0-9.]+) % after/\2/')
awk -v b="$before" -v a="$after" 'BEGIN { exit !(a > b) }' ||
  { echo "FAIL: mean IoU $before % before, $after % after"; exit 1; }

# The base network as PyTorch sees it (train.py --init-onnx) scores the validation views as the
# runtime's ONNX inference does.
python_val=$(grep -A1 'val before fine-tuning' "$work/ore.onnx.data/train.log" | tail -1 |
  sed -E 's/.*mIoU +([0-9.]+).*/\1/')
onnx_val=$("$(dirname "$autoshovel")/segmentation_eval" --data "$work/ore.onnx.data/train" \
  --split val | grep 'mean IoU' | sed -E 's/^\| \*\*mean IoU\*\* \| \*\*([0-9.]+)\*\*.*/\1/')
awk -v p="$python_val" -v o="$onnx_val" 'BEGIN { d = p - o; exit !(d < 0.05 && d > -0.05) }' ||
  { echo "FAIL: validation mIoU $python_val % in PyTorch, $onnx_val % from the ONNX file"; exit 1; }

test "$(sha256sum "$shipped" | cut -d' ' -f1)" = "$sum_before" ||
  { echo "FAIL: the shipped network changed"; exit 1; }
if "$autoshovel" train segmentation "$source/examples/yards/ore_terminal.yaml" \
  -o "$source/models/segmentation/x.onnx" --views 12 2> "$work/refused.txt"; then
  echo "FAIL: wrote into the shipped network's folder"; exit 1
fi
grep -q "the shipped network's folder" "$work/refused.txt" || { cat "$work/refused.txt"; exit 1; }
echo "PASS: mean IoU $before % -> $after %; validation $python_val % (PyTorch) = $onnx_val % (ONNX)"
