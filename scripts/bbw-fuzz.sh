#!/usr/bin/env bash
# bbw-fuzz.sh [SECONDS] [--merge] [--only TARGET]: builds the libFuzzer targets in fuzz/ with
# clang into build-fuzz/ (BBW_FUZZ_BUILD_DIR) and runs each for SECONDS (default 60).
#
# Targets: csv, yaml, calib, scenario, scenario_alias, csv_quoted (fuzz/src/entry_points.hpp);
# a target with fuzz/dicts/<target>.dict gets it as its libFuzzer dictionary. Each starts from the
# committed corpus tests/fuzz_corpus/<target>/ plus its working corpus build-fuzz/corpus/<target>/
# (kept between runs). A crash, leak, sanitizer report, uncaught exception or timeout stops that
# target, leaves the input in build-fuzz/artifacts/<target>/ and makes the command fail.
# --merge adds the working-corpus inputs that reach new coverage to tests/fuzz_corpus/<target>/
# (the regression corpus replayed by ./bbw test), without duplicates.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${BBW_FUZZ_BUILD_DIR:-$ROOT/build-fuzz}"
JOBS="${BBW_JOBS:-2}"
SECONDS_PER_TARGET=60
MERGE=0
ONLY=""
TARGETS=(csv yaml calib scenario scenario_alias csv_quoted)

die() { echo "bbw fuzz: $*" >&2; exit 1; }

while [ $# -gt 0 ]; do
  case "$1" in
    --merge) MERGE=1 ;;
    --only) shift; [ $# -gt 0 ] || die "--only needs a target (${TARGETS[*]})"; ONLY="$1" ;;
    -h|--help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    ''|*[!0-9]*) die "unknown argument '$1' (usage: bbw fuzz [SECONDS] [--merge] [--only TARGET])" ;;
    *) SECONDS_PER_TARGET="$1" ;;
  esac
  shift
done
[ "$SECONDS_PER_TARGET" -ge 1 ] || die "SECONDS must be >= 1"
if [ -n "$ONLY" ]; then
  case " ${TARGETS[*]} " in *" $ONLY "*) TARGETS=("$ONLY") ;; *) die "unknown target '$ONLY' (${TARGETS[*]})" ;; esac
fi
command -v clang++ >/dev/null 2>&1 || die "clang++ not found (./bbw setup installs clang and libclang-rt-14-dev)"

cmake -S "$ROOT/fuzz" -B "$BUILD" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$BUILD" -j "$JOBS" >/dev/null || { cmake --build "$BUILD" -j 1; die "build failed"; }

# Inputs above this are not interesting for line-based readers and only slow the search.
max_len() { case "$1" in csv|csv_quoted) echo 4096 ;; *) echo 8192 ;; esac; }
dict_arg() { [ -f "$ROOT/fuzz/dicts/$1.dict" ] && echo "-dict=$ROOT/fuzz/dicts/$1.dict" || true; }

failed=()
summary=()
for t in "${TARGETS[@]}"; do
  seeds="$ROOT/tests/fuzz_corpus/$t"
  work="$BUILD/corpus/$t"
  art="$BUILD/artifacts/$t"
  log="$BUILD/logs/$t.log"
  mkdir -p "$seeds" "$work" "$art" "$(dirname "$log")"
  echo "bbw fuzz: $t for ${SECONDS_PER_TARGET} s (log $log)"
  set +e
  # -timeout: one input taking more than 10 s is a finding (a hang); -rss_limit_mb bounds memory.
  ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    "$BUILD/fuzz_$t" -max_total_time="$SECONDS_PER_TARGET" -max_len="$(max_len "$t")" -timeout=10 $(dict_arg "$t") \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$art/" "$work" "$seeds" >"$log" 2>&1
  rc=$?
  set -e
  execs="$(grep -m1 -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)"
  cov="$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || true)"
  units="$(ls "$work" | wc -l)"
  if [ "$rc" -ne 0 ]; then
    failed+=("$t")
    summary+=("$t: FAILED (exit $rc) after ${execs:-?} execs; input in $art/; see $log")
    grep -m5 -E "ERROR|SUMMARY|deadly|uncaught|runtime error|Timeout|terminate" "$log" | sed "s/^/  $t: /" || true
  else
    summary+=("$t: ok, ${execs:-?} execs in ${SECONDS_PER_TARGET} s, coverage ${cov:-?} edges, working corpus ${units} inputs")
  fi
  if [ "$MERGE" -eq 1 ] && [ "$rc" -eq 0 ]; then
    before="$(ls "$seeds" | wc -l)"
    # Edge coverage only (-use_counters=0): a small corpus, one input per new branch.
    "$BUILD/fuzz_$t" -merge=1 -use_counters=0 -max_len="$(max_len "$t")" "$seeds" "$work" >"$BUILD/logs/$t.merge.log" 2>&1 ||
      die "merge for $t failed (see $BUILD/logs/$t.merge.log)"
    summary+=("$t: regression corpus $before -> $(ls "$seeds" | wc -l) inputs")
  fi
done
printf 'bbw fuzz: %s\n' "${summary[@]}"
[ ${#failed[@]} -eq 0 ] || die "findings in: ${failed[*]} (fix, then copy the input to tests/fuzz_corpus/<target>/)"
