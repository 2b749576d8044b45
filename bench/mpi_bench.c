/*
 * mpi_bench.c -- the exchange figures of hd_mpi_hausdorff (docs/scale-out.md):
 *     mpirun -n K build/bench/mpi_bench [--points N] [--per-rank] [--cases LIST]
 *                                       [--layout random|tiles] [--threads T]
 *                                       [--check] [--repeat R] [--distances]
 *                                       [--rank-cpu] [--no-prune] [--no-replicate]
 * For each case, every rank generates its share of A and B (N points per
 * side in total, or per rank with --per-rank: weak scaling), and one call
 * of hd_mpi_hausdorff is timed; rank 0 prints one line per case with the
 * figures the targets of issue 14 name: bytes moved per input point (the
 * partition's and the forwarding's), the fraction of points forwarded,
 * the imbalance (largest rank's points, and its points plus answered
 * queries, over the mean), the peak of the call's own buffers per local
 * point, the growth of the peak RSS per local point (meaningful for the
 * first case of a run only: later ones reuse freed memory), times (the
 * slowest rank's total and search, wall clock), the largest CPU time of a
 * rank per local point (the per-point cost for the model: with more ranks
 * than cores it includes MPI's busy waiting), and the share of points
 * searched one by one (the shells), the most CPU time of a rank's calling
 * thread per local point outside the searches and MPI calls ("othercpu":
 * the bookkeeping, c_rest of docs/scale-out.md's model), and the peak RSS of the call over the
 * RSS before it per local point ("hwm": VmHWM reset through
 * /proc/self/clear_refs before the call, so everything the call touched
 * counts, the engine's and MPI's memory too; run one case per process for
 * it, since later cases reuse memory freed by earlier ones), and "own":
 * the largest of a rank's peak over its own local points (the "buf"
 * column divides the largest peak by the mean, so it includes the
 * imbalance), then the most kernel CPU of a rank's calling thread per
 * local point during the call ("sys", part of searchcpu and othercpu:
 * mostly first touches of fresh pages) and the most pages the kernel
 * mapped for a rank's thread ("faults": getrusage's minor and major
 * faults, which count a page mapped in advance by MADV_POPULATE_WRITE as
 * well as one faulted in by a trap; a 2 MiB page counts once).  --repeat R
 * calls R times per case (the repeats' lines are marked "+": memory the
 * first call freed is reused, so they show the costs without first
 * touches of fresh pages).  --check compares with hd_hausdorff on
 * rank 0 (all points gathered; small N only).  --rank-cpu prints each
 * rank's own searchcpu and othercpu per local point and the core it ended
 * on (with `mpirun --bind-to core` rank r stays on core r: on the machine of
 * docs/scale-out.md one core ran 1.4 times slower than the other for an
 * hour on 2026-11-29).  --no-prune sets hd_mpi_options_t's prune to 0:
 * every point moves, the comparison for what the cells keep home.
 * --no-replicate sets its replicate to 0: a tiny side (tinya, tinyb) takes
 * the partition's course instead of being copied to every rank.
 *
 * --distances times hd_mpi_distances (both directions, every point's nearest
 * neighbour; the faster of two calls) instead, and prints per case: bytes moved per input point by
 * the partition, the forwarding and the answers' return, the share of
 * points forwarded, the largest rank's peak over its own local points, the
 * slowest rank's search CPU and process CPU per local point, and, in the
 * same run, single-process hd_distances on all the points gathered on rank
 * 0 (one thread, its CPU per point, the faster of two calls; the other
 * ranks sleep meanwhile; both write into outputs touched before) with
 * the ratio of the two (the slowest rank's search and bookkeeping CPU,
 * MPI's own calls left out as their busy waiting depends on the load, per
 * mean local point, over the single process's CPU per point) and whether the answers are identical (they must
 * be: every distance's bits and nearest index, both directions).
 *
 * Cases:
 *  - uniform: A and B independent, uniform in a cube.
 *  - lidar: two epochs of a 1 km x 1 km LiDAR-like scene: terrain (a smooth
 *    height field), a city quarter four times denser with box buildings
 *    (roofs and walls), a lake with no points at all; epoch B is another
 *    sampling of the same scene, one building demolished and one new.
 *  - copy: B is A with noise of 1 cm on a 1 km scene (a re-registered
 *    scan), same point order.
 *  - apart, near, tinyb, tinya, change, lattice (issue 41's hard cases:
 *    scene.h): fixed sizes a side whatever --points and --per-rank say,
 *    every point made from its global index, so that every K (and K = 1:
 *    the single process) computes on the same sets; rank r holds A's
 *    points [N_A r / K, N_A (r + 1) / K) and B's block (r + K/2) mod K,
 *    rotated as hausdorff-mpi rotates B's shares.  --check makes both sets
 *    on rank 0 and compares with hd_hausdorff.
 * Layouts: "random" (each rank's points spread over the whole scene: every
 * point may move) or "tiles" (rank r generates the strip r of K in x, as a
 * rank reading its share of tile files does: most points stay).
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE /* sched_getcpu */
#endif
#include <hausdorff_mpi.h>

#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "scene.h"

static int rank_, K_;

static double cpu_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Resident kilobytes from /proc/self/status ("VmRSS:" or "VmHWM:"), 0 where missing. */
static double status_kb(const char *key) {
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    double v = 0;
    size_t n = strlen(key);
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, key, n)) v = atof(line + n);
    if (f) fclose(f);
    return 1024.0 * v;
}

/* Reset the peak RSS to the current RSS (Linux >= 4.0: clear_refs 5), so
 * that VmHWM after the call is the call's own peak: everything it touched,
 * the engine's and MPI's memory included. */
static void hwm_reset(void) {
    FILE *f = fopen("/proc/self/clear_refs", "w");
    if (f) {
        fputs("5", f);
        fclose(f);
    }
}

/* The calling thread's kernel CPU seconds and the pages mapped for it (by a
 * trap on first touch or in advance by MADV_POPULATE_WRITE, each once):
 * what first touches of fresh memory cost, inside "searchcpu" and
 * "othercpu" (docs/scale-out.md, "Memory pages on this machine"). */
static void thread_kernel(double *sys, double *faults) {
    struct rusage ru;
    if (getrusage(RUSAGE_THREAD, &ru) != 0) {
        *sys = *faults = 0;
        return;
    }
    *sys = (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    *faults = (double)ru.ru_minflt + (double)ru.ru_majflt;
}

static double thread_cpu_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Rank 0 works alone while the others sleep (no busy waiting in MPI on a
 * shared machine). */
static void wait_for_rank0(void) {
    MPI_Request req;
    MPI_Ibarrier(MPI_COMM_WORLD, &req);
    int done = 0;
    while (!done) {
        MPI_Test(&req, &done, MPI_STATUS_IGNORE);
        if (!done && rank_ != 0) usleep(1000);
    }
}

/* Gather a side's n points (or values, w doubles each) of every rank in
 * rank order (= index order here) on rank 0; NULL elsewhere. */
static double *gather(const double *v, size_t n, int w, size_t *total) {
    int cnt = (int)(w * n), *cnts = malloc((size_t)K_ * sizeof(int)), *disp = malloc((size_t)K_ * sizeof(int));
    MPI_Gather(&cnt, 1, MPI_INT, cnts, 1, MPI_INT, 0, MPI_COMM_WORLD);
    int t = 0;
    for (int q = 0; rank_ == 0 && q < K_; q++) disp[q] = t, t += cnts[q];
    double *all = rank_ == 0 ? malloc((size_t)t * sizeof(double) + 8) : NULL;
    MPI_Gatherv(v, cnt, MPI_DOUBLE, all, cnts, disp, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    free(cnts);
    free(disp);
    *total = (size_t)t / (size_t)w;
    return all;
}

/* One case of --distances: hd_mpi_distances timed, then hd_distances on
 * rank 0 on everything, compared. */
static void bench_distances(const char *c, const double *a, const double *b, size_t n, size_t offset,
                            int threads) {
    hd_mpi_part_t pa = {hd_points_f64(a, n), offset}, pb = {hd_points_f64(b, n), offset};
    hd_mpi_options_t opt;
    hd_mpi_options_init(&opt);
    opt.engine.threads = threads;
    double *d[2] = {malloc(n * sizeof(double) + 8), malloc(n * sizeof(double) + 8)};
    size_t *j[2] = {malloc(n * sizeof(size_t) + 8), malloc(n * sizeof(size_t) + 8)};
    for (int s = 0; s < 2; s++) { /* touched, as the single process's are when it runs again */
        memset(d[s], 0, n * sizeof(double));
        memset(j[s], 0, n * sizeof(size_t));
    }
    hd_mpi_stats_t st, one;
    hd_error_t err;
    double cpumax = 0;
    for (int rep = 0; rep < 2; rep++) { /* the faster of two, as the single process's below */
        MPI_Barrier(MPI_COMM_WORLD);
        double cpu0 = cpu_now();
        int rc = hd_mpi_distances(MPI_COMM_WORLD, &pa, 1, &pb, 1, &opt, d[0], j[0], d[1], j[1], &one, &err);
        double cpu = (cpu_now() - cpu0) / (double)(one.local_points ? one.local_points : 1), most = 0;
        MPI_Reduce(&cpu, &most, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
        if (rc != HD_OK) {
            if (rank_ == 0) fprintf(stderr, "mpi_bench: %s\n", err.message);
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
        if (rep == 0 || one.search_cpu_max + one.other_cpu_max < st.search_cpu_max + st.other_cpu_max) {
            st = one; /* the same choice on every rank: the figures are maxima over the ranks */
            cpumax = most;
        }
    }
    double own = (double)st.peak_bytes / (double)(st.local_points ? st.local_points : 1), ownmax = 0;
    MPI_Reduce(&own, &ownmax, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    /* the single process on the same points, in the same run */
    size_t na, nb, m;
    double *A = gather(a, n, 3, &na), *B = gather(b, n, 3, &nb), *gd[2], *gj[2];
    for (int s = 0; s < 2; s++) {
        gd[s] = gather(d[s], n, 1, &m);
        double *jj = malloc(n * sizeof(double) + 8);
        for (size_t k = 0; k < n; k++) jj[k] = (double)j[s][k];
        gj[s] = gather(jj, n, 1, &m);
        free(jj);
    }
    double single = 0;
    int same = 1;
    if (rank_ == 0) {
        hd_points_t Av = hd_points_f64(A, na), Bv = hd_points_f64(B, nb);
        double *rd[2] = {malloc(na * sizeof(double)), malloc(nb * sizeof(double))};
        size_t *rj[2] = {malloc(na * sizeof(size_t)), malloc(nb * sizeof(size_t))};
        hd_options_t o1;
        hd_options_init(&o1);
        o1.threads = threads;
        for (int rep = 0; rep < 2; rep++) { /* the faster of two: the first touches fresh memory */
            double t0 = thread_cpu_now();
            hd_distances(&Av, &Bv, &o1, rd[0], rj[0], rd[1], rj[1], &err);
            double t = (thread_cpu_now() - t0) / (double)(na + nb);
            single = rep == 0 || t < single ? t : single;
        }
        for (int s = 0; s < 2; s++)
            for (size_t k = 0; k < (s ? nb : na); k++)
                same &= memcmp(&rd[s][k], &gd[s][k], sizeof(double)) == 0 && (double)rj[s][k] == gj[s][k];
        for (int s = 0; s < 2; s++) free(rd[s]), free(rj[s]);
    }
    wait_for_rank0();
    uint64_t tot = st.points;
    if (rank_ == 0)
        printf("%-8s %9llu %9.2f %9.3f %9.2f %7.3f %8.1f %8.1f %8.1f %8.1f %8.1f %7.2f %s\n", c,
               (unsigned long long)tot, (double)st.bytes_partition / (double)tot,
               (double)st.bytes_forwarding / (double)tot, (double)st.bytes_returned / (double)tot,
               100.0 * (double)st.forwarded_points / (double)tot, ownmax, 1e9 * st.search_cpu_max / ((double)tot / K_),
               1e9 * st.other_cpu_max / ((double)tot / K_), 1e9 * cpumax, 1e9 * single,
               (st.search_cpu_max + st.other_cpu_max) / ((double)tot / K_) / single, same ? "identical" : "DIFFERS");
    free(A), free(B);
    for (int s = 0; s < 2; s++) free(d[s]), free(j[s]), free(gd[s]), free(gj[s]);
}

/* A sized case's share of side s on this rank: its first global index
 * and count, and its points (malloc'd). */
static double *sized_share(const char *c, int s, const uint64_t N[2], size_t *offset, size_t *n) {
    int blk = s ? (rank_ + K_ / 2) % K_ : rank_;
    uint64_t lo = N[s] * (uint64_t)blk / (uint64_t)K_, hi = N[s] * (uint64_t)(blk + 1) / (uint64_t)K_;
    double *p = malloc(3 * (size_t)(hi - lo) * sizeof(double) + 8);
    if (!p) {
        fprintf(stderr, "mpi_bench: out of memory\n");
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    for (uint64_t g = lo; g < hi; g++) scene_point(c, s, g, p + 3 * (g - lo));
    *offset = (size_t)lo, *n = (size_t)(hi - lo);
    return p;
}

/* --check of a sized case: rank 0 makes both sets whole and compares. */
static void sized_check(const char *c, const uint64_t N[2], const hd_symmetric_t *r) {
    if (rank_ != 0) return;
    double *all[2];
    for (int s = 0; s < 2; s++) {
        all[s] = malloc(3 * (size_t)N[s] * sizeof(double));
        for (uint64_t g = 0; g < N[s]; g++) scene_point(c, s, g, all[s] + 3 * g);
    }
    hd_points_t A = hd_points_f64(all[0], (size_t)N[0]), B = hd_points_f64(all[1], (size_t)N[1]);
    hd_symmetric_t ref;
    hd_error_t err;
    hd_hausdorff(&A, &B, NULL, &ref, &err);
    int same = ref.distance == r->distance && ref.ab.i == r->ab.i && ref.ab.j == r->ab.j && ref.ba.i == r->ba.i &&
               ref.ba.j == r->ba.j;
    printf("#   check: %s (H = %.17g)\n", same ? "identical to hd_hausdorff" : "DIFFERS", r->distance);
    free(all[0]), free(all[1]);
}

static double maxrss(void) {
    struct rusage ru;
    return getrusage(RUSAGE_SELF, &ru) == 0 ? 1024.0 * (double)ru.ru_maxrss : 0;
}

int main(int argc, char **argv) {
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &K_);
    size_t N = 1000000;
    int per_rank = 0, tiles = 0, threads = 1, check = 0, repeat = 1, dist = 0, rank_cpu = 0, prune = 1, replicate = 1;
    const char *cases = "uniform,lidar,copy";
    for (int k = 1; k < argc; k++) {
        if (!strcmp(argv[k], "--points") && k + 1 < argc) N = (size_t)atof(argv[++k]);
        else if (!strcmp(argv[k], "--per-rank")) per_rank = 1;
        else if (!strcmp(argv[k], "--cases") && k + 1 < argc) cases = argv[++k];
        else if (!strcmp(argv[k], "--layout") && k + 1 < argc) tiles = !strcmp(argv[++k], "tiles");
        else if (!strcmp(argv[k], "--threads") && k + 1 < argc) threads = atoi(argv[++k]);
        else if (!strcmp(argv[k], "--check")) check = 1;
        else if (!strcmp(argv[k], "--repeat") && k + 1 < argc) repeat = atoi(argv[++k]);
        else if (!strcmp(argv[k], "--distances")) dist = 1;
        else if (!strcmp(argv[k], "--rank-cpu")) rank_cpu = 1;
        else if (!strcmp(argv[k], "--no-prune")) prune = 0;
        else if (!strcmp(argv[k], "--no-replicate")) replicate = 0;
        else {
            if (rank_ == 0) fprintf(stderr, "mpi_bench: unknown argument %s\n", argv[k]);
            MPI_Finalize();
            return 1;
        }
    }
    size_t n = per_rank ? N : N / (size_t)K_ + ((size_t)rank_ < N % (size_t)K_);
    size_t offset = per_rank ? n * (size_t)rank_ : N / (size_t)K_ * (size_t)rank_ +
                                                       ((size_t)rank_ < N % (size_t)K_ ? (size_t)rank_ : N % (size_t)K_);
    double *a = malloc(3 * n * sizeof(double) + 8), *b = malloc(3 * n * sizeof(double) + 8);
    if (!a || !b) {
        fprintf(stderr, "mpi_bench: out of memory\n");
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    if (rank_ == 0 && dist)
        printf("# mpi_bench --distances: %d ranks, %zu points per side%s, layout %s, %d thread(s) per rank\n"
               "# case     points  B/pt(part) B/pt(fwd) B/pt(ret) fwd%% own B/pt searchcpu ns/pt othercpu ns/pt "
               "cpu ns/pt single ns/pt ratio answers\n", K_, N, per_rank ? " per rank" : "", tiles ? "tiles" : "random", threads);
    else if (rank_ == 0)
        printf("# mpi_bench: %d ranks, %zu points per side%s, layout %s, %d thread(s) per rank\n"
               "# case     points  B/pt(part) B/pt(fwd) fwd%%    imbal work-imbal buf B/pt rss B/pt "
               "time(s) search(s) search ns/pt cpu ns/pt shell%% searchcpu ns/pt hwm B/pt othercpu ns/pt own B/pt "
               "sys ns/pt faults\n",
               K_, N, per_rank ? " per rank" : "", tiles ? "tiles" : "random", threads);
    char list[256];
    snprintf(list, sizeof list, "%s", cases);
    for (char *c = strtok(list, ","); c; c = strtok(NULL, ","))
      for (int rep = 0; rep < (repeat > 0 ? repeat : 1); rep++) {
        uint64_t NS[2];
        int sized = scene_sized(c, NS);
        double *sa = NULL, *sb = NULL;
        size_t oa = offset, ob = offset, na = n, nb = n;
        if (sized) {
            sa = sized_share(c, 0, NS, &oa, &na);
            sb = sized_share(c, 1, NS, &ob, &nb);
        } else {
            scene_make(c, tiles ? rank_ : 0, tiles ? K_ : 1, 7, (uint64_t)rank_, a, b, n);
        }
        if (dist) { /* the sized cases are for hd_mpi_hausdorff */
            if (!sized) bench_distances(c, a, b, n, offset, threads);
            else if (rank_ == 0) printf("# %s: --distances runs on uniform, lidar and copy only\n", c);
            free(sa), free(sb);
            continue;
        }
        hd_mpi_part_t pa = {hd_points_f64(sized ? sa : a, na), oa}, pb = {hd_points_f64(sized ? sb : b, nb), ob};
        hd_mpi_options_t opt;
        hd_mpi_options_init(&opt);
        opt.engine.threads = threads;
        opt.prune = prune;
        opt.replicate = replicate;
        hd_symmetric_t r;
        hd_mpi_stats_t st;
        hd_error_t err;
        double rss0 = maxrss();
        hwm_reset();
        double cur0 = status_kb("VmRSS:");
        MPI_Barrier(MPI_COMM_WORLD);
        double cpu0 = cpu_now(), sys0, flt0, sys1, flt1;
        thread_kernel(&sys0, &flt0);
        int rc = hd_mpi_hausdorff(MPI_COMM_WORLD, &pa, 1, &pb, 1, &opt, &r, &st, &err);
        thread_kernel(&sys1, &flt1);
        double cpu = (cpu_now() - cpu0) / (double)(st.local_points ? st.local_points : 1), cpumax = 0;
        MPI_Reduce(&cpu, &cpumax, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
        double kern[2] = {(sys1 - sys0) / (double)(st.local_points ? st.local_points : 1), flt1 - flt0}, kernmax[2];
        MPI_Reduce(kern, kernmax, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
        if (rc != HD_OK) {
            if (rank_ == 0) fprintf(stderr, "mpi_bench: %s\n", err.message);
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
        double grow = (maxrss() - rss0) / (double)(st.local_points ? st.local_points : 1), most = 0;
        MPI_Reduce(&grow, &most, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
        double hwm = (status_kb("VmHWM:") - cur0) / (double)(st.local_points ? st.local_points : 1), hwmax = 0;
        MPI_Reduce(&hwm, &hwmax, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
        double own = (double)st.peak_bytes / (double)(st.local_points ? st.local_points : 1), ownmax = 0;
        MPI_Reduce(&own, &ownmax, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
        uint64_t tot = st.points;
        if (rank_ == 0)
            printf("%-8s%s %9llu %9.2f %9.3f %7.3f %6.3f %8.3f %10.1f %10.1f %8.3f %8.3f %8.1f %8.1f %7.3f %8.1f %8.1f %8.1f %8.1f %8.1f %8.0f\n", c, rep ? "+" : "",
                   (unsigned long long)tot, (double)st.bytes_partition / (double)tot,
                   (double)st.bytes_forwarding / (double)tot, 100.0 * (double)st.forwarded_points / (double)tot,
                   st.imbalance, st.work_imbalance, (double)st.peak_bytes_max / ((double)tot / K_), most,
                   st.seconds_max, st.search_seconds_max, 1e9 * st.search_seconds_max / ((double)tot / K_),
                   1e9 * cpumax, 100.0 * (double)st.shell_points / (double)tot,
                   1e9 * st.search_cpu_max / ((double)tot / K_), hwmax, 1e9 * st.other_cpu_max / ((double)tot / K_), ownmax,
                   1e9 * kernmax[0], kernmax[1]);
        if (rank_cpu) { /* each rank's own CPU per local point, and its core */
            double mine[3] = {1e9 * st.search_cpu / (double)(st.local_points ? st.local_points : 1),
                              1e9 * st.other_cpu / (double)(st.local_points ? st.local_points : 1), (double)sched_getcpu()};
            double *all = rank_ == 0 ? malloc((size_t)K_ * sizeof mine) : NULL;
            MPI_Gather(mine, 3, MPI_DOUBLE, all, 3, MPI_DOUBLE, 0, MPI_COMM_WORLD);
            for (int q = 0; rank_ == 0 && q < K_; q++)
                printf("#   rank %d (on cpu %.0f): searchcpu %.1f othercpu %.1f ns a local point\n", q, all[3 * q + 2],
                       all[3 * q], all[3 * q + 1]);
            free(all);
        }
        if (check && sized) sized_check(c, NS, &r);
        if (check && !sized) { /* gather everything on rank 0 and compare */
            double *all[2] = {NULL, NULL};
            int cnt = (int)(3 * n), *cnts = malloc((size_t)K_ * sizeof(int)), *disp = malloc((size_t)K_ * sizeof(int));
            MPI_Gather(&cnt, 1, MPI_INT, cnts, 1, MPI_INT, 0, MPI_COMM_WORLD);
            int total = 0;
            for (int q = 0; rank_ == 0 && q < K_; q++) disp[q] = total, total += cnts[q];
            for (int s = 0; s < 2; s++) {
                if (rank_ == 0) all[s] = malloc((size_t)total * sizeof(double));
                MPI_Gatherv(s ? b : a, cnt, MPI_DOUBLE, all[s], cnts, disp, MPI_DOUBLE, 0, MPI_COMM_WORLD);
            }
            if (rank_ == 0) {
                hd_points_t A = hd_points_f64(all[0], (size_t)total / 3), B = hd_points_f64(all[1], (size_t)total / 3);
                hd_symmetric_t ref;
                hd_hausdorff(&A, &B, NULL, &ref, &err);
                int same = ref.distance == r.distance && ref.ab.i == r.ab.i && ref.ab.j == r.ab.j &&
                           ref.ba.i == r.ba.i && ref.ba.j == r.ba.j;
                printf("#   check: %s (H = %.17g)\n", same ? "identical to hd_hausdorff" : "DIFFERS", r.distance);
            }
            free(all[0]);
            free(all[1]);
            free(cnts);
            free(disp);
        }
        fflush(stdout);
        free(sa), free(sb);
    }
    free(a);
    free(b);
    MPI_Finalize();
    return 0;
}
