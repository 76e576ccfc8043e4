#!/usr/bin/env python3
"""Fails when a module of src/pspslam uses a module listed after it in PSPSLAM_MODULES.

usage: module_order.py SRC_DIR   (the src/pspslam folder)

"Uses" is either a link (pspslam_<module> in the module's CMakeLists.txt) or an include of
"pspslam/<module>/..." from one of its sources. The list's order is the dependency order, so a
module can be read, built and tested with only the modules before it.
"""
import pathlib
import re
import sys


def module_list(src):
    text = (src / "CMakeLists.txt").read_text(encoding="utf-8")
    match = re.search(r"set\(PSPSLAM_MODULES([^)]*)\)", text)
    if not match:
        sys.exit(f"{src / 'CMakeLists.txt'}: no set(PSPSLAM_MODULES ...)")
    return match.group(1).split()


def uses(src, module, modules):
    """(what, used module) for every link and include of a pspslam module by `module`."""
    folder = src / module
    cmake = folder / "CMakeLists.txt"
    for number, line in enumerate(cmake.read_text(encoding="utf-8").splitlines(), 1):
        for used in re.findall(r"\bpspslam_(\w+)", line):
            if used in modules:
                yield f"{cmake}:{number}: links pspslam_{used}", used
    for source in sorted(folder.rglob("*")):
        if source.suffix not in (".h", ".cpp"):
            continue
        for number, line in enumerate(source.read_text(encoding="utf-8").splitlines(), 1):
            match = re.match(r'\s*#\s*include\s+"pspslam/(\w+)/', line)
            if match and match.group(1) in modules:
                yield f"{source}:{number}: includes pspslam/{match.group(1)}/", match.group(1)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__.strip().splitlines()[2])
    src = pathlib.Path(sys.argv[1])
    modules = module_list(src)
    position = {name: i for i, name in enumerate(modules)}
    violations = []
    for module in modules:
        for what, used in uses(src, module, position):
            if position[used] > position[module]:
                violations.append(f"{what}, listed after {module}")
    for violation in violations:
        print(violation)
    print(f"{len(modules)} modules, {len(violations)} uses of a module listed later")
    return 1 if violations else 0


if __name__ == "__main__":
    sys.exit(main())
