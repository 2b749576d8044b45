/*
 * mpi/writeback.c -- hausdorff-mpi's per-point files: --distances,
 * --farther-than and --nearer-than, the same files `hausdorff` writes, byte
 * for byte.
 *
 * A file written back into a side's own format (writeback.c: .las, .laz,
 * text, and .ply when the side is a PLY file) is a copy of the input with
 * the field added, which hd_write_field makes from the whole file in one
 * pass: the side's distances (and nearest indices, for a PLY) are gathered
 * on rank 0 in the side's point order (each rank holds consecutive global
 * indices from its part's offset), rank 0 writes the file as hausdorff
 * does (analysis_write_back: into output.c's temporary, renamed by its
 * out_finish), and its verdict is agreed.  Rank 0 then holds 16 bytes a
 * point of each such side (8 without the index) on top of its share.  A
 * table (.csv, .npy, and .ply of a side that is not a PLY file) is written
 * by every rank at its offset (writer.c).  Which side gets which is
 * decided on rank 0 (it looks at the files) and broadcast, so every rank
 * takes the same path.
 */
#include <hausdorff_mpi.h>

#include "analysis.h"
#include "cli.h"
#include "mpi_cli.h"

#include <stdlib.h>
#include <string.h>

/* Elements sent in one message (below INT_MAX for any element size). */
#define PIECE ((size_t)1 << 24)

/* Every rank's n elements of `size` bytes (its points first, first + 1,
 * ...) into rank 0's `all` at their indices.  Collective. */
static void gather_to_0(const void *mine, size_t n, uint64_t first, size_t size, MPI_Datatype t, void *all) {
    int rank, K;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &K);
    uint64_t me[2] = {first, n}, *each = rank == 0 ? malloc(2 * (size_t)K * sizeof *each) : NULL;
    uint64_t none[2] = {0, 0};
    MPI_Gather(me, 2, MPI_UINT64_T, each ? each : none, 2, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    if (rank != 0) {
        for (size_t o = 0; o < n; o += PIECE)
            MPI_Send((const unsigned char *)mine + o * size, (int)(n - o < PIECE ? n - o : PIECE), t, 0, 0,
                     MPI_COMM_WORLD);
        return;
    }
    if (n) memcpy((unsigned char *)all + first * size, mine, n * size);
    for (int r = 1; r < K; r++)
        for (uint64_t o = 0; each && o < each[2 * r + 1]; o += PIECE) {
            uint64_t m = each[2 * r + 1] - o < PIECE ? each[2 * r + 1] - o : PIECE;
            MPI_Recv((unsigned char *)all + (each[2 * r] + o) * size, (int)m, t, r, 0, MPI_COMM_WORLD,
                     MPI_STATUS_IGNORE);
        }
    free(each);
}

/* Rank 0's whole-side arrays of the sides written back (bit w of sides). */
typedef struct {
    double *d[2];
    size_t *j[2];
} whole_t;

static void whole_free(whole_t *h) {
    for (int w = 0; w < 2; w++) free(h->d[w]), free(h->j[w]);
}

static int gather_sides(int sides, const hd_mpi_part_t part[2], const double *const d[2], const size_t *const j[2],
                        const uint64_t total[2], whole_t *h, hd_error_t *err) {
    int rank, rc = HD_OK;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    memset(h, 0, sizeof *h);
    for (int w = 0; w < 2 && rank == 0; w++) {
        if (!(sides >> w & 1)) continue;
        size_t n = (size_t)total[w] ? (size_t)total[w] : 1;
        if (!(h->d[w] = malloc(n * sizeof(double))) || (j[w] && !(h->j[w] = malloc(n * sizeof(size_t))))) {
            snprintf(err->message, sizeof err->message, "out of memory for %zu distances on rank 0", n);
            rc = err->code = HD_ENOMEM;
        }
    }
    if ((rc = mpi_agree(rc, err)) != HD_OK) return rc;
    _Static_assert(sizeof(size_t) == sizeof(uint64_t), "indices travel as MPI_UINT64_T");
    for (int w = 0; w < 2; w++) {
        if (!(sides >> w & 1)) continue;
        gather_to_0(d[w], part[w].points.count, part[w].offset, sizeof(double), MPI_DOUBLE, h->d[w]);
        if (j[w]) gather_to_0(j[w], part[w].points.count, part[w].offset, sizeof(size_t), MPI_UINT64_T, h->j[w]);
    }
    return HD_OK;
}

/* Which sides are written back (bit w), decided on rank 0. */
static int sides_written_back(const analysis_args_t *an, const char *const path[2], int directed) {
    int rank, sides = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank == 0)
        for (int w = 0; w < (directed ? 1 : 2); w++) {
            int any = an->subset[0].on || an->subset[1].on;
            if (an->distances_out && !any) {
                char *out = w ? path_with_suffix(an->distances_out, "_b") : (char *)an->distances_out;
                any = out && analysis_writes_back(an, w, out, path[w]);
                if (w) free(out);
            }
            sides |= any << w;
        }
    MPI_Bcast(&sides, 1, MPI_INT, 0, MPI_COMM_WORLD);
    return sides;
}

int mpi_write_files(const analysis_args_t *an, const char *path_a, const char *path_b, const hd_mpi_part_t part[2],
                    const double *d_ab, const size_t *j_ab, const double *d_ba, const size_t *j_ba,
                    const uint64_t total[2], double dmax, int directed, analysis_result_t *r, hd_error_t *err) {
    int rank;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    const char *path[2] = {path_a, path_b};
    const double *d[2] = {d_ab, d_ba};
    const size_t *j[2] = {j_ab, j_ba};
    int sides = sides_written_back(an, path, directed);
    whole_t h;
    int rc = gather_sides(sides, part, d, j, total, &h, err);
    if (rc == HD_OK && rank == 0 && sides) {
        writeback_side_t side[2] = {{h.d[0], (size_t)total[0], h.j[0], NULL},
                                    {h.d[1], directed ? 0 : (size_t)total[1], h.j[1], NULL}};
        rc = analysis_write_back(an, path_a, path_b, side, directed, 0, r, err);
    }
    whole_free(&h);
    if ((rc = mpi_agree(rc, err)) != HD_OK || !an->distances_out) return rc;
    /* the tables of the sides whose --distances file is not written back */
    int tables = 0;
    if (rank == 0)
        for (int w = 0; w < (directed ? 1 : 2); w++) {
            char *out = w ? path_with_suffix(an->distances_out, "_b") : NULL;
            tables |= !analysis_writes_back(an, w, w ? out : an->distances_out, path[w]) << w;
            if (w && tables & 2) r->dist_path_b = out;
            else free(out);
        }
    MPI_Bcast(&tables, 1, MPI_INT, 0, MPI_COMM_WORLD);
    char *path_b_out = tables & 2 ? path_with_suffix(an->distances_out, "_b") : NULL;
    if (tables & 2 && !path_b_out) {
        snprintf(err->message, sizeof err->message, "out of memory for a file name");
        rc = err->code = HD_ENOMEM;
    }
    if (tables & 1) r->dist_path_a = an->distances_out;
    const char *out[2] = {an->distances_out, path_b_out};
    for (int w = 0; w < 2 && (rc = mpi_agree(rc, err)) == HD_OK; w++)
        if (tables >> w & 1)
            rc = mpi_write_distances(out[w], &part[w].points, part[w].offset, d[w], j[w], (size_t)total[w], dmax, err);
    free(path_b_out);
    return rc;
}
