#!/bin/sh
# The install paths as a user runs them (tests/install.cmake).
#
#   install_check.sh prefix BUILD SOURCE   cmake --install into a temporary
#       prefix; a C program built with pkg-config and one with CMake's
#       find_package(hausdorff), each run and its answer checked; the
#       .pc and the CMake package must name that prefix.  With MPICC and
#       MPIRUN set (the MPI library was built), hausdorff_mpi.h's first
#       program, taken from the installed header, built with the header's
#       link line, with pkg-config (hausdorff_mpi.pc), statically and with
#       find_package(hausdorff COMPONENTS mpi), each run under
#       `mpirun -n 4` as the header says and its answer checked.
#   install_check.sh make BUILD SOURCE     `make install PREFIX=...` writes a
#       .pc for that prefix and says what to set; no "Entering directory"
#       lines; `make run` builds the command-line tool only.
#   install_check.sh deps SOURCE           scripts/deps.sh's message for a
#       non-root user: each package once, no sudo, --no-install-recommends.
#   install_check.sh makefile SOURCE       the Makefile's own rules, with
#       cmake and ctest replaced by stand-ins that fail on demand: a failed
#       configure is tried again by the next `make run`; `make test` runs
#       the sanitizer half after a failed release half, reports both and
#       fails when either failed.
#
# CC, CMAKE, PKG_CONFIG and MAKE may name the tools; MPICC and MPIRUN the
# MPI compiler wrapper and launcher.
set -eu
what=$1; shift
CC=${CC:-cc}; CMAKE=${CMAKE:-cmake}; PKG_CONFIG=${PKG_CONFIG:-pkg-config}; MAKE=${MAKE:-make}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/hd-install.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# One program, the header's first example: H = sqrt(1.25), realised by A[2], B[0].
write_prog() {
  cat > "$1" <<'C'
#include <hausdorff.h>
#include <stdio.h>
int main(void) {
    double a[] = { 0,0,0,  1,0,0,  0,1,0 };
    double b[] = { 0,0,0.5,  1,0.25,0 };
    hd_points_t A = hd_points_f64(a, 3), B = hd_points_f64(b, 2);
    hd_options_t opt;
    hd_options_init(&opt);
    hd_symmetric_t r;
    hd_error_t err;
    if (hd_hausdorff(&A, &B, &opt, &r, &err) != HD_OK) {
        fprintf(stderr, "hausdorff: %s\n", err.message);
        return 1;
    }
    printf("H = %.17g A[%zu] B[%zu]\n", r.distance, r.ab.i, r.ab.j);
    return 0;
}
C
}
expect="H = 1.1180339887498949 A[2] B[0]"
check_answer() {  # NAME OUTPUT
  [ "$2" = "$expect" ] || fail "$1 printed '$2', expected '$expect'"
  echo "ok: $1: $2"
}
# The program must load libhausdorff.so from the prefix, not from elsewhere.
check_loads() {  # PROGRAM LIBDIR (with LD_LIBRARY_PATH as set by the caller)
  so=$(ldd "$1" | sed -n 's/^[[:space:]]*libhausdorff\.so[^ ]* => \([^ ]*\).*/\1/p')
  [ -n "$so" ] || fail "$1 does not link libhausdorff.so: $(ldd "$1")"
  case "$so" in "$2"/*) ;; *) fail "$1 loads $so, not the one in $2" ;; esac
}

# hausdorff_mpi.h's first program: its opening comment's first block
# indented by five spaces.  On 4 ranks, A's points (r,0,0), (r,1,0) and B's
# (r,0,0.5) for r = 0..3: H = sqrt(1.25), from A[1] (rank 0's (0,1,0)) to
# B[0].
write_mpi_prog() {  # HEADER FILE
  awk '/^ \*     /{p=1; sub(/^ \*     /, ""); print; next} p && /^ \*$/{print ""; next} p{exit}' "$1" > "$2"
  grep -q hd_mpi_hausdorff "$2" || fail "no program in $1's opening comment"
}
mpi_expect="H = 1.1180339887498949, A[1] to B[0]"
run_mpi() {  # NAME PROGRAM (with LD_LIBRARY_PATH as set by the caller)
  # As the header says (mpirun -n 4); as root and on fewer than 4 cores
  # Open MPI also wants these two flags.
  out=$("$MPIRUN" --allow-run-as-root --oversubscribe -n 4 "$2") || fail "$1: mpirun -n 4 $2 failed: $out"
  [ "$out" = "$mpi_expect" ] || fail "$1 printed '$out', expected '$mpi_expect'"
  echo "ok: $1 on 4 ranks: $out"
}
check_mpi() {  # PREFIX LIBDIR
  prefix=$1 libdir=$2
  so="$libdir/libhausdorff_mpi.so"
  [ -e "$so" ] && [ -e "$libdir/libhausdorff_mpi.a" ] || fail "libhausdorff_mpi.so and .a not both installed in $libdir"
  # The shared library exports the header's calls only: the core it holds
  # stays private, and the program's hd_* calls go to libhausdorff.so.
  extra=$(nm -D --defined-only "$so" | awk '{print $3}' | grep -v '^hd_mpi_' | grep -v '^$' || true)
  [ -z "$extra" ] || fail "libhausdorff_mpi.so exports more than hd_mpi_*: $extra"
  nm -D --defined-only "$so" | grep -q ' hd_mpi_hausdorff$' || fail "libhausdorff_mpi.so does not export hd_mpi_hausdorff"
  echo "ok: libhausdorff_mpi.so exports hd_mpi_* only"
  write_mpi_prog "$prefix/include/hausdorff_mpi.h" "$tmp/prog_mpi.c"

  # The header's link line, with the prefix's folders named (installed into
  # /usr/local or /usr they are searched already).
  link=$(awk '/^ \*\//{exit} {sub(/^ \* ?/, ""); printf "%s ", $0}' "$prefix/include/hausdorff_mpi.h" |
    sed -n 's/.*Build with `mpicc -o prog prog\.c \([^`]*\)`.*/\1/p')
  [ "$link" = "-lhausdorff_mpi -lhausdorff" ] || fail "hausdorff_mpi.h's link line is '$link'"
  # shellcheck disable=SC2086
  "$MPICC" -o "$tmp/prog_mpi_l" "$tmp/prog_mpi.c" -I"$prefix/include" -L"$libdir" $link \
    || fail "mpicc prog.c $link (-I$prefix/include -L$libdir)"
  LD_LIBRARY_PATH="$libdir" run_mpi "header's link line (mpicc prog.c $link)" "$tmp/prog_mpi_l"

  export PKG_CONFIG_PATH="$libdir/pkgconfig"
  [ "$("$PKG_CONFIG" --variable=prefix hausdorff_mpi)" = "$prefix" ] || fail "hausdorff_mpi.pc does not name $prefix"
  flags=$("$PKG_CONFIG" --cflags --libs hausdorff_mpi)
  # shellcheck disable=SC2086
  "$MPICC" -o "$tmp/prog_mpi_pc" "$tmp/prog_mpi.c" $flags || fail "mpicc prog.c \$(pkg-config --cflags --libs hausdorff_mpi)"
  unset PKG_CONFIG_PATH
  so=$(LD_LIBRARY_PATH="$libdir" ldd "$tmp/prog_mpi_pc" | sed -n 's/^[[:space:]]*libhausdorff_mpi\.so[^ ]* => \([^ ]*\).*/\1/p')
  case "$so" in "$libdir"/*) ;; *) fail "the pkg-config MPI program loads '$so', not $libdir's libhausdorff_mpi.so" ;; esac
  LD_LIBRARY_PATH="$libdir" run_mpi "pkg-config MPI program ($flags)" "$tmp/prog_mpi_pc"

  # Static: the MPI library before the core, which holds the internal names.
  "$MPICC" -o "$tmp/prog_mpi_static" "$tmp/prog_mpi.c" -I"$prefix/include" \
    "$libdir/libhausdorff_mpi.a" "$libdir/libhausdorff.a" -lm -pthread || fail "static MPI link"
  run_mpi "static MPI program" "$tmp/prog_mpi_static"

  mkdir "$tmp/cmake_mpi"
  cp "$tmp/prog_mpi.c" "$tmp/cmake_mpi/prog.c"
  cat > "$tmp/cmake_mpi/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.16)
project(consumer_mpi C)
find_package(hausdorff 0.1 REQUIRED COMPONENTS mpi)
add_executable(prog_shared prog.c)
target_link_libraries(prog_shared PRIVATE hausdorff::hausdorff_mpi)
add_executable(prog_static prog.c)
target_link_libraries(prog_static PRIVATE hausdorff::hausdorff_mpi_static)
CM
  "$CMAKE" -S "$tmp/cmake_mpi" -B "$tmp/cmake_mpi/build" -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_C_COMPILER="$CC" -DCMAKE_BUILD_TYPE=Release > "$tmp/cmake_mpi.log" 2>&1 \
    || { cat "$tmp/cmake_mpi.log"; fail "find_package(hausdorff COMPONENTS mpi) with CMAKE_PREFIX_PATH=$prefix"; }
  "$CMAKE" --build "$tmp/cmake_mpi/build" > "$tmp/cmake_mpi_build.log" 2>&1 \
    || { cat "$tmp/cmake_mpi_build.log"; fail "building against hausdorff::hausdorff_mpi"; }
  run_mpi "find_package program (hausdorff::hausdorff_mpi)" "$tmp/cmake_mpi/build/prog_shared"
  run_mpi "find_package program (hausdorff::hausdorff_mpi_static)" "$tmp/cmake_mpi/build/prog_static"
  "$prefix/bin/hausdorff-mpi" --version > /dev/null || fail "$prefix/bin/hausdorff-mpi --version"
  echo "ok: $prefix/bin/hausdorff-mpi runs"
}

case "$what" in
prefix)
  build=$1; source=$2
  prefix="$tmp/prefix"
  "$CMAKE" --install "$build" --prefix "$prefix" > "$tmp/install.log" || { cat "$tmp/install.log"; fail "cmake --install"; }
  pc=$(find "$prefix" -name hausdorff.pc)
  [ -n "$pc" ] || fail "no hausdorff.pc under $prefix"
  libdir=$(dirname "$(dirname "$pc")")
  write_prog "$tmp/prog.c"

  # pkg-config, as README says: PKG_CONFIG_PATH, then LD_LIBRARY_PATH to run.
  export PKG_CONFIG_PATH="$libdir/pkgconfig"
  got=$("$PKG_CONFIG" --variable=prefix hausdorff)
  [ "$got" = "$prefix" ] || fail "hausdorff.pc says prefix=$got, installed into $prefix"
  [ "$("$PKG_CONFIG" --variable=libdir hausdorff)" = "$libdir" ] || fail "hausdorff.pc libdir is not $libdir"
  flags=$("$PKG_CONFIG" --cflags --libs hausdorff)
  case " $flags " in *" -I$prefix/include "*) ;; *) fail "pkg-config --cflags gives '$flags', not -I$prefix/include" ;; esac
  # shellcheck disable=SC2086
  "$CC" -o "$tmp/prog_pc" "$tmp/prog.c" $flags || fail "cc prog.c \$(pkg-config --cflags --libs hausdorff)"
  LD_LIBRARY_PATH="$libdir" check_loads "$tmp/prog_pc" "$libdir"
  check_answer "pkg-config program (LD_LIBRARY_PATH)" "$(LD_LIBRARY_PATH="$libdir" "$tmp/prog_pc")"
  # Or with an rpath instead of LD_LIBRARY_PATH.
  # shellcheck disable=SC2086
  "$CC" -o "$tmp/prog_rpath" "$tmp/prog.c" $flags -Wl,-rpath,"$("$PKG_CONFIG" --variable=libdir hausdorff)"
  check_loads "$tmp/prog_rpath" "$libdir"
  check_answer "pkg-config program (rpath)" "$("$tmp/prog_rpath")"
  # The static library, as pkg-config --static describes it.
  # shellcheck disable=SC2086
  "$CC" -o "$tmp/prog_static" "$tmp/prog.c" $("$PKG_CONFIG" --cflags hausdorff) \
    "$libdir/libhausdorff.a" $("$PKG_CONFIG" --static --libs-only-other --libs-only-l hausdorff | sed 's/-lhausdorff//') \
    || fail "static link with pkg-config --static"
  check_answer "static program" "$("$tmp/prog_static")"
  unset PKG_CONFIG_PATH

  # CMake: find_package(hausdorff) with CMAKE_PREFIX_PATH, both targets.
  mkdir "$tmp/cmake"
  cp "$tmp/prog.c" "$tmp/cmake/prog.c"
  cat > "$tmp/cmake/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.16)
project(consumer C)
find_package(hausdorff 0.1 REQUIRED)
message(STATUS "hausdorff_DIR=${hausdorff_DIR}")
add_executable(prog_shared prog.c)
target_link_libraries(prog_shared PRIVATE hausdorff::hausdorff)
add_executable(prog_static prog.c)
target_link_libraries(prog_static PRIVATE hausdorff::hausdorff_static)
CM
  "$CMAKE" -S "$tmp/cmake" -B "$tmp/cmake/build" -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_C_COMPILER="$CC" -DCMAKE_BUILD_TYPE=Release > "$tmp/cmake.log" 2>&1 \
    || { cat "$tmp/cmake.log"; fail "find_package(hausdorff) with CMAKE_PREFIX_PATH=$prefix"; }
  grep -q "hausdorff_DIR=$prefix/" "$tmp/cmake.log" || { cat "$tmp/cmake.log"; fail "find_package found hausdorff outside $prefix"; }
  "$CMAKE" --build "$tmp/cmake/build" > "$tmp/cmake-build.log" 2>&1 || { cat "$tmp/cmake-build.log"; fail "building against hausdorff::hausdorff"; }
  # CMake gives the program an rpath to the imported library.
  check_loads "$tmp/cmake/build/prog_shared" "$libdir"
  check_answer "find_package program (hausdorff::hausdorff)" "$("$tmp/cmake/build/prog_shared")"
  check_answer "find_package program (hausdorff::hausdorff_static)" "$("$tmp/cmake/build/prog_static")"

  # The installed tool runs.
  "$prefix/bin/hausdorff" --version > /dev/null || fail "$prefix/bin/hausdorff --version"
  echo "ok: $prefix/bin/hausdorff runs"
  [ -n "${MPICC:-}" ] && check_mpi "$prefix" "$libdir"
  ;;

make)
  build=$1; source=$2
  # As a user at a shell: make at level 0, no flags inherited from a make above.
  unset MAKEFLAGS MAKELEVEL MFLAGS MAKEOVERRIDES || true
  cd "$source"
  "$MAKE" install BUILD="$build" PREFIX="$tmp/opt/hd" > "$tmp/make.log" 2>&1 || { cat "$tmp/make.log"; fail "make install PREFIX=$tmp/opt/hd"; }
  pc=$(find "$tmp/opt/hd" -name hausdorff.pc)
  grep -qx "prefix=$tmp/opt/hd" "$pc" || fail "PREFIX=$tmp/opt/hd make install wrote $(grep '^prefix=' "$pc")"
  echo "ok: PREFIX=... make install: $(grep '^prefix=' "$pc")"
  grep -q "LD_LIBRARY_PATH=$tmp/opt/hd/" "$tmp/make.log" && grep -q "PKG_CONFIG_PATH=$tmp/opt/hd/" "$tmp/make.log" \
    && grep -q "CMAKE_PREFIX_PATH=$tmp/opt/hd" "$tmp/make.log" || { cat "$tmp/make.log"; fail "make install into a non-system prefix does not say what to set"; }
  echo "ok: make install says what to set for a non-system prefix"
  if grep -q "Entering directory\|Leaving directory" "$tmp/make.log"; then
    cat "$tmp/make.log"; fail "make prints Entering/Leaving directory lines"
  fi
  echo "ok: no Entering/Leaving directory lines"
  # make run builds the command-line tool, not every test and benchmark.
  "$MAKE" -n run BUILD="$build" > "$tmp/run.log" 2>&1 || { cat "$tmp/run.log"; fail "make -n run"; }
  grep -q "cmake --build" "$tmp/run.log" || { cat "$tmp/run.log"; fail "make -n run builds nothing"; }
  if grep "cmake --build" "$tmp/run.log" | grep -v -- "--target hausdorff_cli\$"; then
    fail "make run builds more than hausdorff_cli"
  fi
  echo "ok: make run builds hausdorff_cli only"
  ;;

deps)
  source=$1
  # Every package missing, a non-root user: what deps.sh tells them.
  mkdir "$tmp/bin"
  printf '#!/bin/sh\nexit 1\n' > "$tmp/bin/dpkg-query"
  printf '#!/bin/sh\necho 1000\n' > "$tmp/bin/id"
  printf '#!/bin/sh\necho "apt-get must not run as a user" >&2; exit 3\n' > "$tmp/bin/apt-get"
  chmod +x "$tmp/bin/dpkg-query" "$tmp/bin/id" "$tmp/bin/apt-get"
  rc=0
  PATH="$tmp/bin:$PATH" sh "$source/scripts/deps.sh" build extras test python fuzz > "$tmp/out" 2>&1 || rc=$?
  cat "$tmp/out"
  [ "$rc" = 1 ] || fail "deps.sh exited with $rc, expected 1"
  cmd=$(grep "apt-get install" "$tmp/out") || fail "no apt-get install command"
  grep -q sudo "$tmp/out" && fail "the message assumes sudo"
  case "$cmd" in *"su -c '"*"apt-get install -y --no-install-recommends "*"'") ;;
    *) fail "the command is not \"su -c '... apt-get install -y --no-install-recommends ...'\": $cmd" ;; esac
  grep -q -- "apt-get install -y -q --no-install-recommends" "$source/scripts/deps.sh" \
    || fail "the root path does not install with --no-install-recommends"
  # Each package once, in the message and in the command.
  for line in "$(grep '^Missing' "$tmp/out" | sed 's/^[^:]*://')" \
              "$(echo "$cmd" | sed "s/.*--no-install-recommends//; s/'.*//")"; do
    dup=$(printf '%s\n' $line | sort | uniq -d)
    [ -z "$dup" ] || fail "listed more than once: $dup"
    for p in python3-venv python3-wheel python3 make; do
      printf '%s\n' $line | grep -qx "$p" || fail "$p missing from: $line"
    done
  done
  echo "ok: deps.sh names each package once, without sudo, with --no-install-recommends"
  ;;
makefile)
  source=$1
  unset MAKEFLAGS MAKELEVEL MFLAGS MAKEOVERRIDES || true
  cd "$source"
  mkdir "$tmp/bin"
  # Every package installed: deps.sh installs nothing.
  printf '#!/bin/sh\necho "install ok installed"\n' > "$tmp/bin/dpkg-query"
  # cmake and ctest log their calls and fail when the call (with ctest's
  # folder) matches the pattern in $tmp/fail.  A configure writes
  # CMakeCache.txt first, as CMake does even when configuring fails; a
  # build writes a hausdorff that does nothing.
  cat > "$tmp/bin/cmake" <<EOF
#!/bin/sh
echo "cmake \$*" >> "$tmp/log"
[ "\$1" = -S ] && mkdir -p "\$4" && touch "\$4/CMakeCache.txt"
[ "\$1" = --build ] && printf '#!/bin/sh\\n' > "\$2/hausdorff" && chmod +x "\$2/hausdorff"
pat=\$(cat "$tmp/fail"); case "cmake \$*" in \$pat) exit 1 ;; esac; exit 0
EOF
  cat > "$tmp/bin/ctest" <<EOF
#!/bin/sh
echo "ctest in \$PWD" >> "$tmp/log"
pat=\$(cat "$tmp/fail"); case "ctest in \$PWD" in \$pat) exit 1 ;; esac; exit 0
EOF
  chmod +x "$tmp/bin/dpkg-query" "$tmp/bin/cmake" "$tmp/bin/ctest"
  mk() { PATH="$tmp/bin:$PATH" "$MAKE" BUILD="$tmp/rel" ASAN_BUILD="$tmp/asan" "$@" > "$tmp/out" 2>&1; }
  configures() { grep -c "^cmake -S . -B $tmp/rel " "$tmp/log" || true; }

  # A configure that fails leaves CMakeCache.txt; the next try configures again.
  : > "$tmp/log"; echo "cmake -S*" > "$tmp/fail"
  mk run && { cat "$tmp/out"; fail "make run passed with a failing configure"; }
  [ "$(configures)" = 1 ] || { cat "$tmp/log"; fail "make run did not configure"; }
  echo "no match" > "$tmp/fail"
  mk run || { cat "$tmp/out"; fail "make run failed once the configure passes"; }
  [ "$(configures)" = 2 ] || { cat "$tmp/log"; fail "after a failed configure, make run did not configure again"; }
  grep -q "^cmake --build $tmp/rel .*--target hausdorff_cli" "$tmp/log" || { cat "$tmp/log"; fail "make run built nothing"; }
  mk run || fail "make run, a third time"
  [ "$(configures)" = 2 ] || { cat "$tmp/log"; fail "make run configures again after a finished configure"; }
  echo "ok: a failed configure is tried again by the next make run, a finished one is not"

  # make test: both halves whatever the first gives, both reported.
  for case in "$tmp/rel:FAILED:passed:1" "$tmp/asan:passed:FAILED:1" "none:passed:passed:0"; do
    failing=${case%%:*}; rest=${case#*:}; rel=${rest%%:*}; rest=${rest#*:}; asan=${rest%%:*}; want=${rest#*:}
    : > "$tmp/log"; echo "ctest in $failing" > "$tmp/fail"
    rc=0; mk test || rc=$?
    [ $(( rc != 0 )) = "$want" ] || { cat "$tmp/out"; fail "make test exited $rc with $failing's tests failing"; }
    grep -q "^ctest in $tmp/rel\$" "$tmp/log" && grep -q "^ctest in $tmp/asan\$" "$tmp/log" \
      || { cat "$tmp/log"; fail "make test did not run both halves with $failing's tests failing"; }
    grep -q "release build $rel .*sanitizer build $asan" "$tmp/out" \
      || { cat "$tmp/out"; fail "make test did not report release $rel, sanitizers $asan"; }
    echo "ok: make test with $failing's tests failing: both halves ran, release $rel, sanitizers $asan, exit $rc"
  done
  ;;
*) fail "unknown check $what" ;;
esac
