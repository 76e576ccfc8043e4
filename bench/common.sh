# Sourced by the bench/run_*.sh scripts: the repository root, ../shared and the CLI they run.
#   require_cli BUILD_DIR   sets $cli, or exits 2 saying how to build it
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
shared="${PSPSLAM_SHARED:-$root/../shared}"
require_cli() {
  cli="$1/apps/pspslam"
  [[ -x "$cli" ]] || { echo "error: $cli not built (cmake --build $1 --target pspslam_cli)" >&2; exit 2; }
}
