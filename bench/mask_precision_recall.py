#!/usr/bin/env python3
"""Score a run's dynamic masks against a synthetic sequence's ground-truth people.

usage: bench/mask_precision_recall.py SEQUENCE MASK_DIR [--stretch N] [--masked-only]

SEQUENCE is a `pspslam synth` folder (its mask.txt lists the rendered label images: 0 static,
non-zero a person or a carried object); MASK_DIR is what `pspslam run --save-masks MASK_DIR`
wrote for it (255 = dynamic, one PNG per processed frame, named after the colour image).
Prints pixel precision and recall pooled over the frames, the static pixels masked per frame
(averaged over every scored frame, with or without people in view) and, with --stretch N, the
same per N frames. Frames without a saved mask (not processed) are counted and skipped.
--masked-only needs no ground truth (a recording: SEQUENCE/rgb.txt names the frames) and prints
only the pixels masked per frame, e.g. where nobody is in view.
"""
import argparse
import os
import sys

import cv2
import numpy as np


def read_list(path):
    rows = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.split()
            if len(parts) != 2:
                sys.exit(f"{path}:{number}: expected 'timestamp filename', got {line!r}")
            rows.append(parts[1])
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequence")
    parser.add_argument("mask_dir")
    parser.add_argument("--stretch", type=int, default=0, help="also report per N frames")
    parser.add_argument("--masked-only", action="store_true",
                        help="no ground truth: masked pixels per frame, from rgb.txt's frames")
    args = parser.parse_args()
    listing = os.path.join(args.sequence, "rgb.txt" if args.masked_only else "mask.txt")
    if not os.path.isfile(listing):
        sys.exit(f"{listing}: not found" +
                 ("" if args.masked_only else " (a `pspslam synth` sequence has one)"))
    if not os.path.isdir(args.mask_dir):
        sys.exit(f"{args.mask_dir}: not a folder")
    scored = []  # (true positives, false positives, false negatives) per scored frame
    missing = 0
    for name in read_list(listing):
        # Named as --save-masks names them: the colour image's stem, .png.
        saved = os.path.join(args.mask_dir, os.path.splitext(os.path.basename(name))[0] + ".png")
        if not os.path.isfile(saved):
            missing += 1
            continue
        mask = cv2.imread(saved, cv2.IMREAD_GRAYSCALE)
        if args.masked_only:
            if mask is None:
                sys.exit(f"{saved}: unreadable")
            scored.append((0, int((mask > 0).sum()), 0))
            continue
        truth = cv2.imread(os.path.join(args.sequence, name), cv2.IMREAD_GRAYSCALE)
        if truth is None or mask is None or truth.shape != mask.shape:
            sys.exit(f"{saved}: unreadable or not the size of {name}")
        truth, mask = truth > 0, mask > 0
        scored.append((int((truth & mask).sum()), int((mask & ~truth).sum()),
                       int((truth & ~mask).sum())))
    if not scored:
        sys.exit(f"{args.mask_dir}: no mask named after an image of {listing}")

    def line(rows, label):
        tp, fp, fn = (sum(r[i] for r in rows) for i in range(3))
        if args.masked_only:
            return (f"{label}: pixels masked per frame {fp / len(rows):.0f}, "
                    f"frames with any {sum(r[1] > 0 for r in rows)}")
        precision = f"{tp / (tp + fp):.3f}" if tp + fp else "—"
        recall = f"{tp / (tp + fn):.3f}" if tp + fn else "—"
        return (f"{label}: precision {precision}, recall {recall}, "
                f"static pixels masked per frame {fp / len(rows):.0f}, "
                f"person pixels per frame {(tp + fn) / len(rows):.0f}")

    print(line(scored, f"{len(scored)} frames"))
    if missing:
        print(f"{missing} frames of {listing} have no saved mask (not processed)")
    if args.stretch > 0:
        for start in range(0, len(scored), args.stretch):
            rows = scored[start:start + args.stretch]
            print(line(rows, f"  frames {start}-{start + len(rows) - 1}"))


if __name__ == "__main__":
    main()
