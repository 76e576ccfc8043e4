#!/usr/bin/env python3
"""Every path, command and flag the README, CONTRIBUTING.md and docs/ name exists.

  check_docs.py SOURCE_DIR PSPSLAM_BINARY BUILD_DIR

Checked in each page, in its code (inline spans and fenced blocks) and links:
  - links to files of the repository, relative to the page;
  - repository paths (src/..., docs/..., bench/experiments/X.toml, scripts/X, ...), globs
    included, and file names alone (`tracking_module.h`) somewhere in the repository;
  - `make TARGET` against the Makefile, `pspslam COMMAND [SUBCOMMAND]` against the program,
    and every --flag on a `pspslam` or `bench/runner.py` line against that command's --help;
    a --flag alone in prose must be a flag of some pspslam command or of the runner;
  - `ctest -R PATTERN` against the tests of the build;
  - docs/architecture.md's numbered steps of a frame against the comments of
    TrackingModule::process (src/pspslam/system/tracking_module.cpp): each step the code numbers
    is the page's step of that number, named by the same first words.
Prints one line per problem (page:line: what) and exits 1 when there is any.
"""

import fnmatch
import re
import subprocess
import sys
from pathlib import Path

TOP_FOLDERS = ("src", "apps", "tests", "bench", "docs", "python", "examples", "tools", "config",
               "models", "scripts", "cmake", "web", "fuzz", ".ci")
PATH_RE = re.compile(r"(?<![\w./-])((?:%s)/[\w./*{},+<>-]*)" %
                     "|".join(re.escape(f) for f in TOP_FOLDERS))
# Names of the repository's own code (a YAML or image name is usually the reader's file).
FILE_NAME_RE = re.compile(r"^[\w-]+\.(?:h|cpp|py|toml|sh|js|html)$")
FLAG_RE = re.compile(r"(?<![\w-])(--[a-z][a-z0-9_-]*[a-z0-9])(?![\w*-])")
# A commit a paragraph names: what it cites may be code of that commit, removed since.
COMMIT_RE = re.compile(r"\b[0-9a-f]{7,12}\b")
# Files that are not in the repository: TUM's tools, what scripts/install-deps installs.
EXTERNAL = ("associate.py", "web/node_modules")
LINK_RE = re.compile(r"\]\(([^)\s]+)\)")
SPAN_RE = re.compile(r"`([^`]+)`")
# Placeholders that stand for a name the reader chooses.
PLACEHOLDER_RE = re.compile(r"<[^>]*>|\b[A-Z][A-Z_]{2,}\b|\.\.\.|\bNAME\b")
# Flags of other programs that the pages mention (cmake, ctest, git, pytest, npm, apt, sudo).
OTHER_PROGRAMS_FLAGS = {"--install", "--prefix", "--build", "--target", "--output-on-failure",
                        "--gtest_filter", "--help", "--version", "--no-install-recommends",
                        "--preset", "--config", "--parallel", "--test-dir", "--rerun-failed"}
# Pages or lines that show wrong input on purpose: docs/reliability.md's table (the output of
# tests/cli/bad_inputs.sh) and "did you mean" examples.
DELIBERATELY_WRONG = re.compile(r"did you mean")


def pages(source):
    found = [source / "README.md", source / "CONTRIBUTING.md"]
    found += sorted((source / "docs").rglob("*.md"))
    return found


def code_lines(text):
    """(line number, code) for every inline code span and every line of a fenced block."""
    fenced = False
    for number, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        if fenced:
            yield number, line.split("#", 1)[0] if not line.lstrip().startswith("#") else ""
        else:
            for span in SPAN_RE.findall(line):
                yield number, span


def repository_files(source):
    listed = subprocess.run(["git", "ls-files"], cwd=source, check=True, capture_output=True,
                            text=True).stdout.split()
    return set(listed)


class Program:
    """The flags and commands of `pspslam` and of bench/runner.py, read from their --help."""

    def __init__(self, binary, source):
        self.binary = binary
        self.commands = {}
        top = self.help([])
        self.global_flags = set(FLAG_RE.findall(top))
        for name in self.subcommand_names(top):
            text = self.help([name])
            subs = self.subcommand_names(text)
            self.commands[name] = set(FLAG_RE.findall(text)) | self.global_flags
            for sub in subs:
                self.commands[f"{name} {sub}"] = (set(FLAG_RE.findall(self.help([name, sub]))) |
                                                  self.global_flags)
        runner = [sys.executable, str(source / "bench" / "runner.py")]
        self.runner_flags = set()
        for sub in ("run",) + tuple(self.runner_subcommands(runner)):
            self.runner_flags |= set(FLAG_RE.findall(subprocess.run(
                runner + [sub, "--help"], capture_output=True, text=True).stdout))
        self.all_flags = set().union(*self.commands.values()) | self.runner_flags

    def help(self, words):
        return subprocess.run([self.binary] + words + ["--help"], capture_output=True,
                              text=True).stdout

    @staticmethod
    def subcommand_names(text):
        if "SUBCOMMAND" not in text and "Subcommands:" not in text:
            return []
        names = []
        in_list = False
        for line in text.splitlines():
            if line.strip().lower().startswith("subcommands"):
                in_list = True
                continue
            if in_list:
                match = re.match(r"^\s{2}([a-z][a-z-]*)\s", line)
                if match:
                    names.append(match.group(1))
                elif line.strip() and not line.startswith(" "):
                    in_list = False
        return names

    @staticmethod
    def runner_subcommands(runner):
        text = subprocess.run(runner + ["--help"], capture_output=True, text=True).stdout
        match = re.search(r"\{([a-z,-]+)\}", text)
        return match.group(1).split(",") if match else []


def check_path(token, source, files, folders):
    token = token.rstrip(".,;:")
    if PLACEHOLDER_RE.search(token) or not token:
        return True
    token = token.rstrip("/")
    if "*" in token or "{" in token:
        pattern = re.sub(r"\{([^}]*)\}", "*", token)
        return any(fnmatch.fnmatch(f, pattern) for f in files) or any(
            fnmatch.fnmatch(d, pattern) for d in folders)
    return token in files or token in folders or (source / token).exists()


def check_command(code, program, makefile_targets):
    """Problems of one code line: make targets, pspslam commands and flags, runner flags."""
    problems = []
    for target in re.findall(r"(?<![\w-])make\s+([a-z][\w-]*)", code):
        if target not in makefile_targets:
            problems.append(f"make {target}: no such Makefile target")
    match = re.search(r"(?:^|[\s/(])pspslam\s+(.*)$", code)
    if match:
        words = [w for w in match.group(1).split() if not w.startswith("-")]
        command = None
        if words and words[0] in program.commands:
            command = words[0]
            if len(words) > 1 and f"{words[0]} {words[1]}" in program.commands:
                command = f"{words[0]} {words[1]}"
        elif words and re.fullmatch(r"[a-z]+", words[0]) and not words[0] in ("is", "a"):
            problems.append(f"pspslam {words[0]}: no such command")
        flags = set(FLAG_RE.findall(match.group(1)))
        known = program.commands.get(command, program.global_flags) if command else \
            program.all_flags
        for flag in sorted(flags - known):
            problems.append(f"{flag}: not a flag of pspslam {command or ''}".rstrip())
        return problems
    if "runner.py" in code:
        for flag in sorted(set(FLAG_RE.findall(code)) - program.runner_flags - {"--help"}):
            problems.append(f"{flag}: not a flag of bench/runner.py")
        return problems
    return problems


def paragraph_commits(text, source):
    """For each line number, the commits its paragraph names (that exist in the repository)."""
    commits, paragraph, start = {}, [], 1
    lines = text.splitlines() + [""]
    for number, line in enumerate(lines, 1):
        if line.strip():
            paragraph.append(line)
            continue
        named = {c for c in COMMIT_RE.findall(" ".join(paragraph)) if subprocess.run(
            ["git", "cat-file", "-e", c + "^{commit}"], cwd=source,
            capture_output=True).returncode == 0}
        for n in range(start, number):
            commits[n] = named
        paragraph, start = [], number + 1
    return commits


def at_commit(token, commits, source, path):
    """Whether `token` (a path when `path`, else a name or flag) is in the tree of one of the
    commits."""
    for commit in commits:
        if path:
            if subprocess.run(["git", "cat-file", "-e", f"{commit}:{token}"], cwd=source,
                              capture_output=True).returncode == 0:
                return True
        elif subprocess.run(["git", "grep", "-q", "-F", "-e", token, commit], cwd=source,
                            capture_output=True).returncode == 0:
            return True
    return False


def script_flags_problems(code, source):
    """A repository script's flags on the line must appear in the script."""
    problems = []
    for script in re.findall(r"(?<![\w/])((?:scripts|tools|bench)/[\w./-]+)", code):
        file = source / script
        if not file.is_file() or script.endswith("runner.py"):
            continue
        text = file.read_text(errors="replace")
        for flag in FLAG_RE.findall(code.split(script, 1)[1]):
            if flag not in text:
                problems.append(f"{flag}: not a flag of {script}")
    return problems


def code_problems(code, source, files, folders, program, makefile_targets, tests):
    problems = []
    for token in PATH_RE.findall(code):
        token = token.rstrip(".,;:")
        if token.startswith(EXTERNAL) or check_path(token, source, files, folders):
            continue
        in_history = "git log" in code and subprocess.run(
            ["git", "log", "-1", "--format=%h", "--", token], cwd=source, capture_output=True,
            text=True).stdout.strip()
        if not in_history:
            problems.append((token, True, f"{token}: no such path"))
    for token in code.split():
        token = token.strip("(),;:'\"")
        if (FILE_NAME_RE.match(token) and "/" not in token and token not in EXTERNAL and
                not PLACEHOLDER_RE.search(token) and not any(Path(f).name == token
                                                              for f in files)):
            problems.append((token, False, f"{token}: no such file in the repository"))
    for problem in check_command(code, program, makefile_targets):
        problems.append((problem.split(":")[0].split()[-1], False, problem))
    for problem in script_flags_problems(code, source):
        problems.append((problem.split(":")[0], False, problem))
    if code.lstrip().startswith("--"):  # a flag alone: of pspslam or the runner
        for flag in FLAG_RE.findall(code):
            if flag not in program.all_flags and flag not in OTHER_PROGRAMS_FLAGS:
                problems.append((flag, False, f"{flag}: not a flag of pspslam or "
                                              "bench/runner.py"))
    for pattern in re.findall(r"ctest\s+(?:[\w-]+\s+)*-R\s+'?([\w.*|\\-]+)", code):
        if not any(re.search(pattern, test) for test in tests):
            problems.append((pattern, False, f"ctest -R {pattern}: matches no test"))
    return problems


def check_page(page, source, files, folders, program, makefile_targets, tests):
    text = page.read_text()
    relative = page.relative_to(source)
    commits = paragraph_commits(text, source)
    lines = text.splitlines()
    problems = []
    for number, line in enumerate(lines, 1):
        for link in LINK_RE.findall(line):
            if re.match(r"^[a-z]+:", link) or link.startswith("#"):
                continue
            target = (page.parent / link.split("#", 1)[0]).resolve()
            if not target.exists():
                problems.append(f"{relative}:{number}: link {link}: no such file")
    for number, code in code_lines(text):
        line = lines[number - 1]
        if DELIBERATELY_WRONG.search(line) or (
                str(relative) == "docs/reliability.md" and line.startswith("|")):
            continue
        for token, is_path, problem in code_problems(code, source, files, folders, program,
                                                     makefile_targets, tests):
            if not at_commit(token, commits.get(number, ()), source, is_path):
                problems.append(f"{relative}:{number}: {problem}")
    return problems


def step_titles(text, pattern):
    """{number: first three words, lower case} of the numbered steps that match pattern."""
    steps = {}
    for match in re.finditer(pattern, text, re.MULTILINE):
        words = re.findall(r"[a-z0-9-]+", match.group(2).lower())[:3]
        steps[int(match.group(1))] = " ".join(words)
    return steps


def check_steps(source):
    code = step_titles((source / "src/pspslam/system/tracking_module.cpp").read_text(),
                       r"^\s*// (\d)\. (.*)$")
    page = step_titles((source / "docs/architecture.md").read_text(), r"^\s+│ (\d) (.*)$")
    problems = []
    if not code:
        problems.append("tracking_module.cpp: no numbered steps found")
    if sorted(code) != sorted(page):
        problems.append(f"docs/architecture.md: steps {sorted(page)}, the code's {sorted(code)}")
    for number, words in sorted(code.items()):
        if number in page and page[number] != words:
            problems.append(f"docs/architecture.md: step {number} is '{page[number]}...', the "
                            f"code's is '{words}...'")
    return problems


def main():
    source, binary, build = Path(sys.argv[1]), sys.argv[2], Path(sys.argv[3])
    files = repository_files(source)
    folders = {str(Path(f).parents[i]) for f in files for i in range(len(Path(f).parts) - 1)}
    program = Program(binary, source)
    makefile_targets = set(re.findall(r"^([a-z][\w-]*):", (source / "Makefile").read_text(),
                                      re.MULTILINE))
    tests = re.findall(r"Test\s+#\d+: (\S+)", subprocess.run(
        ["ctest", "-N"], cwd=build, capture_output=True, text=True).stdout)
    problems = []
    for page in pages(source):
        problems += check_page(page, source, files, folders, program, makefile_targets, tests)
    problems += check_steps(source)
    for problem in problems:
        print(problem)
    print(f"{len(pages(source))} pages, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
