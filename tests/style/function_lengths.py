#!/usr/bin/env python3
"""Lists the functions of the C++ sources longer than a limit, and fails when there is one.

usage: function_lengths.py [--max-lines N] [--report] DIR...

A function's length is counted from the first line of its signature to its closing brace, both
included. The sources are clang-formatted (tests/style/clang_format_check.sh), so a definition
at namespace scope starts at column 0 (a member defined in its class at column 2) and ends with
a brace at the same column; that is what is parsed here, not C++ in general.
"""
import argparse
import pathlib
import re
import sys

NOT_A_FUNCTION = re.compile(
    r"^(namespace|class|struct|union|enum|using|typedef|static_assert|extern|#|//|/\*|\*|}|public:|"
    r"private:|protected:)")


def definitions(lines, indent):
    """(name, first line, line count) of every definition starting at `indent` columns."""
    prefix = " " * indent
    i = 0
    while i < len(lines):
        line = lines[i]
        starts_here = (line.startswith(prefix) and len(line) > indent and line[indent] != " "
                       and not NOT_A_FUNCTION.match(line[indent:]))
        if not starts_here:
            i += 1
            continue
        header_end = i
        # The signature runs until a line that ends with `{` (a body), `;` (a declaration) or `}`
        # (a body on the same line).
        while header_end < len(lines) and not re.search(r"[{;}]\s*$", lines[header_end]):
            header_end += 1
        if header_end >= len(lines):
            break
        header = " ".join(lines[i:header_end + 1])
        if not lines[header_end].rstrip().endswith("{") or "(" not in header or "=" in header.split("(")[0]:
            i = header_end + 1
            continue
        end = header_end + 1
        closing = re.compile(r"^" + prefix + r"}[;)]*\s*$")
        while end < len(lines) and not closing.match(lines[end]):
            end += 1
        name = re.findall(r"([~\w:]+)\s*\(", header)
        yield (name[0] if name else header.strip()[:40]), i + 1, end - i + 1
        i = end + 1


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-lines", type=int, default=100)
    parser.add_argument("--report", action="store_true", help="print every function over the "
                        "limit and the count, and exit 0")
    parser.add_argument("dirs", nargs="+", type=pathlib.Path)
    args = parser.parse_args()
    too_long = []
    for directory in args.dirs:
        if not directory.is_dir():
            sys.exit(f"{directory}: not a directory")
        for path in sorted(directory.rglob("*")):
            if path.suffix not in (".cpp", ".h"):
                continue
            lines = path.read_text(encoding="utf-8").splitlines()
            # Members defined inside their class: headers only (a .cpp's column-2 lines are
            # statements of column-0 functions).
            for indent in (0, 2) if path.suffix == ".h" else (0,):
                for name, first, count in definitions(lines, indent):
                    if count > args.max_lines:
                        too_long.append((count, f"{path}:{first}", name))
    for count, where, name in sorted(too_long, reverse=True):
        print(f"{count:5d}  {where}  {name}")
    print(f"{len(too_long)} functions over {args.max_lines} lines")
    return 0 if args.report or not too_long else 1


if __name__ == "__main__":
    sys.exit(main())
