/*
 * mpi_memory.c -- how an MPI call's buffers are counted (src/mpi/context.c):
 * a buffer is charged at what it holds from the system while it is held,
 * so the call's peak (hd_mpi_stats_t.peak_bytes) is what it used.  A
 * long-lived buffer (hd__mpi_alloc) holds exactly its bytes; a scratch
 * buffer (hd__mpi_scratch, freed before the engine's pass) is made whole
 * 2 MiB pages when that adds at most an eighth of its size, starts on a
 * 2 MiB boundary then, and is charged the whole pages; freeing either
 * gives back exactly what was charged.  No MPI call is made (the context
 * only counts bytes), so this runs without mpirun.
 */
#include "check.h"
#include "mpi/context.h"

#include <stdint.h>
#include <stdlib.h>
#include <sys/mman.h>

#define MIB ((size_t)1 << 20)

/* Every byte asked for is writable (AddressSanitizer checks the bounds). */
static void fill(void *p, size_t bytes) { memset(p, 0x5a, bytes); }

TEST(a_long_lived_buffer_is_charged_its_bytes_however_close_to_whole_pages) {
    hd__mpi_ctx_t c;
    memset(&c, 0, sizeof c);
    /* 995,704 points of 24 bytes: 22.8 MiB, 0.8 MiB past whole pages */
    size_t n = 995704;
    double *x = hd__mpi_alloc(&c, n, 3 * sizeof(double));
    CHECK(x != NULL);
    fill(x, n * 3 * sizeof(double));
    CHECK_EQ(c.cur, n * 3 * sizeof(double));
    CHECK_EQ(c.peak, n * 3 * sizeof(double));
    hd__mpi_free(&c, x, n, 3 * sizeof(double));
    CHECK_EQ(c.cur, 0);
}

TEST(a_scratch_buffer_within_an_eighth_of_whole_pages_is_charged_the_whole_pages) {
    hd__mpi_ctx_t c;
    memset(&c, 0, sizeof c);
    size_t n = 1000000; /* 4,000,000 bytes: 4 MiB wastes 4.6 % */
    uint32_t *o = hd__mpi_scratch(&c, n, sizeof(uint32_t));
    CHECK(o != NULL);
    fill(o, n * sizeof(uint32_t));
#ifdef MADV_HUGEPAGE
    CHECK_EQ(c.cur, 4 * MIB);
    CHECK_EQ((uintptr_t)o % (2 * MIB), 0);
#else
    CHECK_EQ(c.cur, n * sizeof(uint32_t));
#endif
    hd__mpi_free_scratch(&c, o, n, sizeof(uint32_t));
    CHECK_EQ(c.cur, 0);
}

TEST(a_scratch_buffer_far_from_whole_pages_is_charged_its_bytes) {
    hd__mpi_ctx_t c;
    memset(&c, 0, sizeof c);
    size_t sizes[] = {1000000, 3 * MIB, 5 * MIB / 2, 100, 0}; /* 2 MiB, 4 MiB or 3 MiB would waste more than an eighth */
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
        CONTEXT("bytes=%zu", sizes[k]);
        unsigned char *p = hd__mpi_scratch(&c, sizes[k], 1);
        CHECK(p != NULL);
        fill(p, sizes[k]);
        CHECK_EQ(c.cur, sizes[k]);
        hd__mpi_free_scratch(&c, p, sizes[k], 1);
        CHECK_EQ(c.cur, 0);
    }
}

TEST(the_peak_counts_a_rounded_scratch_buffer_with_what_else_is_held) {
    hd__mpi_ctx_t c;
    memset(&c, 0, sizeof c);
    unsigned char *a = hd__mpi_alloc(&c, 1000, 1);
    unsigned char *s = hd__mpi_scratch(&c, 2000000, 1); /* 2 MiB wastes 4.9 % */
    CHECK(a != NULL && s != NULL);
    fill(s, 2000000);
    hd__mpi_free_scratch(&c, s, 2000000, 1);
    hd__mpi_free(&c, a, 1000, 1);
    CHECK_EQ(c.cur, 0);
#ifdef MADV_HUGEPAGE
    CHECK_EQ(c.peak, 1000 + 2 * MIB);
#else
    CHECK_EQ(c.peak, 1000 + 2000000);
#endif
}

TEST(a_count_whose_bytes_overflow_gets_nothing_and_charges_nothing) {
    hd__mpi_ctx_t c;
    memset(&c, 0, sizeof c);
    CHECK(hd__mpi_scratch(&c, SIZE_MAX / 2, 4) == NULL);
    CHECK(hd__mpi_alloc(&c, SIZE_MAX / 8 + 1, 16) == NULL);
    CHECK_EQ(c.cur, 0);
    CHECK_EQ(c.peak, 0);
}
