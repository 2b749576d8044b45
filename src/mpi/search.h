/*
 * search.h -- private to src/mpi/: one direction's searches: the
 * per-point searches on slabs (slab.c), the engine's pass and its shell
 * (shell.c), and the forwarding of queries to other ranks with the
 * reduction of the direction (forward.c).
 *
 * Conventions of every function here: a hd__mpi_ctx_t carries the call's
 * communicator, its error (c->e, what hd__mpi_agree() broadcasts) and its
 * count of bytes held (every buffer through hd__mpi_alloc/hd__mpi_free, so
 * the peak is known and the call can assert that it freed everything); a
 * function that can fail returns an HD_* code with c->e set, and collective
 * functions agree on a status before every collective a failed rank would
 * not reach.
 */
#ifndef HD_MPI_SEARCH_H
#define HD_MPI_SEARCH_H

#include "mpi/partition.h"

typedef struct {
    double *P;               /* local points asking, packed xyz (reordered
                                and restored by split/unsplit) */
    const hd__mpi_gidx_t *gP;        /* their global indices, by position */
    size_t nP;
    double *Q;               /* local points searched */
    const hd__mpi_gidx_t *gQ;
    size_t nQ;
    int qside;               /* 0: Q is A, 1: Q is B */
    const struct hd__mpi_pre *pre;   /* the engine's answer, when computed for both
                                directions at once (NULL: not) */
} hd__mpi_dir_t;

/* ---- the per-point searches (slab.c) ------------------------------------- */

/* 1 when every finite face of region r is farther from p than u2 allows
 * (computed fl(gap^2) > u2): then no point of another region is within u2
 * of p, nor at u2 (see mpi.c's essay, step 4). */
static inline int hd__mpi_faces_clear(const hd__box_t *r, const double *p, double u2) {
    for (int a = 0; a < 3; a++) {
        if (isfinite(r->lo[a])) {
            double g = p[a] - r->lo[a];
            if (!(g * g > u2)) return 0;
        }
        if (isfinite(r->hi[a])) {
            double g = r->hi[a] - p[a];
            if (!(g * g > u2)) return 0;
        }
    }
    return 1;
}

/* hd__mpi_faces_clear for many points: the region's finite faces listed
 * once (axis and coordinate), so a point tests only those (one at K = 2).
 * The gap's sign does not matter: fl(s - p) = -fl(p - s), and the square
 * is the same. */
typedef struct {
    int n, ax[6];
    double at[6];
} hd__mpi_faces_t;

static inline void hd__mpi_faces_of(const hd__box_t *r, hd__mpi_faces_t *f) {
    f->n = 0;
    for (int a = 0; a < 3; a++) {
        if (isfinite(r->lo[a])) f->ax[f->n] = a, f->at[f->n++] = r->lo[a];
        if (isfinite(r->hi[a])) f->ax[f->n] = a, f->at[f->n++] = r->hi[a];
    }
}

static inline int hd__mpi_faces_clear_of(const hd__mpi_faces_t *f, const double *p, double u2) {
    for (int t = 0; t < f->n; t++) {
        double g = p[f->ax[t]] - f->at[t];
        if (!(g * g > u2)) return 0;
    }
    return 1;
}

/* The slabs of the searched local set Q (slab.c has the proof). */
typedef struct {
    hd__an_t s;
    int built;
    size_t n, bytes;         /* its points (named by their positions in Q) */
    double M;                /* its margin (infinite: all of Q) */
    hd__box_t kb;            /* the key box its askers use too */
} hd__mpi_slab_t;

typedef struct {
    hd__mpi_slab_t sub, full;
    double M0;               /* the first slab's margin (set by shell_of) */
} hd__mpi_qtree_t;

void hd__mpi_qtree_free(hd__mpi_ctx_t *c, hd__mpi_qtree_t *q);
/* The nearest layer's structure of v (sel NULL), or of v's m points
 * sel[0..m) named by names[] or their positions in v (hd__an_build_sel),
 * charged at its build's measured peak while built, then at what it
 * holds (*bytes, to subtract when it is freed). */
int hd__mpi_an_build(hd__mpi_ctx_t *c, hd__an_t *s, const hd_points_t *v, const uint32_t *sel, const uint32_t *names,
                     size_t m, const hd__box_t *kb, int threads, size_t *bytes);
/* hd__an_nearest_paired(asking, searched, pair_at) into near (no
 * distances; pair_at may be NULL: no partners), its own arrays charged
 * while it runs. */
int hd__mpi_an_nearest(hd__mpi_ctx_t *c, const hd__an_t *asking, const hd__an_t *searched, const uint32_t *pair_at,
                       int threads, size_t *near);
/* Frees a structure hd__mpi_an_build made and takes its bytes off the count. */
void hd__mpi_an_release(hd__mpi_ctx_t *c, hd__an_t *s, size_t bytes);
/* For each of n points, point k at pts + 3 pos[k] (pos NULL: pts + 3 k),
 * its nearest point of Q into near[k] (exact, smallest index on ties, as
 * hd_distances gives it), from q's slabs (slab.c), built as needed.  With
 * `unproven` (n flags, zeroed by the caller), a point the first slab
 * answers but does not prove is left with that answer (a point of Q, so
 * an upper bound of its nearest distance) and flagged, for the caller to
 * prove by a smaller answer from elsewhere (hd__mpi_slab_proves with the
 * first slab's margin, q->M0) or to ask again without `unproven`. */
int hd__mpi_nearest_in_q(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *r, hd__mpi_qtree_t *q, const double *pts,
                         const uint32_t *pos, size_t n, size_t *near, unsigned char *unproven);
/* For each of n points, point k at pts + 3 pos[k] (pos NULL: pts + 3 k;
 * pos increasing), its nearest of the m points S (packed xyz) into
 * near[k]: exact, the smallest position on ties (SIZE_MAX when m = 0);
 * the askers go in batches of at most `batch`.  n and m at most
 * HD__AN_MAX_POINTS. */
int hd__mpi_nearest_among(hd__mpi_ctx_t *c, const double *S, size_t m, const double *pts, const uint32_t *pos, size_t n,
                          size_t batch, size_t *near);
/* Whether every point of Q farther than M from all of r's finite faces is
 * farther from x than sqrt(d2) (slab.c's proof). */
int hd__mpi_slab_proves(const hd__box_t *r, double M, const double *x, double d2);

/* ---- the engine's pass and its shell (shell.c) --------------------------- */

/* What the engine's pass leaves for per-point searches (shell.c's essay). */
typedef struct {
    size_t n;                /* the shell's points, read in P (hd__mpi_shell_pt) */
    size_t *nearest;         /* each one's nearest in Q (NULL if Q is empty) */
    uint32_t *own_pos;       /* each one's position in P (NULL: all of P) */
    unsigned char *unproven; /* each one's: 0, nearest[] exact over the local Q;
                                1, only a point of the first slab
                                (hd__mpi_nearest_in_q); HD__MPI_UNSEARCHED,
                                its partner (shell.c, paired_shell);
                                or NULL: all exact */
    hd__mpi_far_t inner;             /* exact over the interior; d2 = -1 if none
                                or not known (lazy) */
    int lazy;                /* the interior's maximum was not computed */
    int deferred;            /* no local answers yet (nearest and unproven NULL):
                                a shell too large to search one by one, bounded
                                by the sample first (forward.c, one_sided_shell) */
    hd__mpi_far_t h;                 /* then: the engine's answer, whose witness
                                is in the shell and bounds the interior */
} hd__mpi_shell_t;

/* A shell point's answer that is a bound only, from no search (its
 * partner): never proven by the first slab's test (forward.c, resolve). */
#define HD__MPI_UNSEARCHED 2

/* The shell's point k: its coordinates are P's, not a copy. */
static inline const double *hd__mpi_shell_pt(const hd__mpi_dir_t *d, const hd__mpi_shell_t *sh, size_t k) {
    return d->P + 3 * (sh->own_pos ? sh->own_pos[k] : k);
}

/* The points of P the engine's maximum refused (shell.c, keep_clear):
 * those whose region faces are not clear of their own local nearest
 * distance, which may be only local. */
typedef struct {
    const hd__box_t *mine;   /* the rank's region */
    const double *P;
    int on;                  /* the engine's answer is over the points kept */
    double d2;               /* the largest refused u^2 (-1: none) */
    uint32_t *pos;           /* refused positions in P (repeats possible) */
    size_t n, cap;
    int overflow;            /* more than cap were refused: pos is partial */
    uint32_t *near;          /* each one's nearest position in Q, the engine's
                                (the smallest index at its u), by pos: 4
                                bytes, as the local sets' positions are */
} hd__mpi_refused_t;

/* The engine's answer for a direction, computed before it runs: the
 * symmetric call runs the engine once for both directions
 * (hd__mpi_engine_both), since each of its calls builds both sets'
 * structures. */
typedef struct hd__mpi_pre {
    int have;                /* 0: the direction runs the engine itself */
    int paired;              /* the answer is on the pairs (P_c, Q_c) */
    hd_result_t e;           /* positions in P and Q, or in P_c and Q_c */
    const unsigned char *inp, *inq; /* paired: the pairs' masks of P, Q */
    hd__mpi_refused_t ref;           /* not paired: what e's maximum left out */
} hd__mpi_pre_t;

/* mask[s]: NULL, or the pairs' mask of side s (n[s] bytes) when paired,
 * which the caller frees (hd__mpi_free) after both directions, as it
 * frees pre[s] (hd__mpi_pre_free).  mine: the rank's region. */
int hd__mpi_engine_both(hd__mpi_ctx_t *c, double *xyz[2], const hd__mpi_gidx_t *g[2], const size_t n[2], const hd__box_t box[2],
                        const hd__box_t *mine, hd__mpi_pre_t pre[2], unsigned char *mask[2]);
void hd__mpi_pre_free(hd__mpi_ctx_t *c, hd__mpi_pre_t *pre);
void hd__mpi_shell_free(hd__mpi_ctx_t *c, hd__mpi_shell_t *sh);
int hd__mpi_interior_max(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *mine, const hd__mpi_shell_t *sh, double h2,
                         const hd__mpi_far_t *G, hd__mpi_far_t *out);
uint64_t hd__mpi_shell_g(hd__mpi_gcur_t *cu, const hd__mpi_shell_t *sh, size_t k);
int hd__mpi_shell_of(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *mine, hd__mpi_qtree_t *q, hd__mpi_shell_t *sh);

/* ---- one direction over the partition (forward.c) ------------------------ */

/* Forwarded queries (forward.c's hd__mpi_pair_t: point k of the asking
 * set to rank dest), n of them in room for cap. */
typedef struct { struct hd__mpi_pair *p; size_t n, cap; } hd__mpi_pairs_t;
int hd__mpi_pairs_add(hd__mpi_ctx_t *c, hd__mpi_pairs_t *pr, size_t k, const int *list, int n);
void hd__mpi_pairs_free(hd__mpi_ctx_t *c, hd__mpi_pairs_t *pr);

/* Answers m queries pts against this rank's local set: exact (d2,
 * smallest global index), or (infinity, UINT64_MAX) when it holds none. */
typedef int (*hd__mpi_answer_t)(hd__mpi_ctx_t *c, void *arg, const double *pts, size_t m, hd__mpi_ans_t *ans);

/* One round of forwarding (collective; rc is the caller's status, agreed
 * first): each pair (k, r) sends point k of P (at P + 3 pos[k], pos NULL:
 * P + 3 k) to rank r, every rank answers what it receives with fn, and
 * each answer replaces (u2[k], jj[k]) when smaller (d2 first, then the
 * index). */
int hd__mpi_round(hd__mpi_ctx_t *c, int rc, const double *P, const uint32_t *pos, const hd__mpi_pairs_t *pr,
                  hd__mpi_answer_t fn, void *arg, double *u2, uint64_t *jj);

int hd__mpi_direction(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__mpi_node_t *tree, const hd__box_t *region, const hd__mpi_held_t *held,
                      hd__mpi_far_t *result);

#endif /* HD_MPI_SEARCH_H */
