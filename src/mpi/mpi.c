/*
 * mpi.c -- the exact Hausdorff distance of point sets spread over the ranks
 * of an MPI communicator (hausdorff_mpi.h).  A layer above the public entry
 * points: it calls the public API (hd_directed, hd_overlap), the nearest
 * layer's all-nearest search (nearest/nearest.h, what hd_distances runs)
 * and the points layer's geometry (points/points.h: the one squared
 * distance, boxes, the validation pass); nothing below includes it.  docs/scale-out.md has the
 * measurements and the cost model.
 *
 * The files: this one holds the entry points and the call's course (the
 * steps below); context.c the call's context (memory, agreement, MPI
 * types), ranges.c the validation and the index runs, rcb.c the partition
 * (step 1), exchange.c the exchange (2), shell.c the engine's pass (3),
 * slab.c the per-point searches, forward.c the forwarding and reduction
 * (4 to 6), tiny.c the course without a partition when one side is tiny
 * (replicated on every rank), views.c the caller's points as views in index
 * order; gidx.c the local sets' indices, distances.c and analysis.c
 * the per-point distances and their figures.  What they share is in
 * private headers by concern: context.h, ranges.h, partition.h,
 * search.h and course.h.  Each file opens with its invariants.
 *
 * The algorithm, for h(A,B) (the symmetric distance runs it both ways on one
 * partition):
 *  1. Partition.  Every rank samples its points of A and B (evenly spaced in
 *     its own order, as many as its share of 1024 a rank, fewer beyond 64
 *     ranks: rcb.c, FIRST_TOTAL) and sends them to rank 0, which cuts
 *     space by recursive coordinate bisection (RCB): each node of k ranks
 *     splits its samples along their longest axis so that floor(k/2)/k of
 *     them go left.  The split key is a sample's
 *     (coordinate, set, global index), so points on the split plane are
 *     divided too (a lattice, or every point equal, still balances); a
 *     point goes left when its key is smaller.  The tree (k - 1 nodes) is
 *     broadcast, and each split is then moved, level by level, to the plane
 *     of its node's bracket that divides a second, larger sample (up to
 *     32768 a rank) nearest to floor(k/2)/k, counted exactly by one
 *     all-reduce a level (rcb.c, refine: a sample quantile is off by about
 *     a standard deviation, the exact counts are not; mpi_partition_K and
 *     mpi_bench measure the balance, docs/scale-out.md).  Any
 *     tree is a correct partition; the samples decide only the balance.
 *     Each rank's region is a box (faces at split coordinates,
 *     infinite outside), and every point of another region lies on or
 *     beyond one of its faces.
 *  2. MPI_Alltoallv moves each point to the rank of its region as its
 *     coordinates and a 4-byte number, its rank among the sender's points
 *     of its set in index order (28 bytes; every rank knows every rank's
 *     index runs, so the receiver turns it back into the global index).
 *     Each source's run is received straight into its slot of the local
 *     arrays, in rounds of at most an eighth of a rank's points, so the
 *     points are never held twice.  Senders walk their parts in increasing
 *     index order, so each run is sorted; when the runs follow each other
 *     in index order (each rank's parts above the previous rank's) the
 *     local arrays are in global order as received, else the numbers
 *     become 8-byte indices and the arrays are merged in place (a
 *     permutation, 4 bytes a point): local order is global index order,
 *     and a local "smallest index on ties" is the global one.  The indices
 *     are then held Elias-Fano coded over the set's dense ordinals (hd__mpi_gidx_t:
 *     3 + log2(N_side / n) bits a point or so, under 1 byte at K <= 16;
 *     the numbers and indices are freed), so a point costs 24 bytes and a
 *     fraction through the engine's pass, and an index is decoded where
 *     one is needed (by a cursor in the per-point loops).  The arrays are
 *     never reordered afterwards (the engine's passes on a subset move
 *     coordinates only), so a position's index is fixed.
 *     On one rank none of this happens: the engine runs on the caller's
 *     points as they are (one part a set) or packed once (several).
 *  3. The single-machine engine on each rank's part: hd_directed(local A,
 *     local B) gives h2, the rank's largest u(a)^2, where u(a)^2 is the
 *     exact minimum over local B (an upper bound on the minimum over all
 *     of B); the symmetric call runs hd_hausdorff once for both
 *     directions (each engine call builds both sets' structures).  Every
 *     a whose region faces are clear of h2 (step 4's test
 *     with h2 >= u(a)^2) is settled without a search of its own (the
 *     interior).  The engine's maximum keeps only the points whose faces
 *     are clear of their own u (a filter on it: shell.c), so its answer
 *     h_I is a kept point's global u, and every point the filter did not
 *     refuse is interior: kept (exact), or never offered, so below h_I or
 *     at it with a larger index than the witness (hd__keep_t), which no
 *     other rank's points can change; the shell is the refused points
 *     alone.  When the filter's list of refused points overflows, the
 *     filter keeps every point from then on, and the larger of its answer
 *     and the listed points' exact u is the unfiltered answer (no second
 *     pass); when it keeps none, the engine runs unfiltered.  Unfiltered:
 *     When the engine's witness is interior, it is the
 *     interior's maximum; else the interior's maximum is computed (one
 *     more engine call on it, its maximum starting at G, so what cannot
 *     beat G is pruned at once) only on a rank where the engine's answer
 *     beats G, the best over all ranks found without it (step 6): every
 *     interior point is below that answer; the shell is the points within
 *     h of the faces.  The shell's points get per-point searches (the nearest layer's, as
 *     hd_distances runs them: the nearest local b, smallest index on
 *     ties) on a structure of the slab of local B within 1.5h of the
 *     faces, which the forwarded queries of step 5 ask too; a shell
 *     point's answer the slab cannot prove (slab.c) is an upper bound that
 *     steps 4 and 5 use as it is, proven after the round by the smallest
 *     answer or else searched again (forward.c, resolve): a wider slab,
 *     then all of B.
 *     The engine prunes the points that cannot be the farthest, which
 *     per-point searches cannot: on two epochs of one scene that is tens
 *     of times less work.  For a copy and its original (point g of B the
 *     moved point g of A) the rank first passes its whole pairs to the
 *     engine in the same order, so the engine's correspondence path runs
 *     (paired_pass in shell.c).
 *  4. a is *confirmed* when every finite face of its region is strictly
 *     farther than u(a): a point b beyond the face at s on axis k has
 *     |fl(a_k - b_k)| >= |fl(a_k - s)| (rounding is monotone), and the
 *     squared sum keeps that order (points/points.h), so hd__d2(a, b) >=
 *     fl(gap^2) > u(a)^2: no other rank holds a point as near, nor one that
 *     ties.  L, the largest confirmed u^2 over all ranks with the smallest
 *     index i_L of a confirmed point at L (one allreduce), bounds h(A,B)^2
 *     from below: a point with u(a)^2 < L, or u(a)^2 = L and an index above
 *     i_L, cannot be the witness and is never forwarded.  Every other
 *     point adds its own lower bound to L before anything travels: the
 *     smaller of its local u(a)^2 and hd__box_lb2 to every other rank's
 *     box of B (a computed lower bound of its global nearest distance, so
 *     of h^2), entered with no index, so that a point at exactly L is
 *     kept.  Then a sample of B that every rank holds (forward.c) lowers
 *     u(a) to an upper bound from all of B; a point with a sample point
 *     nearer than L is settled as a loser, and when the sample is all of
 *     B (a tiny side) it is the exact answer.  A rank without B, or whose
 *     shell is most of its A (sets far apart), searches none of it one by
 *     one before that: the sample's bounds come first, the points they
 *     show cannot win are dropped with their per-point state, and only the
 *     rest are searched in the local B (forward.c, one_sided_shell).
 *     (Skipping every
 *     u(a)^2 <= L would lose ties: a point at exactly L with a smaller
 *     index is the witness, and its smallest-index nearest point may lie on
 *     another rank; tests/api/mpi_api.c's checkerboard fails that way.)
 *  5. Every other a with u(a)^2 >= L is sent to each rank whose box of B
 *     points lies within u(a) (hd__box_lb2 <= u^2: a computed lower bound
 *     no larger than the computed distance to any point inside, so every
 *     rank holding a point at distance <= u(a), ties included, is asked).
 *     The boxes are all-gathered once and searched through the RCB tree
 *     (each node's box is the union of its ranks').  A rank with no B
 *     point has u = infinity; it bounds a by the nearest farthest corner of
 *     the nonempty boxes (hd__box_ub2: at least the distance to every point
 *     inside), so it asks only the candidate ranks.  The asked ranks answer
 *     with their exact nearest (squared distance, smallest global index),
 *     and the asker keeps the smaller pair: the exact global answer.  Two
 *     rounds: first the few points a rank with the largest upper bounds,
 *     whose exact answers raise L, then every point still able to win;
 *     each round's bounds are final before it is sent.
 *  6. Each rank's farthest exact point (largest d2, smallest index on ties)
 *     is max-reduced; then the ranks of step 3 whose engine answer beats
 *     that add their interior's maximum, and it is reduced again.  The
 *     result is the pair hd_hausdorff gives on the union, bit for bit,
 *     since every value compared is an hd__d2 of the same doubles.
 *
 * Failures: any local failure (a bad point, memory) is agreed on before the
 * next collective that could block (agree(): an allreduce of the first
 * failing rank, then its code and message broadcast), so every rank returns
 * the same code and message and none waits for a rank that gave up.
 */
#include "mpi/course.h"
#include "mpi/search.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

/* K = 1: the engine on the views. */
static int single(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, int both, hd__mpi_far_t *f) {
    hd__mpi_views_t vw;
    int rc = hd__mpi_views(c, in, &vw);
    double t0 = hd__now(), u0 = hd__mpi_cpu();
    for (int s = 0; s < (both ? 2 : 1) && rc == HD_OK; s++) {
        hd_result_t e;
        if ((rc = hd__mpi_engine(c, &vw.v[s], &vw.v[1 - s], &e)) == HD_OK)
            f[s] = (hd__mpi_far_t){e.distance2, hd__mpi_ranges_global(rg, s, 0, e.i), hd__mpi_ranges_global(rg, 1 - s, 0, e.j)};
    }
    c->search += hd__now() - t0;
    c->search_cpu += hd__mpi_cpu() - u0;
    hd__mpi_views_free(c, in, &vw);
    return rc;
}

/* The start of every call: the local checks (agreed), the index runs, the
 * global counts N (an empty set is HD_EEMPTY) and, when box is not NULL,
 * the global boxes of A and B as hd_overlap's corner pairs. */
int hd__mpi_begin(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, const void *res, hd__mpi_ranges_t *rg, uint64_t N[2],
                  double corners[2][6]) {
    int rc = hd__mpi_check_local(c, opt, in, res);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) return rc;
    if ((rc = hd__mpi_check_ranges(c, in, rg)) != HD_OK) return rc;
    uint64_t n[2] = {in->n[0], in->n[1]};
    HD__MPI_TRY(c, MPI_Allreduce(n, N, 2, MPI_UINT64_T, MPI_SUM, c->comm));
    if (N[0] == 0 || N[1] == 0) return hd__err(&c->e, HD_EEMPTY, "point set %s is empty", N[0] ? "B" : "A");
    if (!corners) return HD_OK;
    /* Global boxes (hi negated: one MIN). */
    double bx[12], gb[12];
    for (int s = 0; s < 2; s++)
        for (int k = 0; k < 3; k++) bx[6 * s + k] = in->box[s].lo[k], bx[6 * s + 3 + k] = -in->box[s].hi[k];
    HD__MPI_TRY(c, MPI_Allreduce(bx, gb, 12, MPI_DOUBLE, MPI_MIN, c->comm));
    for (int s = 0; s < 2; s++)
        for (int k = 0; k < 3; k++) corners[s][k] = gb[6 * s + k], corners[s][3 + k] = -gb[6 * s + 3 + k];
    return HD_OK;
}

/* K > 1: the partition, the exchange and what every rank holds. */
int hd__mpi_spread(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, const uint64_t N[2],
                   const hd__mpi_prune_t *pr, hd__mpi_spread_t *sp) {
    int K = c->K, rc = HD_OK;
    sp->tree = hd__mpi_alloc(c, (size_t)K - 1, sizeof(hd__mpi_node_t));
    sp->region = hd__mpi_alloc(c, (size_t)K, sizeof(hd__box_t));
    sp->held = hd__mpi_alloc(c, (size_t)K, sizeof(hd__mpi_held_t));
    if (!sp->tree || !sp->region || !sp->held) rc = hd__mpi_nomem(c, "the partition", (size_t)K);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) return rc;
    if ((rc = hd__mpi_partition(c, in, pr, N[0] + N[1], sp->tree)) != HD_OK) return rc;
    hd__box_t all = {{-INFINITY, -INFINITY, -INFINITY}, {INFINITY, INFINITY, INFINITY}};
    hd__mpi_regions(sp->tree, 0, all, sp->region);
    if ((rc = hd__mpi_exchange(c, in, rg, sp->tree, pr, &sp->loc)) != HD_OK) return rc;
    hd__mpi_held_t h;
    for (int s = 0; s < 2; s++) {
        h.n[s] = sp->loc.n[s];
        h.box[s] = sp->loc.box[s]; /* taken by the exchange as the points arrived */
    }
    HD__MPI_TRY(c, MPI_Allgather(&h, (int)sizeof h, MPI_BYTE, sp->held, (int)sizeof h, MPI_BYTE, c->comm));
    return HD_OK;
}

void hd__mpi_spread_free(hd__mpi_ctx_t *c, hd__mpi_spread_t *sp) {
    int K = c->K;
    for (int s = 0; s < 2; s++) {
        hd__mpi_free(c, sp->loc.xyz[s], sp->loc.n[s], 3 * sizeof(double));
        hd__mpi_gidx_free(c, &sp->loc.gi[s]);
        if (sp->loc.start[s]) hd__mpi_free(c, sp->loc.start[s], 2 * (size_t)K, sizeof(size_t));
    }
    hd__mpi_free(c, sp->tree, (size_t)K - 1, sizeof(hd__mpi_node_t));
    hd__mpi_free(c, sp->region, (size_t)K, sizeof(hd__box_t));
    hd__mpi_free(c, sp->held, (size_t)K, sizeof(hd__mpi_held_t));
    memset(sp, 0, sizeof *sp);
}

/* The figures every call reports (collective): pts is this rank's points
 * after the partition; *tmax receives the slowest rank's seconds. */
int hd__mpi_figures(hd__mpi_ctx_t *c, const hd__mpi_course_t *cs, uint64_t pts, hd_mpi_stats_t *st, double *tmax) {
    int K = c->K;
    const uint64_t *N = cs->N;
    double t0 = cs->t0, cpu0 = cs->cpu0;
    double other = hd__mpi_cpu() - cpu0 - c->search_cpu - c->mpi_cpu;
    double secs = hd__now() - t0, tsum = secs, mine[4] = {secs, c->search, c->search_cpu, other}, most[4];
    HD__MPI_TRY(c, MPI_Allreduce(mine, most, 4, MPI_DOUBLE, MPI_MAX, c->comm));
    *tmax = most[0];
    HD__MPI_TRY(c, MPI_Allreduce(&secs, &tsum, 1, MPI_DOUBLE, MPI_SUM, c->comm));
    if (!st) return HD_OK;
    uint64_t work = pts + c->answered;
    uint64_t sums[8] = {c->bytes_part, c->bytes_fwd, c->forwarded, c->forwarded_points, work, c->shell,
                        c->bytes_back, pts},
             gs[8];
    uint64_t maxes[3] = {pts, work, c->peak}, gm[3];
    HD__MPI_TRY(c, MPI_Allreduce(sums, gs, 8, MPI_UINT64_T, MPI_SUM, c->comm));
    HD__MPI_TRY(c, MPI_Allreduce(maxes, gm, 3, MPI_UINT64_T, MPI_MAX, c->comm));
    memset(st, 0, sizeof *st);
    st->ranks = K;
    st->points = N[0] + N[1];
    st->bytes_partition = gs[0];
    st->bytes_forwarding = gs[1];
    st->bytes_returned = gs[6];
    st->forwarded = gs[2];
    st->forwarded_points = gs[3];
    st->shell_points = gs[5];
    st->rounds = c->rounds;
    st->points_max = gm[0];
    /* over the points the partition placed (those prune.c left out are
     * on no rank's list) */
    st->imbalance = gs[7] ? (double)gm[0] * K / (double)gs[7] : 1.0;
    st->work_imbalance = (double)gm[1] * K / (double)gs[4];
    st->seconds_max = most[0];
    st->seconds_mean = tsum / K;
    st->search_seconds_max = most[1];
    st->search_seconds = c->search;
    st->search_cpu_max = most[2];
    st->other_cpu_max = most[3];
    st->other_cpu = other;
    st->search_cpu = c->search_cpu;
    st->peak_bytes_max = gm[2];
    st->seconds = secs;
    st->local_points = pts;
    st->peak_bytes = c->peak;
    return HD_OK;
}

void hd__mpi_course_init(hd__mpi_ctx_t *c, hd__mpi_course_t *cs) {
    memset(cs, 0, sizeof *cs);
    cs->rg.K = c->K;
    cs->t0 = hd__now();
    cs->cpu0 = hd__mpi_cpu();
}

void hd__mpi_course_free(hd__mpi_ctx_t *c, hd__mpi_course_t *cs) {
    hd__mpi_spread_free(c, &cs->sp);
    hd__mpi_ranges_free(c, &cs->rg);
}

enum { MODE_DIRECTED = 0, MODE_BOTH = 1, MODE_OVERLAP = 2 };
typedef struct { double *alpha; int *disjoint; } overlap_t;
typedef struct { int mode; void *res; } what_t;

/* The Hausdorff distance's course.  what->mode is a MODE_*: what->res is
 * an hd_result_t, an hd_symmetric_t or an overlap_t. */
static int run(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, void *arg, hd_mpi_stats_t *st) {
    const what_t *what = arg;
    int both = what->mode;
    void *res = what->res;
    hd_symmetric_t *out = both == MODE_BOTH ? res : NULL;
    int K = c->K;
    hd__mpi_course_t cs;
    hd__mpi_course_init(c, &cs);
    double corners[2][6];
    int rc = hd__mpi_begin(c, opt, in, res, &cs.rg, cs.N, corners);
    if (rc != HD_OK) goto done;
    hd_points_t ca = hd_points_f64(corners[0], 2), cb = hd_points_f64(corners[1], 2);
    if (both == MODE_OVERLAP) {
        overlap_t *o = res;
        rc = hd_overlap(&ca, &cb, o->alpha, o->disjoint, &c->e);
        goto done;
    }
    memset(res, 0, both ? sizeof(hd_symmetric_t) : sizeof(hd_result_t));
    if (both && (rc = hd_overlap(&ca, &cb, &out->alpha, &out->disjoint, &c->e)) != HD_OK) goto done;

    hd__mpi_far_t f[2];
    uint64_t pts;
    int ts = hd__mpi_tiny_side(c, cs.N);
    if (K == 1) {
        if ((rc = single(c, in, &cs.rg, both, f)) != HD_OK) goto done;
        pts = in->n[0] + in->n[1];
    } else if (ts >= 0) { /* replicated, nothing partitioned (tiny.c) */
        if ((rc = hd__mpi_tiny(c, in, &cs.rg, cs.N, ts, both, f)) != HD_OK) goto done;
        pts = in->n[0] + in->n[1];
    } else {
        hd__mpi_spread_t *sp = &cs.sp;
        /* The points that cannot change the answer stay where they are
         * (prune.c), unless the options turn it off. */
        hd__mpi_prune_t pr = {0};
        if (c->prune && (rc = hd__mpi_prune(c, in, cs.N, corners, both, &pr)) != HD_OK) goto done;
        if ((rc = hd__mpi_spread(c, in, &cs.rg, cs.N, &pr, sp)) != HD_OK) goto done;
        hd__mpi_local_t *loc = &sp->loc;
        /* Both directions: the engine once for both (each of its calls
         * builds both sets' structures); its failure is agreed on before
         * the first direction. */
        hd__mpi_pre_t pre[2];
        memset(pre, 0, sizeof pre);
        unsigned char *mask[2] = {NULL, NULL};
        int pre_rc = HD_OK;
        if (both) {
            const hd__mpi_gidx_t *gp[2] = {&sp->loc.gi[0], &sp->loc.gi[1]};
            double t1 = hd__now(), u1 = hd__mpi_cpu();
            pre_rc = hd__mpi_engine_both(c, loc->xyz, gp, loc->n, sp->held[c->rank].box, &sp->region[c->rank], pre,
                                         mask);
            c->search += hd__now() - t1;
            c->search_cpu += hd__mpi_cpu() - u1;
        }
        rc = hd__mpi_agree(c, pre_rc);
        for (int s = 0; s < (both ? 2 : 1) && rc == HD_OK; s++) {
            hd__mpi_dir_t d = {loc->xyz[s], &sp->loc.gi[s], loc->n[s], loc->xyz[1 - s], &sp->loc.gi[1 - s], loc->n[1 - s], 1 - s,
                       &pre[s]};
            rc = hd__mpi_direction(c, &d, sp->tree, sp->region, sp->held, &f[s]);
        }
        for (int s = 0; s < 2; s++) hd__mpi_free(c, mask[s], loc->n[s], 1), hd__mpi_pre_free(c, &pre[s]);
        if (rc != HD_OK) goto done;
        pts = loc->n[0] + loc->n[1];
    }
    hd_result_t *r[2] = {both ? &out->ab : res, both ? &out->ba : NULL};
    for (int s = 0; s < (both ? 2 : 1); s++) {
        r[s]->distance2 = f[s].d2;
        r[s]->distance = sqrt(f[s].d2);
        r[s]->i = (size_t)f[s].i;
        r[s]->j = (size_t)f[s].j;
        r[s]->algorithm = HD_ALG_AUTO;
    }
    double tmax;
    if ((rc = hd__mpi_figures(c, &cs, pts, st, &tmax)) != HD_OK) goto done;
    for (int s = 0; s < (both ? 2 : 1); s++) r[s]->seconds = tmax;
    if (both) {
        out->distance = out->ab.distance2 >= out->ba.distance2 ? out->ab.distance : out->ba.distance;
        out->seconds = tmax;
    }
done:
    hd__mpi_course_free(c, &cs);
    return rc;
}

void hd_mpi_options_init(hd_mpi_options_t *opt) {
    hd_options_init(&opt->engine);
    opt->prune = 1;
    opt->replicate = 1;
}

int hd__mpi_call(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                 const hd_mpi_options_t *mopt, hd__mpi_body_t body, void *arg, hd_mpi_stats_t *st, hd_error_t *err) {
    const hd_options_t *opt = mopt ? &mopt->engine : NULL;
    hd__err_clear(err);
    hd__mpi_ctx_t c;
    memset(&c, 0, sizeof c);
    c.ans_type = c.q_type = c.far_type = c.sample_type = c.node_type = MPI_DATATYPE_NULL;
    c.far_op = c.near_op = MPI_OP_NULL;
    c.comm = MPI_COMM_NULL;
    hd__err_clear(&c.e);
    int init = 0, fin = 0;
    if (MPI_Initialized(&init) != MPI_SUCCESS || !init || MPI_Finalized(&fin) != MPI_SUCCESS || fin)
        return hd__err(err, HD_EINVAL, "MPI is not initialised (or already finalised)");
    if (comm == MPI_COMM_NULL) return hd__err(err, HD_EINVAL, "the communicator is MPI_COMM_NULL");
    int rc = HD_OK, e;
    if ((e = MPI_Comm_dup(comm, &c.comm)) != MPI_SUCCESS) {
        rc = hd__mpi_failed(&c, "MPI_Comm_dup", e);
    } else {
        MPI_Comm_set_errhandler(c.comm, MPI_ERRORS_RETURN);
        MPI_Comm_rank(c.comm, &c.rank);
        MPI_Comm_size(c.comm, &c.K);
        c.first = hd__mpi_first_samples(c.K);
        c.threads = opt ? opt->threads : 0;
        c.prune = mopt ? mopt->prune : 1;
        c.replicate = mopt ? mopt->replicate : 1;
        if (c.threads < 0) c.threads = 1; /* refused by check_local, on every rank */
        rc = hd__mpi_types_create(&c);
        if ((rc = hd__mpi_agree(&c, rc)) == HD_OK) {
            hd__mpi_input_t in = {{a, b}, {na, nb}, {0, 0}, {{{0}, {0}}, {{0}, {0}}}};
            rc = body(&c, opt, &in, arg, st);
        }
        /* Every buffer of the call was freed, on every path (the
         * sanitizer build checks this instead of LeakSanitizer, which
         * Open MPI's own unfreed allocations drown: tests/mpi.cmake). */
        assert(c.cur == 0);
        hd__mpi_types_free(&c);
        MPI_Comm_free(&c.comm);
    }
    if (rc != HD_OK && err) *err = c.e;
    return rc;
}

int hd_mpi_hausdorff(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                     const hd_mpi_options_t *opt, hd_symmetric_t *out, hd_mpi_stats_t *stats, hd_error_t *err) {
    what_t w = {MODE_BOTH, out};
    return hd__mpi_call(comm, a, na, b, nb, opt, run, &w, stats, err);
}

int hd_mpi_directed(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                    const hd_mpi_options_t *opt, hd_result_t *out, hd_mpi_stats_t *stats, hd_error_t *err) {
    what_t w = {MODE_DIRECTED, out};
    return hd__mpi_call(comm, a, na, b, nb, opt, run, &w, stats, err);
}

int hd_mpi_overlap(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                   double *alpha, int *disjoint, hd_error_t *err) {
    overlap_t o = {alpha, disjoint};
    if (!alpha || !disjoint) o.alpha = NULL; /* refused by check_local, on every rank */
    what_t w = {MODE_OVERLAP, o.alpha ? &o : NULL};
    return hd__mpi_call(comm, a, na, b, nb, NULL, run, &w, NULL, err);
}
