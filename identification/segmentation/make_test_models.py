#!/usr/bin/python3
"""Writes the malformed-model fixture of tests/segmentation: a valid ONNX network that OpenCV
runs but that gives 3 planes instead of the 7 class planes (perception::Segmenter must refuse
it, naming the file). Usage, from the repository root:
  /usr/bin/python3 identification/segmentation/make_test_models.py tests/segmentation/data
"""
import os
import sys

import torch


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else "tests/segmentation/data"
    torch.manual_seed(0)
    model = torch.nn.Conv2d(3, 3, 3, padding=1).eval()
    path = os.path.join(out_dir, "three_classes.onnx")
    torch.onnx.export(model, torch.zeros(1, 3, 384, 480), path, opset_version=13,
                      input_names=["bgr"], output_names=["logits"])
    print(f"wrote {path} ({os.path.getsize(path)} bytes)")


if __name__ == "__main__":
    main()
