#!/usr/bin/env bash
# saloam developer entry point.
#   ./run.sh demo   install dependencies, build, run the full system on a
#                   simulated sequence it makes itself (results in demo_output/)
#   ./run.sh test   install dependencies, build, run the whole test suite
#   ./run.sh test-sanitize
#                   the same suite built with AddressSanitizer + UBSan in
#                   build-sanitize/ (docs/reliability.md)
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

# The whole suite under AddressSanitizer + UndefinedBehaviorSanitizer. -O1 -g1
# keeps the build cheap (line tables are all the reports need) and the tests
# fast enough; no benchmarks. Leak reports of the Debian libraries outside our
# control are suppressed in tests/sanitizers/lsan.supp, each entry with why.
sanitize_env() {
  export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=0:check_initialization_order=1}"
  export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
  export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0}"
}

build_sanitize() {
  deps
  local dir="${SANITIZE_BUILD_DIR:-build-sanitize}"
  local generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  sanitize_env  # the build runs the test programs to list their tests
  if [ ! -f "$dir/CMakeCache.txt" ]; then
    cmake -S . -B "$dir" "${generator[@]}" -DSALOAM_SANITIZE=ON -DSALOAM_BUILD_BENCHMARKS=OFF \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG"
  fi
  cmake --build "$dir" -j "$JOBS"
}

# The tests the sanitizer suite leaves out (tests/sanitizers/release_only.txt,
# each with why), as one CTest regular expression.
release_only_tests() {
  local names
  names=$(grep -v '^[[:space:]]*\(#\|$\)' tests/sanitizers/release_only.txt | sed 's/\./\\./g' | paste -sd'|')
  echo "^(${names})\$"
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
  test-sanitize)
    build_sanitize
    sanitize_env
    ctest --test-dir "${SANITIZE_BUILD_DIR:-build-sanitize}" --output-on-failure -j "$JOBS" \
      -E "$(release_only_tests)" "$@"
    ;;
  bench)
    build
    for b in "$BUILD_DIR"/bench/bench_*; do
      [ -x "$b" ] && "$b" "$@"
    done
    ;;
  *)
    echo "usage: ./run.sh demo|test|test-sanitize|build|deps|bench" >&2
    exit 1
    ;;
esac
