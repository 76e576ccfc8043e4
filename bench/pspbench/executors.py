"""Where runs execute: a local process pool or a dask.distributed cluster, with one contract.

Both run pspbench.jobs.run_job on each job and report through two callbacks: `done(job,
result)` and `failed(job, error)` once a job has failed `retries + 1` times. A job whose worker
process dies (killed, out of memory) counts as a failed attempt and is run again elsewhere.
"""
import concurrent.futures
import tempfile
import uuid
import zipfile
from pathlib import Path

from .jobs import run_job


class LocalPool:
    def __init__(self, processes, retries):
        self.processes, self.retries = processes, retries

    def describe(self):
        return f"local pool of {self.processes} process{'es' if self.processes > 1 else ''}"

    def run(self, jobs, done, failed, retrying):
        attempts = {job["key"]: 0 for job in jobs}
        pending = list(jobs)
        while pending:
            # A pool whose process died is broken for good: the next round gets a new one.
            with concurrent.futures.ProcessPoolExecutor(max_workers=self.processes) as pool:
                futures = {pool.submit(run_job, job): job for job in pending}
                pending = []
                for future in concurrent.futures.as_completed(futures):
                    job = futures[future]
                    try:
                        done(job, future.result())
                    except Exception as error:  # the job's own failure or its process's death
                        attempts[job["key"]] += 1
                        if attempts[job["key"]] > self.retries:
                            failed(job, error)
                        else:
                            retrying(job, error)
                            pending.append(job)


class DaskCluster:
    """Submits the same run_job to a dask.distributed scheduler. Workers must see the build, the
    data and WORK at the same paths as this machine (a shared file system)."""

    def __init__(self, address, retries):
        try:
            import distributed
        except ImportError as error:
            raise SystemExit(f"runner.py: --scheduler needs dask.distributed ({error}); install "
                             "python3-distributed or run without --scheduler") from None
        self.distributed = distributed
        try:
            self.client = distributed.Client(address, timeout=30)
        except OSError as error:
            raise SystemExit(f"runner.py: --scheduler {address}: cannot connect "
                             f"({error})") from None
        self.address, self.retries = address, retries
        self.upload_runner_code()

    def upload_runner_code(self):
        """Sends this package to every worker (and any that joins later): tasks refer to
        pspbench.jobs.run_job by name, and workers need not have bench/ on their path."""
        package = Path(__file__).resolve().parent
        with tempfile.TemporaryDirectory() as folder:
            archive = Path(folder) / "pspbench.zip"
            with zipfile.ZipFile(archive, "w") as zipped:
                for source in sorted(package.glob("*.py")):
                    zipped.write(source, f"pspbench/{source.name}")
            self.client.upload_file(str(archive))

    def describe(self):
        workers = self.client.scheduler_info()["workers"]
        return f"dask.distributed scheduler {self.address} ({len(workers)} workers)"

    def run(self, jobs, done, failed, retrying):
        del retrying  # the scheduler retries on its own: a raised error `retries` times, and a
        # task whose worker died up to its allowed-failures setting
        futures = {self.client.submit(run_job, job, key=f"run-{job['key'][:16]}-{uuid.uuid4().hex}",
                                      pure=False, retries=self.retries): job for job in jobs}
        for future in self.distributed.as_completed(futures):
            job = futures[future]
            try:
                done(job, future.result())
            except Exception as error:
                failed(job, error)

    def close(self):
        self.client.close()
