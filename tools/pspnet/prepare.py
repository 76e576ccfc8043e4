"""Fixes the human_seg split and precomputes the teachers' soft targets once.

Writes tools/pspnet/work/cache.npz with, for every training sample
(human_seg training photos + every 4th bonn_crowd_dev frame + frames of `pspslam synth`
sequences when given), the image stretched to the cache size, the ground-truth person
mask where there is one, and the teachers' ensemble log-probabilities (the mean of
their log-softmax outputs) at 1/4 of the cache size (float16). Synthetic frames get no
teacher targets (zeros): their rendered ground truth is exact, and the teachers do not
recognise the renderer's people (person IoU ~0.3), so train.py leaves them out of the
distillation term.
The default teachers are DeepLab v3 MobileNetV2 1.0 and ESPNetv2 s2.0 (the best person
model in ../shared, 0.881 IoU); the two take ~18 min for the 286 samples on the 2-core
machine, once: each sample's targets are kept in work/teacher_cache/ and reused.
"""

import argparse
import time
from pathlib import Path

import cv2
import numpy as np

import common


class OrtNet:
    """cv2.dnn-like wrapper over onnxruntime, for OpenCV builds that cannot read a teacher."""

    def __init__(self, path):
        import onnxruntime  # optional: only where cv2.dnn fails

        self.session = onnxruntime.InferenceSession(path, providers=["CPUExecutionProvider"])
        self.blob = None

    def setInput(self, blob):  # noqa: N802 (cv2.dnn's name)
        self.blob = blob

    def forward(self):
        name = self.session.get_inputs()[0].name
        return self.session.run(None, {name: self.blob})[0]


def teacher_nets(names):
    nets = []
    for name in names:
        spec = common.TEACHERS[name]
        path = str(common.SHARED / "models" / spec["onnx"])
        try:
            net = cv2.dnn.readNetFromONNX(path)
        except cv2.error:
            net = OrtNet(path)
        nets.append((name, spec, net))
    return nets


def teacher_log_probs(nets, bgr, out_w, out_h):
    """Mean of the teachers' log-softmax outputs, resized to out_w x out_h."""
    total = None
    for _, spec, net in nets:
        net.setInput(common.to_blob(bgr, spec["width"], spec["height"], spec["mean"],
                                    spec["std"]))
        logits = net.forward()[0]  # C x H x W
        hwc = cv2.resize(logits.transpose(1, 2, 0), (out_w, out_h),
                         interpolation=cv2.INTER_LINEAR)
        hwc = hwc - hwc.max(axis=2, keepdims=True)
        logp = hwc - np.log(np.exp(hwc).sum(axis=2, keepdims=True))
        total = logp if total is None else total + logp
    return (total / len(nets)).transpose(2, 0, 1)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seed", type=int, default=5, help="split seed")
    parser.add_argument("--width", type=int, default=512, help="cache image width")
    parser.add_argument("--height", type=int, default=384, help="cache image height")
    parser.add_argument("--bonn-step", type=int, default=4,
                        help="use every N-th bonn_crowd_dev frame")
    parser.add_argument("--synth-sequences", nargs="*", default=[],
                        help="`pspslam synth` sequence folders (colour + ground-truth masks)")
    parser.add_argument("--synth-step", type=int, default=12,
                        help="use every N-th frame of each synthetic sequence")
    parser.add_argument("--teachers", nargs="+",
                        default=["deeplabv3_mnv2_pascal", "espnetv2_s2.0_pascal_384x384"],
                        help="teacher names (see common.TEACHERS)")
    parser.add_argument("--threads", type=int, default=2, help="OpenCV threads")
    parser.add_argument("--out", default=str(common.WORK / "cache.npz"), help="output file")
    args = parser.parse_args()

    cv2.setNumThreads(args.threads)
    split = common.make_split(args.seed)
    nets = teacher_nets(args.teachers)
    samples = [("human_seg", i) for i in split["train"]]
    samples += [("bonn", p) for p in common.bonn_frames(args.bonn_step)]
    for sequence in args.synth_sequences:
        samples += [("synth", pair) for pair in common.synth_frames(sequence, args.synth_step)]

    w, h = args.width, args.height
    images = np.zeros((len(samples), h, w, 3), np.uint8)
    masks = np.zeros((len(samples), h, w), np.uint8)  # 255 person, 0 not, 254 = no GT
    soft = np.zeros((len(samples), 21, h // 4, w // 4), np.float16)
    kinds = []
    start = time.time()
    for k, (kind, ref) in enumerate(samples):
        if kind in ("human_seg", "synth"):
            bgr, gt = common.load_human_seg(ref) if kind == "human_seg" else \
                common.load_synth_frame(*ref)
            masks[k] = cv2.resize(gt.astype(np.uint8) * 255, (w, h),
                                  interpolation=cv2.INTER_NEAREST)
        else:
            bgr = cv2.imread(str(ref), cv2.IMREAD_COLOR)
            masks[k] = 254
        images[k] = cv2.resize(bgr, (w, h), interpolation=cv2.INTER_AREA)
        kinds.append(kind)
        if kind == "synth":
            continue  # no teacher targets (see above)
        # Teacher outputs are cached per sample so that an interrupted run resumes.
        key = f"{kind}_{Path(str(ref)).stem}_{'+'.join(args.teachers)}_{w}x{h}.npy"
        part = common.WORK / "teacher_cache" / key
        if part.exists():
            soft[k] = np.load(part)
        else:
            soft[k] = teacher_log_probs(nets, bgr, w // 4, h // 4).astype(np.float16)
            part.parent.mkdir(parents=True, exist_ok=True)
            np.save(part, soft[k])
        if k % 25 == 0:
            print(f"{k}/{len(samples)} {time.time() - start:.0f}s", flush=True)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    np.savez(args.out, images=images, masks=masks, soft=soft, kinds=np.array(kinds),
             teachers=np.array(args.teachers))
    print(f"wrote {args.out}: {len(samples)} samples ({kinds.count('human_seg')} human_seg, "
          f"{kinds.count('bonn')} bonn, {kinds.count('synth')} synth) in "
          f"{time.time() - start:.0f}s")


if __name__ == "__main__":
    main()
