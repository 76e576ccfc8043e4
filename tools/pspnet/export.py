"""Exports the trained PSPNet to ONNX (opset 10) for OpenCV 4.6 DNN and checks it.

* fixed input size (the pyramid pooling bins become fixed-kernel average pooling);
* Identity nodes on initialisers replaced by initialiser copies (OpenCV 4.6 rejects them);
* Pad nodes with all-zero pads removed (each costs OpenCV a copy);
* loads the file with cv2.dnn and fails (exit 1) when any logit differs from PyTorch by
  more than --tolerance on the golden input and on validation photos;
* writes the metadata YAML read by the C++ OnnxSegmenter and, with --golden, a small
  golden input/output pair for the C++ test; writes the teachers' metadata YAMLs.
"""

import argparse
import sys
from pathlib import Path

import cv2
import numpy as np
import onnx
import torch

import common
from model import ARCHITECTURES, PSPNet
from onnx_fix import remove_zero_pads, replace_identity_on_initializers


def golden_image(width, height, seed=7):
    """A deterministic synthetic test picture (no dataset pixels are shipped)."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float32)
    img = np.stack([80 + 100 * xx / width, 60 + 120 * yy / height,
                    150 - 80 * xx / width], axis=2)
    for _ in range(12):
        cx, cy = rng.integers(0, width), rng.integers(0, height)
        ax, ay = rng.integers(10, width // 4), rng.integers(10, height // 3)
        colour = [int(v) for v in rng.integers(0, 256, 3)]
        cv2.ellipse(img, (int(cx), int(cy)), (int(ax), int(ay)), float(rng.integers(0, 180)),
                    0, 360, colour, -1)
    img += rng.normal(0, 6, img.shape).astype(np.float32)
    return np.clip(img, 0, 255).astype(np.uint8)


def metadata_yaml(name, onnx_ref, width, height, mean, std, comment):
    classes = ", ".join(common.VOC_CLASSES)
    dynamic = ", ".join(common.DYNAMIC_CLASSES)
    return (f"# {comment}\n"
            f"name: {name}\n"
            f"onnx: {onnx_ref}\n"
            f"input:\n"
            f"  width: {width}\n"
            f"  height: {height}\n"
            f"  channel_order: RGB\n"
            f"  layout: NCHW\n"
            f"  mean: [{', '.join(f'{v:g}' for v in mean)}]  # pixel units: (p - mean) / std\n"
            f"  std: [{', '.join(f'{v:g}' for v in std)}]\n"
            f"output:\n"
            f"  stride: 1  # logits 1 x 21 x height x width (bilinear upsampling in the graph)\n"
            f"classes: [{classes}]\n"
            f"# person + VOC animals + vehicles\n"
            f"dynamic_classes: [{dynamic}]\n")


def write_teacher_yamls():
    out = common.REPO / "models" / "teachers"
    out.mkdir(parents=True, exist_ok=True)
    for name, spec in common.TEACHERS.items():
        text = metadata_yaml(name, "${shared}/models/" + spec["onnx"], spec["width"],
                             spec["height"], spec["mean"], spec["std"],
                             "Teacher network from the read-only shared folder (not committed); "
                             "see ../shared/README.md for its origin and licence.")
        (out / f"{name}.yaml").write_text(text)


def reference(model, blob):
    """PyTorch logits of the model as trained (plain dilated convolutions)."""
    phase = model.backbone.phase_layout
    model.backbone.phase_layout = False
    with torch.no_grad():
        out = model(torch.from_numpy(blob)).numpy()
    model.backbone.phase_layout = phase
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--checkpoint", default=str(common.WORK / "pspnet.pt"),
                        help="train.py output")
    parser.add_argument("--width", type=int, default=384, help="input width")
    parser.add_argument("--height", type=int, default=288, help="input height")
    parser.add_argument("--yaml", default="pspnet.yaml",
                        help="metadata file name written into models/pspnet/")
    parser.add_argument("--golden", action="store_true",
                        help="write models/pspnet/golden/ (input.png, labels.png, logits.txt)")
    parser.add_argument("--out-dir", default=str(common.MODEL_DIR),
                        help="where the ONNX, metadata and golden files go")
    parser.add_argument("--tolerance", type=float, default=1e-3,
                        help="max abs logit difference OpenCV vs PyTorch")
    args = parser.parse_args()

    torch.set_num_threads(2)
    cv2.setNumThreads(2)
    state = torch.load(args.checkpoint, map_location="cpu")
    hw = (args.height, args.width)
    arch = ARCHITECTURES[state["arch"]]
    model = PSPNet(hw, state["width_multiplier"], state["branch_channels"],
                   state["head_channels"], last_dilation=state["last_dilation"], **arch)
    model.load_state_dict(state["model"])
    model.eval()
    # Same function, faster graph for OpenCV 4.6 where the phase rows are wide enough.
    stride = arch["output_stride"]
    model.backbone.phase_layout = model.backbone.phase_layout_pays(
        (args.height // stride, args.width // stride))
    print(f"space-to-batch layout for the dilated stages: {model.backbone.phase_layout}")

    out_dir = Path(args.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    onnx_name = f"pspnet_{args.width}x{args.height}.onnx"
    onnx_path = out_dir / onnx_name
    dummy = torch.zeros(1, 3, args.height, args.width)
    torch.onnx.export(model, dummy, str(onnx_path), opset_version=10, input_names=["input"],
                      output_names=["logits"], do_constant_folding=True)
    graph = onnx.load(str(onnx_path))
    replaced = replace_identity_on_initializers(graph)
    pads = remove_zero_pads(graph)
    onnx.checker.check_model(graph)
    onnx.save(graph, str(onnx_path))
    size_mb = onnx_path.stat().st_size / 2**20
    print(f"wrote {onnx_path} ({size_mb:.2f} MiB, {replaced} Identity nodes replaced, "
          f"{pads} zero Pad nodes removed)")

    net = cv2.dnn.readNetFromONNX(str(onnx_path))
    inputs = [("golden", golden_image(args.width, args.height))]
    for sample_id in common.load_split()["val"][:3]:
        inputs.append((f"val {sample_id}", common.load_human_seg(sample_id)[0]))
    worst = 0.0
    for label, bgr in inputs:
        blob = common.to_blob(bgr, args.width, args.height)
        ref = reference(model, blob)
        net.setInput(blob)
        out = net.forward()
        diff = float(np.abs(out - ref).max())
        worst = max(worst, diff)
        print(f"  {label}: max |OpenCV - PyTorch| = {diff:.2e}")
    if worst > args.tolerance:
        print(f"FAILED: OpenCV output differs from PyTorch by {worst:.2e} > {args.tolerance}")
        sys.exit(1)

    yaml_text = metadata_yaml(
        f"pspnet_mnv2_{state['width_multiplier']}", onnx_name, args.width, args.height,
        common.MEAN, common.STD,
        "Our compact PSPNet (tools/pspnet); see MODEL_CARD.md. Read by pspslam::OnnxSegmenter.")
    (out_dir / args.yaml).write_text(yaml_text)
    print(f"wrote {out_dir / args.yaml}")

    if args.golden:
        golden = out_dir / "golden"
        golden.mkdir(exist_ok=True)
        image = inputs[0][1]
        cv2.imwrite(str(golden / "input.png"), image)
        # Re-read: the test feeds the PNG, so the logits must be of the decoded pixels.
        image = cv2.imread(str(golden / "input.png"))
        # The reference is PyTorch's output, not OpenCV's.
        logits = reference(model, common.to_blob(image, args.width, args.height))[0]
        cv2.imwrite(str(golden / "labels.png"), logits.argmax(0).astype(np.uint8))
        rng = np.random.default_rng(3)
        lines = []
        for _ in range(12):
            y, x = int(rng.integers(0, args.height)), int(rng.integers(0, args.width))
            for c in range(logits.shape[0]):
                lines.append(f"{c} {y} {x} {logits[c, y, x]:.6f}")
        (golden / "logits.txt").write_text("\n".join(lines) + "\n")
        print(f"wrote golden pair into {golden}")
    write_teacher_yamls()


if __name__ == "__main__":
    main()
