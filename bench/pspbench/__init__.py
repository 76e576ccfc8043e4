"""The experiment runner's library: experiment files, sequences, runs, statistics and reports.

The same cell function (pspbench.jobs.run_job) runs in a local process pool and on a
dask.distributed worker; it needs the standard library only (numpy and matplotlib for
segmentation cells).
"""
