#!/usr/bin/env bash
# saloam developer entry point.
#   ./run.sh demo   install dependencies, build, run the full system on a
#                   simulated sequence it makes itself (results in demo_output/)
#   ./run.sh test   install dependencies, build, run the whole test suite
#   ./run.sh build | deps | bench
set -euo pipefail
cd "$(dirname "$0")"

BUILD_DIR="${BUILD_DIR:-build}"
JOBS="${JOBS:-$(nproc)}"

deps() { bash scripts/install_deps.sh; }

build() {
  deps
  local generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    cmake -S . -B "$BUILD_DIR" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release
  fi
  cmake --build "$BUILD_DIR" -j "$JOBS"
}

command="${1:-}"
[ $# -gt 0 ] && shift
case "$command" in
  deps) deps ;;
  build) build ;;
  demo)
    build
    "$BUILD_DIR/saloam" demo --out "${DEMO_OUT:-demo_output}" "$@"
    ;;
  test)
    build
    ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" "$@"
    ;;
  bench)
    build
    for b in "$BUILD_DIR"/bench/bench_*; do
      [ -x "$b" ] && "$b" "$@"
    done
    ;;
  *)
    echo "usage: ./run.sh demo|test|build|deps|bench" >&2
    exit 1
    ;;
esac
