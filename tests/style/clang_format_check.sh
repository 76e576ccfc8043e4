#!/usr/bin/env bash
# Every C++ source of the project is as clang-format (.clang-format) writes it.
# usage: tests/style/clang_format_check.sh SOURCE_DIR
set -euo pipefail
root=${1:?usage: clang_format_check.sh SOURCE_DIR}
if ! command -v clang-format >/dev/null; then
  echo "clang-format not found (scripts/install-deps installs it)" >&2
  exit 1
fi
cd "$root"
mapfile -t files < <(find apps bench fuzz python src tests -type f \( -name '*.cpp' -o -name '*.h' \) | sort)
if [[ ${#files[@]} -lt 300 ]]; then
  echo "found only ${#files[@]} C++ files under $root: not the source tree?" >&2
  exit 1
fi
bad=()
for f in "${files[@]}"; do
  clang-format --dry-run --Werror "$f" >/dev/null 2>&1 || bad+=("$f")
done
if [[ ${#bad[@]} -gt 0 ]]; then
  echo "not clang-formatted (run: clang-format -i FILE):" >&2
  printf '  %s\n' "${bad[@]}" >&2
  exit 1
fi
echo "${#files[@]} files clang-formatted"
