"""One run of one cell: the function a local pool process or a dask.distributed worker executes.

A job is a plain dict (see runner.make_job); its result is a JSON file WORK/results/KEY.json,
written to a temporary name and renamed, so a reader sees a whole result or none. Each attempt
runs in a folder of its own, so an attempt whose worker was killed cannot write into the retry's.
Every executed run adds a line to WORK/executed.log. Runs need only the standard library;
segmentation cells also read PNG masks with numpy and matplotlib.
"""
import json
import os
import re
import socket
import subprocess
import time
import uuid
from pathlib import Path


def result_path(work, key):
    return Path(work) / "results" / f"{key}.json"


def read_result(work, key):
    """The finished result of `key`, or None."""
    path = result_path(work, key)
    return json.loads(path.read_text()) if path.exists() else None


def write_atomically(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.{uuid.uuid4().hex}")
    with open(temporary, "w") as stream:
        stream.write(text)
        stream.flush()
        os.fsync(stream.fileno())
    os.replace(temporary, path)


def run_job(job):
    """Runs the job unless its result exists; returns the result. Raises on failure (the caller
    retries)."""
    finished = read_result(job["work"], job["key"])
    if finished is not None:
        return finished
    work = Path(job["work"])
    attempt_name = f"attempt-{socket.gethostname()}-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    attempt = work / "runs" / job["key"] / attempt_name
    attempt.mkdir(parents=True)
    marker = work / "running" / f"{job['key']}.{socket.gethostname()}.{os.getpid()}"
    marker.parent.mkdir(parents=True, exist_ok=True)
    marker.write_text(f"{os.getpid()}\n")
    started = time.time()
    load_at_start = os.getloadavg()
    try:
        measured = MEASURE[job["kind"]](job, attempt)
    finally:
        marker.unlink(missing_ok=True)
    result = {"key": job["key"], "recipe": job["recipe"], "label": job["label"],
              "kind": job["kind"], "host": socket.gethostname(),
              "finished_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
              "wall_s": round(time.time() - started, 3), "load_at_start": load_at_start,
              "attempt": str(attempt), **measured}
    write_atomically(result_path(work, job["key"]), json.dumps(result, indent=1))
    with open(work / "executed.log", "a") as log:
        log.write(f"{job['key']} {job['label']}\n")
    return result


def _execute(command, attempt, cwd, env):
    """Runs `command` with its output in attempt/log.txt; raises with the log's tail if it fails."""
    log_path = attempt / "log.txt"
    with open(log_path, "w") as log:
        log.write(" ".join(command) + "\n")
        log.flush()
        completed = subprocess.run(command, stdout=log, stderr=subprocess.STDOUT, cwd=cwd,
                                   env={**os.environ, **env})
    if completed.returncode != 0:
        tail = log_path.read_text()[-800:]
        raise RuntimeError(f"{command[0]} exited {completed.returncode} (log {log_path}):\n{tail}")
    return log_path.read_text()


def measure_slam(job, attempt):
    """`pspslam run`, then the ATE of the online, final and keyframe files on every stretch."""
    command = list(job["command"]) + ["--out", str(attempt / "run")]
    if job["config_text"] is not None:
        (attempt / "config.yaml").write_text(job["config_text"])
        command += ["--config", str(attempt / "config.yaml")]
    if job.get("busy_cores"):
        # The competitor spins only while the run lasts and stops with it.
        command = [str(Path(job["cwd"]) / "scripts" / "busy-cores"), "--cores",
                   str(job["busy_cores"]), "--"] + command
    _execute(command, attempt, job["cwd"], job["env"])
    run = attempt / "run"
    stats = json.loads((run / "stats.json").read_text())
    _online_at_keyframes(run)
    files = {"online": "trajectory.txt", "final": "trajectory_refined.txt",
             "keyframes": "keyframes.txt", "online_at_keyframes": "online_at_keyframes.txt"}
    evaluations = {stretch["id"]: {label: _ate(job["command"][0], stretch, run / name)
                                   for label, name in files.items()}
                   for stretch in job["stretches"]}
    return {"stats": stats, "evaluations": evaluations}


def _online_at_keyframes(run):
    """run/online_at_keyframes.txt: the lines of trajectory.txt at the stamps of keyframes.txt,
    the online poses to hold the keyframes after bundle adjustment against."""
    def lines(name):
        path = run / name
        if not path.exists():
            return []
        return [line for line in path.read_text().splitlines()
                if line.strip() and not line.startswith("#")]
    stamps = {line.split()[0] for line in lines("keyframes.txt")}
    kept = [line for line in lines("trajectory.txt") if line.split()[0] in stamps]
    (run / "online_at_keyframes.txt").write_text("".join(line + "\n" for line in kept))


def _ate(cli, stretch, estimate):
    """{"rmse": metres, "poses": associated poses} of one trajectory file, or None when it has
    no pose that meets the ground truth. `pspslam eval` aligns a monocular run with scale (it
    reads the run's stats.json beside the file)."""
    if not estimate.exists() or estimate.stat().st_size == 0:
        return None
    # Only the ATE is read; an RPE over consecutive frames exists for any stretch (the default
    # one-second RPE fails on a stretch shorter than a second).
    command = [cli, "-q", "eval", "--gt", stretch["ground_truth"], "--est", str(estimate),
               "--json", "--rpe-delta", "1", "--rpe-unit", "f"]
    if stretch["body_to_camera"]:
        command += ["--gt-body-to-camera", stretch["body_to_camera"]]
    completed = subprocess.run(command, capture_output=True, text=True)
    if completed.returncode != 0:
        return None
    error = json.loads(completed.stdout)["ate"]["error_m"]
    return {"rmse": error["rmse"], "poses": error["count"]}


def measure_segment(job, attempt):
    """`pspslam segment` on the cell's images, then each image's person IoU against its mask."""
    import numpy
    from matplotlib import image as images

    out = attempt / "out"
    log = _execute(list(job["command"]) + ["--out", str(out)], attempt, job["cwd"], job["env"])
    folder = Path(job["sequence"])
    ious = {}
    for photo in sorted((folder / "images").iterdir()):
        predicted = _binary_mask(images.imread(out / f"{photo.stem}_mask.png"))
        truth = _binary_mask(images.imread(folder / "masks" / f"{photo.stem}.png"))
        # Some masks are stored smaller than their photo: scale them up (nearest neighbour).
        rows = numpy.arange(predicted.shape[0]) * truth.shape[0] // predicted.shape[0]
        columns = numpy.arange(predicted.shape[1]) * truth.shape[1] // predicted.shape[1]
        truth = truth[rows][:, columns]
        union = numpy.logical_or(predicted, truth).sum()
        both = numpy.logical_and(predicted, truth).sum()
        ious[photo.stem] = float(both / union) if union else 1.0
    timing = re.search(r"median ([0-9.]+) ms", log)
    return {"ious": ious, "mean_iou": sum(ious.values()) / len(ious),
            "median_ms": float(timing.group(1)) if timing else None}


def _binary_mask(pixels):
    """A mask image (grey, RGB or RGBA, values 0-1) as booleans: True where it is white."""
    return (pixels if pixels.ndim == 2 else pixels[..., 0]) > 0.5


def measure_gbench(job, attempt):
    """A Google Benchmark program: each benchmark's real and CPU time."""
    output = attempt / "benchmark.json"
    command = list(job["command"]) + ["--benchmark_format=json", f"--benchmark_out={output}"]
    _execute(command, attempt, job["cwd"], job["env"])
    benchmarks = json.loads(output.read_text())["benchmarks"]
    return {"benchmarks": [{key: b.get(key) for key in ("name", "real_time", "cpu_time",
                                                       "time_unit", "run_type")}
                           for b in benchmarks]}


MEASURE = {"slam": measure_slam, "segment": measure_segment, "gbench": measure_gbench}
