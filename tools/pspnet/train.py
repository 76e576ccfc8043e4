"""Trains the compact PSPNet (CPU; a CUDA GPU when present): human_seg person masks +
teacher distillation.

Loss per pixel (ignoring padding):
  * cross-entropy on hard labels: on human_seg and synthetic frames, GT person -> class 15
    and GT background -> the teachers' arg-max among the non-person classes (background on
    synthetic frames, which have no teacher targets); on frames without ground truth (bonn)
    the teachers' arg-max (weight --pseudo-weight);
  * KL(teacher || student) at temperature T, times T^2 (weight --kd-weight), on the frames
    with teacher targets (not the synthetic ones);
  * optionally a soft-Jaccard person loss on the photos with GT (--iou-weight), since the
    target metric is person IoU against those masks.
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
from model import ARCHITECTURES, PSPNet, PERSON

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
    """Random scale (0.6-1.5 of the network input), crop (or placement with grey
    padding), horizontal flip and colour jitter, done as one affine resampling per sample
    on the training device; the same geometry is applied to the image, the person mask
    and the teachers' log-probabilities.  Padding is marked invalid (ignored by the loss)."""

    def __init__(self, cache, out_hw, device, generator, scale=(0.6, 1.5)):
        self.out_h, self.out_w = out_hw
        self.device = device
        self.gen = generator
        self.scale = scale
        images = torch.from_numpy(cache["images"]).permute(0, 3, 1, 2)  # N x 3 x H x W BGR
        # Pre-shrink (antialiased) to 1.5x the input so that bilinear sampling does not alias.
        if images.shape[-1] > 1.5 * self.out_w:
            size = (int(round(1.5 * self.out_h)), int(round(1.5 * self.out_w)))
            images = torch.cat([F.interpolate(images[i:i + 32].float(), size=size,
                                              mode="bilinear", align_corners=False,
                                              antialias=True).round().clamp(0, 255).byte()
                                for i in range(0, len(images), 32)])
        self.images = images.to(device)
        self.masks = torch.from_numpy(cache["masks"])[:, None].to(device)
        self.soft = torch.from_numpy(cache["soft"]).to(device)

    def rand(self, n, lo, hi):
        return lo + (hi - lo) * torch.rand(n, generator=self.gen)

    def batch(self, idx, mean, std):
        n = len(idx)
        s = self.rand(n, *self.scale)
        flip = torch.where(torch.rand(n, generator=self.gen) < 0.5, -1.0, 1.0)
        # Offset of the crop in the rescaled image (pixels), uniform over the valid range
        # (negative when the rescaled image is smaller than the input: grey padding).
        off = []
        for out in (self.out_w, self.out_h):
            extra = out * s - out
            off.append(torch.minimum(extra, torch.zeros(n)) + self.rand(n, 0, 1) * extra.abs())
        # Normalised output coordinate -> normalised source coordinate; a flip mirrors
        # the sampling around the crop's centre.
        theta = torch.zeros(n, 2, 3)
        theta[:, 0, 0] = flip / s
        theta[:, 0, 2] = (self.out_w + 2 * off[0]) / (self.out_w * s) - 1
        theta[:, 1, 1] = 1 / s
        theta[:, 1, 2] = (self.out_h + 2 * off[1]) / (self.out_h * s) - 1
        shape = (n, 1, self.out_h, self.out_w)
        grid = F.affine_grid(theta.to(self.device), shape, align_corners=False)
        idx_t = torch.as_tensor(idx, device=self.device)
        img = F.grid_sample(self.images[idx_t].float(), grid, mode="bilinear",
                            padding_mode="border", align_corners=False)
        valid = F.grid_sample(torch.ones(shape, device=self.device), grid, mode="nearest",
                              padding_mode="zeros", align_corners=False)[:, 0] > 0.5
        mask = F.grid_sample(self.masks[idx_t].float(), grid, mode="nearest",
                             padding_mode="border", align_corners=False)[:, 0].long()
        soft = F.grid_sample(self.soft[idx_t].float(), grid, mode="bilinear",
                             padding_mode="border", align_corners=False)
        rgb = self.jitter(img).flip(1)  # BGR -> RGB
        mean_t = torch.tensor(mean, device=self.device).view(1, 3, 1, 1)
        std_t = torch.tensor(std, device=self.device).view(1, 3, 1, 1)
        x = (rgb - mean_t) / std_t * valid[:, None]  # padding = the mean (grey)
        mask[~valid] = 254
        return x, mask, soft, valid

    def jitter(self, img):
        n = img.shape[0]
        view = (n, 1, 1, 1)
        contrast = self.rand(n, 0.7, 1.3).view(view).to(self.device)
        bright = self.rand(n, -25, 25).view(view).to(self.device)
        sat = self.rand(n, 0.6, 1.4).view(view).to(self.device)
        f = img * contrast + bright
        gray = f.mean(1, keepdim=True)
        return (gray + (f - gray) * sat).clamp(0, 255)


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


class Validator:
    """Person IoU over validation images (BGR, GT mask pairs) with the C++ path's
    preprocessing (stretch to the input with bilinear resize, arg-max, nearest-neighbour resize
    to the image)."""

    def __init__(self, images, hw, mean, std):
        self.hw = hw
        self.samples = [(torch.from_numpy(common.to_blob(bgr, hw[1], hw[0], mean, std)), gt)
                        for bgr, gt in images]

    def __call__(self, model, device):
        model.eval()
        ious = []
        with torch.no_grad():
            for blob, gt in self.samples:
                labels = model(blob.to(device))[0].argmax(0).byte().cpu().numpy()
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
    parser.add_argument("--arch", default="os16_decoder", choices=sorted(ARCHITECTURES),
                        help="architecture (model.ARCHITECTURES; MODEL_CARD.md compares them)")
    parser.add_argument("--last-dilation", type=int, default=2, choices=[1, 2, 4],
                        help="dilation of the 160/320 stages (model.stage_plan; with output "
                             "stride 8, 2 lets the export run every dilated stage undilated in "
                             "space-to-batch layout)")
    parser.add_argument("--branch-channels", type=int, default=32, help="PPM branch channels")
    parser.add_argument("--head-channels", type=int, default=64, help="3x3 head conv channels")
    parser.add_argument("--input-width", type=int, default=384, help="training/shipping width")
    parser.add_argument("--input-height", type=int, default=288, help="training/shipping height")
    parser.add_argument("--epochs", type=int, default=2, help="epochs (cosine schedule over them)")
    parser.add_argument("--batch", type=int, default=8, help="batch size")
    parser.add_argument("--lr", type=float, default=1e-3, help="head learning rate (AdamW)")
    parser.add_argument("--backbone-lr", type=float, default=3e-4, help="backbone learning rate")
    parser.add_argument("--temperature", type=float, default=2.0, help="distillation temperature")
    parser.add_argument("--kd-weight", type=float, default=1.0, help="distillation loss weight")
    parser.add_argument("--gt-weight", type=float, default=1.0,
                        help="CE weight of pixels with a ground-truth person mask")
    parser.add_argument("--iou-weight", type=float, default=0.0,
                        help="weight of a soft-Jaccard person loss on ground-truth photos")
    parser.add_argument("--pseudo-weight", type=float, default=0.5,
                        help="CE weight of teacher arg-max labels on frames without GT")
    parser.add_argument("--seed", type=int, default=5, help="random seed")
    parser.add_argument("--threads", type=int, default=2, help="torch CPU threads")
    parser.add_argument("--device", default="auto", help="auto (CUDA if present), cpu, cuda")
    parser.add_argument("--eval-every", type=int, default=1, help="validate every N epochs")
    parser.add_argument("--fit-minutes", type=float, default=0.0,
                        help="if > 0: after the first epoch, lower --epochs so that the run "
                             "takes about this long (the cosine schedule then spans them)")
    parser.add_argument("--max-minutes", type=float, default=45.0,
                        help="stop after the epoch that passes this wall time")
    parser.add_argument("--initial-eval", action="store_true",
                        help="also log the validation IoU before training")
    parser.add_argument("--resume", default="",
                        help="start from this checkpoint's weights (fine-tuning) instead of --init")
    parser.add_argument("--synth-val", nargs="*", default=[],
                        help="`pspslam synth` sequences never trained on: their person IoU is "
                             "logged beside the photos' (every --synth-val-step-th frame)")
    parser.add_argument("--synth-val-step", type=int, default=12)
    parser.add_argument("--out", default=str(common.WORK / "pspnet.pt"), help="checkpoint")
    parser.add_argument("--log", default=str(common.MODEL_DIR / "training_log.txt"),
                        help="per-epoch log file")
    args = parser.parse_args()

    if args.device == "auto":
        args.device = "cuda" if torch.cuda.is_available() else "cpu"
    device = torch.device(args.device)
    torch.set_num_threads(args.threads)
    cv2.setNumThreads(1)
    torch.manual_seed(args.seed)
    np.random.seed(args.seed)
    rng = random.Random(args.seed)
    gen = torch.Generator().manual_seed(args.seed)
    # CUDA has no deterministic kernel for some backward passes (bilinear upsampling):
    # there the run is seeded but not bit-reproducible.
    torch.use_deterministic_algorithms(True, warn_only=device.type == "cuda")
    if device.type == "cuda":
        torch.backends.cudnn.benchmark = False

    hw = (args.input_height, args.input_width)
    cache = dict(np.load(args.cache))
    kinds = list(cache["kinds"])
    split = common.load_split()
    model = PSPNet(hw, args.width_multiplier, branch_channels=args.branch_channels,
                   head_channels=args.head_channels, last_dilation=args.last_dilation,
                   **ARCHITECTURES[args.arch])
    if args.resume:
        model.load_state_dict(torch.load(args.resume)["model"])
        origin = f"all weights from {Path(args.resume).name} (fine-tuning)"
    else:
        origin = (f"backbone initialised from {Path(args.init).name} "
                  f"({load_backbone_from_onnx(model, args.init)} conv layers)")
    model.to(device)
    backbone, head = model.param_groups()
    opt = torch.optim.AdamW([{"params": backbone, "lr": args.backbone_lr},
                             {"params": head, "lr": args.lr}], weight_decay=1e-4)
    base_lrs = [args.backbone_lr, args.lr]
    aug = Augmenter(cache, hw, device, gen)
    # Synthetic frames have no teacher targets: no distillation term there.
    has_teacher = torch.tensor([kind != "synth" for kind in kinds], device=device)
    validate = Validator([common.load_human_seg(i) for i in split["val"]], hw, common.MEAN,
                         common.STD)
    synth_val = [common.load_synth_frame(*pair) for sequence in args.synth_val
                 for pair in common.synth_frames(sequence, args.synth_val_step)]
    validate_synth = Validator(synth_val, hw, common.MEAN, common.STD) if synth_val else None
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

    say(f"# pspnet training started {time.strftime('%Y-%m-%d %H:%M:%S UTC', time.gmtime())} "
        f"on {device.type}"
        + (f" ({torch.cuda.get_device_name(device)})" if device.type == "cuda" else "")
        + f", torch {torch.__version__}")
    say(f"# args {json.dumps(vars(args))}")
    say(f"# data: {kinds.count('human_seg')} human_seg train photos (split seed "
        f"{split['seed']}, {len(split['val'])} validation photos never trained on), "
        f"{kinds.count('bonn')} bonn_crowd_dev frames, {kinds.count('synth')} synthetic frames; "
        f"teachers {list(cache['teachers'])}")
    say(f"# {origin}; params {sum(p.numel() for p in model.parameters())}")

    def validation():
        """The photos' person IoU, and the log text with the rendered frames' beside it."""
        photos = validate(model, device)
        text = f" val_person_iou {photos:.4f}"
        if validate_synth:
            text += f" val_synth_person_iou {validate_synth(model, device):.4f}"
        return photos, text

    if args.initial_eval:
        say(f"epoch 0{validation()[1]}")
    start = time.time()
    step = 0
    T = args.temperature
    best, iou = -1.0, float("nan")
    for epoch in range(1, args.epochs + 1):
        order = list(range(n))
        rng.shuffle(order)
        sums = {"loss": 0.0, "ce": 0.0, "kd": 0.0, "iou": 0.0}
        epoch_start = time.time()
        model.train()
        for b in range(steps_per_epoch):
            idx = order[b * args.batch:(b + 1) * args.batch]
            x, mask, soft, valid = aug.batch(idx, common.MEAN, common.STD)
            labels, has_gt = hard_labels(mask, soft, valid)
            factor = (step + 1) / warmup if step < warmup else 0.5 * (
                1 + math.cos(math.pi * (step - warmup) / max(1, total_steps - warmup)))
            for group, lr in zip(opt.param_groups, base_lrs):
                group["lr"] = lr * factor
            logits = model(x)
            ce_map = F.cross_entropy(logits, labels, ignore_index=IGNORE, reduction="none")
            weight = torch.where(has_gt, args.gt_weight, args.pseudo_weight) * valid
            ce = (ce_map * weight).sum() / weight.sum().clamp(min=1)
            log_p = F.log_softmax(logits / T, 1)
            q = F.softmax(soft / T, 1)
            kd_map = (q * (torch.log(q.clamp(min=1e-8)) - log_p)).sum(1)
            kd_valid = valid & has_teacher[torch.as_tensor(idx, device=device)][:, None, None]
            kd = (kd_map * kd_valid).sum() / kd_valid.sum().clamp(min=1) * T * T
            loss = ce + args.kd_weight * kd
            soft_iou_loss = torch.zeros((), device=device)
            gt_photo = (has_gt & valid).flatten(1).any(1)
            if args.iou_weight > 0 and gt_photo.any():
                # Soft Jaccard of the person probability against the GT mask, per photo.
                p = F.softmax(logits, 1)[:, PERSON] * valid
                g = ((mask == 255) & valid).float()
                inter = (p * g).flatten(1).sum(1)
                union = (p + g - p * g).flatten(1).sum(1).clamp(min=1)
                soft_iou_loss = (1 - inter / union)[gt_photo].mean()
                loss = loss + args.iou_weight * soft_iou_loss
            opt.zero_grad()
            loss.backward()
            opt.step()
            step += 1
            sums["loss"] += loss.item()
            sums["ce"] += ce.item()
            sums["kd"] += kd.item()
            sums["iou"] += soft_iou_loss.item()
        m = {k: v / steps_per_epoch for k, v in sums.items()}
        if epoch == 1 and args.fit_minutes > 0:
            fit = max(2, int(args.fit_minutes * 60 / (time.time() - epoch_start)))
            if fit < args.epochs:
                args.epochs = fit
                total_steps = steps_per_epoch * args.epochs
                say(f"# --fit-minutes {args.fit_minutes}: training {args.epochs} epochs")
        last = epoch == args.epochs or (time.time() - start) / 60 > args.max_minutes
        text = ""
        if epoch % args.eval_every == 0 or last:
            iou, text = validation()
            best = max(best, iou)
        say(f"epoch {epoch} loss {m['loss']:.4f} ce {m['ce']:.4f} kd {m['kd']:.4f} "
            f"soft_iou_loss {m['iou']:.4f}{text} epoch_s {time.time() - epoch_start:.1f} "
            f"total_s {time.time() - start:.0f}")
        if last:
            if epoch < args.epochs:
                say(f"# stopped after epoch {epoch}: time limit {args.max_minutes} min reached")
            break
    state = {"model": {k: v.cpu() for k, v in model.state_dict().items()}, "epoch": epoch,
             "val_iou": iou, "width_multiplier": args.width_multiplier,
             "branch_channels": args.branch_channels, "head_channels": args.head_channels,
             "last_dilation": args.last_dilation, "arch": args.arch, "input_hw": hw, "args": vars(args)}
    torch.save(state, args.out)  # the last epoch is the shipped one
    say(f"# finished {time.strftime('%Y-%m-%d %H:%M:%S UTC', time.gmtime())}; shipped the last "
        f"epoch (val IoU {iou:.4f}); best validated epoch IoU {best:.4f} (not used for "
        f"selection)")
    log.close()


if __name__ == "__main__":
    main()
