/*
 * page_cost.c -- what fresh memory costs on this machine, per byte
 * (docs/scale-out.md, "Memory pages on this machine"):
 *     build/bench/page_cost [--mib M] [--rounds R]
 * Each round maps M MiB (default 256) of anonymous memory in each of three
 * ways and writes one byte a page, then writes it all (memset) and unmaps
 * it:
 *   small     4 KiB pages, a fault each on first write;
 *   populate  4 KiB pages, mapped in one call (MADV_POPULATE_WRITE) first;
 *   huge      2 MiB pages (MADV_HUGEPAGE on a 2 MiB aligned range), a
 *             fault each.
 * It prints ns a byte for each round: the first touch (mapping and the
 * kernel's zeroing), the memset of the mapped memory (the memory's own
 * bandwidth, for comparison) and the unmapping.  The first round's huge
 * pages are often far slower than the later ones: memory the process has
 * not used since it started may be memory the host has not backed either
 * (on a virtual machine), and the later rounds get back what the previous
 * round freed.  The library's buffers are written whole right after they
 * are allocated, so these figures bound what its fresh memory costs
 * (src/mpi/context.c, src/base/memory.c).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include "benchutil.h"

#define HUGE ((size_t)2 << 20)

enum { SMALL, POPULATE, HUGEPG, KINDS };
static const char *kind_name[KINDS] = {"small", "populate", "huge"};

/* One mapping of `bytes` the given way: ns a byte to touch, to memset, to
 * unmap; 0 on success. */
static int one(int kind, size_t bytes, double out[3]) {
    size_t len = bytes + HUGE;
    unsigned char *m = mmap(NULL, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) return -1;
    unsigned char *a = (unsigned char *)(((uintptr_t)m + HUGE - 1) & ~(uintptr_t)(HUGE - 1));
    int ok = madvise(a, bytes, kind == HUGEPG ? MADV_HUGEPAGE : MADV_NOHUGEPAGE) == 0;
    double t0 = bench_now();
#ifdef MADV_POPULATE_WRITE
    if (kind == POPULATE) ok = ok && madvise(a, bytes, MADV_POPULATE_WRITE) == 0;
#else
    if (kind == POPULATE) ok = 0;
#endif
    for (size_t o = 0; ok && o < bytes; o += 4096) a[o] = 1;
    double t1 = bench_now();
    if (ok) memset(a, 2, bytes);
    double t2 = bench_now();
    ok = ok && a[bytes / 2] == 2;
    munmap(m, len);
    double t3 = bench_now();
    out[0] = (t1 - t0) * 1e9 / (double)bytes;
    out[1] = (t2 - t1) * 1e9 / (double)bytes;
    out[2] = (t3 - t2) * 1e9 / (double)bytes;
    return ok ? 0 : -1;
}

int main(int argc, char **argv) {
    size_t mib = 256;
    int rounds = 6;
    for (int k = 1; k < argc; k++) {
        if (k + 1 < argc && strcmp(argv[k], "--mib") == 0) mib = strtoull(argv[++k], NULL, 10);
        else if (k + 1 < argc && strcmp(argv[k], "--rounds") == 0) rounds = atoi(argv[++k]);
        else {
            fprintf(stderr, "page_cost: unknown argument %s\n", argv[k]);
            return 1;
        }
    }
    if (mib == 0 || mib > ((size_t)1 << 20) || rounds < 1) {
        fprintf(stderr, "page_cost: --mib must be 1..1048576 and --rounds at least 1\n");
        return 1;
    }
    size_t bytes = mib << 20;
    printf("# page_cost: %zu MiB a mapping, %d rounds; ns a byte\n# round kind      touch   memset  munmap\n", mib,
           rounds);
    for (int r = 0; r < rounds; r++)
        for (int k = HUGEPG; k >= SMALL; k--) { /* huge first: the first round's is the cold one */
            double t[3];
            if (one(k, bytes, t) != 0) {
                printf("%d %-9s unavailable\n", r, kind_name[k]);
                continue;
            }
            printf("%d %-9s %7.3f %7.3f %7.3f\n", r, kind_name[k], t[0], t[1], t[2]);
        }
    return 0;
}
