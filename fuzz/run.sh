#!/bin/sh
# fuzz/run.sh -- build one libFuzzer target per reader and run each for
# FUZZ_SECONDS (default 60) from its seed corpus tests/corpus/FORMAT/.
#
#   FUZZ_SECONDS=300 fuzz/run.sh            every format
#   FUZZ_SECONDS=60  fuzz/run.sh ply las    some formats
#
# Targets and their growing corpora live in $FUZZ_BUILD (default
# build-fuzz/); the seed corpus in the repository is only read.  A finding
# leaves crash-*/leak-*/timeout-* files in $FUZZ_BUILD/FORMAT/ and makes the
# script exit 1.  The last line per format is libFuzzer's count of
# executions ("stat::number_of_executed_units").
set -e
cd "$(dirname "$0")/.."
CC=${FUZZ_CC:-clang}
SECONDS_EACH=${FUZZ_SECONDS:-60}
ROOT=$(pwd)
OUT=${FUZZ_BUILD:-build-fuzz}
FORMATS=${*:-"ply obj off stl xyz pcd las npy"}
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
SOURCES="src/io/*.c src/error.c src/memory.c src/parallel.c src/rng.c src/points.c"
status=0
for f in $FORMATS; do
  [ -d "tests/corpus/$f" ] || { echo "fuzz: no seed corpus tests/corpus/$f" >&2; exit 2; }
  mkdir -p "$OUT/$f/corpus"
  # shellcheck disable=SC2086
  $CC -g -O1 -std=c11 -ffp-contract=off -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE \
      -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
      -Iinclude -Isrc -DHD_FUZZ_FORMAT="\"$f\"" fuzz/fuzz_reader.c $SOURCES -lm -lpthread \
      -o "$OUT/fuzz_$f"
  echo "== fuzz_$f: $SECONDS_EACH s"
  if (cd "$OUT/$f" && ASAN_OPTIONS=detect_leaks=1 "../fuzz_$f" -max_total_time="$SECONDS_EACH" \
        -max_len=65536 -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
        corpus "$ROOT/tests/corpus/$f" > log.txt 2>&1); then
    grep -E "stat::number_of_executed_units|stat::new_units_added" "$OUT/$f/log.txt" | sed "s/^/$f: /"
  else
    status=1
    echo "fuzz_$f FOUND A PROBLEM; see $OUT/$f/log.txt:" >&2
    grep -E "ERROR|SUMMARY|Test unit written" "$OUT/$f/log.txt" >&2 || tail -20 "$OUT/$f/log.txt" >&2
  fi
done
exit $status
