/*
 * test_oom.c -- running out of memory is an error like any other: every
 * allocation the library makes, in turn, is made to fail, and the call must
 * then return HD_ENOMEM with a message (or, where the library has a
 * fallback, succeed with the exact answer), never crash, hang, leak or
 * return a wrong number.  This is SQLite's out-of-memory test, on a small
 * scale.
 *
 * How: this executable is linked with -Wl,--wrap=malloc,--wrap=calloc,
 * --wrap=realloc (tests/oom.cmake), so every allocation of the library's
 * objects goes through the wrappers below.  An armed countdown lets k
 * allocations succeed and fails the next one: in one mode every later one
 * too (memory is gone: a fallback that allocates again fails as well), in
 * the other only that one (a transient failure: the code must not carry on
 * with what it did not get, as if it had).  For k = 0, 1, 2, ... each
 * operation runs until a run completes without reaching the failure; every
 * run before that must fail cleanly or give the reference answer.  Leaks
 * on the error paths are caught by LeakSanitizer in the sanitizer build.
 * Allocations made inside the C library itself (thread stacks, stdio) are
 * not wrapped.  pthread_create is wrapped too, so that threads that cannot
 * start are also tested: they may cost speed, never part of an answer.
 */
#include "brute.h"
#include "check.h"
#include "gen.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

/* ---- the failing allocator ------------------------------------------------ */

void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t size);
void *__real_realloc(void *p, size_t n);

static atomic_long budget = -1; /* allocations left before failing; -1: off */
static atomic_int reached;      /* a failure was injected since arming */
static int once;                /* fail only that one allocation, not the later ones */

static atomic_int failed_kind;  /* 'm', 'c' or 'r': which call was made to fail */

static int allow(int kind) {
    long left = atomic_load(&budget);
    while (left >= 0) {
        if (left == 0) {
            atomic_store(&reached, 1);
            atomic_store(&failed_kind, kind);
            if (once) atomic_store(&budget, -1);
            return 0;
        }
        if (atomic_compare_exchange_weak(&budget, &left, left - 1)) return 1;
    }
    return 1;
}

void *__wrap_malloc(size_t n) { return allow('m') ? __real_malloc(n) : NULL; }
void *__wrap_calloc(size_t n, size_t size) { return allow('c') ? __real_calloc(n, size) : NULL; }
void *__wrap_realloc(void *p, size_t n) { return allow('r') ? __real_realloc(p, n) : NULL; }

/* Threads too: while no_threads is set, no thread can be started. */
int __real_pthread_create(pthread_t *t, const pthread_attr_t *attr, void *(*fn)(void *), void *arg);
static atomic_int no_threads, refused;

int __wrap_pthread_create(pthread_t *t, const pthread_attr_t *attr, void *(*fn)(void *), void *arg) {
    if (!atomic_load(&no_threads)) return __real_pthread_create(t, attr, fn, arg);
    atomic_fetch_add(&refused, 1);
    return EAGAIN;
}

/* Mappings of files too: while map_errno is set, mapping a file fails with
 * it (the address space is gone: RLIMIT_AS), as mmap reports it.
 * Anonymous mappings (the library's large blocks) are not touched. */
void *__real_mmap(void *addr, size_t len, int prot, int flags, int fd, off_t off);
static atomic_int map_errno;

void *__wrap_mmap(void *addr, size_t len, int prot, int flags, int fd, off_t off) {
    int e = atomic_load(&map_errno);
    if (!e || fd < 0) return __real_mmap(addr, len, prot, flags, fd, off);
    errno = e;
    return MAP_FAILED;
}

static void arm(long k) {
    atomic_store(&reached, 0);
    atomic_store(&budget, k);
}

/* Disarm; returns whether a failure was injected. */
static int disarm(void) {
    atomic_store(&budget, -1);
    return atomic_load(&reached);
}

/* ---- the driver -------------------------------------------------------------- */

/* One operation: run it (the allocator possibly armed), returning its code;
 * check the answer of a successful run against the reference. */
typedef struct op op_t;
struct op {
    const char *name;
    int (*run)(op_t *op, hd_error_t *err);
    void (*check)(op_t *op); /* after an HD_OK run, allocator disarmed */
    void *ctx;
};

/* Fail each allocation of op in turn until it needs no more, in both
 * modes. */
static void exhaust_mode(op_t *op);

static void exhaust(op_t *op) {
    for (once = 0; once <= 1 && !hdt_failed(); once++) exhaust_mode(op);
    once = 0;
}

static void exhaust_mode(op_t *op) {
    long k;
    for (k = 0; k < 20000 && !hdt_failed(); k++) {
        CONTEXT("%s, allocation %ld made to fail%s", op->name, k, once ? " (only that one)" : " (and every later one)");
        hd_error_t err;
        memset(&err, 0, sizeof err);
        arm(k);
        int rc = op->run(op, &err);
        int injected = disarm();
        if (rc == HD_OK) {
            op->check(op);
            if (!injected) break; /* every allocation succeeded: done */
            continue;             /* a fallback absorbed the failure */
        }
        CHECK(injected);
        if (rc != HD_ENOMEM)
            hdt_fail(__FILE__, __LINE__, "returned %s (%s), expected HD_ENOMEM", hd_err_name(rc),
                     err.message);
        CHECK_EQ(err.code, HD_ENOMEM);
        CHECK(err.message[0] != '\0');
    }
    CHECK(k > 0);         /* the operation allocates at all */
    CHECK(k < 20000);     /* and it ended */
}

/* ---- the operations ------------------------------------------------------------ */

typedef struct {
    double *a, *b;
    size_t na, nb;
    hd_options_t opt;
    brute_t ab, ba;       /* the reference */
    double *want_dist[2]; /* the reference per-point answers */
    size_t *want_near[2];
    hd_symmetric_t got;
    double *dist[2];
    size_t *near[2];
} pair_ctx;

static void pair_init(pair_ctx *c, size_t na, size_t nb, int threads) {
    memset(c, 0, sizeof *c);
    c->na = na, c->nb = nb;
    c->a = malloc(24 * na);
    c->b = malloc(24 * nb);
    hd_options_init(&c->opt);
    c->opt.threads = threads;
}

/* The per-point answers of the points q against p. */
static void nearest_all(const double *q, size_t nq, const double *p, size_t np, double *dist,
                        size_t *near) {
    for (size_t k = 0; k < nq; k++) dist[k] = sqrt(brute_nearest(q + 3 * k, p, np, &near[k]));
}

/* The reference: the brute force on small sets.  On large ones (where it
 * would take minutes) the library's own answers with nothing failing:
 * their exactness is test_engine's and test_analysis's subject, the
 * question here is only whether a failure changes anything. */
static void pair_reference(pair_ctx *c) {
    for (int d = 0; d < 2; d++) {
        size_t n = d ? c->nb : c->na;
        c->dist[d] = malloc(8 * n);
        c->near[d] = malloc(sizeof(size_t) * n);
        c->want_dist[d] = malloc(8 * n);
        c->want_near[d] = malloc(sizeof(size_t) * n);
    }
    if (c->na * c->nb <= 10000000) {
        c->ab = brute_directed(c->a, c->na, c->b, c->nb);
        c->ba = brute_directed(c->b, c->nb, c->a, c->na);
        nearest_all(c->a, c->na, c->b, c->nb, c->want_dist[0], c->want_near[0]);
        nearest_all(c->b, c->nb, c->a, c->na, c->want_dist[1], c->want_near[1]);
        return;
    }
    hd_points_t A = hd_points_f64(c->a, c->na), B = hd_points_f64(c->b, c->nb);
    hd_symmetric_t s;
    CHECK_RC(hd_hausdorff(&A, &B, &c->opt, &s, NULL), HD_OK);
    c->ab = (brute_t){s.ab.distance2, s.ab.i, s.ab.j};
    c->ba = (brute_t){s.ba.distance2, s.ba.i, s.ba.j};
    CHECK_RC(hd_distances(&A, &B, &c->opt, c->want_dist[0], c->want_near[0], c->want_dist[1],
                          c->want_near[1], NULL),
             HD_OK);
}

static void pair_free(pair_ctx *c) {
    free(c->a);
    free(c->b);
    for (int d = 0; d < 2; d++) {
        free(c->dist[d]), free(c->near[d]);
        free(c->want_dist[d]), free(c->want_near[d]);
    }
}

static int run_hausdorff(op_t *op, hd_error_t *err) {
    pair_ctx *c = op->ctx;
    hd_points_t A = hd_points_f64(c->a, c->na), B = hd_points_f64(c->b, c->nb);
    return hd_hausdorff(&A, &B, &c->opt, &c->got, err);
}

static void check_hausdorff(op_t *op) {
    pair_ctx *c = op->ctx;
    CHECK_BITS(c->got.ab.distance2, c->ab.d2);
    CHECK_EQ(c->got.ab.i, c->ab.i);
    CHECK_EQ(c->got.ab.j, c->ab.j);
    CHECK_BITS(c->got.ba.distance2, c->ba.d2);
    CHECK_EQ(c->got.ba.i, c->ba.i);
    CHECK_EQ(c->got.ba.j, c->ba.j);
}

/* Per-point answers of direction d against the reference. */
static void check_nearest(const pair_ctx *c, int d) {
    size_t n = d ? c->nb : c->na;
    for (size_t k = 0; k < n && !hdt_failed(); k++) {
        CHECK_BITS(c->dist[d][k], c->want_dist[d][k]);
        CHECK_EQ(c->near[d][k], c->want_near[d][k]);
    }
}

static int run_distances(op_t *op, hd_error_t *err) {
    pair_ctx *c = op->ctx;
    hd_points_t A = hd_points_f64(c->a, c->na), B = hd_points_f64(c->b, c->nb);
    return hd_distances(&A, &B, &c->opt, c->dist[0], c->near[0], c->dist[1], c->near[1], err);
}

static void check_distances(op_t *op) {
    pair_ctx *c = op->ctx;
    check_nearest(c, 0);
    check_nearest(c, 1);
}

/* Build an index of B, then h(A,B) and A's per-point answers through it. */
static int run_index(op_t *op, hd_error_t *err) {
    pair_ctx *c = op->ctx;
    hd_points_t A = hd_points_f64(c->a, c->na), B = hd_points_f64(c->b, c->nb);
    hd_index_t *idx = NULL;
    int rc = hd_index_build(&B, &c->opt, &idx, err);
    if (rc != HD_OK) CHECK(idx == NULL);
    if (rc == HD_OK) rc = hd_index_directed(idx, &A, NULL, &c->opt, &c->got.ab, err);
    if (rc == HD_OK) rc = hd_index_nearest(idx, &A, NULL, &c->opt, c->dist[0], c->near[0], err);
    hd_index_free(idx);
    return rc;
}

static void check_index(op_t *op) {
    pair_ctx *c = op->ctx;
    CHECK_BITS(c->got.ab.distance2, c->ab.d2);
    CHECK_EQ(c->got.ab.i, c->ab.i);
    CHECK_EQ(c->got.ab.j, c->ab.j);
    check_nearest(c, 0);
}

static void exhaust_pair(const char *name, pair_ctx *c, int (*run)(op_t *, hd_error_t *),
                         void (*check)(op_t *)) {
    pair_reference(c);
    op_t op = {name, run, check, c};
    exhaust(&op);
}

/* Overlapping Gaussians (the engine's grid pass). */
static void gaussians(pair_ctx *c, uint64_t seed) {
    gen_rng_t g;
    gen_seed(&g, seed);
    double m[3] = {0, 0, 0};
    gen_gauss(&g, c->a, c->na, m, 1.0);
    m[0] = 0.3;
    gen_gauss(&g, c->b, c->nb, m, 1.0);
}

/* ---- the behaviours --------------------------------------------------------------- */

TEST(every_allocation_of_the_auto_engine_can_fail_cleanly) {
    /* The four plans: the grid pass, the copy in the same order, the same
     * copy shuffled (bucket trees), an ordered subset; 1 and 2 threads; and
     * the trees once more on 70000 points, where the sorts run in parallel
     * parts. */
    for (int plan = 0; plan < 5 && !hdt_failed(); plan++)
        for (int threads = 1; threads <= 2 && !hdt_failed(); threads++) {
            if (plan == 4 && threads == 1) continue;
            uint64_t seed = 21000 + (uint64_t)plan;
            char name[128];
            snprintf(name, sizeof name, "hd_hausdorff auto, seed=%llu plan=%d threads=%d",
                     (unsigned long long)seed, plan, threads);
            pair_ctx c;
            size_t n = plan == 4 ? 70000 : 3000;
            pair_init(&c, n, plan == 3 ? n / 10 : n, threads);
            gen_rng_t g;
            gen_seed(&g, seed);
            if (plan == 0) {
                gaussians(&c, seed);
            } else if (plan == 3) {
                double m[3] = {0, 0, 0};
                gen_gauss(&g, c.a, n, m, 1.0);
                for (size_t k = 0; k < c.nb; k++) memcpy(c.b + 3 * k, c.a + 30 * k, 24);
            } else {
                gen_copy(&g, GEN_COPY_NOISE, c.a, c.b, n);
                for (size_t k = n - 1; plan != 1 && k > 0; k--) gen_swap(c.b, k, gen_u64(&g) % (k + 1));
            }
            exhaust_pair(name, &c, run_hausdorff, check_hausdorff);
            pair_free(&c);
        }
}

TEST(every_allocation_of_every_algorithm_can_fail_cleanly) {
    static const char *const names[] = {"naive", "earlybreak", "inc", "nohd", "ohd", "framework", "kdtree"};
    for (size_t k = 0; k < sizeof names / sizeof names[0] && !hdt_failed(); k++) {
        char name[128];
        snprintf(name, sizeof name, "hd_hausdorff %s, seed=21100 threads=2", names[k]);
        pair_ctx c;
        pair_init(&c, 700, 500, 2);
        gaussians(&c, 21100);
        CHECK_RC(hd_algorithm_from_name(names[k], &c.opt.algorithm), HD_OK);
        exhaust_pair(name, &c, run_hausdorff, check_hausdorff);
        pair_free(&c);
    }
}

TEST(every_allocation_of_per_point_distances_can_fail_cleanly) {
    /* Small sets, and sets large enough for the sorts' parallel parts. */
    for (int size = 0; size < 2 && !hdt_failed(); size++)
        for (int threads = 1; threads <= 2 && !hdt_failed(); threads++) {
            if (size == 1 && threads == 1) continue;
            char name[128];
            snprintf(name, sizeof name, "hd_distances, seed=21200 size=%d threads=%d", size, threads);
            pair_ctx c;
            pair_init(&c, size ? 70000 : 2500, size ? 66000 : 2000, threads);
            gaussians(&c, 21200);
            exhaust_pair(name, &c, run_distances, check_distances);
            pair_free(&c);
        }
}

TEST(every_allocation_of_an_index_and_its_queries_can_fail_cleanly) {
    /* hd_index_nearest falls back to searching the index's tree when the
     * per-point structures cannot be had: those runs must still be exact. */
    for (int threads = 1; threads <= 2 && !hdt_failed(); threads++) {
        char name[128];
        snprintf(name, sizeof name, "hd_index_build, _directed, _nearest, seed=21300 threads=%d", threads);
        pair_ctx c;
        pair_init(&c, 2000, 2500, threads);
        gaussians(&c, 21300);
        exhaust_pair(name, &c, run_index, check_index);
        pair_free(&c);
    }
}

typedef struct {
    pair_ctx *pair;
    hd_percentile_t want, got;
} pct_ctx;

static int run_percentile(op_t *op, hd_error_t *err) {
    pct_ctx *c = op->ctx;
    hd_points_t A = hd_points_f64(c->pair->a, c->pair->na), B = hd_points_f64(c->pair->b, c->pair->nb);
    return hd_hausdorff_percentile(&A, &B, &c->pair->opt, 95, &c->got, err);
}

static void check_percentile(op_t *op) {
    pct_ctx *c = op->ctx;
    CHECK(memcmp(&c->got, &c->want, sizeof c->got) == 0);
}

TEST(every_allocation_of_a_percentile_hausdorff_can_fail_cleanly) {
    /* The bands' passes, point by point on overlapping sets, with whole
     * nodes settled from bounds on sets 20 apart.  The reference is the
     * same call with nothing failing (test_analysis compares it with
     * numpy's definition). */
    for (int apart = 0; apart < 2 && !hdt_failed(); apart++) {
        pair_ctx p;
        pair_init(&p, 2500, 2000, 2);
        gaussians(&p, 21400);
        for (size_t i = 0; apart && i < p.nb; i++) p.b[3 * i] += 20;
        pct_ctx c;
        memset(&c, 0, sizeof c);
        c.pair = &p;
        hd_points_t A = hd_points_f64(p.a, p.na), B = hd_points_f64(p.b, p.nb);
        CHECK_RC(hd_hausdorff_percentile(&A, &B, &p.opt, 95, &c.want, NULL), HD_OK);
        op_t op = {apart ? "hd_hausdorff_percentile 95, seed=21400 threads=2, B 20 apart"
                         : "hd_hausdorff_percentile 95, seed=21400 threads=2",
                   run_percentile, check_percentile, &c};
        exhaust(&op);
        pair_free(&p);
    }
}

TEST(threads_that_cannot_start_cost_speed_not_answers) {
    /* At 2 threads with pthread_create failing, the caller's thread does
     * every task: each plan of the engine, per-point distances and the index
     * give the reference answers. */
    for (int plan = 0; plan < 3 && !hdt_failed(); plan++) {
        uint64_t seed = 21500 + (uint64_t)plan;
        CONTEXT("seed=%llu plan=%d, no thread can start", (unsigned long long)seed, plan);
        pair_ctx c;
        size_t n = 70000;
        pair_init(&c, n, n, 2);
        gen_rng_t g;
        gen_seed(&g, seed);
        if (plan == 0) {
            gaussians(&c, seed);
        } else {
            gen_copy(&g, GEN_COPY_NOISE, c.a, c.b, n);
            for (size_t k = n - 1; plan == 2 && k > 0; k--) gen_swap(c.b, k, gen_u64(&g) % (k + 1));
        }
        pair_reference(&c);
        op_t ops[3] = {{"hd_hausdorff", run_hausdorff, check_hausdorff, &c},
                       {"hd_distances", run_distances, check_distances, &c},
                       {"hd_index", run_index, check_index, &c}};
        for (int k = 0; k < 3 && !hdt_failed(); k++) {
            atomic_store(&refused, 0);
            atomic_store(&no_threads, 1);
            int rc = ops[k].run(&ops[k], NULL);
            atomic_store(&no_threads, 0);
            CHECK(atomic_load(&refused) > 0); /* it did try to start threads */
            CHECK_RC(rc, HD_OK);
            if (rc == HD_OK) ops[k].check(&ops[k]);
        }
        pair_free(&c);
    }
}

TEST(per_point_queries_of_an_index_fall_back_to_its_tree_without_memory) {
    /* hd_index_nearest builds per-point structures for each call; when one
     * of their allocations fails, the index's own tree answers instead, at
     * the same values.  With the index built beforehand, some transient
     * failures of malloc during the query must therefore end in HD_OK.
     * (A failed realloc may end in HD_OK anyway: the structures shrink
     * their arrays when built, and keep the larger block if that fails.) */
    pair_ctx c;
    pair_init(&c, 2000, 2500, 1);
    gaussians(&c, 21350);
    pair_reference(&c);
    hd_points_t A = hd_points_f64(c.a, c.na), B = hd_points_f64(c.b, c.nb);
    hd_index_t *idx = NULL;
    CHECK_RC(hd_index_build(&B, &c.opt, &idx, NULL), HD_OK);
    long absorbed = 0, k;
    once = 1;
    for (k = 0; k < 1000 && idx && !hdt_failed(); k++) {
        CONTEXT("seed=21350, allocation %ld of hd_index_nearest made to fail (only that one)", k);
        arm(k);
        int rc = hd_index_nearest(idx, &A, NULL, &c.opt, c.dist[0], c.near[0], NULL);
        int injected = disarm();
        if (rc == HD_OK) check_nearest(&c, 0);
        else CHECK_RC(rc, HD_ENOMEM);
        if (!injected) break;
        absorbed += rc == HD_OK && atomic_load(&failed_kind) != 'r';
    }
    once = 0;
    CHECK(absorbed > 0);
    hd_index_free(idx);
    pair_free(&c);
}

/* ---- readers ------------------------------------------------------------------------ */

typedef struct {
    const char *path;
    hd_read_options_t opt;
    hd_cloud_t *want; /* read with nothing failing */
    hd_cloud_t *got;
} read_ctx;

static int run_read(op_t *op, hd_error_t *err) {
    read_ctx *c = op->ctx;
    c->got = NULL;
    int rc = hd_read_file(c->path, &c->opt, &c->got, err);
    if (rc != HD_OK) CHECK(c->got == NULL);
    return rc;
}

static void check_read(op_t *op) {
    read_ctx *c = op->ctx;
    CHECK_EQ(c->got->count, c->want->count);
    CHECK_EQ(c->got->dtype, c->want->dtype);
    if (c->got->count == c->want->count && c->got->dtype == c->want->dtype)
        CHECK(memcmp(c->got->data, c->want->data,
                     c->got->count * (c->got->dtype == HD_FLOAT32 ? 12 : 24)) == 0);
    hd_cloud_free(c->got);
    c->got = NULL;
}

/* Read c->path with nothing failing, then with each allocation failing. */
static void exhaust_read(read_ctx *c, const char *name) {
    CHECK_RC(hd_read_file(c->path, &c->opt, &c->want, NULL), HD_OK);
    if (!c->want) return;
    op_t op = {name, run_read, check_read, c};
    exhaust(&op);
    hd_cloud_free(c->want);
}

TEST(every_allocation_of_every_reader_can_fail_cleanly) {
    /* One file of each format, and a larger PLY and OFF (several blocks
     * for the parallel parsers). */
    static const char *const files[] = {
        "tests/corpus/ply/ascii.ply",   "tests/corpus/ply/binary_little_endian.ply",
        "tests/corpus/obj/mesh.obj",    "tests/corpus/off/coff.off",
        "tests/corpus/stl/ascii.stl",   "tests/corpus/stl/binary.stl",
        "tests/corpus/xyz/header.csv",  "tests/corpus/xyz/leica.pts",
        "tests/corpus/pcd/ascii.pcd",   "tests/corpus/pcd/compressed.pcd",
        "tests/corpus/las/v14_fmt6.las", "tests/corpus/npy/f_be_f4.npy",
        "tests/corpus/laz/fmt3_extra2.laz", "tests/corpus/laz/fmt6_channels.laz",
        "tests/corpus/laz/fmt3_laszip1_extra1.laz", "tests/corpus/laz/fmt0_repeated_point.laz",
        "data/cgal_lion_head.ply",      "data/orig/lion-head.off",
    };
    for (size_t k = 0; k < sizeof files / sizeof files[0] && !hdt_failed(); k++)
        for (int threads = 1; threads <= 2 && !hdt_failed(); threads++) {
            char name[512];
            snprintf(name, sizeof name, "hd_read_file %s, threads=%d", files[k], threads);
            CONTEXT("%s", name);
            read_ctx c;
            memset(&c, 0, sizeof c);
            c.path = files[k];
            hd_read_options_init(&c.opt);
            c.opt.threads = threads;
            exhaust_read(&c, name);
        }
}

TEST(every_allocation_of_sampling_a_mesh_can_fail_cleanly) {
    /* Points drawn on the faces (a face table, cumulative areas, seeded
     * draws) rather than the vertices. */
    read_ctx c;
    memset(&c, 0, sizeof c);
    c.path = "data/orig/lion-head.off";
    hd_read_options_init(&c.opt);
    c.opt.mesh = HD_MESH_SAMPLE;
    c.opt.sample = 5000;
    c.opt.seed = 7;
    c.opt.threads = 2;
    exhaust_read(&c, "hd_read_file data/orig/lion-head.off, 5000 points sampled, seed=7");
}

/* ---- cloud to mesh ------------------------------------------------------------------ */

typedef struct {
    hd_mesh_file_t *mesh;
    double *p, *want, *got;
    size_t n;
    hd_options_t opt;
} c2m_ctx;

static int run_c2m(op_t *op, hd_error_t *err) {
    c2m_ctx *c = op->ctx;
    hd_points_t P = hd_points_f64(c->p, c->n);
    hd_mesh_t M = hd_mesh_file_view(c->mesh);
    return hd_mesh_distances(&P, &M, &c->opt, c->got, NULL, NULL, NULL, NULL, err);
}

static void check_c2m(op_t *op) {
    c2m_ctx *c = op->ctx;
    CHECK(memcmp(c->got, c->want, c->n * sizeof *c->got) == 0);
}

TEST(every_allocation_of_a_cloud_to_mesh_call_can_fail_cleanly) {
    /* The triangles' copy, the tree (keys, nodes, boxes, prepared records,
     * frames: optional), the points' order, the runs' results; 2 threads.
     * Points near the cow's vertices (seed 37). */
    c2m_ctx c;
    memset(&c, 0, sizeof c);
    CHECK_RC(hd_read_mesh("data/orig/cow.off", NULL, &c.mesh, NULL), HD_OK);
    if (!c.mesh) return;
    gen_rng_t g;
    gen_seed(&g, 37);
    c.n = 2000;
    c.p = malloc(3 * c.n * sizeof *c.p), c.want = malloc(c.n * sizeof *c.want), c.got = malloc(c.n * sizeof *c.got);
    for (size_t i = 0; i < c.n; i++)
        for (int k = 0; k < 3; k++)
            c.p[3 * i + k] = c.mesh->vertices[3 * (gen_u64(&g) % c.mesh->n_vertices) + k] + 0.01 * (gen_unit(&g) - 0.5);
    hd_options_init(&c.opt);
    c.opt.threads = 2;
    op_t op = {"hd_mesh_distances data/orig/cow.off, 2000 points, seed=37 threads=2", run_c2m, check_c2m, &c};
    double *keep = c.got;
    c.got = c.want;
    CHECK_RC(run_c2m(&op, NULL), HD_OK);
    c.got = keep;
    exhaust(&op);
    free(c.p), free(c.want), free(c.got);
    hd_mesh_file_free(c.mesh);
}

TEST(a_file_that_cannot_be_mapped_for_want_of_memory_is_out_of_memory_not_bad_input) {
    /* ENOMEM (address space) and EAGAIN (locked memory) are a lack of
     * memory: HD_ENOMEM, which the tools exit 3 for; another failure of
     * the mapping stays an input error */
    static const int errs[3] = {ENOMEM, EAGAIN, ENODEV};
    static const int codes[3] = {HD_ENOMEM, HD_ENOMEM, HD_EIO};
    const char *path = "tests/corpus/ply/ascii.ply";
    for (int k = 0; k < 3; k++) {
        CONTEXT("mmap failing with %s", strerror(errs[k]));
        hd_cloud_t *c = NULL;
        hd_error_t err;
        atomic_store(&map_errno, errs[k]);
        int rc = hd_read_file(path, NULL, &c, &err);
        atomic_store(&map_errno, 0);
        CHECK_RC(rc, codes[k]);
        CHECK(c == NULL);
        CHECK(strstr(err.message, path) && strstr(err.message, strerror(errs[k])));
        uint64_t n;
        atomic_store(&map_errno, errs[k]);
        rc = hd_read_count(path, NULL, &n, &err);
        atomic_store(&map_errno, 0);
        CHECK_RC(rc, codes[k]);
    }
    hd_cloud_t *c = NULL;
    CHECK_RC(hd_read_file(path, NULL, &c, NULL), HD_OK); /* and mapped again once memory is back */
    hd_cloud_free(c);
}
