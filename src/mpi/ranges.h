/*
 * ranges.h -- private to src/mpi/: the input and its index runs
 * (ranges.c), and the local sets' global indices, Elias-Fano coded, with
 * their cursor (gidx.c).
 *
 * Conventions of every function here: a hd__mpi_ctx_t carries the call's
 * communicator, its error (c->e, what hd__mpi_agree() broadcasts) and its
 * count of bytes held (every buffer through hd__mpi_alloc/hd__mpi_free, so
 * the peak is known and the call can assert that it freed everything); a
 * function that can fail returns an HD_* code with c->e set, and collective
 * functions agree on a status before every collective a failed rank would
 * not reach.
 */
#ifndef HD_MPI_RANGES_H
#define HD_MPI_RANGES_H

#include "mpi/context.h"

/* ---- the input and its index runs (ranges.c) ----------------------------- */

typedef struct {
    const hd_mpi_part_t *parts[2];
    size_t nparts[2];
    uint64_t n[2];            /* local points of A, B (input) */
    hd__box_t box[2];         /* local boxes (input) */
} hd__mpi_input_t;

/* A view of packed doubles (the common layout) as its array, read in
 * place; NULL for any other layout, read through hd_points_get. */
static inline const double *hd__mpi_packed(const hd_points_t *p) {
    if (p->dtype == HD_FLOAT64 && (p->stride == 0 || p->stride == 3 * (ptrdiff_t)sizeof(double)) &&
        (p->cstride == 0 || p->cstride == (ptrdiff_t)sizeof(double)))
        return p->data;
    return NULL;
}

/* Point k of a view. */
static inline void hd__mpi_get_point(const hd_points_t *p, size_t k, double out[3]) {
    const double *x = hd__mpi_packed(p);
    if (x) memcpy(out, x + 3 * k, 3 * sizeof(double));
    else hd_points_get(p, k, out);
}

typedef struct { uint64_t lo, hi; int side, rank; } hd__mpi_range_t;

/* Every rank's nonempty parts (all-gathered by check_ranges), sorted by
 * (side, rank, first index): side s, rank r's are all[seg[s (K + 1) + r]]
 * up to all[seg[s (K + 1) + r + 1]], and first[i] is the number of part
 * i's first point among its rank's points of its side in index order.  So
 * point number m of rank r's side s names a global index (ranges_globals),
 * which lets the exchange send 4-byte numbers instead of 8-byte indices.
 * The same runs sorted by (side, first index) are bylo (side s's at the
 * same positions seg[s (K + 1)] .. seg[s (K + 1) + K] as in all), and
 * ord[i] is the number of side indices below bylo[i].lo over all ranks:
 * index g of run i is the side's ordinal ord[i] + (g - lo), dense in
 * 0 .. N_side - 1 (what hd__mpi_gidx_t encodes). */
struct hd__mpi_ranges {
    int K;
    hd__mpi_range_t *all;
    size_t total;
    size_t *seg;
    uint64_t *first;
    hd__mpi_range_t *bylo;
    uint64_t *ord;
};

/* The global indices of a local set, by position (gidx.c).  Local order is
 * global index order, so the ordinals (hd__mpi_ranges_t.ord) of a local set
 * increase with the position, and they are held Elias-Fano coded: with
 * n points among the side's U indices and l = floor(log2(U / n)), the low
 * l bits of each ordinal in a packed array, and the high part h of the
 * k-th ordinal as bit h + k of a bit array of n + (U - 1 >> l) + 1 bits
 * (one 1 a point, U >> l < 2n zeros), with the position of every 64th 1
 * (samp): l + 1 + 2^f bits a point (U / n = 2^(l + f), 0 <= f < 1) and
 * a word per 64 points, less than 4 + log2(U / n) bits in all, not 4 or 8
 * bytes (0.5 B/pt at U / n = 2, 0.625 at 4, 0.875 at 16: K ranks holding
 * equal shares; docs/scale-out.md).  The exchange encodes them once (from its 4-byte
 * numbers, or from the 8-byte indices of merged runs, both freed then),
 * and they are never reordered afterwards (split and unsplit move
 * coordinates only), so position k's index is fixed for the call.  An index is the ordinal's run's first index plus the ordinal's
 * offset in it (run, rord: the side's runs of hd__mpi_ranges_t by first index). */
typedef struct hd__mpi_ranges hd__mpi_ranges_t;
typedef struct {
    uint64_t *w;             /* one allocation: low, high, samp */
    size_t words;            /* its words (charged) */
    const uint64_t *low, *high, *samp;
    size_t n;                /* positions */
    int l;                   /* low bits an ordinal */
    const hd__mpi_range_t *run;      /* the side's runs by first index */
    const uint64_t *rord;    /* each one's first ordinal */
    size_t nrun;
    int side;
} hd__mpi_gidx_t;

int hd__mpi_gidx_init(hd__mpi_ctx_t *c, hd__mpi_gidx_t *x, const hd__mpi_ranges_t *rg, int side, size_t n);
/* Positions k .. k + n - 1's indices are g[0 .. n - 1] (increasing, and
 * above those of the positions before k), or the indices of numbers
 * num[0 .. n - 1] at their sender r (increasing: a run received in index
 * order).  The code is written once, from calls covering 0 .. x->n - 1. */
void hd__mpi_gidx_put_indices(hd__mpi_gidx_t *x, size_t k, const uint64_t *g, size_t n);
void hd__mpi_gidx_put_numbers(hd__mpi_gidx_t *x, const hd__mpi_ranges_t *rg, int r, size_t k, const uint32_t *num, size_t n);
/* The code emptied (every word zero), to be written again. */
void hd__mpi_gidx_clear(hd__mpi_gidx_t *x);
void hd__mpi_gidx_free(hd__mpi_ctx_t *c, hd__mpi_gidx_t *x);
/* Position k's index, at any k (a select from the sample before it and a
 * binary search of the runs). */
uint64_t hd__mpi_gidx(const hd__mpi_gidx_t *x, size_t k);
/* Positions k .. k + m - 1's indices into g[0 .. m - 1]: a select for the
 * first, then the 1s of the high bits in order and the runs only forward
 * (a fraction of a cursor's cost a position, when all are wanted). */
void hd__mpi_gidx_decode(const hd__mpi_gidx_t *x, size_t k, size_t m, uint64_t *g);
/* The global indices two local sets share (each in index order): their
 * number, and, when mp is not NULL, mp[i] = mq[j] = 1 at each pair of
 * positions holding the same index (the other bytes untouched).  One
 * merge walk over both codes in order (the 1s of the high bits and the
 * low bits as they come: no select, no cursor). */
size_t hd__mpi_gidx_common(const hd__mpi_gidx_t *p, const hd__mpi_gidx_t *q, unsigned char *mp, unsigned char *mq);

/* The low l bits of position k's ordinal. */
static inline uint64_t hd__mpi_gidx_low(const hd__mpi_gidx_t *x, size_t k) {
    if (x->l == 0) return 0;
    uint64_t bit = (uint64_t)k * (uint64_t)x->l;
    size_t w = (size_t)(bit >> 6);
    unsigned o = (unsigned)(bit & 63);
    uint64_t v = x->low[w] >> o;
    if (o + (unsigned)x->l > 64) v |= x->low[w + 1] << (64 - o);
    return v & ((UINT64_C(1) << x->l) - 1);
}

/* A walk over a local set's global indices at nondecreasing positions:
 * the next position's 1 is the next set bit of the high bits (in the
 * current word or a following one), and its run the current one (a
 * subtraction and a comparison); anything else (a jump, a new run) is
 * hd__mpi_gcur_next's.  Positions may also go back (then as
 * hd__mpi_gidx). */
typedef struct {
    const hd__mpi_gidx_t *x;
    size_t k;                /* the last position decoded (SIZE_MAX: none) */
    size_t wi;               /* the word of the high bits holding its 1 */
    uint64_t w;              /* that word's 1s after it */
    size_t run;              /* the run of its ordinal (SIZE_MAX: none) */
    uint64_t first, span, lo; /* that run: ordinals first .. first + span
                                 name indices lo .. lo + span */
    uint64_t g;              /* its index */
} hd__mpi_gcur_t;

void hd__mpi_gcur_init(hd__mpi_gcur_t *cu, const hd__mpi_gidx_t *x);
uint64_t hd__mpi_gcur_next(hd__mpi_gcur_t *cu, size_t k);

static inline uint64_t hd__mpi_gcur_at(hd__mpi_gcur_t *cu, size_t k) {
    if (k == cu->k) return cu->g;
    if (k == cu->k + 1 && cu->run != SIZE_MAX) { /* k < n: a 1 follows */
        size_t wi = cu->wi;
        uint64_t w = cu->w;
        while (!w) w = cu->x->high[++wi];
        uint64_t h = (((uint64_t)wi << 6) | (uint64_t)__builtin_ctzll(w)) - k;
        uint64_t d = ((h << cu->x->l) | hd__mpi_gidx_low(cu->x, k)) - cu->first;
        if (d <= cu->span) {
            cu->wi = wi;
            cu->w = w & (w - 1);
            cu->k = k;
            return cu->g = cu->lo + d;
        }
    }
    return hd__mpi_gcur_next(cu, k);
}

/* The rank whose parts hold the cursor's last index. */
static inline int hd__mpi_gcur_rank(const hd__mpi_gcur_t *cu) {
    return cu->x->run[cu->run].rank;
}

int hd__mpi_by_offset(const void *x, const void *y);
int hd__mpi_by_range(const void *x, const void *y); /* hd__mpi_range_t by (side, lo) */
void hd__mpi_ranges_free(hd__mpi_ctx_t *c, hd__mpi_ranges_t *rg);
int hd__mpi_ranges_index(hd__mpi_ctx_t *c, hd__mpi_ranges_t *rg);
void hd__mpi_ranges_globals(const hd__mpi_ranges_t *rg, int s, int r, size_t *i, const uint32_t *num, size_t n, uint64_t *g);
uint64_t hd__mpi_ranges_global(const hd__mpi_ranges_t *rg, int s, int r, uint64_t m);
/* *i, a run of rank r's side s at or before number m's (numbers only grow
 * along a walk), becomes the run holding number m. */
static inline void hd__mpi_ranges_seek(const hd__mpi_ranges_t *rg, int s, int r, size_t *i, uint64_t m) {
    while (m - rg->first[*i] > rg->all[*i].hi - rg->all[*i].lo) ++*i;
    assert(*i < rg->seg[(size_t)s * ((size_t)rg->K + 1) + (size_t)r + 1] && m >= rg->first[*i]);
    (void)s, (void)r; /* the assert's */
}
int hd__mpi_check_ranges(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, hd__mpi_ranges_t *rg);
int hd__mpi_check_local(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, const void *out);

#endif /* HD_MPI_RANGES_H */
