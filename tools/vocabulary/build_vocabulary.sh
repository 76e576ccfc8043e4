#!/usr/bin/env bash
# Rebuilds the vocabulary pspslam ships (models/vocabulary/orb_k10_l5.pspvoc) from data any
# Debian 12 machine can obtain: the photographs of four Debian "main" wallpaper packages plus
# synthetic frames rendered by our synth library with seeds 1000-1019 (tests and benchmarks use
# seeds below 1000). Never trained on the sequences we evaluate on.
#
# usage: tools/vocabulary/build_vocabulary.sh [OUT_FILE]
#   PSPSLAM=path/to/pspslam   the CLI to use (default: build/apps/pspslam, then build-*/apps/pspslam)
#   EXTRA_FLAGS="..."         extra flags for `pspslam vocab train` (e.g. "--levels 6")
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
out="${1:-$root/models/vocabulary/orb_k10_l5.pspvoc}"

# Debian main, licences in /usr/share/doc/<package>/copyright (see models/vocabulary/README.md).
packages=(lomiri-wallpapers-16.04 lomiri-wallpapers-20.04 ukui-wallpapers mate-backgrounds)

if [[ -z "${PSPSLAM:-}" ]]; then
  for candidate in "$root/build/apps/pspslam" "$root"/build-*/apps/pspslam; do
    if [[ -x "$candidate" ]]; then PSPSLAM="$candidate"; break; fi
  done
fi
if [[ -z "${PSPSLAM:-}" || ! -x "$PSPSLAM" ]]; then
  echo "error: pspslam CLI not found; build it (cmake --build build --target pspslam_cli) or set PSPSLAM" >&2
  exit 2
fi

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if (( ${#missing[@]} > 0 )); then
  echo "installing ${missing[*]}"
  sudo_cmd=()
  if [[ "$(id -u)" != 0 ]]; then sudo_cmd=(sudo); fi
  "${sudo_cmd[@]}" apt-get update
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y --no-install-recommends "${missing[@]}"
fi

# Exactly the packages' pictures (not whatever else lies in /usr/share/backgrounds), once each:
# links in a staging folder, duplicates by content dropped. MATE's abstract/desktop pictures are
# drawings, only its nature/ photographs are used.
stage="$(mktemp -d)"
trap 'rm -rf "$stage"' EXIT
declare -A seen
count=0
for package in "${packages[@]}"; do
  mkdir -p "$stage/$package"
  while IFS= read -r file; do
    if [[ "$package" == mate-backgrounds && "$file" != */nature/* ]]; then continue; fi
    sum="$(md5sum "$file" | cut -d' ' -f1)"
    if [[ -n "${seen[$sum]:-}" ]]; then continue; fi
    seen[$sum]=1
    ln -s "$file" "$stage/$package/$(basename "$file")"
    count=$((count + 1))
  done < <(dpkg -L "$package" | grep -iE '\.(jpe?g|png)$' | sort)
done
echo "$count photographs from ${packages[*]}"

mkdir -p "$(dirname "$out")"
# shellcheck disable=SC2086
"$PSPSLAM" vocab train \
  --images "$stage/lomiri-wallpapers-16.04" --images "$stage/lomiri-wallpapers-20.04" \
  --images "$stage/ukui-wallpapers" --images "$stage/mate-backgrounds" \
  --synthetic-frames 400 --synthetic-seed 1000 \
  --k 10 --levels 5 --max-descriptors 1000000 --iterations 10 --seed 1 \
  --out "$out" ${EXTRA_FLAGS:-}
"$PSPSLAM" vocab info --vocabulary "$out"
