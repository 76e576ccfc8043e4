#!/usr/bin/env python3
"""Collects the runs of bench/run_modes.sh (standard library only).

Reads WORK/runs/<sequence>/<mode>/run<k>/{stats.json,eval.json} and writes
  RESULTS/modes.json   every run and the per sequence x mode summary (machine-readable)
  RESULTS/modes.csv    one row per run
  RESULTS/modes.md     the section for docs/benchmarks.md
  DOCS/modes_ate_bars.{svg,png}: ATE statistics (the PNG rendered from the SVG by rsvg-convert,
      librsvg2-bin; without it the PNG has the bars only). --bars-from-results redraws just these
      two from RESULTS/modes.json.
  DOCS/modes_trajectories/<sequence>_<mode>.png: run 1's trajectory_refined.txt against ground truth (`pspslam eval --plot`)
Only measured values are written; a sequence x mode without runs is listed as missing.
"""
import argparse
import json
import math
import shutil
import struct
import zlib
import statistics
import subprocess
import sys
from pathlib import Path

MODES = ["off", "semantic", "geometry", "full", "exhaustive"]
COLOURS = {"off": "#888888", "semantic": "#1f77b4", "geometry": "#2ca02c", "full": "#d62728",
           "exhaustive": "#9467bd"}


def load(path):
    try:
        return json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None


def summary(values):
    values = [v for v in values if v is not None]
    if not values:
        return None
    return {"median": statistics.median(values), "mean": statistics.fmean(values),
            "min": min(values), "max": max(values), "runs": len(values)}


def collect(work):
    runs = []
    for stats_file in sorted(Path(work, "runs").glob("*/*/run*/stats.json")):
        run_dir = stats_file.parent
        stats = load(stats_file)
        if stats is None:
            continue
        ev = load(run_dir / "eval.json") or {}
        timing = stats.get("timing_ms", {})
        runs.append({
            "sequence": run_dir.parent.parent.name, "mode": run_dir.parent.name,
            "run": run_dir.name, "frames": stats.get("frames"),
            "lost_frames": stats.get("lost_frames"), "fps": stats.get("fps"),
            "interrupted": stats.get("interrupted"),
            "ate_rmse": (stats.get("ate") or {}).get("rmse"),
            "ate_refined_rmse": (stats.get("ate_refined") or {}).get("rmse"),
            "rpe_trans_rmse_m": ev.get("rpe", {}).get("translation_m", {}).get("rmse"),
            "rpe_rot_rmse_deg": ev.get("rpe", {}).get("rotation_deg", {}).get("rmse"),
            # pspslam eval: the ground truth tracks another body than the camera -> RPE meaningless
            "rpe_body_frames_differ": ev.get("rpe", {}).get("body_frames_differ", False),
            "rpe_body_frame_rotation_deg": ev.get("rpe", {}).get("body_frame_rotation_deg"),
            "timing_median_ms": {k: v.get("median") for k, v in timing.items() if v.get("count")},
            "dynamic": stats.get("dynamic"), "mask_latency": stats.get("mask_latency"),
            "dir": str(run_dir)})
    return runs


def write_png(path, width, height, rects):
    """Minimal RGB PNG (no imaging library on the machine): white canvas + filled rectangles
    (x0, y0, x1, y1, "#rrggbb"). Text is only in the SVG twin."""
    pixels = [bytearray(b"\xff" * (3 * width)) for _ in range(height)]
    for x0, y0, x1, y1, colour in rects:
        rgb = bytes.fromhex(colour[1:])
        for y in range(max(0, int(y0)), min(height, int(y1))):
            row = pixels[y]
            for x in range(max(0, int(x0)), min(width, int(x1))):
                row[3 * x:3 * x + 3] = rgb
    raw = b"".join(b"\x00" + bytes(row) for row in pixels)

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    Path(path).write_bytes(b"\x89PNG\r\n\x1a\n" +
                           chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
                           chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def fmt(value, digits=4):
    return "-" if value is None else f"{value:.{digits}f}"


def rasterise(svg_file, png_file, width, height, rects):
    """PNG twin of a labelled SVG: rendered by librsvg's rsvg-convert (text included) when it is
    installed (Debian: librsvg2-bin); otherwise the bars alone, drawn here, with a warning."""
    tool = shutil.which("rsvg-convert")
    if tool and subprocess.run([tool, "--background-color", "white", "-w", str(width), "-h",
                                str(height), "-o", str(png_file), str(svg_file)],
                               capture_output=True).returncode == 0:
        return True
    print(f"warning: rsvg-convert not found (apt-get install librsvg2-bin): {png_file} has the "
          "bars but no text; the SVG is labelled", file=sys.stderr)
    write_png(png_file, width, height, rects)
    return False


def draw_ate_bars(table, sequences, docs):
    """DOCS/modes_ate_bars.svg and .png: the final trajectory's ATE RMSE per sequence and mode
    (bar = median over runs, whisker = min..max, value in mm above each bar)."""
    width, height, left, bottom, top = 900, 440, 80, 80, 50
    best = 1.1 * max([((row["ate_refined_rmse_m"] or {}).get("max") or 0) for row in table.values()] + [1e-3])
    best_mm = 1000.0 * best
    scale = (height - bottom - top) / best_mm
    font = 'font-family="DejaVu Sans, sans-serif"'
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" {font}>',
           f'<rect width="{width}" height="{height}" fill="white"/>',
           f'<text x="{width / 2}" y="20" text-anchor="middle" font-size="15">ATE RMSE of trajectory_refined.txt per sequence and dynamic mode</text>',
           f'<text x="{width / 2}" y="38" text-anchor="middle" font-size="11">bar = median over runs, whisker = min..max, value = median in mm (bench/run_modes.sh, bench/results/modes.json)</text>']
    rects = []
    # Ticks at 1, 2 or 5 times a power of ten, about five of them.
    raw = best_mm / 5
    power = 10 ** math.floor(math.log10(raw))
    step = next(f * power for f in (1, 2, 5, 10) if f * power >= raw)
    for k in range(int(best_mm // step) + 1):
        value = k * step
        y = height - bottom - value * scale
        svg.append(f'<text x="{left - 6}" y="{y + 4:.1f}" text-anchor="end" font-size="11">{value:.0f}</text>')
        svg.append(f'<line x1="{left}" y1="{y:.1f}" x2="{width - 10}" y2="{y:.1f}" stroke="#dddddd"/>')
        rects.append((left, y, width - 10, y + 1, "#dddddd"))
    svg.append(f'<line x1="{left}" y1="{height - bottom}" x2="{width - 10}" y2="{height - bottom}" stroke="black"/>')
    svg.append(f'<line x1="{left}" y1="{top}" x2="{left}" y2="{height - bottom}" stroke="black"/>')
    rects += [(left, height - bottom, width - 10, height - bottom + 1, "#000000"),
              (left, top, left + 1, height - bottom, "#000000")]
    svg.append(f'<text x="22" y="{(top + height - bottom) / 2}" text-anchor="middle" font-size="12" transform="rotate(-90 22 {(top + height - bottom) / 2})">ATE RMSE [mm]</text>')
    svg.append(f'<text x="{(left + width - 10) / 2}" y="{height - 34}" text-anchor="middle" font-size="12">sequence</text>')
    group_width = (width - left - 20) / max(1, len(sequences))
    bar = group_width / (len(MODES) + 1)
    for g, seq in enumerate(sequences):
        x0 = left + 10 + g * group_width
        svg.append(f'<text x="{x0 + group_width / 2 - bar / 2:.1f}" y="{height - bottom + 18}" text-anchor="middle" font-size="12">{seq}</text>')
        for m, mode in enumerate(MODES):
            row = table.get(f"{seq}/{mode}")
            if not row or not row["ate_refined_rmse_m"]:
                continue
            a = {k: 1000.0 * v for k, v in row["ate_refined_rmse_m"].items() if k != "runs"}
            x = x0 + m * bar
            y = height - bottom - a["median"] * scale
            svg.append(f'<rect x="{x:.1f}" y="{y:.1f}" width="{bar * 0.9:.1f}" height="{a["median"] * scale:.1f}" fill="{COLOURS[mode]}"/>')
            rects.append((x, y, x + bar * 0.9, height - bottom, COLOURS[mode]))
            cx = x + bar * 0.45
            rects.append((cx, height - bottom - a["max"] * scale, cx + 1,
                          height - bottom - a["min"] * scale + 1, "#000000"))
            svg.append(f'<line x1="{cx:.1f}" y1="{height - bottom - a["min"] * scale:.1f}" x2="{cx:.1f}" y2="{height - bottom - a["max"] * scale:.1f}" stroke="black"/>')
            label_y = min(y, height - bottom - a["max"] * scale) - 4
            svg.append(f'<text x="{cx:.1f}" y="{label_y:.1f}" text-anchor="middle" font-size="10">{a["median"]:.1f}</text>')
    for m, mode in enumerate(MODES):
        svg.append(f'<rect x="{left + 10 + m * 130}" y="{height - 22}" width="12" height="12" fill="{COLOURS[mode]}"/>')
        rects.append((left + 10 + m * 130, height - 22, left + 22 + m * 130, height - 10, COLOURS[mode]))
        svg.append(f'<text x="{left + 26 + m * 130}" y="{height - 12}" font-size="12">{mode}</text>')
    svg.append("</svg>")
    (docs / "modes_ate_bars.svg").write_text("\n".join(svg) + "\n")
    labelled = rasterise(docs / "modes_ate_bars.svg", docs / "modes_ate_bars.png", width, height, rects)
    return ["docs/modes_ate_bars.svg",
            "docs/modes_ate_bars.png" + ("" if labelled else " (bars only: no rsvg-convert)")]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--work")
    parser.add_argument("--cli")
    parser.add_argument("--results", required=True)
    parser.add_argument("--docs", required=True)
    parser.add_argument("--sequence-dirs", default="")
    parser.add_argument("--bars-from-results", action="store_true",
                        help="only redraw DOCS/modes_ate_bars.{svg,png} from RESULTS/modes.json "
                             "(no runs needed)")
    args = parser.parse_args()
    if args.bars_from_results:
        summary_table = json.loads(Path(args.results, "modes.json").read_text())["summary"]
        docs = Path(args.docs)
        docs.mkdir(parents=True, exist_ok=True)
        print("\n".join(draw_ate_bars(summary_table,
                                      sorted({row["sequence"] for row in summary_table.values()}),
                                      docs)))
        return
    if not args.work or not args.cli:
        parser.error("--work and --cli are required (unless --bars-from-results)")
    sequence_dirs = dict(item.split("=", 1) for item in args.sequence_dirs.split() if "=" in item)

    runs = collect(args.work)
    sequences = sorted({r["sequence"] for r in runs})
    table = {}
    for seq in sequences:
        for mode in MODES:
            group = [r for r in runs if r["sequence"] == seq and r["mode"] == mode]
            if not group:
                continue
            timings = {}
            for key in ["extraction", "semantic", "semantic_wait", "flow_homography", "geometry",
                        "geometry_search", "tracking", "local_mapping"]:
                timings[key] = summary([r["timing_median_ms"].get(key) for r in group])
            table[f"{seq}/{mode}"] = {
                "sequence": seq, "mode": mode, "runs": len(group),
                "ate_rmse_m": summary([r["ate_rmse"] for r in group]),
                "ate_refined_rmse_m": summary([r["ate_refined_rmse"] for r in group]),
                "rpe_trans_rmse_m": summary([r["rpe_trans_rmse_m"] for r in group]),
                "rpe_body_frames_differ": any(r["rpe_body_frames_differ"] for r in group),
                "fps": summary([r["fps"] for r in group]),
                "lost_frames": summary([r["lost_frames"] for r in group]),
                "timing_median_ms": timings,
                "tested_points": summary([(r["dynamic"] or {}).get("tested_points") for r in group]),
            }
    results = Path(args.results)
    results.mkdir(parents=True, exist_ok=True)
    (results / "modes.json").write_text(json.dumps({"runs": runs, "summary": table}, indent=1))
    with open(results / "modes.csv", "w") as csv:
        csv.write("sequence,mode,run,frames,lost_frames,fps,ate_rmse_m,ate_refined_rmse_m,"
                  "rpe_trans_rmse_m,extraction_ms,semantic_ms,geometry_ms,geometry_search_ms,"
                  "tracking_ms,local_mapping_ms\n")
        for r in runs:
            t = r["timing_median_ms"]
            csv.write(",".join(str(x) for x in [
                r["sequence"], r["mode"], r["run"], r["frames"], r["lost_frames"], r["fps"],
                r["ate_rmse"], r["ate_refined_rmse"], r["rpe_trans_rmse_m"], t.get("extraction"),
                t.get("semantic"), t.get("geometry"), t.get("geometry_search"), t.get("tracking"),
                t.get("local_mapping")]) + "\n")

    docs = Path(args.docs)
    md = ["## Dynamic modes (issue #7, `bench/run_modes.sh`)", "",
          "Measured by `bench/run_modes.sh`; every number is from `stats.json` / `pspslam eval` of "
          "the runs listed in `bench/results/modes.csv`. Deterministic mode (each frame waits for "
          "its own mask). Runs per cell in the `runs` column.", "",
          ]
    # The final trajectory first (what SLAM papers evaluate: ORB-SLAM2 saves its keyframe-refined
    # trajectory), then the online one a live user gets frame by frame.
    for title, key in [("trajectory_refined.txt (final: every frame moved with the BA-refined "
                        "keyframes around it)", "ate_refined_rmse_m"),
                       ("trajectory.txt (online: each frame's pose as tracked)", "ate_rmse_m")]:
        md += [f"### ATE RMSE (m) of {title}, over runs", "",
               "| sequence | mode | runs | median | mean | min | max | RPE trans (m, 1 s) | fps |",
               "|---|---|---|---|---|---|---|---|---|"]
        for row in table.values():
            ate = row[key] or {}
            rpe = ("n/a (a)" if row["rpe_body_frames_differ"]
                   else fmt((row['rpe_trans_rmse_m'] or {}).get('median')))
            md.append(f"| {row['sequence']} | {row['mode']} | {row['runs']} | "
                      f"{fmt(ate.get('median'))} | {fmt(ate.get('mean'))} | {fmt(ate.get('min'))} | "
                      f"{fmt(ate.get('max'))} | {rpe} | {fmt((row['fps'] or {}).get('median'), 1)} |")
        md.append("")
    md.append("RPE: of trajectory.txt.")
    differ = sorted({(r["sequence"], round(r["rpe_body_frame_rotation_deg"]))
                     for r in runs if r["rpe_body_frames_differ"]})
    if differ:
        seqs = sorted({seq for seq, _ in differ})
        angles = sorted({angle for _, angle in differ})
        md += ["", f"(a) {', '.join(seqs)}: `pspslam eval` finds the ground truth's body frame "
               f"rotated {'/'.join(str(a) for a in angles)} deg from the camera's (it tracks the "
               "motion-capture markers), so RPE compares motions in different frames; the ATE "
               "(positions only) is valid."]
    missing = [f"{s}/{m}" for s in sequences for m in MODES if f"{s}/{m}" not in table]
    if missing:
        md += ["", "Not run (no time): " + ", ".join(missing)]
    md += ["", "### Per-thread time (ms, median of per-run medians)", "",
           "| sequence | mode | extraction | semantic inference | waited for mask | flow + H | geometry | of which search | tracking | local BA |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for key, row in table.items():
        t = row["timing_median_ms"]
        cell = lambda k: fmt((t.get(k) or {}).get("median"), 1)
        md.append(f"| {row['sequence']} | {row['mode']} | {cell('extraction')} | {cell('semantic')} | "
                  f"{cell('semantic_wait')} | {cell('flow_homography')} | {cell('geometry')} | "
                  f"{cell('geometry_search')} | {cell('tracking')} | {cell('local_mapping')} |")
    md += ["", "### Geometry: ant colony vs exhaustive (paper Table 2)", "",
           "| sequence | search | tested points / frame | search ms | geometry stage ms | ATE median (final) |",
           "|---|---|---|---|---|---|"]
    for seq in sequences:
        for mode in ["full", "exhaustive"]:
            row = table.get(f"{seq}/{mode}")
            if not row:
                continue
            frames = statistics.median([r["frames"] for r in runs if r["sequence"] == seq and r["mode"] == mode])
            tested = (row["tested_points"] or {}).get("median")
            t = row["timing_median_ms"]
            md.append(f"| {seq} | {'ant colony' if mode == 'full' else 'exhaustive'} | "
                      f"{fmt(tested / frames if tested is not None and frames else None, 0)} | "
                      f"{fmt((t.get('geometry_search') or {}).get('median'), 2)} | "
                      f"{fmt((t.get('geometry') or {}).get('median'), 1)} | "
                      f"{fmt((row['ate_refined_rmse_m'] or {}).get('median'))} |")

    docs.mkdir(parents=True, exist_ok=True)
    images = draw_ate_bars(table, sequences, docs)

    # Trajectory overlays of run 1's final trajectory (paper Fig. 7-9).
    plots = docs / "modes_trajectories"
    for seq in sequences:
        gt = Path(sequence_dirs.get(seq, ""), "groundtruth.txt")
        if not gt.is_file():
            continue
        for mode in MODES:
            run1 = Path(args.work, "runs", seq, mode, "run1", "trajectory_refined.txt")
            if not run1.is_file() or not (run1.parent / "stats.json").is_file():
                continue  # still running or never finished
            tmp = Path(args.work, "plots", seq, mode)
            if subprocess.run([args.cli, "eval", "--gt", str(gt), "--est", str(run1), "--plot", str(tmp)],
                              capture_output=True).returncode != 0:
                continue
            plots.mkdir(parents=True, exist_ok=True)
            png = tmp / "trajectory_top_view.png"
            if png.is_file():
                shutil.copy(png, plots / f"{seq}_{mode}.png")
                images.append(f"docs/modes_trajectories/{seq}_{mode}.png")
    md += ["", "Plots: " + ", ".join(f"`{i}`" for i in images), ""]
    (results / "modes.md").write_text("\n".join(md) + "\n")
    print("\n".join(md))


if __name__ == "__main__":
    main()
