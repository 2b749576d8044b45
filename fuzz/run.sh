#!/bin/sh
# fuzz/run.sh -- build the libFuzzer targets (fuzz/fuzz.mk) and run each for
# FUZZ_SECONDS (default 60) from its seed corpus in tests/corpus/.
#
#   fuzz/run.sh                           every target
#   FUZZ_SECONDS=300 fuzz/run.sh ply_sample nifti cli
#   fuzz/run.sh readers | meshes | all    the 9 vertex targets | the 4 sample ones
#
# Targets (docs/formats.md, "Fuzzing"):
#   ply obj off stl xyz pcd las npy laz  a reader as points    seeds tests/corpus/FORMAT/
#   ply_sample ... stl_sample         a mesh's faces sampled seeds tests/corpus/FORMAT/
#   nifti                             a NIfTI mask           seeds tests/corpus/nifti/
#   cli                               the argument parser    seeds tests/corpus/cli/
#
# Environment: FUZZ_BUILD (default build-fuzz/) holds the binaries, and per
# target a directory with its growing corpus, log.txt and any finding;
# FUZZ_FRESH=1 empties each growing corpus first (the smoke test, so a run
# depends on the repository only); FUZZ_JOBS (default 2) build jobs; FUZZ_CC
# (default clang); FUZZ_ARGS more libFuzzer options (e.g. "-fork=1
# -ignore_crashes=1" to go on past a finding; each reproducer written is
# still a finding).  FUZZ_RUNS=N stops each target after N inputs (or
# FUZZ_SECONDS, whichever comes first); FUZZ_SEED=S fixes libFuzzer's
# random seed, so a run draws the same mutations again (the smoke test's 1:
# a failure there replays; the readers' parsing threads still vary the
# coverage they report, and so the corpus, a little).  The seed corpus in
# the repository is only read.
#
# A finding (crash, leak, timeout, undefined behaviour, a broken contract)
# leaves crash-*/leak-*/timeout-*/oom-* in $FUZZ_BUILD/TARGET/, is reported
# with its sanitizer summary, and makes the script exit 1 after running the
# other targets.  Without clang it exits 2: it never passes without fuzzing.
# Per target it prints libFuzzer's count of executions
# ("stat::number_of_executed_units").
set -e
cd "$(dirname "$0")/.."
ROOT=$(pwd)
CC=${FUZZ_CC:-clang}
SECONDS_EACH=${FUZZ_SECONDS:-60}
OUT=${FUZZ_BUILD:-build-fuzz}
JOBS=${FUZZ_JOBS:-2}
READERS="ply obj off stl xyz pcd las npy laz"
MESHES="ply_sample obj_sample off_sample stl_sample"
ALL="$READERS $MESHES nifti cli"

targets=""
for a in ${*:-all}; do
  case "$a" in
    all) targets="$targets $ALL" ;;
    readers) targets="$targets $READERS" ;;
    meshes) targets="$targets $MESHES" ;;
    *) case " $ALL " in
         *" $a "*) targets="$targets $a" ;;
         *) echo "fuzz: unknown target '$a' (targets: $ALL; or all, readers, meshes)" >&2; exit 2 ;;
       esac ;;
  esac
done

if ! command -v "$CC" > /dev/null 2>&1; then
  echo "fuzz: FAILED: $CC not found; the fuzz targets need clang with libFuzzer" >&2
  echo "fuzz: install it with scripts/deps.sh fuzz (as root), i.e. apt-get install clang libclang-rt-14-dev libnifti2-dev" >&2
  exit 2
fi
command -v make > /dev/null 2>&1 || { echo "fuzz: FAILED: make not found" >&2; exit 2; }

mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
bins=""
for t in $targets; do bins="$bins $OUT/fuzz_$t"; done
# shellcheck disable=SC2086
if ! make --no-print-directory -f fuzz/fuzz.mk OUT="$OUT" FUZZ_CC="$CC" -j"$JOBS" $bins > "$OUT/build.log" 2>&1; then
  cat "$OUT/build.log" >&2
  echo "fuzz: FAILED to build the targets (log above, in $OUT/build.log)" >&2
  exit 2
fi

status=0
for t in $targets; do
  seeds="tests/corpus/${t%_sample}"
  [ -d "$seeds" ] || { echo "fuzz: no seed corpus $seeds" >&2; exit 2; }
  [ "${FUZZ_FRESH:-0}" = 1 ] && rm -rf "$OUT/$t/corpus"
  mkdir -p "$OUT/$t/corpus"
  echo "== fuzz_$t: $SECONDS_EACH s${FUZZ_RUNS:+ or $FUZZ_RUNS inputs}${FUZZ_SEED:+ (seed $FUZZ_SEED)} from $seeds/"
  touch "$OUT/$t/.started"
  ok=0
  (cd "$OUT/$t" && ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} "../fuzz_$t" \
        -max_total_time="$SECONDS_EACH" -max_len=65536 -rss_limit_mb=2048 -timeout=10 \
        -print_final_stats=1 ${FUZZ_RUNS:+-runs=$FUZZ_RUNS} ${FUZZ_SEED:+-seed=$FUZZ_SEED} ${FUZZ_ARGS:-} \
        corpus "$ROOT/$seeds" > log.txt 2>&1) && ok=1
  # a finding is a failing exit or a reproducer written during this run
  # (with -fork=N -ignore_crashes=1 there may be many: each is listed)
  found=$(find "$OUT/$t" -maxdepth 1 -newer "$OUT/$t/.started" \
            \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) | sort)
  if [ $ok = 1 ] && [ -z "$found" ]; then
    grep -E "stat::number_of_executed_units|stat::new_units_added" "$OUT/$t/log.txt" | sed "s/^/$t: /"
    # fork mode prints no final stats: its last progress line has the count
    grep -q "stat::number_of_executed_units" "$OUT/$t/log.txt" ||
      grep -E '^#[0-9]+: ' "$OUT/$t/log.txt" | tail -1 | sed "s/^#\([0-9]*\):.*/$t: executed units \1 (fork mode)/"
  else
    status=1
    echo "fuzz_$t FOUND A PROBLEM; see $OUT/$t/log.txt:" >&2
    # the sanitizer's verdict, the top of the first stack, the reproducer
    awk '/ERROR|SUMMARY|Test unit written|crash-|leak-|timeout-|oom-/ { print; next }
         /^ *#[0-5] / && !done { print; if ($1 == "#5") done = 1 }' "$OUT/$t/log.txt" >&2
    grep -q "ERROR\|SUMMARY" "$OUT/$t/log.txt" || tail -20 "$OUT/$t/log.txt" >&2
    [ -z "$found" ] || printf '%s\n' "reproducers of this run:" $found >&2
  fi
done
[ $status = 0 ] && echo "fuzz: no finding in: $targets"
exit $status
