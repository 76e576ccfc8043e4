"""One tiny experiment through the local pool and through a real dask.distributed cluster
(a scheduler and two worker processes on 127.0.0.1): the same tables, a killed worker changes
nothing but the time, and a second invocation runs nothing."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import executed_runs, run_runner, section_tables

RUNS = 4  # 2 cells x 2 variants x 1 repeat


def dask_available():
    completed = subprocess.run([sys.executable, "-c", "import distributed"], capture_output=True)
    return completed.returncode == 0


needs_dask = pytest.mark.skipif(not dask_available(),
                                reason=f"{sys.executable} cannot import dask.distributed "
                                       "(apt install python3-distributed)")


@pytest.fixture(scope="module")
def local_tables(build, tmp_path_factory):
    """The tiny experiment through the local pool: its tables, work folder and results file."""
    folder = tmp_path_factory.mktemp("local")
    experiment = folder / "tiny.toml"
    from conftest import TINY_EXPERIMENT
    experiment.write_text(TINY_EXPERIMENT)
    results = folder / "results.md"
    run_runner(experiment, "--work", folder / "work", "--results", results, "--jobs", "2",
               build=build)
    return {"tables": section_tables(results, "tiny"), "work": folder / "work",
            "results": results, "experiment": experiment}


def fresh_work(local_tables, tmp_path):
    """An empty work folder that already has the tiny experiment's rendered sequences (keyed by
    their recipe, so the runner takes them as made): the runs start at once."""
    work = tmp_path / "work"
    work.mkdir()
    (work / "sequences").symlink_to(local_tables["work"] / "sequences")
    return work


def test_local_pool_fills_every_cell(local_tables):
    tables = local_tables["tables"]
    rows = [line for line in tables if line.startswith("| tiny_s")]
    assert len(rows) == 2 * 2  # the accuracy table and the paired per-cell table
    assert not any("missing" in row or "lost" in row or "failed" in row for row in rows)
    assert len(executed_runs(local_tables["work"])) == RUNS
    results = list((local_tables["work"] / "results").glob("*.json"))
    assert len(results) == RUNS
    for path in results:
        result = json.loads(path.read_text())
        whole_cell = next(iter(result["evaluations"].values()))
        assert whole_cell["online"]["poses"] > 0


def test_second_invocation_reruns_nothing(local_tables, build):
    before = executed_runs(local_tables["work"])
    completed = run_runner(local_tables["experiment"], "--work", local_tables["work"],
                           "--results", local_tables["results"], build=build)
    assert executed_runs(local_tables["work"]) == before
    assert f"{RUNS} runs: {RUNS} have results, 0 to run" in completed.stderr
    assert section_tables(local_tables["results"], "tiny") == local_tables["tables"]


class Cluster:
    """A dask scheduler and worker processes on 127.0.0.1, each in its own process group so
    that a test can kill a worker together with the runs it started."""

    def __init__(self, folder, workers):
        self.folder = folder
        self.scheduler_file = folder / "scheduler.json"
        environment = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        common = dict(cwd=folder, env=environment, start_new_session=True,
                      stdout=subprocess.DEVNULL, stderr=open(folder / "cluster.log", "a"))
        self.scheduler = subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
             "--port", "0", "--no-dashboard", "--scheduler-file", str(self.scheduler_file)],
            **common)
        self.wait_for(self.scheduler_file.exists, "the scheduler file")
        # Without a nanny a killed worker stays dead: the scheduler must move its runs.
        self.workers = [subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", "--scheduler-file",
             str(self.scheduler_file), "--nthreads", "1", "--no-nanny", "--no-dashboard",
             "--host", "127.0.0.1"], **common) for _ in range(workers)]
        self.address = json.loads(self.scheduler_file.read_text())["address"]
        import distributed
        with distributed.Client(self.address, timeout=30) as client:
            client.wait_for_workers(workers, timeout=60)

    @staticmethod
    def wait_for(condition, what, timeout=60):
        deadline = time.time() + timeout
        while not condition():
            if time.time() > deadline:
                raise AssertionError(f"timed out waiting for {what}")
            time.sleep(0.2)

    def kill_worker(self, pid):
        """Kills the worker process `pid` (one of ours) and the runs it started."""
        worker = next(w for w in self.workers if w.pid == pid)
        os.killpg(worker.pid, signal.SIGKILL)
        worker.wait()

    def close(self):
        for process in self.workers + [self.scheduler]:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGTERM)
        for process in self.workers + [self.scheduler]:
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()


@pytest.fixture
def cluster(tmp_path):
    started = Cluster(tmp_path, workers=2)
    yield started
    started.close()


@needs_dask
def test_cluster_gives_the_local_pool_tables(local_tables, cluster, tmp_path, build):
    work, results = fresh_work(local_tables, tmp_path), tmp_path / "results.md"
    run_runner(local_tables["experiment"], "--work", work, "--results", results,
               "--scheduler", cluster.address, build=build)
    assert section_tables(results, "tiny") == local_tables["tables"]
    assert len(executed_runs(work)) == RUNS


@needs_dask
def test_killed_worker_still_leaves_a_complete_table(local_tables, cluster, tmp_path, build):
    work, results = fresh_work(local_tables, tmp_path), tmp_path / "results.md"
    runner = subprocess.Popen(
        [sys.executable, str(Path(__file__).parents[1] / "runner.py"), "run",
         str(local_tables["experiment"]), "--work", str(work), "--results", str(results),
         "--scheduler", cluster.address, "--build", str(build)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    running = work / "running"
    # A run in progress leaves a marker named KEY.HOST.PID; kill the worker that runs it.
    Cluster.wait_for(lambda: running.is_dir() and any(running.iterdir()), "a run to start")
    victim = int(next(running.iterdir()).read_text())
    cluster.kill_worker(victim)
    stdout, stderr = runner.communicate(timeout=300)
    assert runner.returncode == 0, stderr[-3000:]
    assert section_tables(results, "tiny") == local_tables["tables"]
    # Every run finished once; the killed attempt left a folder but no result.
    finished = [line.split()[0] for line in executed_runs(work)]
    assert len(finished) == len(set(finished)) == RUNS
    attempts = list((work / "runs").glob("*/attempt-*"))
    assert len(attempts) > RUNS


def test_killed_pool_process_still_leaves_a_complete_table(local_tables, tmp_path, build):
    work, results = fresh_work(local_tables, tmp_path), tmp_path / "results.md"
    runner = subprocess.Popen(
        [sys.executable, str(Path(__file__).parents[1] / "runner.py"), "run",
         str(local_tables["experiment"]), "--work", str(work), "--results", str(results),
         "--jobs", "2", "--build", str(build)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    running = work / "running"
    Cluster.wait_for(lambda: running.is_dir() and any(running.iterdir()), "a run to start")
    victim = int(next(running.iterdir()).read_text())
    # Only a process of this runner's pool: its parent is the runner.
    assert Path(f"/proc/{victim}/stat").read_text().split(") ")[1].split()[1] == str(runner.pid)
    os.kill(victim, signal.SIGKILL)
    stdout, stderr = runner.communicate(timeout=300)
    assert runner.returncode == 0, stderr[-3000:]
    assert "attempt failed, running it again" in stderr
    assert section_tables(results, "tiny") == local_tables["tables"]
    finished = [line.split()[0] for line in executed_runs(work)]
    assert len(finished) == len(set(finished)) == RUNS


def test_runs_are_ordered_round_by_round(local_tables, tmp_path, build):
    """Each round runs every variant once, so that a machine drifting during an invocation moves
    all variants alike: the dry run lists the runs in the order they are executed."""
    experiment = tmp_path / "rounds.toml"
    experiment.write_text(local_tables["experiment"].read_text().replace(
        'base = "off"\n', 'base = "off"\nrepeats = 2\n'))
    completed = run_runner(experiment, "--work", fresh_work(local_tables, tmp_path),
                           "--results", tmp_path / "results.md", "--dry-run", build=build)
    labels = [line.split("  ")[1] for line in completed.stdout.splitlines()
              if line.startswith("to run")]
    assert labels == [f"tiny_s{seed} · {mode} · run {repeat}"
                      for repeat in (1, 2) for seed in (1, 2) for mode in ("off", "geometry")]
