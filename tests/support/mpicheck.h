/*
 * mpicheck.h -- the harness of the MPI tests (tests/api/mpi_api.c,
 * tests/api/mpi_figures.c), which tests/support/check.c cannot be: it has a
 * main of its own and knows nothing of ranks.  A failing CHECK prints the
 * rank, the file and line and the context (set it with snprintf into
 * context_: the case and the seed); check_agreed checks that a failure is
 * the same code and message on every rank; mpicheck_finish agrees on the
 * verdict, prints "NAME on K ranks: N checks, M failed" on rank 0, calls
 * MPI_Finalize and returns the exit status.  Header only: each test is one
 * program, whose globals these are.
 */
#ifndef HD_TEST_MPICHECK_H
#define HD_TEST_MPICHECK_H

#include <hausdorff_mpi.h>

#include <stdio.h>
#include <string.h>

static int rank_, K_, failures, checks;
static char context_[256];

#define CHECK(cond)                                                                     \
    do {                                                                                \
        checks++;                                                                       \
        if (!(cond)) {                                                                  \
            failures++;                                                                 \
            fprintf(stderr, "rank %d/%d: %s:%d: CHECK(%s) failed [%s]\n", rank_, K_,     \
                    __FILE__, __LINE__, #cond, context_);                               \
        }                                                                               \
    } while (0)

#define SAME_BITS(x, y) (memcmp(&(x), &(y), sizeof(double)) == 0)

/* The same code and message on every rank. */
static inline void check_agreed(int rc, int expected, const hd_error_t *err, const char *must_contain) {
    CHECK(rc == expected);
    char msg[1024];
    memcpy(msg, err->message, sizeof msg);
    MPI_Bcast(msg, (int)sizeof msg, MPI_CHAR, 0, MPI_COMM_WORLD);
    CHECK(strcmp(msg, err->message) == 0);
    CHECK(err->code == expected);
    CHECK(strstr(err->message, must_contain) != NULL);
    if (rc != expected || !strstr(err->message, must_contain))
        fprintf(stderr, "rank %d: %s: %s (expected %s with \"%s\")\n", rank_, hd_err_name(rc), err->message,
                hd_err_name(expected), must_contain);
}

static inline int mpicheck_finish(const char *name) {
    int all[2] = {failures, checks}, sum[2];
    MPI_Reduce(all, sum, 2, MPI_INT, MPI_SUM, 0, MPI_COMM_WORLD);
    int any = failures > 0, anyall = 0;
    MPI_Allreduce(&any, &anyall, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (rank_ == 0) printf("%s on %d ranks: %d checks, %d failed\n", name, K_, sum[1], sum[0]);
    MPI_Finalize();
    return anyall ? 1 : 0;
}

#endif
