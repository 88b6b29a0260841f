#!/usr/bin/python3
"""Trains the yard segmentation network and exports it to ONNX for perception::Segmenter.

Data: a folder written by `segmentation_dataset` (DIR/split.csv, DIR/images/*.png BGR camera
frames, DIR/labels/*.png class indices 0..6 in the order of core::SemanticClass). Views of split
"train" are trained on, views of split "val" are scored during and after training.

Network (YardSegNet): a compact encoder-decoder of depthwise-separable convolutions. The encoder
(MobileNetV2 inverted residual blocks, Sandler et al. CVPR 2018) halves the resolution four
times to 1/16, where two dilated blocks widen the receptive field to most of the frame; the
decoder adds each encoder level back (FPN-like, Lin et al. CVPR 2017) through 1x1 projections
and a depthwise-separable refinement up to 1/2 resolution, where a 1x1 convolution gives the 7
class scores, upsampled bilinearly to the input size. Only Conv (batch norm folded in), Relu,
Add and Resize remain in the exported graph: all run by OpenCV 4.6's dnn module.

Contract with runtime/perception/segmentation.cc: input "bgr" 1x3xHxW float, the B, G, R bytes
mapped to (v - 127.5) / 127.5; output "logits" 1x7xHxW; H and W multiples of 16 (exported at
384x480; the runtime pads the 480x383 camera frame by one repeated row).

Usage (training dependencies: apt-get install -y --no-install-recommends python3-torch
python3-onnx; see README.md):
  /usr/bin/python3 identification/segmentation/train.py --data build/segmentation/train \
      --out models/segmentation/yard_segmenter.onnx
"""

import argparse
import csv
import json
import math
import os
import struct
import sys
import time
import zlib

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

CLASSES = ["ground", "pile", "own_loader", "other_loader", "person", "wall", "other"]
LIGHTINGS = ["normal", "bright", "dim"]
NUM_CLASSES = len(CLASSES)
STRIDE = 16  # the network halves the resolution four times


# ----------------------------------------------------------------------------------------------
# Data


def read_png(path):
    """Decodes an 8-bit grey or RGB PNG as written by OpenCV's imwrite (no PIL or cv2 needed).

    OpenCV's encoder filters every row with the PNG "Sub" filter (or none), which undoes as a
    running sum along the row; other filters are refused with a clear message."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG file")
    pos, idat, header = 8, [], None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        pos += 12 + length
    width, height, depth, color, _, _, interlace = header
    channels = {0: 1, 2: 3}.get(color)
    if depth != 8 or channels is None or interlace != 0:
        raise ValueError(f"{path}: only 8-bit grey or RGB, non-interlaced PNGs are supported")
    raw = np.frombuffer(zlib.decompress(b"".join(idat)), np.uint8)
    raw = raw.reshape(height, 1 + width * channels)
    filters = raw[:, 0]
    pixels = raw[:, 1:].reshape(height, width, channels)
    if not np.all((filters == 0) | (filters == 1)):
        raise ValueError(f"{path}: PNG row filters {sorted(set(filters.tolist()))} not supported "
                         "(write it with OpenCV's imwrite)")
    out = pixels.copy()
    sub = filters == 1
    out[sub] = np.cumsum(pixels[sub], axis=1, dtype=np.uint8)  # wraps modulo 256, as PNG
    return out if channels == 3 else out[:, :, 0]


def load_split(data_dir, split):
    """Images (N, H, W, 3) uint8 in BGR order, labels (N, H, W) uint8, lighting names."""
    rows = []
    with open(os.path.join(data_dir, "split.csv")) as f:
        reader = csv.reader(line for line in f if not line.startswith("#"))
        head = next(reader)
        for r in reader:
            row = dict(zip(head, r))
            if row["split"] == split:
                rows.append(row)
    if not rows:
        raise SystemExit(f"no views of split '{split}' in {data_dir}/split.csv")
    images, labels = [], []
    for i, row in enumerate(rows):
        rgb = read_png(os.path.join(data_dir, "images", row["id"] + ".png"))
        images.append(rgb[:, :, ::-1])  # PNG holds RGB; the runtime feeds OpenCV's BGR
        labels.append(read_png(os.path.join(data_dir, "labels", row["id"] + ".png")))
        if (i + 1) % 500 == 0:
            print(f"  read {i + 1}/{len(rows)} {split} views", flush=True)
    return np.stack(images), np.stack(labels), [r["lighting"] for r in rows]


def normalise(bgr_uint8):
    """(N, H, W, 3) uint8 -> (N, 3, H, W) float in [-1, 1], as the runtime's blobFromImage."""
    x = torch.from_numpy(np.ascontiguousarray(bgr_uint8)).permute(0, 3, 1, 2).float()
    return (x - 127.5) / 127.5


class CropSampler:
    """Random crops for training. A third of the crops are centred (with jitter) on a pixel of a
    rare class (other_loader, person, wall), so small objects are not mostly cut away."""

    RARE = [3, 4, 5]

    def __init__(self, images, labels, crop_hw, rng):
        self.images, self.labels, self.crop, self.rng = images, labels, crop_hw, rng
        self.rare = []  # per view: (n, 2) rows, cols of a subsample of rare-class pixels
        for lab in labels:
            mask = np.isin(lab[::4, ::4], self.RARE)
            rc = np.argwhere(mask) * 4
            self.rare.append(rc[:: max(1, len(rc) // 64)])
        self.with_rare = [i for i in range(len(labels)) if len(self.rare[i])]

    def batch(self, n):
        ch, cw = self.crop
        h, w = self.labels.shape[1:]
        xs = np.empty((n, ch, cw, 3), np.uint8)
        ys = np.empty((n, ch, cw), np.uint8)
        for k in range(n):
            if self.with_rare and self.rng.random() < 1 / 3:
                i = self.with_rare[self.rng.integers(len(self.with_rare))]
                r, c = self.rare[i][self.rng.integers(len(self.rare[i]))]
                r0 = int(np.clip(r - ch // 2 + self.rng.integers(-ch // 3, ch // 3 + 1), 0, h - ch))
                c0 = int(np.clip(c - cw // 2 + self.rng.integers(-cw // 3, cw // 3 + 1), 0, w - cw))
            else:
                i = self.rng.integers(len(self.labels))
                r0, c0 = self.rng.integers(h - ch + 1), self.rng.integers(w - cw + 1)
            img = self.images[i, r0:r0 + ch, c0:c0 + cw]
            lab = self.labels[i, r0:r0 + ch, c0:c0 + cw]
            if self.rng.random() < 0.5:  # the yard has no handedness; the sun is anywhere
                img, lab = img[:, ::-1], lab[:, ::-1]
            xs[k], ys[k] = img, lab
        x = normalise(xs)
        # Mild photometric jitter (gain ±8 %, per-channel ±3 %) around the simulated exposures.
        gain = torch.from_numpy(self.rng.uniform(0.92, 1.08, (n, 1, 1, 1)).astype(np.float32))
        tint = torch.from_numpy(self.rng.uniform(0.97, 1.03, (n, 3, 1, 1)).astype(np.float32))
        x = ((x + 1) * gain * tint).clamp(0, 2) - 1
        return x, torch.from_numpy(ys).long()


# ----------------------------------------------------------------------------------------------
# Network


def conv_bn(cin, cout, k=3, stride=1, groups=1, dilation=1, relu=True):
    layers = [nn.Conv2d(cin, cout, k, stride, dilation * (k // 2), dilation=dilation,
                        groups=groups, bias=False), nn.BatchNorm2d(cout)]
    if relu:
        layers.append(nn.ReLU(inplace=True))
    return nn.Sequential(*layers)


class SeparableConv(nn.Module):
    """Depthwise 3x3 then pointwise 1x1, each with batch norm and ReLU."""

    def __init__(self, cin, cout, stride=1):
        super().__init__()
        self.dw = conv_bn(cin, cin, 3, stride, groups=cin)
        self.pw = conv_bn(cin, cout, 1)

    def forward(self, x):
        return self.pw(self.dw(x))


class InvertedResidual(nn.Module):
    """MobileNetV2 block: 1x1 expansion, depthwise 3x3 (strided or dilated), linear 1x1."""

    def __init__(self, cin, cout, stride=1, expand=4, dilation=1):
        super().__init__()
        hidden = cin * expand
        self.body = nn.Sequential(conv_bn(cin, hidden, 1),
                                  conv_bn(hidden, hidden, 3, stride, hidden, dilation),
                                  conv_bn(hidden, cout, 1, relu=False))
        self.residual = stride == 1 and cin == cout

    def forward(self, x):
        y = self.body(x)
        return x + y if self.residual else y


def up2(x):
    return F.interpolate(x, scale_factor=2.0, mode="bilinear", align_corners=False)


class YardSegNet(nn.Module):
    def __init__(self, width=1.5, classes=NUM_CLASSES):
        super().__init__()
        c2, c4, c8, c16 = (int(round(width * c)) for c in (16, 24, 48, 96))
        self.stem = nn.Sequential(conv_bn(3, c2, 3, 2), SeparableConv(c2, c2))          # 1/2
        self.enc4 = nn.Sequential(SeparableConv(c2, c4, 2), InvertedResidual(c4, c4))    # 1/4
        self.enc8 = nn.Sequential(InvertedResidual(c4, c8, 2), InvertedResidual(c8, c8),
                                  InvertedResidual(c8, c8))                               # 1/8
        self.enc16 = nn.Sequential(InvertedResidual(c8, c16, 2),
                                   InvertedResidual(c16, c16, dilation=2),
                                   InvertedResidual(c16, c16, dilation=4),
                                   InvertedResidual(c16, c16))                            # 1/16
        self.lat16, self.ref8 = conv_bn(c16, c8, 1), SeparableConv(c8, c8)
        self.lat8, self.ref4 = conv_bn(c8, c4, 1), SeparableConv(c4, c4)
        self.lat4, self.ref2 = conv_bn(c4, c2, 1), SeparableConv(c2, c2)
        self.head = nn.Conv2d(c2, classes, 1)

    def forward(self, x):
        f2 = self.stem(x)
        f4 = self.enc4(f2)
        f8 = self.enc8(f4)
        f16 = self.enc16(f8)
        d8 = self.ref8(up2(self.lat16(f16)) + f8)
        d4 = self.ref4(up2(self.lat8(d8)) + f4)
        d2 = self.ref2(up2(self.lat4(d4)) + f2)
        return up2(self.head(d2))


# ----------------------------------------------------------------------------------------------
# Scoring


def pad16(x):
    h, w = x.shape[-2:]
    ph, pw = (-h) % STRIDE, (-w) % STRIDE
    return F.pad(x, (0, pw, 0, ph), mode="replicate") if ph or pw else x


@torch.no_grad()
def confusion(model, images, labels, batch=4):
    """Confusion counts [truth, predicted] over full frames, padded as the runtime pads them."""
    modes = [m.training for m in model.modules()]
    model.eval()
    counts = np.zeros((len(images), NUM_CLASSES, NUM_CLASSES), np.int64)
    h, w = labels.shape[1:]
    for s in range(0, len(images), batch):
        x = pad16(normalise(images[s:s + batch]))
        pred = model(x)[:, :, :h, :w].argmax(1).numpy()
        for k in range(len(pred)):
            t = labels[s + k].astype(np.int64).ravel()
            counts[s + k] = np.bincount(t * NUM_CLASSES + pred[k].ravel(),
                                        minlength=NUM_CLASSES ** 2).reshape(NUM_CLASSES, -1)
    for m, training in zip(model.modules(), modes):  # as it was (frozen batch norm stays frozen)
        m.training = training
    return counts


def iou(counts):
    tp = np.diag(counts).astype(float)
    union = counts.sum(0) + counts.sum(1) - tp
    return np.where(union > 0, tp / np.maximum(union, 1), np.nan)


def report(counts, lightings):
    lines, result = [], {}
    for name in ["all"] + LIGHTINGS:
        sel = [i for i, l in enumerate(lightings) if name == "all" or l == name]
        if not sel:
            continue
        per_class = iou(counts[sel].sum(0))
        result[name] = {"miou": float(np.nanmean(per_class)),
                        "iou": {c: float(v) for c, v in zip(CLASSES, per_class)}}
        lines.append(f"    {name:6s} mIoU {100 * np.nanmean(per_class):6.2f} | " +
                     " ".join(f"{c} {100 * v:5.1f}" for c, v in zip(CLASSES, per_class)))
    return "\n".join(lines), result


# ----------------------------------------------------------------------------------------------
# Training


def dice_loss(logits, target):
    """1 - soft Dice averaged over the classes present in the batch: an overlap (IoU-like) term
    that does not let the large classes (floor, the own hood, sky) drown the small ones."""
    p = logits.softmax(1)
    onehot = F.one_hot(target, NUM_CLASSES).permute(0, 3, 1, 2).float()
    inter = (p * onehot).sum((0, 2, 3))
    total = p.sum((0, 2, 3)) + onehot.sum((0, 2, 3))
    present = onehot.sum((0, 2, 3)) > 0
    dice = (2 * inter + 1) / (total + 1)
    return 1 - dice[present].mean()


def load_onnx(model, path):
    """Starts `model` from a network that export() wrote, for fine-tuning on a new site
    (`autoshovel train segmentation`). The exported graph has every batch norm folded into the
    convolution before it; its Conv nodes, in graph order, are the model's Conv2d modules in
    module order (forward() runs them in the order __init__ makes them). Each convolution takes
    the folded weight; the batch norm after it becomes the identity plus the folded bias
    (γ = 1, β = bias, mean 0, variance 1 − eps), so that the model computes what the file does.
    The batch norms must then stay frozen (eval mode) while fine-tuning: batch statistics would
    undo the folding at the first step."""
    import onnx  # only needed here
    from onnx import numpy_helper
    graph = onnx.load(path).graph
    weights = {i.name: numpy_helper.to_array(i) for i in graph.initializer}
    nodes = [n for n in graph.node if n.op_type == "Conv"]
    convs = [m for m in model.modules() if isinstance(m, nn.Conv2d)]
    if len(nodes) != len(convs):
        raise SystemExit(f"{path}: {len(nodes)} convolutions, the network has {len(convs)} "
                         "(another architecture or --width?)")
    after = {}
    for seq in model.modules():
        children = list(seq.children())
        for a, b in zip(children, children[1:]):
            if isinstance(a, nn.Conv2d) and isinstance(b, nn.BatchNorm2d):
                after[a] = b
    with torch.no_grad():
        for k, (node, conv) in enumerate(zip(nodes, convs)):
            w = weights.get(node.input[1])
            b = weights.get(node.input[2]) if len(node.input) > 2 else None
            if w is None or b is None or tuple(w.shape) != tuple(conv.weight.shape):
                raise SystemExit(f"{path}: convolution {k} ({node.name}) does not match the "
                                 f"network's {tuple(conv.weight.shape)}")
            conv.weight.copy_(torch.from_numpy(w.copy()))
            bn = after.get(conv)
            if bn is None:
                conv.bias.copy_(torch.from_numpy(b.copy()))
            else:
                bn.weight.fill_(1.0)
                bn.bias.copy_(torch.from_numpy(b.copy()))
                bn.running_mean.zero_()
                bn.running_var.fill_(1.0 - bn.eps)


def freeze_batch_norm(model):
    for m in model.modules():
        if isinstance(m, nn.BatchNorm2d):
            m.eval()


def export(model, path):
    model.eval()
    dummy = torch.zeros(1, 3, 384, 480)
    torch.onnx.export(model, dummy, path, opset_version=13, input_names=["bgr"],
                      output_names=["logits"], do_constant_folding=True)
    import onnx  # only needed here
    graph = onnx.load(path)
    onnx.checker.check_model(graph)
    ops = sorted({n.op_type for n in graph.graph.node})
    print(f"exported {path}: {os.path.getsize(path) / 1e6:.2f} MB, ops {ops}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", default="build/segmentation/train",
                    help="folder written by segmentation_dataset")
    ap.add_argument("--out", default="models/segmentation/yard_segmenter.onnx")
    ap.add_argument("--iters", type=int, default=6000, help="optimiser steps")
    ap.add_argument("--batch", type=int, default=8)
    ap.add_argument("--crop", default="192x256", help="training crop HxW (full resolution)")
    ap.add_argument("--width", type=float, default=1.5, help="channel multiplier")
    ap.add_argument("--lr", type=float, default=3e-3)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--eval-every", type=int, default=2000)
    ap.add_argument("--checkpoint", default="", help="save the state here while training")
    ap.add_argument("--resume", default="", help="continue from a --checkpoint file")
    ap.add_argument("--init", default="",
                    help="start from the weights of a --checkpoint file with a fresh optimiser "
                         "and schedule (fine-tuning on new data)")
    ap.add_argument("--init-onnx", default="",
                    help="start from a network this script exported (batch norm folded; it is "
                         "kept frozen), with a fresh optimiser and schedule: fine-tuning on a new "
                         "site")
    ap.add_argument("--log", default="", help="write the final scores as JSON here")
    args = ap.parse_args()

    torch.set_num_threads(args.threads)
    torch.manual_seed(args.seed)
    rng = np.random.default_rng(args.seed)
    crop = tuple(int(v) for v in args.crop.split("x"))

    t0 = time.time()
    train_x, train_y, _ = load_split(args.data, "train")
    val_x, val_y, val_light = load_split(args.data, "val")
    print(f"{len(train_x)} train, {len(val_x)} val views of {train_x.shape[2]}x{train_x.shape[1]}"
          f" read in {time.time() - t0:.0f} s", flush=True)

    # Class weights for cross-entropy: (median frequency / frequency)^0.5, bounded, so that
    # a person (0.1 % of the pixels) weighs more than the hood (30 %) without dominating.
    freq = np.bincount(train_y[:, ::4, ::4].ravel(), minlength=NUM_CLASSES).astype(float)
    freq /= freq.sum()
    weights = np.clip(np.sqrt(np.median(freq) / np.maximum(freq, 1e-6)), 0.3, 5.0)
    print("pixel share " + " ".join(f"{c} {100 * f:.2f}%" for c, f in zip(CLASSES, freq)))
    print("class weights " + " ".join(f"{c} {w:.2f}" for c, w in zip(CLASSES, weights)))
    weights = torch.tensor(weights, dtype=torch.float32)

    model = YardSegNet(args.width)
    print(f"YardSegNet width {args.width}: {sum(p.numel() for p in model.parameters())} "
          "parameters", flush=True)
    opt = torch.optim.AdamW(model.parameters(), lr=args.lr, weight_decay=1e-4)
    # One cycle: 3 % warm-up, then cosine decay to 1 % of the peak rate.
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=args.lr, total_steps=args.iters,
                                                pct_start=0.03, final_div_factor=100)
    start = 0
    if args.init:
        model.load_state_dict(torch.load(args.init)["model"])
        print(f"initialised from {args.init}")
    if args.init_onnx:
        load_onnx(model, args.init_onnx)
        print(f"initialised from {args.init_onnx} (batch norm folded, frozen)")
    if args.resume:
        state = torch.load(args.resume)
        model.load_state_dict(state["model"])
        opt.load_state_dict(state["opt"])
        sched.load_state_dict(state["sched"])
        start = state["iter"]
        rng = np.random.default_rng([args.seed, start])
        print(f"resumed at step {start}")
    sampler = CropSampler(train_x, train_y, crop, rng)

    model.train()
    if args.init_onnx:
        freeze_batch_norm(model)
    if args.init_onnx and args.iters > 0:
        text, _ = report(confusion(model, val_x, val_y), val_light)
        print(f"val before fine-tuning\n{text}", flush=True)
    t_train, running = time.time(), []
    for it in range(start, args.iters):
        x, y = sampler.batch(args.batch)
        logits = model(x)
        loss = F.cross_entropy(logits, y, weight=weights) + 0.5 * dice_loss(logits, y)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        sched.step()
        running.append(loss.item())
        if (it + 1) % 100 == 0:
            rate = (time.time() - t_train) / (it + 1 - start)
            print(f"step {it + 1}/{args.iters} loss {np.mean(running):.4f} "
                  f"lr {sched.get_last_lr()[0]:.2e} {rate:.3f} s/step "
                  f"eta {(args.iters - it - 1) * rate / 60:.1f} min", flush=True)
            running = []
        if args.checkpoint and (it + 1) % 500 == 0:
            torch.save({"model": model.state_dict(), "opt": opt.state_dict(),
                        "sched": sched.state_dict(), "iter": it + 1}, args.checkpoint)
        if (it + 1) % args.eval_every == 0 and it + 1 < args.iters:
            text, _ = report(confusion(model, val_x, val_y), val_light)
            print(f"  val after {it + 1} steps\n{text}", flush=True)
    train_minutes = (time.time() - t_train) / 60

    text, scores = report(confusion(model, val_x, val_y), val_light)
    print(f"final val ({len(val_x)} views)\n{text}")
    export(model, args.out)
    if args.log:
        with open(args.log, "w") as f:
            json.dump({"args": vars(args), "train_views": len(train_x), "val_views": len(val_x),
                       "parameters": sum(p.numel() for p in model.parameters()),
                       "train_minutes": train_minutes, "val": scores}, f, indent=1)
    print(f"trained {args.iters - start} steps in {train_minutes:.1f} min")


if __name__ == "__main__":
    sys.exit(main())
