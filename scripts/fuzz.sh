#!/usr/bin/env bash
# Builds one libFuzzer target with clang (Debian's clang and libclang-rt: libFuzzer, ASan, UBSan) in build/fuzz and
# runs it for SECONDS over its seed inputs (fuzz/corpus/TARGET) and a work corpus that keeps every new interesting
# input (build/fuzz/corpus/TARGET). A crash, hang, leak or undefined behaviour stops the run; the input is written
# under build/fuzz/crashes/TARGET/ (printed). The normal build needs no clang: it only replays the seeds
# (ctest -L fuzz). docs/results/fuzzing.md.
set -euo pipefail
cd "$(dirname "$0")/.."

TARGETS=(rawlog config scenario qp set dds_sample)
usage() {
  cat <<USAGE
usage: scripts/fuzz.sh TARGET SECONDS [--keep-going] [--no-build] [--json]
       scripts/fuzz.sh --list | --help
Builds fuzz_TARGET with clang, -fsanitize=fuzzer,address,undefined (build/fuzz) and fuzzes it for SECONDS.
New interesting inputs go to build/fuzz/corpus/TARGET, crashers to build/fuzz/crashes/TARGET/, the log to
build/fuzz/logs/TARGET.log. At the end: seconds, executions, corpus size, coverage (cov, ft) and findings;
--no-build: run build/fuzz/fuzz/fuzz_TARGET as it is (another build of build/fuzz is running).
--keep-going: libFuzzer's fork mode, which keeps fuzzing after a crash or hang (each crasher kept) for the whole
time. --json prints the figures as one JSON object. Exit status: 0 nothing found, 1 a finding, 2 bad usage or build failure.
Targets: ${TARGETS[*]}
USAGE
}
fail() { echo "fuzz.sh: $*" >&2; exit 2; }

json=0
keep_going=()
build_it=1
args=()
for a in "$@"; do
  case "$a" in
    --help|-h) usage; exit 0 ;;
    --list) printf '%s\n' "${TARGETS[@]}"; exit 0 ;;
    --json) json=1 ;;
    --no-build) build_it=0 ;;
    --keep-going) keep_going=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1) ;;
    -*) fail "unknown option '$a' (see --help)" ;;
    *) args+=("$a") ;;
  esac
done
[ ${#args[@]} -eq 2 ] || fail "expected TARGET SECONDS (see --help)"
target=${args[0]}
seconds=${args[1]}
[[ " ${TARGETS[*]} " == *" $target "* ]] || fail "unknown target '$target' (targets: ${TARGETS[*]})"
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] || fail "SECONDS must be a whole number of seconds > 0, got '$seconds'"
command -v clang++ >/dev/null || fail "clang++ not found: bash scripts/install-deps.sh installs clang"
[ -n "$(clang++ -print-file-name=libclang_rt.fuzzer-x86_64.a | grep /)" ] && \
  [ -f "$(clang++ -print-file-name=libclang_rt.fuzzer-x86_64.a)" ] || \
  fail "libFuzzer not found: bash scripts/install-deps.sh installs libclang-rt-dev"

build=build/fuzz
if [ $build_it -eq 0 ]; then
  [ -x "$build/fuzz/fuzz_$target" ] || fail "--no-build: $build/fuzz/fuzz_$target is not built"
elif [ ! -f "$build/build.ninja" ]; then
  cmake -S . -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
    -DMFT_FUZZ=ON -DMFT_BUILD_TESTS=OFF -DMFT_BUILD_BENCH=OFF >/dev/null || fail "configuring $build failed"
fi
if [ $build_it -eq 1 ]; then
  cmake --build "$build" -j "${MFT_BUILD_JOBS:-$(nproc)}" --target "fuzz_$target" >"$build/build-$target.log" 2>&1 || {
    tail -20 "$build/build-$target.log" >&2; fail "building fuzz_$target failed (log: $build/build-$target.log)"; }
fi

work="$build/corpus/$target"
crashes="$build/crashes/$target"
log="$build/logs/$target.log"
mkdir -p "$work" "$crashes" "$build/logs"
echo "fuzz.sh: fuzzing $target for $seconds s; new inputs: $work; crashers: $crashes/; log: $log" >&2
started="$build/logs/$target.started"
touch "$started"
load_start=$(cut -d' ' -f1 /proc/loadavg)
started_utc=$(date -u +%Y-%m-%dT%H:%MZ)
# the code fuzzed: the commit at the start, marked when files other than the docs differ from it
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
git diff --quiet HEAD -- . ':(exclude)docs' ':(exclude)*.md' 2>/dev/null || commit="$commit+changes"
status=0
ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1} \
  "$build/fuzz/fuzz_$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
  "${keep_going[@]}" -artifact_prefix="$crashes/" "$work" "fuzz/corpus/$target" >"$log" 2>&1 || status=$?

# libFuzzer's last status line ("#N DONE cov: C ft: F corp: K/..." or, in fork mode, "#N: cov: C ft: F corp: K
# ... time: Ts") and its final statistics.
last=$(grep -E '^#[0-9]+' "$log" | grep ' cov: ' | tail -1 || true)
field() { echo "$last" | sed -nE "s/.* $1: ([0-9]+).*/\1/p"; }
execs=$(sed -nE 's/^stat::number_of_executed_units: ([0-9]+)/\1/p' "$log" | tail -1)
execs=${execs:-$(echo "$last" | sed -nE 's/^#([0-9]+).*/\1/p')}
ran=$(sed -nE 's/^Done [0-9]+ runs in ([0-9]+) second.*/\1/p' "$log" | tail -1)
ran=${ran:-$(field time)}
corpus=$(field corp)
found=$(find "$crashes" -type f -newer "$started" | wc -l)  # this run's
finding=""
if [ "$status" -ne 0 ] || [ "$found" -gt 0 ]; then
  finding=$(grep -m1 -E '(==ERROR|runtime error:|ALARM: working on the last Unit|deadly signal|out-of-memory|uncaught exception)' "$log" ||
            echo "exit status $status")
fi
if [ $json -eq 1 ]; then
  # where and when: the figures depend on the machine's load (libFuzzer's rate), so the JSON says what it was
  printf '{"target": "%s", "seconds": %s, "executions": %s, "corpus": %s, "cov": %s, "ft": %s, "crashers": %s, "finding": "%s", "commit": "%s", "started_utc": "%s", "cores": %s, "load_1min_start": %s, "load_1min_end": %s}\n' \
    "$target" "${ran:-0}" "${execs:-0}" "${corpus:-0}" "$(field cov || true)" "$(field ft || true)" "$found" \
    "$(echo "$finding" | tr -d '"\\' | cut -c1-200)" "$commit" "$started_utc" "$(nproc)" "$load_start" \
    "$(cut -d' ' -f1 /proc/loadavg)" | sed -E 's/: ,/: null,/g'
else
  echo "$target: ${ran:-?} s, ${execs:-?} executions, corpus ${corpus:-?}, cov $(field cov) ft $(field ft), crashers in $crashes/: $found"
  [ -z "$finding" ] || echo "$target: finding: $finding (log: $log)"
fi
[ -z "$finding" ] || exit 1
