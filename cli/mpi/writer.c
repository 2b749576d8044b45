/*
 * mpi/writer.c -- hausdorff-mpi's --distances files, written by every rank
 * at once, byte for byte the file `hausdorff --distances` writes
 * (writers.c's header and rows, output.c's temporary and rename).
 *
 * Each rank holds one run of a side's points, consecutive global indices
 * from `first` (mpi/main.c reads the shares that way; B's are rotated, so
 * not in rank order), so the file is the header, then the ranks' rows in
 * the order of their first indices.  Every rank counts its rows' bytes; an
 * allgather of (first, count, bytes) gives each its offset (the header's
 * length plus the bytes of every run before its own) and the file's
 * length.  Rank 0 creates the temporary with out_open; then every rank
 * opens it by name and writes its rows at its offset with pwrite, in
 * pieces of at most CHUNK bytes (rank 0 the header at 0 first).  A PLY's
 * colour scale and the width of its index column are the same on every
 * rank (the scale is given; the width is an allreduce).  A CSV row's
 * length depends on its numbers, so its bytes are counted in a first pass
 * (formatting, without keeping the text); binary rows have one length.
 *
 * Lost bytes are a failure, never a quiet success.  The rows are written
 * with POSIX calls, not MPI-IO: Open MPI's MPI-IO (OMPIO) returns success
 * and a full count (MPI_Get_count) from a collective write that a full
 * file system refused, and a short count without an error from an
 * independent one, leaving a file cut short, or of the right length with
 * a hole in the middle.  Here every pwrite's count is checked (a short
 * write is continued, and the call that fails gives its errno: ENOSPC,
 * EFBIG, EDQUOT, EIO), then fsync (errors a file system reports only when
 * the data reach it: NFS's quota, a disk's EIO) and close, on every rank;
 * once all ranks are done, rank 0 checks that the file's length is the
 * length agreed (a file truncated or replaced meanwhile).  SIGXFSZ is
 * ignored on every rank, so a file beyond `ulimit -f` is EFBIG rather than
 * a rank killed.  Unlike hausdorff's files (output.c), these are fsync'ed:
 * the ranks may write through other machines' caches, and a file system
 * that defers its errors reports them there.
 *
 * A target that is not a regular file (a FIFO, a device: out_open writes
 * it in place) cannot be written at offsets: there rank 0 writes the file
 * through its stream, the header and then every rank's rows in the order of
 * their first indices, each other rank sending its rows in messages of at
 * most CHUNK bytes and an empty one to end (stream_rows).  Rank 0 receives
 * every message even after a write failed, so no sender waits; the
 * failure is agreed after the last.
 *
 * Failures: rank 0's out_open (an unwritable directory), a rank's open,
 * write, fsync or close, and the length check are agreed (mpi_agree):
 * every rank returns the same OUT_EFAIL and message ("PATH: cannot write:
 * reason", exit 3), and the caller's out_discard removes the temporary.
 * The file appears under its name only at rank 0's out_finish.  The ranks
 * open rank 0's temporary by name, so the file must be on a file system
 * they all see (on one machine, any).
 */
#include <hausdorff_mpi.h>

#include "analysis.h"
#include "cli.h"
#include "mpi_cli.h"
#include "output.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Bytes a rank formats and writes at a time (and sends, to a stream). */
#define CHUNK ((size_t)1 << 20)

int mpi_agree(int rc, hd_error_t *err) {
    int rank, K;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &K);
    int mine = rc != HD_OK ? rank : K, first = K;
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (first == K) return HD_OK;
    if (rank == first) err->code = rc;
    MPI_Bcast(err, (int)sizeof *err, MPI_BYTE, first, MPI_COMM_WORLD);
    return err->code;
}

/* "PATH: cannot write: reason" (e: an errno, or -1 when unknown). */
static int write_failed(const char *path, int e, hd_error_t *err) {
    snprintf(err->message, sizeof err->message, "%.800s: cannot write: %s", path, e > 0 ? strerror(e) : "write error");
    return err->code = OUT_EFAIL;
}

/* Rows [*k, n) into buf, as many as fit in CHUNK bytes; *k advances. */
static size_t fill(const dist_layout_t *lay, const hd_points_t *P, const double *d, const size_t *nearest,
                   size_t *k, unsigned char *buf) {
    size_t at = 0;
    for (; *k < P->count && at + DIST_ROW_MAX <= CHUNK; ++*k) {
        double q[3];
        hd_points_get(P, *k, q);
        at += distances_row(lay, q, d[*k], nearest ? &nearest[*k] : NULL, buf + at);
    }
    return at;
}

/* Every rank's rows: (first index, count, bytes) a rank, all-gathered
 * into *all (3 K values; the caller frees it).  Collective; a failure to
 * allocate is agreed. */
static int rows_of_ranks(uint64_t first, uint64_t count, uint64_t bytes, uint64_t **all, hd_error_t *err) {
    int K;
    MPI_Comm_size(MPI_COMM_WORLD, &K);
    uint64_t mine[3] = {first, count, bytes};
    int rc = HD_OK;
    if (!(*all = malloc(3 * (size_t)K * sizeof **all))) {
        snprintf(err->message, sizeof err->message, "out of memory for %d ranks' rows", K);
        rc = err->code = HD_ENOMEM;
    }
    if ((rc = mpi_agree(rc, err)) != HD_OK) {
        free(*all);
        *all = NULL;
        return rc;
    }
    MPI_Allgather(mine, 3, MPI_UINT64_T, *all, 3, MPI_UINT64_T, MPI_COMM_WORLD);
    return HD_OK;
}

/* Where this rank's rows start (*off: after the header and every rank's
 * rows of smaller indices; B's shares are not in rank order) and where
 * the file ends (*end).  Collective. */
static int row_offset(uint64_t first, uint64_t count, uint64_t bytes, uint64_t head, uint64_t *off, uint64_t *end,
                      hd_error_t *err) {
    int K;
    MPI_Comm_size(MPI_COMM_WORLD, &K);
    uint64_t *all;
    int rc = rows_of_ranks(first, count, bytes, &all, err);
    if (rc != HD_OK) return rc;
    *off = *end = head;
    for (int r = 0; r < K; r++) {
        if (!all[3 * r + 1]) continue;
        if (all[3 * r] < first) *off += all[3 * r + 2];
        *end += all[3 * r + 2];
    }
    free(all);
    return HD_OK;
}

/* The rows of every rank through rank 0's stream f (see the essay),
 * ranks in the order of their first indices; rank 0 writes the header
 * first.  Collective; rank 0 closes f. */
static int stream_rows(FILE *f, const dist_layout_t *lay, const hd_points_t *P, const double *d,
                       const size_t *nearest, uint64_t first, unsigned char *buf, hd_error_t *err) {
    enum { TAG = 7311 };
    int rank, K;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &K);
    uint64_t *all = NULL;
    int *order = malloc((size_t)K * sizeof *order), rc = HD_OK;
    if (!order) {
        snprintf(err->message, sizeof err->message, "out of memory for %d ranks' rows", K);
        rc = err->code = HD_ENOMEM;
    }
    if ((rc = mpi_agree(rc, err)) == HD_OK) rc = rows_of_ranks(first, P->count, 0, &all, err);
    if (rc != HD_OK) {
        free(order);
        if (rank == 0) (void)out_close(f, 0, err);
        return rc;
    }
    int n = 0; /* the ranks with rows, by first index (insertion: K is small) */
    for (int r = 0; r < K; r++) {
        if (!all[3 * r + 1]) continue;
        int at = n++;
        while (at > 0 && all[3 * order[at - 1]] > all[3 * r]) order[at] = order[at - 1], at--;
        order[at] = r;
    }
    size_t k = 0;
    if (rank == 0) {
        int werr = 0;
        size_t head = distances_header(lay, (char *)buf);
        if (fwrite(buf, 1, head, f) != head) werr = errno ? errno : -1;
        for (int q = 0; q < n; q++) {
            for (;;) {
                size_t len = 0;
                if (order[q] == 0) {
                    len = fill(lay, P, d, nearest, &k, buf);
                } else {
                    MPI_Status st;
                    int got = 0;
                    MPI_Recv(buf, (int)CHUNK, MPI_BYTE, order[q], TAG, MPI_COMM_WORLD, &st);
                    MPI_Get_count(&st, MPI_BYTE, &got);
                    len = (size_t)got;
                }
                if (!len) break;
                if (!werr && fwrite(buf, 1, len, f) != len) werr = errno ? errno : -1;
            }
        }
        rc = out_close(f, werr, err);
    } else if (P->count) {
        size_t len;
        do {
            len = fill(lay, P, d, nearest, &k, buf);
            MPI_Send(buf, (int)len, MPI_BYTE, 0, TAG, MPI_COMM_WORLD);
        } while (len);
    }
    free(all);
    free(order);
    return mpi_agree(rc, err);
}


/* All n bytes of buf at offset off of fd: 0, or the errno of the call
 * that failed (-1 when unknown).  A short write is continued: the next
 * call says why the file system stopped. */
static int put_at(int fd, const unsigned char *buf, size_t n, uint64_t off) {
    while (n) {
        if (off > (uint64_t)INT64_MAX - n) return EFBIG;
        ssize_t w = pwrite(fd, buf, n, (off_t)off);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return w < 0 && errno ? errno : -1;
        buf += w;
        n -= (size_t)w;
        off += (uint64_t)w;
    }
    return 0;
}

/* This rank's rows at off of the temporary tmp (rank 0: the header at 0
 * first), then fsync and close: 0, or the errno of the first failure.  A
 * rank without rows does not open the file. */
static int rows_at(const char *tmp, const dist_layout_t *lay, const hd_points_t *P, const double *d,
                   const size_t *nearest, uint64_t off, unsigned char *buf) {
    int rank;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank != 0 && !P->count) return 0;
    int fd = open(tmp, O_WRONLY | O_CLOEXEC);
    if (fd < 0) return errno ? errno : -1;
    int e = rank == 0 ? put_at(fd, buf, distances_header(lay, (char *)buf), 0) : 0;
    for (size_t k = 0; !e && k < P->count;) {
        size_t n = fill(lay, P, d, nearest, &k, buf);
        e = put_at(fd, buf, n, off);
        off += n;
    }
    /* EINVAL: a file system that has no sync (so no deferred error) */
    if (fsync(fd) != 0 && !e && errno != EINVAL) e = errno ? errno : -1;
    if (close(fd) != 0 && !e && errno != EINTR) e = errno ? errno : -1;
    return e;
}

/* Rank 0, once every rank wrote: the temporary holds exactly `end` bytes.
 * Opened, not stat'ed by name: an open revalidates what a network file
 * system caches of a file that other machines wrote (NFS's close-to-open). */
static int check_length(const char *path, const char *tmp, uint64_t end, hd_error_t *err) {
    struct stat st;
    int fd = open(tmp, O_RDONLY | O_CLOEXEC), e = 0;
    if (fd < 0 || fstat(fd, &st) != 0) e = errno ? errno : -1;
    if (fd >= 0) close(fd);
    if (e) return write_failed(path, e, err);
    if ((uint64_t)st.st_size == end) return HD_OK;
    snprintf(err->message, sizeof err->message, "%.800s: cannot write: the file holds %llu bytes of the %llu written",
             path, (unsigned long long)st.st_size, (unsigned long long)end);
    return err->code = OUT_EFAIL;
}

/* Rank 0's name (any length) on every rank, in *out from malloc; HD_OK on
 * every rank, or HD_ENOMEM on every rank with err filled.  Collective. */
static int share_name(const char *mine, int rank, char **out, const char *path, hd_error_t *err) {
    unsigned long long len = rank == 0 ? strlen(mine) : 0;
    MPI_Bcast(&len, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
    int rc = HD_OK;
    if (len >= INT_MAX || !(*out = malloc((size_t)len + 1))) {
        snprintf(err->message, sizeof err->message, "out of memory for writing %s", path);
        rc = err->code = HD_ENOMEM;
    } else if (rank == 0) {
        memcpy(*out, mine, (size_t)len + 1);
    }
    if ((rc = mpi_agree(rc, err)) != HD_OK) {
        free(*out);
        *out = NULL;
        return rc;
    }
    MPI_Bcast(*out, (int)len + 1, MPI_CHAR, 0, MPI_COMM_WORLD);
    return HD_OK;
}

int mpi_write_distances(const char *path, const hd_points_t *P, size_t first, const double *d,
                        const size_t *nearest, size_t total, double dmax, hd_error_t *err) {
    int rank;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    int wide = distances_wide(nearest, P->count), any = 0;
    MPI_Allreduce(&wide, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    dist_layout_t lay;
    int rc = distances_layout(path, total, dmax, any, &lay, err); /* the same verdict on every rank */
    if (rc != HD_OK) return rc;
    signal(SIGXFSZ, SIG_IGN); /* beyond ulimit -f: EFBIG, reported */
    const char *tmp0 = NULL; /* rank 0's temporary, which every rank writes by name */
    FILE *f = NULL; /* rank 0's, kept open when the target is written in place */
    int direct = 0;
    if (rank == 0) {
        f = out_open(path, err);
        if (!f) {
            rc = err->code;
        } else if (!(direct = out_is_direct(f))) {
            tmp0 = out_file_path(f); /* out.c's: valid until the outputs are finished */
            rc = out_close(f, 0, err); /* empty: the ranks write it by name */
        }
    }
    unsigned char *buf = malloc(CHUNK);
    if (rc == HD_OK && !buf) {
        snprintf(err->message, sizeof err->message, "out of memory for writing %s", path);
        rc = err->code = HD_ENOMEM;
    }
    if ((rc = mpi_agree(rc, err)) != HD_OK) {
        free(buf);
        return rc;
    }
    MPI_Bcast(&direct, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (direct) {
        rc = stream_rows(f, &lay, P, d, nearest, first, buf, err);
        free(buf);
        return rc;
    }
    char *tmp = NULL;
    if ((rc = share_name(tmp0, rank, &tmp, path, err)) != HD_OK) {
        free(buf);
        return rc;
    }
    /* This rank's bytes (text rows: a first pass), its offset, the end. */
    size_t head = distances_header(&lay, (char *)buf), k = 0;
    uint64_t bytes = 0, off = 0, end = 0;
    if (lay.format == DIST_CSV) {
        while (k < P->count) bytes += fill(&lay, P, d, nearest, &k, buf);
    } else {
        unsigned char row[DIST_ROW_MAX];
        bytes = (uint64_t)P->count * distances_row(&lay, (const double[3]){0, 0, 0}, 0, nearest, row);
    }
    if ((rc = row_offset(first, P->count, bytes, head, &off, &end, err)) == HD_OK) {
        int e = rows_at(tmp, &lay, P, d, nearest, off, buf);
        if (e) rc = write_failed(path, e, err);
        if ((rc = mpi_agree(rc, err)) == HD_OK && rank == 0) rc = check_length(path, tmp, end, err);
        rc = mpi_agree(rc, err);
    }
    free(buf);
    free(tmp);
    return rc;
}
