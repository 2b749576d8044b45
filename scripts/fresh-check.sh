#!/bin/sh
# The README on a machine that has nothing: a Debian 12 (bookworm) minbase
# root made by debootstrap, the project's `git archive` in it, and there,
# as root, exactly the steps the README and the headers give a new user:
#
#   apt-get update && apt-get install -y make       (README, first section)
#   make run
#   make install
#   hausdorff.h's first program, built as that header says (pkg-config)
#   hausdorff_mpi.h's first program, built and run as that header says
#   make test                                        (skipped with --no-test)
#
# usage: scripts/fresh-check.sh [--no-test] [--keep] [REF]
#
#   REF        the commit to check (default HEAD; `git archive REF`)
#   --no-test  stop after the programs (make test is the long step)
#   --keep     leave the run's root in place (its path is printed)
#
# Needs root (debootstrap, chroot, mounts) and Debian's mirror.  The pristine
# root is made once and kept in $HD_FRESH_CACHE/root (default
# /var/cache/hd-fresh/root); each run works in a copy of it, so nothing one
# run installs is seen by the next.  A pristine root that debootstrap did not
# finish is made again.  debootstrap itself is installed with apt-get when
# missing.  HD_FRESH_MIRROR names another Debian mirror.
#
# Prints each step's time and a summary; exits non-zero at the first step
# that fails, naming it.  The mounts in the run's root (/proc, /sys, /dev,
# /dev/pts, /dev/shm) are always unmounted on exit.
set -eu

CACHE=${HD_FRESH_CACHE:-/var/cache/hd-fresh}
MIRROR=${HD_FRESH_MIRROR:-http://deb.debian.org/debian}
SUITE=bookworm
run_test=1 keep=0 ref=HEAD
for arg in "$@"; do
  case "$arg" in
    --no-test) run_test=0 ;;
    --keep) keep=1 ;;
    -h|--help) sed -n '2,/^set -eu/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "fresh-check: unknown option $arg" >&2; exit 2 ;;
    *) ref=$arg ;;
  esac
done
[ "$(id -u)" = 0 ] || { echo "fresh-check: run as root (debootstrap, chroot and mounts need it)" >&2; exit 2; }
src=$(cd "$(dirname "$0")/.." && pwd)
commit=$(git -C "$src" rev-parse --verify "$ref^{commit}") || { echo "fresh-check: no commit $ref" >&2; exit 2; }

say() { printf '\n=== fresh-check: %s\n' "$*"; }
now() { date +%s; }
summary=""

# --- the pristine root -------------------------------------------------------
# Complete when debootstrap got to its end: it removes /debootstrap last, and
# dpkg then knows of no half-installed package.
root_complete() {
  [ -d "$1" ] && [ ! -e "$1/debootstrap" ] && [ -x "$1/usr/bin/apt-get" ] && [ -s "$1/var/lib/dpkg/status" ] &&
    [ -z "$(chroot "$1" dpkg --audit 2>&1)" ]
}

ensure_debootstrap() {
  command -v debootstrap > /dev/null 2>&1 && return 0
  say "installing debootstrap"
  export DEBIAN_FRONTEND=noninteractive
  apt-get install -y -q --no-install-recommends debootstrap || {
    apt-get update -q && apt-get install -y -q --no-install-recommends debootstrap; }
}

ensure_root() {
  mkdir -p "$CACHE"
  # One run at a time makes the pristine root; the others wait for it.
  exec 9> "$CACHE/lock"
  flock 9
  if ! root_complete "$CACHE/root"; then
    ensure_debootstrap
    [ -e "$CACHE/root" ] && echo "fresh-check: $CACHE/root is incomplete: making it again"
    rm -rf "$CACHE/root" "$CACHE/root.new"
    say "debootstrap --variant=minbase $SUITE $CACHE/root $MIRROR"
    t=$(now)
    debootstrap --variant=minbase "$SUITE" "$CACHE/root.new" "$MIRROR"
    root_complete "$CACHE/root.new" || { echo "fresh-check: debootstrap left an incomplete root" >&2; exit 1; }
    mv "$CACHE/root.new" "$CACHE/root"
    echo "=== fresh-check: debootstrap: ok ($(( $(now) - t )) s)"
    summary="$summary
  $(printf '%-36s %5d s' "debootstrap (cached for next runs)" "$(( $(now) - t ))")"
  fi
  flock -u 9
}

# --- the run's root: a copy, with the kernel's file systems mounted ----------
work="" mounted=""
cleanup() {
  rc=$?
  # Unmount in reverse order; a busy mount is detached lazily.
  for m in $mounted; do
    umount "$m" 2> /dev/null || umount -l "$m" || echo "fresh-check: could not unmount $m" >&2
  done
  mounted=""
  if [ -n "$work" ] && [ -d "$work" ]; then
    if [ "$keep" = 1 ]; then echo "fresh-check: the run's root is kept in $work/root"
    elif grep -q " $work/" /proc/mounts; then echo "fresh-check: $work still has mounts: not removed" >&2
    else rm -rf "$work"; fi
  fi
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT TERM HUP

mount_in() {  # SOURCE TARGET [mount options...]
  s=$1 t=$2; shift 2
  mount "$@" "$s" "$t"
  mounted="$t $mounted"
}

prepare_run_root() {
  work=$(mktemp -d "$CACHE/run.XXXXXX")
  say "copying the pristine root into $work/root"
  cp -a "$CACHE/root" "$work/root"
  r=$work/root
  # What an installed machine has and debootstrap leaves out: the name
  # server, and /etc/hosts as Debian's installer writes it (without it every
  # lookup of the host's name, as mpirun makes, waits for the name server).
  cp /etc/resolv.conf "$r/etc/resolv.conf"
  [ -e "$r/etc/hosts" ] || printf '127.0.0.1\tlocalhost\n127.0.1.1\t%s\n::1\tlocalhost ip6-localhost ip6-loopback\n' \
    "$(uname -n)" > "$r/etc/hosts"
  mount_in proc "$r/proc" -t proc
  mount_in sysfs "$r/sys" -t sysfs -o ro
  mount_in /dev "$r/dev" --bind
  mount_in /dev/pts "$r/dev/pts" --bind
  mount_in shm "$r/dev/shm" -t tmpfs -o mode=1777
  # The project as `git archive` gives it: no build directories, no
  # untracked files.
  mkdir -p "$r/root/hausdorff"
  git -C "$src" archive "$commit" | tar -x -C "$r/root/hausdorff"
}

# --- the steps -------------------------------------------------------------
# Each step runs as root in the run's root with a new login's environment.
in_root() {  # COMMAND (sh text, run in /root/hausdorff)
  chroot "$work/root" /usr/bin/env -i HOME=/root TERM=dumb \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    /bin/sh -c "cd /root/hausdorff && $1"
}

step() {  # NAME COMMAND
  say "$1: $2"
  t=$(now)
  if in_root "$2"; then
    d=$(( $(now) - t ))
    summary="$summary
  $(printf '%-36s %5d s' "$1" "$d")"
    echo "=== fresh-check: $1: ok ($d s)"
  else
    rc=$?
    d=$(( $(now) - t ))
    summary="$summary
  $(printf '%-36s %5d s  FAILED (exit %d)' "$1" "$d" "$rc")"
    say "FAILED: $1 (exit $rc, $d s): $2"
    printf 'fresh-check: %s on a fresh %s minbase root\n%s\n' "$commit" "$SUITE" "$summary"
    exit 1
  fi
}

# A header's first program: the first block indented by five spaces in its
# opening comment, written to FILE.
header_program() {  # HEADER FILE
  awk '/^ \*     /{p=1; sub(/^ \*     /, ""); print; next} p && /^ \*$/{print ""; next} p{exit}' \
    "$work/root/root/hausdorff/$1" > "$work/root/root/hausdorff/$2"
  [ -s "$work/root/root/hausdorff/$2" ] || { echo "fresh-check: no program in $1's opening comment" >&2; exit 1; }
}

# The text between backquotes that follows WORDS in a header's opening
# comment (joined into one line first), e.g. "Build with".
header_says() {  # HEADER WORDS
  awk '/^ \*\//{exit} {sub(/^ \* ?/, ""); printf "%s ", $0}' "$work/root/root/hausdorff/$1" |
    sed -n "s/.*$2 \`\([^\`]*\)\`.*/\1/p"
}

ensure_root
prepare_run_root
total=$(now)
echo "fresh-check: $commit ($ref) on a fresh $SUITE minbase root"

step "apt-get install make" "apt-get update && apt-get install -y make"
step "make run" "make run"
step "make install" "make install"

build=$(header_says include/hausdorff.h "Build with")
[ -n "$build" ] || { echo "fresh-check: hausdorff.h says no build command" >&2; exit 1; }
header_program include/hausdorff.h prog.c
step "hausdorff.h's program" "mkdir -p /root/prog && cp prog.c /root/prog && cd /root/prog && $build && ./a.out"

build=$(header_says include/hausdorff_mpi.h "Build with")
run=$(header_says include/hausdorff_mpi.h "run with")
[ -n "$build" ] && [ -n "$run" ] || { echo "fresh-check: hausdorff_mpi.h says no build or run command" >&2; exit 1; }
header_program include/hausdorff_mpi.h prog_mpi.c
# As root, and on fewer cores than ranks, Open MPI wants the two flags the
# header names for those cases.
run=$(echo "$run" | sed 's/^mpirun /mpirun --allow-run-as-root --oversubscribe /')
step "hausdorff_mpi.h's program" \
  "mkdir -p /root/prog_mpi && cp prog_mpi.c /root/prog_mpi/prog.c && cd /root/prog_mpi && $build && $run"

if [ "$run_test" = 1 ]; then
  step "make test" "make test"
fi
printf '\nfresh-check: %s passed on a fresh %s minbase root in %d s%s\n' "$commit" "$SUITE" "$(( $(now) - total ))" "$summary"
