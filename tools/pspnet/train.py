"""Trains the compact PSPNet on CPU: human_seg person masks + teacher distillation.

Loss per pixel (ignoring padding):
  * cross-entropy on hard labels: on human_seg, GT person -> class 15 and GT
    background -> the teachers' arg-max among the non-person classes; on frames
    without ground truth (bonn, synthetic) the teachers' arg-max (weight --pseudo-weight);
  * KL(teacher || student) at temperature T, times T^2 (weight --kd-weight).
Validation person IoU (mean over the fixed validation split, at photo
resolution, same preprocessing as the C++ path) is logged every epoch.
"""

import argparse
import json
import math
import random
import time
from pathlib import Path

import cv2
import numpy as np
import onnx
import torch
import torch.nn.functional as F
from onnx import numpy_helper

import common
from model import PSPNet, PERSON

IGNORE = 255


def load_backbone_from_onnx(model, onnx_path):
    """Copies the (batch-norm folded) conv weights+biases of a DeepLab v3 MobileNetV2
    ONNX into our backbone, in graph order; returns the number of layers copied."""
    graph = onnx.load(str(onnx_path)).graph
    inits = {i.name: numpy_helper.to_array(i) for i in graph.initializer}
    onnx_convs = [n for n in graph.node if n.op_type == "Conv"]
    ours = model.backbone.convs()
    for conv, node in zip(ours, onnx_convs):
        w, b = inits[node.input[1]], inits[node.input[2]]
        if tuple(conv.weight.shape) != w.shape:
            raise ValueError(f"shape mismatch {tuple(conv.weight.shape)} vs {w.shape}")
        conv.weight.data.copy_(torch.from_numpy(w.copy()))
        conv.bias.data.copy_(torch.from_numpy(b.copy()))
    return len(ours)


class Augmenter:
    """Random scale, crop, flip and colour jitter applied identically to image,
    mask and teacher log-probabilities."""

    def __init__(self, cache, out_hw, rng, scale=(0.6, 1.5)):
        self.images, self.masks, self.soft = cache["images"], cache["masks"], cache["soft"]
        self.out_h, self.out_w = out_hw
        self.rng = rng
        self.scale = scale

    def sample(self, k):
        rng = self.rng
        s = rng.uniform(*self.scale)
        w, h = int(round(self.out_w * s)), int(round(self.out_h * s))
        img = cv2.resize(self.images[k], (w, h), interpolation=cv2.INTER_LINEAR)
        mask = cv2.resize(self.masks[k], (w, h), interpolation=cv2.INTER_NEAREST)
        soft = cv2.resize(self.soft[k].astype(np.float32).transpose(1, 2, 0), (w, h),
                          interpolation=cv2.INTER_LINEAR)
        valid = np.ones((h, w), np.uint8)
        # Pad to at least the crop size.
        ph, pw = max(0, self.out_h - h), max(0, self.out_w - w)
        if ph or pw:
            img = cv2.copyMakeBorder(img, 0, ph, 0, pw, cv2.BORDER_CONSTANT, value=(128,) * 3)
            mask = cv2.copyMakeBorder(mask, 0, ph, 0, pw, cv2.BORDER_CONSTANT, value=254)
            soft = np.pad(soft, ((0, ph), (0, pw), (0, 0)))
            valid = cv2.copyMakeBorder(valid, 0, ph, 0, pw, cv2.BORDER_CONSTANT, value=0)
        y = rng.randint(0, img.shape[0] - self.out_h)
        x = rng.randint(0, img.shape[1] - self.out_w)
        sl = (slice(y, y + self.out_h), slice(x, x + self.out_w))
        img, mask, soft, valid = img[sl], mask[sl], soft[sl], valid[sl]
        if rng.random() < 0.5:
            img, mask, soft, valid = img[:, ::-1], mask[:, ::-1], soft[:, ::-1], valid[:, ::-1]
        img = self.jitter(img)
        return (np.ascontiguousarray(img), np.ascontiguousarray(mask),
                np.ascontiguousarray(soft.transpose(2, 0, 1)), np.ascontiguousarray(valid))

    def jitter(self, img):
        rng = self.rng
        f = img.astype(np.float32)
        f = f * rng.uniform(0.7, 1.3) + rng.uniform(-25, 25)  # contrast, brightness
        gray = f.mean(axis=2, keepdims=True)
        f = gray + (f - gray) * rng.uniform(0.6, 1.4)  # saturation
        return np.clip(f, 0, 255).astype(np.uint8)


def batch_tensors(samples, mean, std):
    imgs = np.stack([s[0] for s in samples])[:, :, :, ::-1].astype(np.float32)
    imgs = (imgs - np.float32(mean)) / np.float32(std)
    x = torch.from_numpy(np.ascontiguousarray(imgs.transpose(0, 3, 1, 2)))
    mask = torch.from_numpy(np.stack([s[1] for s in samples]).astype(np.int64))
    soft = torch.from_numpy(np.stack([s[2] for s in samples]))
    valid = torch.from_numpy(np.stack([s[3] for s in samples]).astype(bool))
    return x, mask, soft, valid


def hard_labels(mask, soft, valid):
    """GT person -> 15; GT background -> best non-person teacher class; no GT -> teacher arg-max."""
    non_person = soft.clone()
    non_person[:, PERSON] = -1e4
    labels = soft.argmax(1)
    has_gt = mask != 254
    labels = torch.where(has_gt & (mask == 255), torch.full_like(labels, PERSON), labels)
    labels = torch.where(has_gt & (mask == 0), non_person.argmax(1), labels)
    labels[~valid] = IGNORE
    return labels, has_gt


def evaluate(model, ids, hw, mean, std):
    model.eval()
    ious = []
    with torch.no_grad():
        for sample_id in ids:
            bgr, gt = common.load_human_seg(sample_id)
            x = torch.from_numpy(common.to_blob(bgr, hw[1], hw[0], mean, std))
            labels = model(x)[0].argmax(0).numpy().astype(np.uint8)
            labels = cv2.resize(labels, (gt.shape[1], gt.shape[0]),
                                interpolation=cv2.INTER_NEAREST)
            ious.append(common.person_iou(labels, gt))
    model.train()
    return float(np.mean(ious))


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cache", default=str(common.WORK / "cache.npz"), help="prepare.py output")
    parser.add_argument("--init", default=str(common.SHARED / "models" /
                                              "deeplabv3_mnv2_dm05_pascal.onnx"),
                        help="DeepLab v3 MobileNetV2 ONNX to initialise the backbone from")
    parser.add_argument("--width-multiplier", default="0.5", choices=["0.5", "1.0"],
                        help="MobileNetV2 width (must match --init)")
    parser.add_argument("--input-width", type=int, default=384, help="training/shipping width")
    parser.add_argument("--input-height", type=int, default=288, help="training/shipping height")
    parser.add_argument("--epochs", type=int, default=2, help="epochs")
    parser.add_argument("--batch", type=int, default=8, help="batch size")
    parser.add_argument("--lr", type=float, default=1e-3, help="head learning rate (AdamW)")
    parser.add_argument("--backbone-lr", type=float, default=3e-4, help="backbone learning rate")
    parser.add_argument("--temperature", type=float, default=2.0, help="distillation temperature")
    parser.add_argument("--kd-weight", type=float, default=1.0, help="distillation loss weight")
    parser.add_argument("--pseudo-weight", type=float, default=0.5,
                        help="CE weight of teacher arg-max labels on frames without GT")
    parser.add_argument("--seed", type=int, default=5, help="random seed")
    parser.add_argument("--threads", type=int, default=2, help="torch CPU threads")
    parser.add_argument("--max-minutes", type=float, default=45.0,
                        help="stop after the epoch that passes this wall time")
    parser.add_argument("--initial-eval", action="store_true",
                        help="also log the validation IoU before training (0.1632 for the "
                             "default setting: random head)")
    parser.add_argument("--out", default=str(common.WORK / "pspnet.pt"), help="checkpoint")
    parser.add_argument("--log", default=str(common.MODEL_DIR / "training_log.txt"),
                        help="per-epoch log file")
    args = parser.parse_args()

    torch.set_num_threads(args.threads)
    cv2.setNumThreads(1)
    torch.manual_seed(args.seed)
    np.random.seed(args.seed)
    rng = random.Random(args.seed)
    torch.use_deterministic_algorithms(True)

    hw = (args.input_height, args.input_width)
    cache = dict(np.load(args.cache))
    kinds = list(cache["kinds"])
    split = common.load_split()
    model = PSPNet(hw, args.width_multiplier, branch_channels=32, head_channels=64)
    n_init = load_backbone_from_onnx(model, args.init)
    backbone, head = model.param_groups()
    opt = torch.optim.AdamW([{"params": backbone, "lr": args.backbone_lr},
                             {"params": head, "lr": args.lr}], weight_decay=1e-4)
    base_lrs = [args.backbone_lr, args.lr]
    aug = Augmenter(cache, hw, rng)
    n = len(kinds)
    steps_per_epoch = n // args.batch
    total_steps = steps_per_epoch * args.epochs
    warmup = min(30, total_steps // 10)

    log_path = Path(args.log)
    log_path.parent.mkdir(parents=True, exist_ok=True)
    log = open(log_path, "w")

    def say(text):
        print(text, flush=True)
        log.write(text + "\n")
        log.flush()

    say(f"# pspnet training started {time.strftime('%Y-%m-%d %H:%M:%S UTC', time.gmtime())}")
    say(f"# args {json.dumps(vars(args))}")
    say(f"# data: {kinds.count('human_seg')} human_seg train photos (split seed "
        f"{split['seed']}, {len(split['val'])} validation photos never trained on), "
        f"{kinds.count('bonn')} bonn_crowd_dev frames, {kinds.count('synth')} synthetic frames; "
        f"teachers {list(cache['teachers'])}")
    say(f"# backbone initialised from {Path(args.init).name} ({n_init} conv layers); "
        f"params {sum(p.numel() for p in model.parameters())}")
    if args.initial_eval:
        iou0 = evaluate(model, split["val"], hw, common.MEAN, common.STD)
        say(f"epoch 0 val_person_iou {iou0:.4f}")
    start = time.time()
    step = 0
    T = args.temperature
    best = -1.0
    for epoch in range(1, args.epochs + 1):
        order = list(range(n))
        rng.shuffle(order)
        sums = {"loss": 0.0, "ce": 0.0, "kd": 0.0}
        epoch_start = time.time()
        model.train()
        for b in range(steps_per_epoch):
            idx = order[b * args.batch:(b + 1) * args.batch]
            x, mask, soft, valid = batch_tensors([aug.sample(k) for k in idx], common.MEAN,
                                                 common.STD)
            labels, has_gt = hard_labels(mask, soft, valid)
            factor = (step + 1) / warmup if step < warmup else 0.5 * (
                1 + math.cos(math.pi * (step - warmup) / max(1, total_steps - warmup)))
            for group, lr in zip(opt.param_groups, base_lrs):
                group["lr"] = lr * factor
            logits = model(x)
            ce_map = F.cross_entropy(logits, labels, ignore_index=IGNORE, reduction="none")
            weight = torch.where(has_gt, 1.0, args.pseudo_weight) * valid
            ce = (ce_map * weight).sum() / weight.sum().clamp(min=1)
            log_p = F.log_softmax(logits / T, 1)
            q = F.softmax(soft / T, 1)
            kd_map = (q * (torch.log(q.clamp(min=1e-8)) - log_p)).sum(1)
            kd = (kd_map * valid).sum() / valid.sum().clamp(min=1) * T * T
            loss = ce + args.kd_weight * kd
            opt.zero_grad()
            loss.backward()
            opt.step()
            step += 1
            sums["loss"] += loss.item()
            sums["ce"] += ce.item()
            sums["kd"] += kd.item()
            if b % 5 == 4:
                print(f"  epoch {epoch} step {b + 1}/{steps_per_epoch} loss {loss.item():.3f} "
                      f"{time.time() - epoch_start:.0f}s", flush=True)
        iou = evaluate(model, split["val"], hw, common.MEAN, common.STD)
        m = {k: v / steps_per_epoch for k, v in sums.items()}
        say(f"epoch {epoch} loss {m['loss']:.4f} ce {m['ce']:.4f} kd {m['kd']:.4f} "
            f"val_person_iou {iou:.4f} epoch_s {time.time() - epoch_start:.0f} "
            f"total_s {time.time() - start:.0f}")
        state = {"model": model.state_dict(), "epoch": epoch, "val_iou": iou,
                 "width_multiplier": args.width_multiplier, "branch_channels": 32,
                 "head_channels": 64, "input_hw": hw, "args": vars(args)}
        torch.save(state, args.out)  # the last epoch is the shipped one
        best = max(best, iou)
        if (time.time() - start) / 60 > args.max_minutes and epoch < args.epochs:
            say(f"# stopped after epoch {epoch}: time limit {args.max_minutes} min reached")
            break
    say(f"# finished {time.strftime('%Y-%m-%d %H:%M:%S UTC', time.gmtime())}; shipped the last "
        f"epoch (val IoU {iou:.4f}); best epoch val IoU {best:.4f} (not used for selection)")
    log.close()


if __name__ == "__main__":
    main()
