#!/usr/bin/python3
"""Runs a declared experiment (bench/experiments/*.toml) and regenerates its section of
docs/results.md.

Every cell of the experiment is run with every variant, `repeats` times, in a local process
pool (--jobs) or on a dask.distributed cluster (--scheduler). Each run's result is a JSON file
in WORK/results/, named by the digest of what made it (the binary, the data, the config, the
flags), so an interrupted or repeated invocation runs only what has no result yet, and two
experiments that share a run share its result.
"""
import argparse
import concurrent.futures
import importlib.util
import os
import platform
import shlex
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from pspbench import content, experiment as experiments, report, sequences  # noqa: E402
from pspbench.executors import DaskCluster, LocalPool  # noqa: E402
from pspbench.jobs import read_result  # noqa: E402

REPO = Path(__file__).resolve().parent.parent
# Bumped when what a result holds changes, so older results are not read as current ones.
RESULT_FORMAT = 2


def log(message):
    print(f"[{time.strftime('%H:%M:%S')}] {message}", file=sys.stderr, flush=True)


def add_common_arguments(command):
    command.add_argument("--build", default=str(REPO / "build"),
                         help="build folder with apps/pspslam (default: %(default)s)")
    command.add_argument("--data", default=os.environ.get("PSPSLAM_DATA"),
                         help="folder holding downloaded sequences (TUM, Bonn) by their official "
                              "folder names (default: $PSPSLAM_DATA); cells not found there are "
                              "listed as missing")
    command.add_argument("--shared",
                     default=os.environ.get("PSPSLAM_SHARED", str(REPO.parent / "shared")),
                         help="the project's shared folder (default: $PSPSLAM_SHARED or ../shared)")
    command.add_argument("--work", default=os.environ.get("PSPSLAM_BENCH_WORK", "/tmp/pspslam-bench"),
                         help="folder for sequences, runs and results; shared by experiments "
                              "(default: $PSPSLAM_BENCH_WORK or %(default)s)")
    command.add_argument("--jobs", type=int, default=None,
                         help="runs at a time in the local pool (default: 1 for an experiment "
                              "marked exclusive, else the number of cores)")
    command.add_argument("--scheduler", metavar="ADDRESS",
                         help="run on this dask.distributed scheduler (e.g. tcp://HOST:8786) instead "
                              "of the local pool; workers must see the build, data and --work at "
                              "the same paths")
    command.add_argument("--retries", type=int, default=2,
                         help="times a failed run (or one whose worker died) is run again "
                              "(default: %(default)s)")
    command.add_argument("--results",
                         help="file whose section is regenerated (default: the experiment's "
                              "decision record for decision evidence, else docs/results.md)")
    command.add_argument("--limit-frames", type=int, default=0, metavar="N",
                         help="cap every run at N frames: a quick check of an experiment's "
                              "definitions, kept apart from full runs (default: no cap)")
    command.add_argument("--dry-run", action="store_true",
                         help="list the runs and which have results, run nothing")


def parse_arguments(argv):
    parser = argparse.ArgumentParser(prog="runner.py", description=__doc__.split("\n\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)
    run = commands.add_parser(
        "run", help="run an experiment and regenerate its section of the results",
        description="Run EXPERIMENT (a bench/experiments/*.toml file) and regenerate its section "
                    "of the results file.",
        epilog="examples:\n"
               "  bench/runner.py run bench/experiments/modes.toml --jobs 2\n"
               "  bench/runner.py run bench/experiments/tum_dynamic.toml --data ~/datasets\n"
               "  bench/runner.py run bench/experiments/bonn_dynamic.toml --data ~/datasets "
               "--scheduler tcp://HOST:8786\n"
               "The experiment file format: bench/experiments/README.md.",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    run.add_argument("experiment", help="experiment file (bench/experiments/NAME.toml)")
    run.add_argument("--variants", help="comma-separated variants to run (default: all); the "
                                        "section then shows these only")
    every = commands.add_parser(
        "all", help="regenerate every current figure that needs no download, in one invocation",
        description="Run every experiment of bench/experiments/ that needs no downloaded "
                    "sequences and is no decision's evidence (those live in their records), at "
                    "one clean commit on this machine: the others first, then the timing "
                    "(exclusive) ones one run at a time with nothing beside them. Refuses a "
                    "checkout with changes or a build of another commit.")
    every.add_argument("--allow-dirty", action="store_true",
                       help="run on a checkout with changes or a build of another commit (the "
                            "sections then say so in their commit)")
    every.add_argument("--skip", default="", metavar="NAMES",
                       help="comma-separated experiments to leave out (their sections keep the "
                            "figures they have, with their own commit): for one too long for "
                            "this sitting, e.g. patrol")
    for command in (run, every):
        add_common_arguments(command)
    return parser, parser.parse_args(argv)


def load_experiment(parser, args):
    try:
        experiment = experiments.load(args.experiment)
    except experiments.ExperimentError as error:
        print(f"runner.py: {error}", file=sys.stderr)
        sys.exit(2)
    if args.variants:
        wanted = args.variants.split(",")
        unknown = [name for name in wanted if name not in [v.name for v in experiment.variants]]
        if unknown:
            parser.error(f"--variants: {experiment.path} has no variant '{unknown[0]}'")
        experiment.variants = [v for v in experiment.variants if v.name in wanted]
        if experiment.base not in wanted:
            experiment.base = experiment.variants[0].name
        if experiment.spread_variant not in wanted:
            experiment.spread_variant = None
    return experiment


def build_source(build):
    """The source folder a CMake build was configured from (for its commit), or None."""
    cache = build / "CMakeCache.txt"
    if not cache.exists():
        return None
    for line in cache.read_text(errors="replace").splitlines():
        if line.startswith("CMAKE_HOME_DIRECTORY:"):
            return Path(line.split("=", 1)[1])
    return None


def make_setup(parser, args):
    build = Path(args.build).resolve()
    cli = build / "apps" / "pspslam"
    if not os.access(cli, os.X_OK):
        parser.error(f"--build: {cli} is not built (cmake --build {args.build} --target "
                     "pspslam_cli)")
    data = Path(args.data).resolve() if args.data else None
    if data is not None and not data.is_dir():
        parser.error(f"--data: {data} is not a folder")
    source = build_source(build) or REPO
    return sequences.Setup(repo=REPO, build=build, cli=cli, cli_sha256=content.file_sha256(cli),
                           shared=Path(args.shared).resolve(), data=data,
                           work=Path(args.work).resolve(),
                           models_sha256=content.tree_sha256(source / "models"),
                           limit_frames=args.limit_frames)


def variant_cli(parser, variant, setup):
    """The binary a variant runs: its own build's, or the invocation's."""
    if not variant.build:
        return setup.cli, setup.cli_sha256
    cli = (REPO / variant.build).resolve() / "apps" / "pspslam"
    if not os.access(cli, os.X_OK):
        parser.error(f"variant '{variant.name}': {cli} is not built")
    return cli, content.file_sha256(cli)


def run_command(experiment, cell, variant, prepared, cli, setup):
    """The command of one run, without its output folder (and config, which the worker writes)."""
    if experiment.kind == "gbench":
        return [str(prepared.folder)] + cell.args + variant.flags
    if experiment.kind == "segment":
        model = ["--model", str(REPO / variant.model)] if variant.model else []
        return ([str(cli), "-q", "segment", "--images", str(prepared.folder / "images"),
                 "--dilation", "0"] + model + variant.flags)
    flags = [flag.replace("{sequence}", str(prepared.folder)) for flag in variant.flags]
    command = [str(cli), "-q", "run", "--sequence", str(prepared.folder), "--dynamic",
               experiment.mode_of(cell, variant)] + flags + cell.args
    limits = [n for n in (prepared.max_frames, setup.limit_frames) if n]
    if limits:
        command += ["--max-frames", str(min(limits))]
    return command


def make_job(experiment, cell, variant, prepared, repeat, setup, cli, cli_sha256):
    command = run_command(experiment, cell, variant, prepared, cli, setup)
    # What makes the run what it is; paths are left out (the same data elsewhere is the same
    # run), the digests of the things they name are in.
    recipe = {"format": RESULT_FORMAT, "kind": experiment.kind, "pspslam_sha256": cli_sha256,
              "models_sha256": setup.models_sha256, "data": prepared.identity,
              "config": (None if prepared.config_text is None
                         else content.digest(prepared.config_text)),
              "arguments": [a.replace(str(prepared.folder), "SEQUENCE").replace(str(REPO), "REPO")
                            for a in command[1:]],
              "env": variant.env, "busy_cores": variant.busy_cores, "repeat": repeat,
              "evaluations": sorted(s["id"] for s in prepared.stretches),
              "model_file": variant.model and content.file_sha256(REPO / variant.model)}
    return {"key": content.digest(recipe), "recipe": recipe, "kind": experiment.kind,
            "label": f"{cell.name} · {variant.name} · run {repeat + 1}", "command": command,
            "cwd": str(REPO), "env": {"PSPSLAM_SHARED": str(setup.shared), **variant.env},
            "config_text": prepared.config_text, "busy_cores": variant.busy_cores,
            "stretches": prepared.stretches, "sequence": str(prepared.folder),
            "work": str(setup.work)}


def prepare_all(parser, experiment, setup, jobs):
    """Every (cell, variant): its prepared sequence or why it is missing. Rendering synthetic
    sequences is the slow part; it runs `jobs` at a time."""
    clis = {v.name: variant_cli(parser, v, setup) for v in experiment.variants}
    pairs = [(cell, variant) for cell in experiment.cells for variant in experiment.variants]
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = [pool.submit(sequences.prepare, experiment, cell, variant, setup)
                   for cell, variant in pairs]
        try:
            prepared = [future.result() for future in futures]
        except experiments.ExperimentError as error:
            print(f"runner.py: {error}", file=sys.stderr)
            sys.exit(2)
        except RuntimeError as error:  # a sequence that could not be made (synth, re-encoding)
            print(f"runner.py: {error}", file=sys.stderr)
            sys.exit(1)
    return {(cell.name, variant.name): (p, clis[variant.name])
            for (cell, variant), p in zip(pairs, prepared)}


def expand(experiment, setup, prepared):
    """The report's table skeleton and the jobs that fill it."""
    table, jobs = {}, []
    for cell in experiment.cells:
        table[cell.name] = {}
        for variant in experiment.variants:
            ready, (cli, cli_sha256) = prepared[(cell.name, variant.name)]
            if isinstance(ready, sequences.Missing):
                table[cell.name][variant.name] = report.CellRuns(missing=ready.reason)
                continue
            runs = report.CellRuns(results=[None] * experiment.repeats,
                                   rows=[(s["name"], s["id"]) for s in ready.stretches])
            table[cell.name][variant.name] = runs
            for repeat in range(experiment.repeats):
                job = make_job(experiment, cell, variant, ready, repeat, setup, cli, cli_sha256)
                job["slot"] = (cell.name, variant.name, repeat)
                jobs.append(job)
    # Repeat by repeat: each round runs every variant once, so a machine that drifts during an
    # invocation (a neighbour, the clock) moves all variants alike and the pairing stays fair.
    jobs.sort(key=lambda job: job["slot"][2])
    return table, jobs


def headline(result):
    """A run's figures in one line of progress."""
    if result["kind"] == "slam":
        whole = next(iter(result["evaluations"].values()), {})
        parts = [f"{name} {report.millimetres(whole[name]['rmse'])} mm"
                 for name in ("online", "final") if whole.get(name)]
        online = whole.get("online")
        if online:
            parts.append(f"{online['poses']}/{result['stats']['frames']} poses")
        return ", ".join(parts) or "no pose evaluated"
    if result["kind"] == "segment":
        return f"mean IoU {result['mean_iou']:.4f}"
    return f"{len(result['benchmarks'])} benchmarks"


def execute(executor, jobs, table):
    """Runs the jobs, fills the table; returns the number of failed runs."""
    total, counts = len(jobs), {"done": 0, "failed": 0}
    started = time.time()

    def place(job, result):
        cell, variant, repeat = job["slot"]
        table[cell][variant].results[repeat] = result

    def done(job, result):
        place(job, result)
        counts["done"] += 1
        log(f"[{counts['done'] + counts['failed']}/{total}] {job['label']}: {headline(result)} "
            f"({result['wall_s']:.0f} s)")

    def failed(job, error):
        counts["failed"] += 1
        log(f"[{counts['done'] + counts['failed']}/{total}] {job['label']}: FAILED: "
            f"{str(error).strip()[:600]}")

    def retrying(job, error):
        log(f"{job['label']}: attempt failed, running it again ({str(error).strip()[:200]})")

    if jobs:
        log(f"running {total} runs on the {executor.describe()}")
        executor.run(jobs, done, failed, retrying)
        log(f"{counts['done']} runs done, {counts['failed']} failed, "
            f"{(time.time() - started) / 60:.1f} min")
    return counts["failed"]


def cpu_model():
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def build_commit(setup):
    """The commit the binary was built from (its --version names it), else the checkout's."""
    try:
        version = subprocess.run([str(setup.cli), "--version"], capture_output=True,
                                 text=True).stdout
    except OSError:  # the binary went away during the runs (a rebuild)
        version = ""
    if "(git " in version:
        return version.split("(git ", 1)[1].split(")", 1)[0]
    source = build_source(setup.build) or REPO
    commit = subprocess.run(["git", "-C", str(source), "rev-parse", "--short=10", "HEAD"],
                            capture_output=True, text=True).stdout.strip()
    return f"{commit} (of the checkout the build was configured from)" if commit else "unknown"


def plural(count, word):
    return f"{count} {word}{'' if count == 1 else 's'}"


def regenerate_command(args, experiment):
    """The command that regenerates a section, as run from the repository's root: the runner
    and the experiment by their repository paths, and only what changes the figures (where the
    build, the shared folder and the work folder lie is the reader's own)."""
    path = experiment.path.resolve()
    shown = path.relative_to(REPO).as_posix() if path.is_relative_to(REPO) else str(experiment.path)
    words = ["bench/runner.py", "run", shown]
    if experiment.needs_download():
        words += ["--data", "DIR"]
    if getattr(args, "variants", None):
        words += ["--variants", args.variants]
    if args.limit_frames:
        words += ["--limit-frames", str(args.limit_frames)]
    return " ".join(shlex.quote(word) for word in words)


def when_made(table):
    """When the results were made and at what load: reused results may be older than the
    section."""
    results = [r for cell in table.values() for runs in cell.values() for r in runs.results if r]
    if not results:
        return ""
    stamps = sorted(r["finished_utc"][:16].replace("T", " ") for r in results)
    first, last = stamps[0], stamps[-1]
    if first != last:
        last = last[11:] if last[:10] == first[:10] else last  # the time alone on the same day
    span = first if first == last else f"{first} to {last}"
    loads = [r["load_at_start"][0] for r in results]
    return (f"runs finished {span} UTC, load average {min(loads):.1f}–{max(loads):.1f} at their "
            "start; ")


def provenance(args, experiment, setup, executor, counts, loads, table):
    return [f"Regenerate: `{regenerate_command(args, experiment)}`", "",
            f"_{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; measured at commit "
            f"{build_commit(setup)} (pspslam sha256 {setup.cli_sha256[:12]}); machine: "
            f"{cpu_model()}, {os.cpu_count()} cores; {when_made(table)}load average "
            f"{loads[0]:.1f} before, {loads[1]:.1f} after this invocation; "
            f"{plural(counts['runs'], 'run')} ({counts['new']} run now, {counts['reused']} "
            f"reused) on the {executor}._"]


def results_file_of(args, experiment):
    """Where a section goes: --results, else the experiment's decision record, else the current
    figures."""
    if args.results:
        return Path(args.results).resolve()
    if experiment.record:
        return REPO / experiment.record
    return REPO / "docs" / "results.md"


def write_report(args, experiment, setup, table, executor_text, counts, loads):
    lines = report.tables(experiment, table)
    results_file = results_file_of(args, experiment)
    image = results_file.parent / "results" / f"{experiment.name}.png"
    link = None
    if report.plot(experiment, table, image):
        link = os.path.relpath(image, results_file.parent)
    else:
        image.unlink(missing_ok=True)  # an older run's picture would not match the tables
        if importlib.util.find_spec("matplotlib") is None:
            log(f"no picture for '{experiment.name}': {sys.executable} has no matplotlib "
                "(run bench/runner.py itself: its first line names /usr/bin/python3)")
    text = report.section(
        experiment, lines,
        provenance(args, experiment, setup, executor_text, counts, loads, table), link)
    report.replace_section(results_file, experiment.name, text)
    log(f"wrote the '{experiment.name}' section of {results_file}")


def choose_jobs(parser, args, experiment):
    if args.jobs is not None and args.jobs < 1:
        parser.error("--jobs: must be at least 1")
    if experiment.exclusive:
        if args.jobs not in (None, 1):
            log(f"{experiment.path} is exclusive (timing): running one run at a time, not "
                f"{args.jobs}")
        return 1
    return args.jobs or os.cpu_count() or 1


def run_experiment(parser, args, experiment, setup):
    """Runs one experiment and writes its section; returns the number of failed runs, or None
    for a dry run."""
    jobs = choose_jobs(parser, args, experiment)
    log(f"{experiment.name}: {plural(len(experiment.cells), 'cell')} × "
        f"{plural(len(experiment.variants), 'variant')} × {plural(experiment.repeats, 'run')}; "
        f"work in {setup.work}")
    prepared = prepare_all(parser, experiment, setup, jobs)
    table, all_jobs = expand(experiment, setup, prepared)
    for cell in experiment.cells:
        reasons = {runs.missing for runs in table[cell.name].values() if runs.missing}
        if reasons:
            log(f"{cell.name}: missing ({'; '.join(sorted(reasons))})")
    pending = []
    for job in all_jobs:
        finished = read_result(job["work"], job["key"])
        if finished is None:
            pending.append(job)
        else:
            cell, variant, repeat = job["slot"]
            table[cell][variant].results[repeat] = finished
    log(f"{len(all_jobs)} runs: {len(all_jobs) - len(pending)} have results, {len(pending)} to run")
    if args.dry_run:
        for job in all_jobs:
            state = "to run" if job in pending else "done"
            print(f"{state:7} {job['label']}  {job['key'][:12]}  {shlex.join(job['command'])}")
        return None
    loads = [os.getloadavg()[0]]
    executor = (DaskCluster(args.scheduler, args.retries) if args.scheduler
                else LocalPool(jobs, args.retries))
    executor_text = executor.describe()
    failures = execute(executor, pending, table)
    if args.scheduler:
        executor.close()
    loads.append(os.getloadavg()[0])
    counts = {"runs": len(all_jobs), "new": len(pending) - failures,
              "reused": len(all_jobs) - len(pending)}
    write_report(args, experiment, setup, table, executor_text, counts, loads)
    return failures


def current_experiments(skip=()):
    """Every experiment `all` regenerates, the timing (exclusive) ones last: no download, no
    decision record, not named in `skip`."""
    chosen = []
    for path in sorted((REPO / "bench" / "experiments").glob("*.toml")):
        experiment = experiments.load(path)
        if (not experiment.needs_download() and experiment.record is None
                and experiment.name not in skip):
            chosen.append(experiment)
    return sorted(chosen, key=lambda e: e.exclusive)


def require_clean_commit(parser, setup):
    """`all` measures one commit: the checkout has no changes and the build is of its HEAD."""
    changes = subprocess.run(["git", "-C", str(REPO), "status", "--porcelain",
                              "--untracked-files=no"], capture_output=True, text=True).stdout
    if changes.strip():
        parser.error("the checkout has changes: commit them first (or --allow-dirty)")
    head = subprocess.run(["git", "-C", str(REPO), "rev-parse", "HEAD"], capture_output=True,
                          text=True).stdout.strip()
    built = build_commit(setup)
    if not head or "-dirty" in built or not head.startswith(built.split(" ")[0]):
        parser.error(f"the build is of commit {built}, the checkout at {head[:10]}: rebuild "
                     "first (or --allow-dirty)")


def run_all(parser, args, setup):
    if not args.allow_dirty:
        require_clean_commit(parser, setup)
    skip = [name for name in args.skip.split(",") if name]
    known = [e.name for e in current_experiments()]
    for name in skip:
        if name not in known:
            parser.error(f"--skip: '{name}' is not one of the experiments `all` runs "
                         f"({', '.join(known)})")
    chosen = current_experiments(skip)
    if skip:
        log("all: leaving out " + ", ".join(skip) + " (their sections keep their own commit)")
    log("all: " + ", ".join(e.name + (" (alone)" if e.exclusive else "") for e in chosen))
    failed = []
    for experiment in chosen:
        if run_experiment(parser, args, experiment, setup):
            failed.append(experiment.name)
    if failed:
        log(f"runs failed in {', '.join(failed)}; run the same command again to retry them "
            "(finished runs are kept)")
        return 1
    return 0


def main(argv=None):
    parser, args = parse_arguments(argv)
    experiment = load_experiment(parser, args) if args.command == "run" else None
    setup = make_setup(parser, args)
    setup.work.mkdir(parents=True, exist_ok=True)
    if args.command == "all":
        return run_all(parser, args, setup)
    failures = run_experiment(parser, args, experiment, setup)
    if failures:
        log(f"{failures} runs failed; their cells show it. Run the same command again to retry "
            "them (finished runs are kept)")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
