/*
 * gidx.c -- the global indices of a local set, Elias-Fano coded over the
 * side's dense ordinals (ranges.h's hd__mpi_gidx_t), with random access and a
 * sequential cursor.
 *
 * Invariants.
 *  - Ordinals.  The side's index runs over all ranks, by first index
 *    (hd__mpi_ranges_t.bylo), with the number of indices below each (hd__mpi_ranges_t.ord),
 *    map every global index g of the side to its ordinal, the number of the
 *    side's indices below g: ord[i] + (g - lo) for g in run i.  The map is
 *    strictly increasing, so a local set (in global index order, without
 *    repeats) has strictly increasing ordinals o_0 < .. < o_{n-1} < U, U
 *    the side's points over all ranks.
 *  - The code.  l = the largest l <= 63 with n 2^l <= U (0 when n = 0 or
 *    U < 2n).  low holds o_k mod 2^l at bits k l .. k l + l - 1; high has
 *    bit (o_k >> l) + k set for every k and no other: since o_k >> l is
 *    nondecreasing, these are n distinct increasing positions below
 *    n + ((U - 1) >> l) + 1, and the k-th 1 (from 0) is at (o_k >> l) + k,
 *    so o_k = ((select1(k) - k) << l) | low_k.  samp[t] is the position of
 *    the 1 of k = 64 t: select1(k) scans from samp[k / 64] for the
 *    (k mod 64)-th 1 after it, over at most 63 ones and the zeros between
 *    (U >> l < 2n zeros in all: about 2 words on average).
 *  - Writing.  The words start zeroed, and the code of consecutive
 *    positions (a piece: a sender's run received in a round, or the merged
 *    indices) is gathered in registers and OR-ed into them a word at a
 *    time: a piece's bits are a function of its positions and ordinals
 *    alone, and the words at its ends may hold a neighbouring piece's
 *    bits, so pieces may be written in any order, each once.
 *  - Memory: ceil(n l / 64) + ceil(bits / 64) + ceil(n / 64) words, all in
 *    one allocation through the call's allocator, so counted in the peak:
 *    n l + n + (U >> l) + n bits, less than l + 4 bits a point with
 *    l <= log2(U / n) (l + 2 + 2^f bits, U / n = 2^(l + f), 0 <= f < 1;
 *    this l is the best: l + 1 costs 1 - 2^(f - 1) >= 0 bits more).
 *  - The cursor holds the word of the last decoded position's 1 with the
 *    1s after it, so the next position's 1 is the lowest bit left (or in a
 *    following word), and the run of the last ordinal: within it an index
 *    is lo + (o - first).  Anything else is the slow path here: steps
 *    forward over the next 1s for jumps of at most GCUR_STEP positions, a
 *    select for longer ones or backwards; the ordinal's run is the current
 *    one, the next, or else searched (binary).  So any order of positions
 *    is correct, and nondecreasing ones cost a few operations each.
 */
#include "mpi/ranges.h"

#include <assert.h>

/* Bit counts without the CPU's instruction (the library is built for any
 * x86-64, where __builtin_popcountll is a call): each byte's count, and
 * the sum of all. */
static inline uint64_t byte_counts(uint64_t w) {
    w = w - ((w >> 1) & UINT64_C(0x5555555555555555));
    w = (w & UINT64_C(0x3333333333333333)) + ((w >> 2) & UINT64_C(0x3333333333333333));
    return (w + (w >> 4)) & UINT64_C(0x0F0F0F0F0F0F0F0F);
}

static inline unsigned ones(uint64_t w) {
    return (unsigned)((byte_counts(w) * UINT64_C(0x0101010101010101)) >> 56);
}

/* The position of the r-th 1 (from 0) of w, which has more than r: the
 * byte holding it from the bytes' running counts (byte i of sums is the
 * count of bytes 0 .. i, at most 64, so the bytewise subtraction below
 * never borrows across bytes: its high bit is set where sums <= r), then
 * the bit in that byte. */
static inline unsigned select64(uint64_t w, unsigned r) {
    const uint64_t L8 = UINT64_C(0x0101010101010101), H8 = UINT64_C(0x8080808080808080);
    uint64_t sums = byte_counts(w) * L8;
    unsigned place = ones(((((uint64_t)r * L8) | H8) - sums) & H8) * 8;
    unsigned left = r - (unsigned)(((sums << 8) >> place) & 0xFF);
    uint64_t v = (w >> place) & 0xFF;
    while (left--) v &= v - 1;
    return place + (unsigned)__builtin_ctzll(v);
}

/* From word *wi whose 1s still to count are *w: the position of the
 * left-th 1 (from 0) among them and after; *wi and *w become its word and
 * that word's 1s after it. */
static inline uint64_t ones_from(const uint64_t *high, size_t *wi, uint64_t *w, uint64_t left) {
    uint64_t v = *w;
    size_t i = *wi;
    for (;;) {
        unsigned c = ones(v);
        if (left < c) break;
        left -= c;
        v = high[++i];
    }
    unsigned b = select64(v, (unsigned)left);
    *wi = i;
    *w = b == 63 ? 0 : v & (~UINT64_C(0) << (b + 1));
    return ((uint64_t)i << 6) | b;
}

/* The k-th 1 of high, through the sample before it. */
static inline uint64_t select1(const hd__mpi_gidx_t *x, size_t k, size_t *wi, uint64_t *w) {
    uint64_t at = x->samp[k >> 6];
    *wi = (size_t)(at >> 6);
    *w = x->high[*wi] & (~UINT64_C(0) << (at & 63));
    return ones_from(x->high, wi, w, k & 63);
}

/* The run of ordinal o: the last whose first ordinal is <= o. */
static size_t run_of(const hd__mpi_gidx_t *x, uint64_t o) {
    size_t lo = 0, hi = x->nrun - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo + 1) / 2;
        if (x->rord[mid] <= o) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

int hd__mpi_gidx_init(hd__mpi_ctx_t *c, hd__mpi_gidx_t *x, const hd__mpi_ranges_t *rg, int side, size_t n) {
    memset(x, 0, sizeof *x);
    size_t a = rg->seg[(size_t)side * ((size_t)rg->K + 1)], b = rg->seg[(size_t)side * ((size_t)rg->K + 1) + (size_t)rg->K];
    x->run = rg->bylo + a;
    x->rord = rg->ord + a;
    x->nrun = b - a;
    x->n = n;
    x->side = side;
    uint64_t U = x->nrun ? x->rord[x->nrun - 1] + (x->run[x->nrun - 1].hi - x->run[x->nrun - 1].lo) + 1 : 0;
    assert(n <= U);
    int l = 0;
    while (n && l < 63 && (U >> (l + 1)) >= n) l++;
    x->l = l;
    /* n <= 2^32 and l <= 63: no product below overflows 64 bits */
    uint64_t lw = ((uint64_t)n * (uint64_t)l + 63) / 64, hbits = n ? n + ((U - 1) >> l) + 1 : 0,
             hw = (hbits + 63) / 64, sw = ((uint64_t)n + 63) / 64, words = lw + hw + sw;
    if (words > SIZE_MAX / sizeof(uint64_t) || !(x->w = hd__mpi_alloc(c, (size_t)words, sizeof(uint64_t))))
        return hd__mpi_nomem(c, "the local indices", n);
    x->words = (size_t)words;
    hd__mpi_gidx_clear(x);
    x->low = x->w;
    x->high = x->w + lw;
    x->samp = x->w + lw + hw;
    return HD_OK;
}

/* The run holding index g (one of the side's). */
static size_t run_at(const hd__mpi_gidx_t *x, uint64_t g) {
    size_t lo = 0, hi = x->nrun - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo + 1) / 2;
        if (x->run[mid].lo <= g) lo = mid;
        else hi = mid - 1;
    }
    assert(g >= x->run[lo].lo && g <= x->run[lo].hi);
    return lo;
}

/* The ordinals of consecutive positions gathered in registers, a word of
 * low bits and a word of high bits at a time, OR-ed into the code when
 * full (the words at either end may be shared with other calls' runs). */
typedef struct {
    uint64_t *low, *high, *samp;
    int l;
    uint64_t lbit, lacc;     /* the next low bit, and its word's bits so far */
    size_t hw;               /* the high word being filled, */
    uint64_t hacc;           /* and its bits so far */
} seq_t;

static void seq_begin(seq_t *q, hd__mpi_gidx_t *x, size_t k) {
    q->low = x->w, q->high = x->w + (x->high - x->low), q->samp = x->w + (x->samp - x->low);
    q->l = x->l;
    q->lbit = (uint64_t)k * (uint64_t)x->l, q->lacc = 0;
    q->hw = SIZE_MAX, q->hacc = 0;
}

/* Ordinals o[0 .. m - 1] at positions k .. k + m - 1, the state in
 * locals for the loop (through q, every store to the code's words would
 * make the compiler load q's fields again: they may alias). */
static void seq_puts(seq_t *q, size_t k, const uint64_t *o, size_t m) {
    uint64_t *const high = q->high, *const low = q->low, *const samp = q->samp;
    const int l = q->l;
    const uint64_t lmask = l ? (UINT64_C(1) << l) - 1 : 0;
    uint64_t lbit = q->lbit, lacc = q->lacc, hacc = q->hacc;
    size_t hw = q->hw;
    for (size_t t = 0; t < m; t++, k++) {
        uint64_t h = (o[t] >> l) + k;
        if ((size_t)(h >> 6) != hw) {
            if (hw != SIZE_MAX) high[hw] |= hacc;
            hw = (size_t)(h >> 6), hacc = 0;
        }
        hacc |= UINT64_C(1) << (h & 63);
        if ((k & 63) == 0) samp[k >> 6] = h;
        if (l) {
            uint64_t v = o[t] & lmask;
            unsigned s = (unsigned)(lbit & 63);
            lacc |= v << s;
            if (s + (unsigned)l >= 64) {
                low[lbit >> 6] |= lacc;
                lacc = s + (unsigned)l > 64 ? v >> (64 - s) : 0;
            }
            lbit += (uint64_t)l;
        }
    }
    q->lbit = lbit, q->lacc = lacc, q->hacc = hacc, q->hw = hw;
}

/* Ordinals go to seq_puts through a buffer of this many on the stack. */
#define SEQ_BUF 256

static void seq_end(seq_t *q) {
    if (q->hw != SIZE_MAX) q->high[q->hw] |= q->hacc;
    if (q->l && (q->lbit & 63)) q->low[q->lbit >> 6] |= q->lacc;
}

void hd__mpi_gidx_put_numbers(hd__mpi_gidx_t *x, const hd__mpi_ranges_t *rg, int r, size_t k, const uint32_t *num, size_t n) {
    if (n == 0) return;
    seq_t q;
    seq_begin(&q, x, k);
    size_t i = rg->seg[(size_t)x->side * ((size_t)rg->K + 1) + (size_t)r];
    /* rank r's run i: numbers first .. first + span, ordinals from ob */
    uint64_t first = UINT64_MAX, span = 0, ob = 0; /* m - first > span: no run yet */
    uint64_t o[SEQ_BUF];
    for (size_t t0 = 0; t0 < n; t0 += SEQ_BUF) {
        size_t b = n - t0 < SEQ_BUF ? n - t0 : SEQ_BUF;
        for (size_t t = 0; t < b; t++) {
            uint64_t m = num[t0 + t];
            if (m - first > span) {
                hd__mpi_ranges_seek(rg, x->side, r, &i, m);
                first = rg->first[i], span = rg->all[i].hi - rg->all[i].lo;
                ob = x->rord[run_at(x, rg->all[i].lo)];
            }
            o[t] = ob + (m - first);
        }
        seq_puts(&q, k + t0, o, b);
    }
    seq_end(&q);
}

void hd__mpi_gidx_put_indices(hd__mpi_gidx_t *x, size_t k, const uint64_t *g, size_t n) {
    if (n == 0) return;
    seq_t q;
    seq_begin(&q, x, k);
    size_t i = run_at(x, g[0]);
    uint64_t o[SEQ_BUF];
    for (size_t t0 = 0; t0 < n; t0 += SEQ_BUF) {
        size_t b = n - t0 < SEQ_BUF ? n - t0 : SEQ_BUF;
        for (size_t t = 0; t < b; t++) {
            uint64_t gt = g[t0 + t];
            while (gt > x->run[i].hi) i++;
            assert(i < x->nrun && gt >= x->run[i].lo);
            o[t] = x->rord[i] + (gt - x->run[i].lo);
        }
        seq_puts(&q, k + t0, o, b);
    }
    seq_end(&q);
}

void hd__mpi_gidx_clear(hd__mpi_gidx_t *x) {
    if (x->words) memset(x->w, 0, x->words * sizeof(uint64_t));
}

void hd__mpi_gidx_free(hd__mpi_ctx_t *c, hd__mpi_gidx_t *x) {
    hd__mpi_free(c, x->w, x->words, sizeof(uint64_t));
    x->w = NULL;
    x->words = 0;
}

uint64_t hd__mpi_gidx(const hd__mpi_gidx_t *x, size_t k) {
    assert(k < x->n);
    size_t wi;
    uint64_t w, o = ((select1(x, k, &wi, &w) - k) << x->l) | hd__mpi_gidx_low(x, k);
    size_t r = run_of(x, o);
    return x->run[r].lo + (o - x->rord[r]);
}

void hd__mpi_gidx_decode(const hd__mpi_gidx_t *x, size_t k, size_t m, uint64_t *g) {
    if (m == 0) return;
    assert(k + m <= x->n);
    size_t wi, r = SIZE_MAX;
    uint64_t w, at = select1(x, k, &wi, &w);
    for (size_t t = 0;;) {
        uint64_t o = ((at - (k + t)) << x->l) | hd__mpi_gidx_low(x, k + t);
        if (r == SIZE_MAX) r = run_of(x, o);
        while (r + 1 < x->nrun && o >= x->rord[r + 1]) r++; /* ordinals grow: runs only advance */
        g[t] = x->run[r].lo + (o - x->rord[r]);
        if (++t == m) break;
        while (!w) w = x->high[++wi];
        at = ((uint64_t)wi << 6) | (uint64_t)__builtin_ctzll(w);
        w &= w - 1;
    }
}

/* A walk over every position in order, for hd__mpi_gidx_common: the next
 * 1 of the high bits, the low bits read from the bit after the last's, and
 * the run only forward (ordinals grow).  Everything it reads is held here,
 * not read through the code's struct: the caller's byte stores may alias
 * any memory, and the compiler would load each field again after each. */
typedef struct {
    const uint64_t *high, *low, *rord;
    const hd__mpi_range_t *run;
    size_t nrun, wi, r;
    uint64_t w, lbit, mask, next, delta; /* next: the next run's first ordinal; delta: index - ordinal in run r */
    int l;
} walk_t;

static void walk_run(walk_t *v) {
    v->next = v->r + 1 < v->nrun ? v->rord[v->r + 1] : UINT64_MAX;
    v->delta = v->run[v->r].lo - v->rord[v->r]; /* modulo 2^64: o + delta is the index */
}

static void walk_init(walk_t *v, const hd__mpi_gidx_t *x) {
    *v = (walk_t){x->high, x->low, x->rord, x->run, x->nrun, 0, 0, x->n ? x->high[0] : 0, 0, 0, 0, 0, x->l};
    v->mask = x->l ? (UINT64_C(1) << x->l) - 1 : 0;
    walk_run(v);
}

/* Positions k .. k + m - 1's indices into g[0 .. m - 1] (k: the walk's
 * count so far), with the walk's state in locals for the loop. */
static void walk_block(walk_t *v, size_t k, size_t m, uint64_t *g) {
    const uint64_t *high = v->high, *low = v->low, mask = v->mask;
    const int l = v->l;
    size_t wi = v->wi;
    uint64_t w = v->w, lbit = v->lbit, next = v->next, delta = v->delta;
    for (size_t t = 0; t < m; t++) {
        while (!w) w = high[++wi];
        uint64_t o = (((uint64_t)wi << 6) | (uint64_t)__builtin_ctzll(w)) - (k + t);
        w &= w - 1;
        if (l) {
            size_t wd = (size_t)(lbit >> 6);
            unsigned b = (unsigned)(lbit & 63);
            uint64_t lo = low[wd] >> b;
            if (b + (unsigned)l > 64) lo |= low[wd + 1] << (64 - b);
            o = (o << l) | (lo & mask);
            lbit += (uint64_t)l;
        }
        if (o >= next) {
            while (o >= v->next) v->r++, walk_run(v);
            next = v->next, delta = v->delta;
        }
        g[t] = o + delta;
    }
    v->wi = wi, v->w = w, v->lbit = lbit;
}

/* Decoded a block at a time (WALK_BLOCK indices a side, on the stack). */
#define WALK_BLOCK 256

size_t hd__mpi_gidx_common(const hd__mpi_gidx_t *p, const hd__mpi_gidx_t *q, unsigned char *mp, unsigned char *mq) {
    size_t np = p->n, nq = q->n, nc = 0;
    if (np == 0 || nq == 0) return 0;
    walk_t a, b;
    walk_init(&a, p);
    walk_init(&b, q);
    uint64_t ga[WALK_BLOCK], gb[WALK_BLOCK];
    size_t i0 = 0, j0 = 0, ma = 0, mb = 0, i = 0, j = 0; /* blocks [i0, i0 + ma), [j0, j0 + mb); i, j in them */
    for (;;) {
        if (i == ma) {
            i0 += ma, i = 0, ma = np - i0 < WALK_BLOCK ? np - i0 : WALK_BLOCK;
            if (ma == 0) break;
            walk_block(&a, i0, ma, ga);
        }
        if (j == mb) {
            j0 += mb, j = 0, mb = nq - j0 < WALK_BLOCK ? nq - j0 : WALK_BLOCK;
            if (mb == 0) break;
            walk_block(&b, j0, mb, gb);
        }
        while (i < ma && j < mb) {
            uint64_t gi = ga[i], gj = gb[j];
            if (gi == gj) {
                if (mp) mp[i0 + i] = mq[j0 + j] = 1;
                nc++, i++, j++;
            } else {
                i += gi < gj;
                j += gj < gi;
            }
        }
    }
    return nc;
}

void hd__mpi_gcur_init(hd__mpi_gcur_t *cu, const hd__mpi_gidx_t *x) {
    memset(cu, 0, sizeof *cu);
    cu->x = x;
    cu->k = SIZE_MAX;
    cu->run = SIZE_MAX;
}

/* Jumps of at most this many positions step over the 1s between (a word
 * or two at the densest: about what a select from the sample costs). */
#define GCUR_STEP 48

uint64_t hd__mpi_gcur_next(hd__mpi_gcur_t *cu, size_t k) {
    const hd__mpi_gidx_t *x = cu->x;
    assert(k < x->n);
    if (k == cu->k) return cu->g;
    uint64_t at;
    if (cu->k != SIZE_MAX && k > cu->k && k - cu->k <= GCUR_STEP)
        at = ones_from(x->high, &cu->wi, &cu->w, k - cu->k - 1);
    else
        at = select1(x, k, &cu->wi, &cu->w);
    uint64_t o = ((at - k) << x->l) | hd__mpi_gidx_low(x, k);
    size_t r = cu->run;
    if (r == SIZE_MAX || o < cu->first || o - cu->first > cu->span) /* not the current run, */
        r = r != SIZE_MAX && o >= cu->first && r + 1 < x->nrun && o >= x->rord[r + 1] &&
                    o - x->rord[r + 1] <= x->run[r + 1].hi - x->run[r + 1].lo
                ? r + 1 /* the next, */
                : run_of(x, o); /* or any */
    cu->run = r;
    assert(cu->run < x->nrun);
    cu->first = x->rord[cu->run];
    cu->span = x->run[cu->run].hi - x->run[cu->run].lo;
    cu->lo = x->run[cu->run].lo;
    cu->k = k;
    return cu->g = cu->lo + (o - cu->first);
}
