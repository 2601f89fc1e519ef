#!/usr/bin/env bash
# Runs one CTest test again and again, each run in a private network namespace, until it fails or COUNT runs
# passed; optionally with one CPU kept busy by a busy loop this script starts (and stops, by pid). Prints a
# line per run (duration, load average) and a summary; the output of every run is kept in a file.
# Test reliability figures in docs/guide/testing.md come from this script.
set -u

usage() {
  cat <<'EOF'
usage: scripts/repeat-tests.sh NAME COUNT [--busy-core | --busy-all] [--cpu N] [--build-dir DIR] [--log-dir DIR]
                               [--results FILE]

Runs the CTest test NAME (exact name, e.g. security_stack) up to COUNT times, stopping at the first failure.
Each run: unshare -n sh -c 'ip link set lo up; ctest --test-dir DIR -R "^NAME$" --output-on-failure'
(a private network namespace: DDS domains of other users never collide). Needs root (unshare -n).

  --busy-core      keep one CPU busy with a shell busy loop pinned to it (taskset) for the whole series
  --busy-all       keep every CPU this script may use busy, one busy loop pinned to each (another job loading
                   both cores of a 2-core machine)
  --cpu N          the CPU to keep busy with --busy-core (default: the last one)
  --build-dir DIR  the CTest build folder (default: build/release)
  --log-dir DIR    where the output of every run is kept, run-N.log (default: a new folder under /tmp)
  --results FILE   append one tab-separated line: date, name, busy, runs, passes, first failure,
                   min/median/max duration s, load average (1 min) at start and end
Exit status: 0 when all COUNT runs passed, 1 at a failure, 2 on bad usage.
EOF
}

die() { echo "repeat-tests.sh: $*" >&2; exit 2; }

[ $# -ge 1 ] && { [ "$1" = "--help" ] || [ "$1" = "-h" ]; } && { usage; exit 0; }
[ $# -ge 2 ] || { usage >&2; exit 2; }
name=$1
count=$2
shift 2
case "$count" in '' | *[!0-9]*) die "COUNT must be a positive whole number, not '$count'" ;; esac
[ "$count" -ge 1 ] || die "COUNT must be at least 1"
busy=0
cpu=$(( $(nproc) - 1 ))
build_dir=build/release
log_dir=
results=
while [ $# -gt 0 ]; do
  case "$1" in
    --busy-core) busy=1 ;;
    --busy-all) busy=all ;;
    --cpu) [ $# -ge 2 ] || die "--cpu needs a CPU number"; cpu=$2; shift ;;
    --build-dir) [ $# -ge 2 ] || die "--build-dir needs a folder"; build_dir=$2; shift ;;
    --log-dir) [ $# -ge 2 ] || die "--log-dir needs a folder"; log_dir=$2; shift ;;
    --results) [ $# -ge 2 ] || die "--results needs a file"; results=$2; shift ;;
    -h | --help) usage; exit 0 ;;
    *) die "unknown option '$1' (see --help)" ;;
  esac
  shift
done
case "$cpu" in '' | *[!0-9]*) die "--cpu must be a CPU number, not '$cpu'" ;; esac
[ -d "$build_dir" ] || die "no build folder $build_dir (build first: bash scripts/build.sh release)"
command -v unshare >/dev/null || die "unshare (util-linux) is not installed"
[ "$busy" = 0 ] || command -v taskset >/dev/null || die "taskset (util-linux) is not installed"
listed=$(ctest --test-dir "$build_dir" -N -R "^${name}\$" 2>/dev/null | grep -c "Test *#")
[ "$listed" = 1 ] || die "no CTest test named '$name' in $build_dir (ctest --test-dir $build_dir -N lists them)"
[ -n "$log_dir" ] || log_dir=$(mktemp -d "/tmp/repeat-${name}-XXXXXX")
mkdir -p "$log_dir" || die "cannot create $log_dir"

busy_pids=()
stop_busy() {
  for pid in "${busy_pids[@]}"; do
    kill "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
  done
  busy_pids=()
}
trap 'stop_busy; exit 130' INT TERM
trap stop_busy EXIT
busy_cpus=
[ "$busy" = 1 ] && busy_cpus=$cpu
[ "$busy" = all ] && busy_cpus=$(taskset -cp $$ | sed 's/.*: //' | tr ',' '\n' |
  awk -F- '{ if (NF == 2) for (c = $1; c <= $2; c++) print c; else print $1 }' | tr '\n' ' ')
for c in $busy_cpus; do
  taskset -c "$c" sh -c 'while :; do :; done' &
  busy_pids+=($!)
  echo "busy loop pid $! on CPU $c"
done

load1() { cut -d' ' -f1 /proc/loadavg; }
load_start=$(load1)
durations=()
passes=0
first_failure=-
for i in $(seq 1 "$count"); do
  out="$log_dir/run-$i.log"
  t0=$(date +%s.%N)
  unshare -n sh -c "ip link set lo up && ctest --test-dir '$build_dir' -R '^${name}\$' --output-on-failure" >"$out" 2>&1
  code=$?
  t1=$(date +%s.%N)
  d=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
  durations+=("$d")
  # A pass is CTest's own verdict for exactly one test (a missing test also exits 0).
  if [ "$code" = 0 ] && grep -q "100% tests passed, 0 tests failed out of 1" "$out"; then
    passes=$((passes + 1))
    echo "$name run $i: passed in $d s (load $(load1))"
  else
    first_failure=$i
    echo "$name run $i: FAILED (exit $code) after $d s (load $(load1)); output kept in $out"
    tail -n 60 "$out"
    break
  fi
done
runs=${#durations[@]}
stats=$(printf '%s\n' "${durations[@]}" | sort -n | awk '{ v[NR] = $1 } END { printf "%s\t%s\t%s", v[1], v[int((NR + 1) / 2)], v[NR] }')
load_end=$(load1)
busy_text=no
[ -n "$busy_cpus" ] && busy_text="CPU $(echo $busy_cpus | tr ' ' ',')"
echo "$name: $passes of $runs runs passed (busy core: $busy_text); duration min/median/max $(echo "$stats" | tr '\t' '/') s;" \
     "load average at start $load_start, at end $load_end"
if [ -n "$results" ]; then
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$(date -u +%FT%TZ)" "$name" "$busy_text" "$runs" "$passes" \
    "$first_failure" "$stats" "$load_start" "$load_end" >>"$results"
fi
[ "$passes" = "$count" ]
