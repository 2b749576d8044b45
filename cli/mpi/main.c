/*
 * mpi/main.c -- `mpirun -n K hausdorff-mpi [options] A B`: the exact
 * Hausdorff distance of two sides that no single process needs to hold,
 * printed as `hausdorff` prints it (report.c), the same numbers and
 * witnesses to the bit, with the exchange's figures added.
 *
 * Each side is one file, a directory or @LIST of tiles (tiles.c).  Each rank
 * reads its share of each side's tiles (tiles_share: a contiguous range,
 * balanced by bytes; B's shares are rotated by K/2 ranks, so a side of one
 * file each puts A and B on different ranks), and numbers its points by the
 * counts of the tiles before its range (an allreduce of every tile's
 * count).  Then hd_mpi_hausdorff (or hd_mpi_directed and hd_mpi_overlap)
 * over MPI_COMM_WORLD.
 *
 * Failures: every step that can fail on some ranks only (expanding a side,
 * reading a tile, the computation) ends with agree(): the ranks learn the
 * first failing rank's code and message, rank 0 prints it, and every rank
 * exits with the same status; no rank waits in a collective for one that
 * gave up.  Only rank 0 writes to standard output and standard error (the
 * others' are /dev/null), so a message appears once, not K times.  The
 * per-point outputs are hausdorff's, computed where the points are: every
 * rank's per-point distances (hd_mpi_distances), the figures over the
 * ranks and the pictures from merged layers (figures.c), the --distances
 * files written by every rank at its offset (writer.c).  Under --empty a side
 * whose ranks read no point at all gets the policy's answer
 * (analysis_empty) in the same report as every run (report_print), and
 * --distances files with the policy's value.
 */
#include <hausdorff_mpi.h>

#include "analysis.h"
#include "cli.h"
#include "mpi_cli.h"
#include "output.h"
#include "report.h"
#include "tiles.h"

#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

static int rank_, K_;

static int agree(int rc, hd_error_t *err) { return mpi_agree(rc, err); }

static void fetch_point(const hd_mpi_part_t *p, size_t g, double q[3]);

/* The per-point distances of this rank's points (hd_mpi_distances, both
 * directions unless --directed) into r->d_ab, j_ab, d_ba, j_ba (this
 * rank's points only, in its parts' order; analysis_free frees them), with
 * what the report says of them: r->n_a, n_b are the sides' totals, and
 * r->seconds the slowest rank's time; the call's exchange figures in *st
 * (zeroed when it is not reached).  Collective. */
static int distances_mpi(const cli_args_t *a, const hd_mpi_part_t part[2], const uint64_t total[2],
                         analysis_result_t *r, hd_mpi_stats_t *st, hd_error_t *err) {
    size_t n[2] = {part[0].points.count, part[1].points.count};
    r->active = 1;
    r->directed = a->directed;
    r->n_a = (size_t)total[0];
    r->n_b = (size_t)total[1];
    double **d[2] = {&r->d_ab, &r->d_ba};
    size_t **j[2] = {&r->j_ab, &r->j_ba};
    int rc = HD_OK;
    for (int w = 0; w < (a->directed ? 1 : 2); w++) {
        *d[w] = malloc((n[w] ? n[w] : 1) * sizeof(double));
        *j[w] = malloc((n[w] ? n[w] : 1) * sizeof(size_t));
        if (!*d[w] || !*j[w]) {
            snprintf(err->message, sizeof err->message, "out of memory for %zu per-point distances", n[w]);
            rc = err->code = HD_ENOMEM;
        }
    }
    memset(st, 0, sizeof *st);
    hd_mpi_options_t mo;
    hd_mpi_options_init(&mo);
    mo.engine = a->opt;
    if ((rc = agree(rc, err)) == HD_OK)
        rc = hd_mpi_distances(MPI_COMM_WORLD, &part[0], 1, &part[1], 1, &mo, r->d_ab, r->j_ab, r->d_ba, r->j_ba, st,
                              err);
    r->seconds = rc == HD_OK ? st->seconds_max : 0;
    return rc;
}

/* --distances, --farther-than, --nearer-than: r's per-rank distances
 * written as hausdorff writes them (writeback.c), the colour scale as
 * hausdorff's (--max-distance, else the Hausdorff distance).  Collective. */
static int distances_files_mpi(const cli_args_t *a, const hd_mpi_part_t part[2], const uint64_t total[2],
                               const hd_symmetric_t *s, analysis_result_t *r, hd_error_t *err) {
    double scale = a->an.max_distance > 0 ? a->an.max_distance : s->distance;
    return mpi_write_files(&a->an, a->path_a, a->path_b, part, r->d_ab, r->j_ab, r->d_ba, r->j_ba, total, scale,
                           a->directed, r, err);
}

/* --render: the witness pair's points from the ranks that hold them, then
 * the picture from every rank's layers (figures.c).  Collective. */
static int render_mpi(const cli_args_t *a, const hd_mpi_part_t part[2], const hd_symmetric_t *s,
                      analysis_result_t *r, hd_error_t *err) {
    int from_a;
    const hd_result_t *wit = report_witness(a, s, &from_a);
    double wp[3], wq[3];
    fetch_point(&part[!from_a], wit->i, wp);
    fetch_point(&part[from_a], wit->j, wq);
    return mpi_render(&a->an, part, r->d_ab, wp, wq, s, a->path_a, a->path_b, r, err);
}

/* The same exit status on every rank (rank 0's). */
static int finish(int status) {
    MPI_Bcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD);
    MPI_Finalize();
    return status;
}

/* A failed run's message (rank 0's), its files discarded: the exit code. */
static int fail(int rc, const hd_error_t *err) {
    fprintf(stderr, "hausdorff-mpi: %s\n", safe_text(err->message));
    out_discard();
    return cli_exit_for(rc);
}

/* Silence every rank but 0: one message, one report. */
static void quiet_others(void) {
    if (rank_ == 0) return;
    int fd = open("/dev/null", O_WRONLY);
    if (fd < 0) return;
    dup2(fd, 1);
    dup2(fd, 2);
    if (fd > 2) close(fd);
}

/* A side of one file that is a stream (standard input, a FIFO, a
 * device): the ranks read each input themselves, by name, one a count from
 * its header and others its ranges, and only rank 0 has the standard
 * input; a stream would be used up by the first read. */
static int refuse_stream(const char *path, hd_error_t *err) {
    const char *kind = tiles_stream(path);
    if (!kind) return HD_OK;
    snprintf(err->message, sizeof err->message,
             "%.800s: %s cannot be read by hausdorff-mpi, whose ranks each read their share of every input "
             "(some more than once); save it to a file",
             path, kind);
    return err->code = HD_EFORMAT;
}

/* Every rank expanded the side itself: they must have found the same
 * tiles, stat for stat (tiles_digest), or their shares and counts would
 * belong to different sides.  Collective; the same verdict everywhere. */
static int same_listing(const tiles_t *t, hd_error_t *err) {
    uint64_t d = tiles_digest(t), lo = 0, hi = 0;
    MPI_Allreduce(&d, &lo, 1, MPI_UINT64_T, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(&d, &hi, 1, MPI_UINT64_T, MPI_MAX, MPI_COMM_WORLD);
    if (lo == hi) return HD_OK;
    snprintf(err->message, sizeof err->message,
             "%.800s: changed during the run (the ranks listed different files, sizes or times); run again once "
             "nothing writes it",
             t->arg);
    return err->code = HD_EIO;
}

/* Every tile's count over all ranks (each tile was read by one rank), then
 * tiles_number; *offset is the first index of this rank's range. */
static int number_tiles(tiles_t *t, size_t first, size_t n, size_t *offset, hd_error_t *err) {
    size_t m = t->n ? t->n : 1;
    uint64_t *mine = calloc(m, sizeof *mine), *all = calloc(m, sizeof *all);
    int rc = mine && all ? HD_OK : HD_ENOMEM;
    if (rc) snprintf(err->message, sizeof err->message, "out of memory for %zu tiles", t->n);
    if ((rc = agree(rc, err)) == HD_OK) {
        for (size_t k = first; k < first + n; k++) mine[k] = t->t[k].count;
        MPI_Allreduce(mine, all, (int)m, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
        for (size_t k = 0; k < t->n; k++) t->t[k].count = (size_t)all[k];
        rc = tiles_number(t, err); /* the same verdict on every rank */
        *offset = n && rc == HD_OK ? t->t[first].first : 0;
    }
    free(mine);
    free(all);
    return rc;
}

/* Read this rank's share of a side by points rather than by tiles, when
 * every tile's header gives its count (LAS, LAZ, NPY, binary PLY/PCD/STL):
 * the side's N points are cut into K equal ranges, and part `share` reads
 * [N share / K, N (share + 1) / K), parts of at most two tiles and the
 * whole of those between.  One big file is then read by every rank, each
 * touching only its range's bytes (or, in a LAZ, decoding only the chunks
 * that meet it).  *split is 0 when some tile's count is unknown or zero
 * (an empty tile has to be reported as the whole read reports it): the
 * caller shares by tiles then. */
static int read_split(tiles_t *t, int share, const cli_args_t *a, analysis_args_t *an, int which, int *split,
                      hd_cloud_t **out, size_t *offset, hd_error_t *err) {
    *split = 0;
    size_t m = t->n ? t->n : 1;
    uint64_t *mine = calloc(m, sizeof *mine), *all = calloc(m, sizeof *all);
    int rc = mine && all ? HD_OK : HD_ENOMEM;
    if (rc) snprintf(err->message, sizeof err->message, "out of memory for %zu tiles", t->n);
    if ((rc = agree(rc, err)) == HD_OK && t->n) {
        tiles_count(t, rank_, K_, &a->read, mine);
        MPI_Allreduce(mine, all, (int)m, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
        int known = 1;
        for (size_t k = 0; k < t->n; k++) known &= all[k] > 1;
        if (known) {
            for (size_t k = 0; k < t->n; k++) t->t[k].count = (size_t)(all[k] - 1);
            rc = tiles_number(t, err); /* the same verdict on every rank */
        }
        if (known && rc == HD_OK) {
            uint64_t n = (uint64_t)t->t[t->n - 1].first + t->t[t->n - 1].count;
            uint64_t lo = tiles_bound(n, share, K_), hi = tiles_bound(n, share + 1, K_);
            *split = 1;
            *offset = (size_t)lo;
            rc = tiles_read_points(t, lo, hi - lo, &a->read, an, which, out, err);
        }
    }
    free(mine);
    free(all);
    return rc;
}

/* A side's format: its ranks' common one, or "mixed". */
static void side_format(const hd_cloud_t *c, char out[16]) {
    char mine[16] = {0}, *all = rank_ == 0 ? calloc((size_t)K_, 16) : NULL;
    if (c->count) memcpy(mine, c->format, 15);
    MPI_Gather(mine, 16, MPI_CHAR, all, 16, MPI_CHAR, 0, MPI_COMM_WORLD);
    memset(out, 0, 16);
    if (!all) return;
    for (int r = 0; r < K_; r++) {
        const char *f = all + 16 * r;
        if (!f[0]) continue;
        if (!out[0]) memcpy(out, f, 16);
        else if (strcmp(out, f) != 0) strcpy(out, "mixed");
    }
    free(all);
}

/* Point g of a side, from the rank that holds it, on every rank. */
static void fetch_point(const hd_mpi_part_t *p, size_t g, double q[3]) {
    int own = p->points.count && g >= p->offset && g - p->offset < p->points.count, from = K_;
    int mine = own ? rank_ : K_;
    MPI_Allreduce(&mine, &from, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (own && from == rank_) hd_points_get(&p->points, g - p->offset, q);
    MPI_Bcast(q, 3, MPI_DOUBLE, from < K_ ? from : 0, MPI_COMM_WORLD);
}

/* One call's exchange figures as JSON members (after an opening brace):
 * the totals of *st and, per rank, the columns secs and peak (gathered to
 * rank 0). */
static void call_json(FILE *out, const hd_mpi_stats_t *st, const double *secs, const double *peak) {
    fprintf(out, "\"rounds\": %d, \"bytes_per_point\": ", st->rounds);
    json_number(out, (double)(st->bytes_partition + st->bytes_forwarding + st->bytes_returned) / (double)st->points);
    fprintf(out, ", \"bytes_partition\": %llu, \"bytes_forwarding\": %llu, \"bytes_returned\": %llu",
            (unsigned long long)st->bytes_partition, (unsigned long long)st->bytes_forwarding,
            (unsigned long long)st->bytes_returned);
    fprintf(out, ", \"forwarded_fraction\": ");
    json_number(out, (double)st->forwarded_points / (double)st->points);
    fprintf(out, ", \"forwarded_queries\": %llu, \"shell_points\": %llu", (unsigned long long)st->forwarded,
            (unsigned long long)st->shell_points);
    fprintf(out, ", \"imbalance\": ");
    json_number(out, st->imbalance);
    fprintf(out, ", \"work_imbalance\": ");
    json_number(out, st->work_imbalance);
    const char *keys[2] = {"seconds_per_rank", "buffer_bytes_per_rank"};
    const double *vals[2] = {secs, peak};
    for (int k = 0; k < 2; k++) {
        fprintf(out, ", \"%s\": [", keys[k]);
        for (int r = 0; r < K_; r++) {
            if (r) fputs(", ", out);
            json_number(out, k == 0 ? round(vals[k][r] * 1e6) / 1e6 : vals[k][r]);
        }
        fputc(']', out);
    }
}

/* The member "mpi": the distance call's figures (call_json), the peak RSS
 * of each rank, and, when the per-point distances were computed (dst not
 * NULL), their call's figures as the member "distances".  col[] holds the
 * per-rank columns gathered by main: the distance call's seconds and
 * peak, the peak RSS, the distances call's seconds and peak. */
static void mpi_json(FILE *out, const hd_mpi_stats_t *st, const hd_mpi_stats_t *dst, double *const col[5],
                     const int split[2]) {
    fprintf(out, ", \"mpi\": {\"ranks\": %d", st->ranks);
    fprintf(out, ", \"read_by_points\": [%s, %s], ", split[0] ? "true" : "false", split[1] ? "true" : "false");
    call_json(out, st, col[0], col[1]);
    fprintf(out, ", \"peak_rss_bytes_per_rank\": [");
    for (int r = 0; r < K_; r++) {
        if (r) fputs(", ", out);
        json_number(out, col[2][r]);
    }
    fputc(']', out);
    if (dst) {
        fprintf(out, ", \"distances\": {");
        call_json(out, dst, col[3], col[4]);
        fputc('}', out);
    }
    fputc('}', out);
}

/* --version (cli_parse): the library's version and the MPI the tool runs on. */
static void print_version(FILE *out) {
    char lib[MPI_MAX_LIBRARY_VERSION_STRING];
    int len = 0, major = 0, minor = 0;
    MPI_Get_library_version(lib, &len);
    MPI_Get_version(&major, &minor);
    lib[len > 0 && len < MPI_MAX_LIBRARY_VERSION_STRING ? len : 0] = '\0';
    char *nl = strpbrk(lib, "\r\n,");
    if (nl) *nl = '\0'; /* the library's first line, name and version */
    fprintf(out, "hausdorff-mpi %s (MPI %d.%d: %s)\n", hd_version(), major, minor, lib);
}

/* What a run holds, made by its phases and freed by main in one place. */
typedef struct run {
    cli_args_t a;
    tiles_t side[2];
    hd_cloud_t *cloud[2];
    analysis_result_t an;
    hd_mpi_part_t part[2];
    int split[2];              /* a side read by points (read_split), not by files */
    uint64_t total[2];         /* the sides' points over all ranks */
    double read_seconds;       /* the slowest rank's */
    hd_symmetric_t s;
    hd_mpi_stats_t st, dst;    /* the distance call's and the per-point distances' */
} run_t;

/* Each side's files, checked alike on every rank, then this rank's share of
 * each side read.  Collective. */
static int read_sides(run_t *r, hd_error_t *err) {
    cli_args_t *a = &r->a;
    const char *paths[2] = {a->path_a, a->path_b}, *formats[2] = {a->format_a, a->format_b};
    int rc = HD_OK;
    for (int w = 0; w < 2 && rc == HD_OK; w++) {
        rc = tiles_expand(paths[w], formats[w], &r->side[w], err);
        if (rc == HD_OK && r->side[w].kind == TILES_FILE) rc = refuse_stream(paths[w], err);
        if ((rc = agree(rc, err)) == HD_OK) rc = same_listing(&r->side[w], err);
    }
    if (rc == HD_OK) { /* no output may overwrite an input: rank 0 checks */
        int bad = rank_ == 0 ? out_check_outputs(a, r->side) : 0;
        hd_error_t e;
        if (rank_ == 0 && !bad && analysis_check_outputs(&a->an, a->path_a, a->path_b, a->directed, &e) != HD_OK) {
            fprintf(stderr, "%s: %s\n", cli_prog(), safe_text(e.message));
            bad = EXIT_USAGE;
        }
        MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
        if (bad) return bad;
    }
    double t0 = cli_now();
    for (int w = 0; w < 2 && rc == HD_OK; w++) {
        hd_mpi_part_t *part = &r->part[w];
        int share = w ? (rank_ + K_ / 2) % K_ : rank_;
        rc = read_split(&r->side[w], share, a, &a->an, w, &r->split[w], &r->cloud[w], &part->offset, err);
        if ((rc = agree(rc, err)) != HD_OK || r->split[w]) {
            if (rc == HD_OK) part->points = hd_cloud_points(r->cloud[w]);
            continue;
        }
        size_t first, n;
        tiles_share(&r->side[w], share, K_, &first, &n);
        rc = tiles_read(&r->side[w], first, n, &a->read, &a->an, w, &r->cloud[w], err);
        if ((rc = agree(rc, err)) == HD_OK) rc = number_tiles(&r->side[w], first, n, &part->offset, err);
        if (rc == HD_OK) part->points = hd_cloud_points(r->cloud[w]);
    }
    if (rc != HD_OK) return rc;
    double read_local = cli_now() - t0;
    MPI_Allreduce(&read_local, &r->read_seconds, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    uint64_t mine[2] = {r->part[0].points.count, r->part[1].points.count};
    MPI_Allreduce(mine, r->total, 2, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    return HD_OK;
}

/* A side with no point (only under --empty: reading refuses it otherwise):
 * the policy's answer, as hausdorff gives it, and with --distances the
 * files hausdorff writes, every row at the policy's value with nearest
 * index -1 (a side with no point gets a file with no rows).  Collective. */
static int compute_empty(run_t *r, hd_error_t *err) {
    const cli_args_t *a = &r->a;
    int rc = agree(analysis_empty(&a->an, (size_t)r->total[0], (size_t)r->total[1], a->directed, &r->s, &r->an,
                                  err), err);
    if (rc != HD_OK || (!a->an.distances_out && !a->an.subset[0].on && !a->an.subset[1].on)) return rc;
    size_t most = r->part[0].points.count > r->part[1].points.count ? r->part[0].points.count
                                                                    : r->part[1].points.count;
    double *d = malloc((most ? most : 1) * sizeof *d);
    if (!d) {
        snprintf(err->message, sizeof err->message, "out of memory for %zu per-point distances", most);
        rc = err->code = HD_ENOMEM;
    }
    for (size_t k = 0; k < most && d; k++) d[k] = r->s.ab.distance;
    if ((rc = agree(rc, err)) == HD_OK)
        rc = mpi_write_files(&a->an, a->path_a, a->path_b, r->part, d, NULL, d, NULL, r->total, 1.0, a->directed,
                             &r->an, err);
    free(d);
    return rc;
}

/* The distance (h(A,B) with --directed) and the analysis asked for: as
 * analysis_run, the distances, the figures, the files, the pictures.
 * Collective. */
static int compute(run_t *r, hd_error_t *err) {
    cli_args_t *a = &r->a;
    const hd_mpi_part_t *part = r->part;
    hd_symmetric_t *s = &r->s;
    hd_mpi_options_t mo;
    hd_mpi_options_init(&mo);
    mo.engine = a->opt;
    int rc;
    if (a->directed) {
        rc = hd_mpi_directed(MPI_COMM_WORLD, &part[0], 1, &part[1], 1, &mo, &s->ab, &r->st, err);
        if (rc == HD_OK) {
            s->distance = s->ab.distance;
            s->seconds = s->ab.seconds;
            rc = hd_mpi_overlap(MPI_COMM_WORLD, &part[0], 1, &part[1], 1, &s->alpha, &s->disjoint, err);
        }
    } else {
        rc = hd_mpi_hausdorff(MPI_COMM_WORLD, &part[0], 1, &part[1], 1, &mo, s, &r->st, err);
    }
    if (rc != HD_OK || !analysis_active(&a->an)) return rc;
    if (!a->directed && analysis_percentile_only(&a->an)) { /* without every distance (src/mpi/select.c) */
        r->an.active = 1, r->an.n_a = (size_t)r->total[0], r->an.n_b = (size_t)r->total[1];
        rc = hd_mpi_hausdorff_percentile(MPI_COMM_WORLD, &part[0], 1, &part[1], 1, &mo, a->an.percentile,
                                         &r->an.pct, &r->dst, err);
        r->an.seconds = rc == HD_OK ? r->dst.seconds_max : 0;
        return rc;
    }
    if ((rc = distances_mpi(a, part, r->total, &r->an, &r->dst, err)) == HD_OK)
        rc = mpi_figures(&a->an, r->an.d_ab, part[0].points.count, r->an.d_ba, part[1].points.count, &r->an, err);
    if (rc == HD_OK && (a->an.distances_out || a->an.subset[0].on || a->an.subset[1].on))
        rc = distances_files_mpi(a, part, r->total, s, &r->an, err);
    if (rc == HD_OK && a->an.render_out) rc = render_mpi(a, part, s, &r->an, err);
    return rc;
}

/* What "mpi" adds to the report (report_print's more): the exchange's
 * figures, per rank in col[] (gathered by print_report). */
typedef struct mpi_more {
    const run_t *r;
    double *col[5];
} mpi_more_t;

static void mpi_more(FILE *out, int json, const void *ctx) {
    const mpi_more_t *m = ctx;
    const hd_mpi_stats_t *st = &m->r->st, *dst = m->r->an.active ? &m->r->dst : NULL;
    if (json) {
        mpi_json(out, st, dst, m->col, m->r->split);
        return;
    }
    char b[NUM_TEXT], f[NUM_TEXT], im[NUM_TEXT];
    fprintf(out, "mpi: %d rank%s, %s bytes moved per point, %s of the points forwarded, imbalance %s\n", K_,
            plural((unsigned)K_), num_ratio((double)(st->bytes_partition + st->bytes_forwarding) / (double)st->points, b),
            num_ratio((double)st->forwarded_points / (double)st->points, f), num_ratio(st->imbalance, im));
    if (dst)
        fprintf(out, "mpi: per-point distances: %s bytes moved per point, %s of the points forwarded\n",
                num_ratio((double)(dst->bytes_partition + dst->bytes_forwarding + dst->bytes_returned) /
                              (double)dst->points, b),
                num_ratio((double)dst->forwarded_points / (double)dst->points, f));
}

/* Everything the report shows, gathered to rank 0, which prints it (the
 * exchange's figures unless a side was empty) and finishes the outputs:
 * the exit status (rank 0's).  Collective. */
static int print_report(const run_t *r) {
    const cli_args_t *a = &r->a;
    int empty = r->an.empty;
    report_t rep = {a, &r->s, r->side, {(size_t)r->total[0], (size_t)r->total[1]}, {NULL, NULL}, {0, 0},
                    {0, 0, 0}, {0, 0, 0}, r->read_seconds, {0, 0}, empty};
    char fmt[2][16];
    uint64_t faces[2] = {r->cloud[0]->n_faces, r->cloud[1]->n_faces}, sums[2];
    MPI_Allreduce(faces, sums, 2, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    for (int w = 0; w < 2; w++) {
        side_format(r->cloud[w], fmt[w]);
        rep.faces[w] = (size_t)sums[w];
        rep.format[w] = fmt[w];
    }
    if (!empty) {
        if (!a->json) { /* only the text prints coordinates: float32 data when it is on every rank */
            int single[2] = {report_single(&r->part[0].points, &a->an.mask[0]),
                             report_single(&r->part[1].points, &a->an.mask[1])};
            MPI_Allreduce(single, rep.single, 2, MPI_INT, MPI_LAND, MPI_COMM_WORLD);
        }
        int from_a;
        const hd_result_t *wit = report_witness(a, &r->s, &from_a);
        fetch_point(&r->part[!from_a], wit->i, rep.wp);
        fetch_point(&r->part[from_a], wit->j, rep.wq);
    }
    struct rusage ru;
    enum { COLS = 5 }; /* per rank: seconds, peak; RSS; the distances call's seconds, peak */
    double mine[COLS] = {r->st.seconds, (double)r->st.peak_bytes, 0, r->dst.seconds, (double)r->dst.peak_bytes};
    double *all = rank_ == 0 ? calloc(COLS * (size_t)K_, sizeof(double)) : NULL;
    if (getrusage(RUSAGE_SELF, &ru) == 0) mine[2] = 1024.0 * (double)ru.ru_maxrss;
    MPI_Gather(mine, COLS, MPI_DOUBLE, all, COLS, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    int status = EXIT_OK;
    if (rank_ == 0) {
        mpi_more_t more = {r, {NULL}};
        int ok = all != NULL;
        for (int k = 0; k < COLS && ok; k++) {
            ok = (more.col[k] = malloc((size_t)K_ * sizeof(double))) != NULL;
            for (int q = 0; q < K_ && ok; q++) more.col[k][q] = all[COLS * q + k];
        }
        if (ok) {
            report_print(stdout, &rep, r->an.active || empty ? &r->an : NULL, empty ? NULL : mpi_more, &more);
            status = out_finish();
        } else {
            fprintf(stderr, "hausdorff-mpi: out of memory\n");
            out_discard();
            status = EXIT_FAILURE_;
        }
        for (int k = 0; k < COLS; k++) free(more.col[k]);
    }
    free(all);
    return status;
}

/* The run after parsing, collective: its exit status (every rank's;
 * rank 0's is the one printed). */
static int run(run_t *r) {
    hd_error_t err;
    memset(&err, 0, sizeof err);
    int rc = read_sides(r, &err);
    if (rc > 0) return rc; /* an output would overwrite an input: said */
    if (rc == HD_OK) rc = !r->total[0] || !r->total[1] ? compute_empty(r, &err) : compute(r, &err);
    if (rc != HD_OK) return fail(rc, &err);
    return print_report(r);
}

int main(int argc, char **argv) {
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &K_);
    quiet_others();
    out_guard_std();
    static run_t r; /* zero: what was made is freed below */
    cli_set_mpi(print_version);
    int rc = cli_parse(argc, argv, &r.a); /* the same verdict on every rank */
    if (rc >= 0) return finish(rc == EXIT_OK ? out_finish() : rc);
    rc = run(&r);
    analysis_free(&r.an);
    for (int w = 0; w < 2; w++) {
        hd_cloud_free(r.cloud[w]);
        tiles_free(&r.side[w]);
    }
    return finish(rc);
}
