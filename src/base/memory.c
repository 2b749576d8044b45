/*
 * memory.c -- checked allocation and the arena that tree nodes come from.
 *
 * Every allocation of "count items of size bytes" goes through
 * hd__malloc_array, which refuses a product that overflows size_t before
 * calling malloc: a header that promises 2^62 vertices becomes HD_ENOMEM or
 * HD_EOVERFLOW, never a short buffer.  Trees allocate their nodes from an
 * arena (a list of large blocks) so that building costs a few mallocs, not
 * one per node, and freeing is one walk over the blocks.
 *
 * hd__reuse_* keeps the large arrays one call frees, for the
 * arrays it allocates next: each block starts with a header of
 * REUSE_HEADER bytes holding its capacity, so a block is reused by any
 * request of at least a third of its capacity (best fit), and the pages
 * already touched are written again instead of fresh ones.  Requests below
 * REUSE_SMALL bytes are not worth keeping and are freed at once.
 *
 * What a set holds from the system (its blocks in use or kept, its chunks)
 * is counted in `held`, and its most in `peak`, which is the engine's
 * memory high-water mark (its results' stats.peak_bytes).  A caller that knows the
 * kept blocks will not serve it gives them back (hd__reuse_trim,
 * hd__reuse_take), and one that uses only the start of a block gives back
 * the pages after it (hd__reuse_shrink): that, not reuse, is what bounds
 * the engine's peak (docs/engine.md, "Threads and memory").
 *
 * hd__prefault asks the kernel to map a fresh block's pages in one call
 * (madvise MADV_POPULATE_WRITE) instead of one page fault per page on first
 * write; only for arrays that are written whole, since it maps every page.
 *
 * Fresh blocks of the reuse set are mapped in transparent huge pages where
 * the kernel gives them: large blocks each on their own (huge_map), middle-
 * sized ones cut from the set's 2 MiB chunks (chunk_get) where the chunks
 * are not more than the call needs (chunk_opens), else from malloc.  A block's pages
 * are then 2 MiB, one fault each instead of 512.  Every block, however it
 * was made, starts REUSE_HEADER bytes after its header and is released by
 * reuse_release, which knows from the header how.
 */
#include "base/base.h"

#include <stdint.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>

void *hd__malloc_array(size_t n, size_t size) {
    if (hd__mul_overflows(n, size)) return NULL;
    size_t bytes = n * size;
    return malloc(bytes ? bytes : 1);
}

void *hd__calloc_array(size_t n, size_t size) {
    if (hd__mul_overflows(n, size)) return NULL;
    return calloc(n ? n : 1, size ? size : 1);
}

void *hd__realloc_array(void *p, size_t n, size_t size) {
    if (hd__mul_overflows(n, size)) return NULL;
    size_t bytes = n * size;
    return realloc(p, bytes ? bytes : 1);
}

struct hd__arena_block {
    struct hd__arena_block *next;
    size_t used, cap;
    _Alignas(16) unsigned char data[];
};

void hd__prefault(void *p, size_t bytes) {
#ifdef MADV_POPULATE_WRITE
    if (!p || bytes < HD__PREFAULT_MIN) return;
    long page = sysconf(_SC_PAGESIZE);
    if (page <= 0) return;
    uintptr_t a = ((uintptr_t)p + (uintptr_t)page - 1) & ~((uintptr_t)page - 1);
    uintptr_t e = ((uintptr_t)p + bytes) & ~((uintptr_t)page - 1);
    /* A hint: when the kernel cannot (before Linux 5.14: EINVAL) the pages
     * are mapped on first touch, as without it. */
    if (e > a) (void)madvise((void *)a, e - a, MADV_POPULATE_WRITE);
#else
    (void)p, (void)bytes;
#endif
}

#define REUSE_HEADER 64
#define REUSE_SMALL 65536

/* A block's header, the REUSE_HEADER bytes before the array: its capacity,
 * and for a block mapped by huge_map the mapping to unmap (else NULL). */
typedef struct {
    size_t cap;
    void *map;
    size_t map_len;
    int cut; /* cut from one of the pool's chunks: freed with the pool */
    size_t huge; /* the array's first bytes mapped in 2 MiB pages (huge_map) */
} reuse_head_t;

static reuse_head_t *reuse_head(const void *p) { return (reuse_head_t *)((unsigned char *)p - REUSE_HEADER); }

/* Blocks of at least HUGE_MIN bytes are mapped by huge_map: the array
 * starts on a HUGE_ALIGN boundary, its header sits at the end of the page
 * before it, and the pages that hold only the array are marked for
 * transparent huge pages (MADV_HUGEPAGE; the kernel's default mode here is
 * "madvise") before they are mapped: a 2 MiB page costs one fault instead
 * of 512 (docs/benchmarks.md, "Issue 15, item 2").  The mapping ends at
 * the array's last small page, so a partly used last 2 MiB stays in small
 * pages and the block costs no more memory than the array (plus a page).
 * Where the system has no such call, or mmap fails, the block comes from
 * malloc as below. */
#define HUGE_ALIGN ((size_t)2 << 20)
#define HUGE_MIN (HUGE_ALIGN / 9 * 8)

static void *huge_map(size_t bytes, int prefault) {
#if defined(MADV_HUGEPAGE) && defined(MAP_ANONYMOUS)
    long page = sysconf(_SC_PAGESIZE);
    if (page < 4096 || (size_t)page > HUGE_ALIGN || bytes < HUGE_MIN || bytes > SIZE_MAX / 4) return NULL;
    size_t pg = (size_t)page, used = (bytes + pg - 1) & ~(pg - 1);
    size_t whole = (bytes + HUGE_ALIGN - 1) & ~(HUGE_ALIGN - 1);
    if (whole - bytes <= bytes / 8) used = whole;
    size_t len = pg + used + HUGE_ALIGN;
    unsigned char *m = mmap(NULL, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) return NULL;
    unsigned char *a = (unsigned char *)(((uintptr_t)m + pg + HUGE_ALIGN - 1) & ~(uintptr_t)(HUGE_ALIGN - 1));
    unsigned char *lo = a - pg, *hi = a + used; /* kept: the header's page and the array's pages */
    if (lo > m) munmap(m, (size_t)(lo - m));
    if (m + len > hi) munmap(hi, (size_t)(m + len - hi));
    /* The huge part is mapped by writing one byte per 2 MiB, not by
     * MADV_POPULATE_WRITE, which made the first call slower here.  When the
     * kernel gave small pages instead (THP off, or no free 2 MiB block),
     * the last page of the last 2 MiB is still absent, and the whole block
     * is prefaulted as any other; the small pages after the huge part are
     * prefaulted in any case. */
    size_t huge = used & ~(HUGE_ALIGN - 1);
    if (huge && madvise(a, huge, MADV_HUGEPAGE) == 0) {
        for (size_t o = 0; o < huge; o += HUGE_ALIGN) a[o] = 0;
        unsigned char in[HUGE_ALIGN / 4096];
        size_t last = HUGE_ALIGN / pg - 1;
        if (mincore(a + huge - HUGE_ALIGN, HUGE_ALIGN, in) != 0 || !(in[last] & 1)) huge = 0;
    } else {
        huge = 0;
    }
    if (huge < bytes && prefault) hd__prefault(a + huge, bytes - huge);
    reuse_head_t *h = reuse_head(a);
    h->cut = 0;
    h->map = lo;
    h->map_len = (size_t)(hi - lo);
    h->huge = huge;
    return a;
#else
    (void)bytes, (void)prefault;
    return NULL;
#endif
}

/* The bytes a block takes from the system: its mapping, or its malloc'ed
 * header and array.  A block cut from a chunk takes nothing of its own:
 * the chunk is counted once, as it is mapped. */
static size_t reuse_span(const void *p) {
    const reuse_head_t *h = reuse_head(p);
    return h->cut ? 0 : h->map ? h->map_len : REUSE_HEADER + h->cap;
}

static void reuse_held(hd__reuse_t *pool, size_t more) {
    if (!pool) return;
    pool->held += more;
    if (pool->held > pool->peak) pool->peak = pool->held;
}

static void reuse_release(hd__reuse_t *pool, void *p) {
    reuse_head_t *h = reuse_head(p);
    if (h->cut) return;
    if (pool) pool->held -= reuse_span(p);
    if (h->map) munmap(h->map, h->map_len);
    else free(h);
}

/* Whether a request of `need` bytes (header included) that the open chunk
 * cannot take maps a fresh 2 MiB chunk, while the pool holds `held` bytes.
 * A chunk is held and charged whole (its huge page is resident whole), so
 * it is mapped only where the arrays cut from it are what the call needs:
 * - the request is at most half a chunk, so the chunk it opens can take a
 *   second array of its size; a larger one, which would leave a tail no
 *   array of its kind fits, gets a block of its own at its bytes;
 * - and either the request fills at least a quarter of the chunk, or the
 *   pool already holds at least a chunk and a half in other blocks, so
 *   that a chunk, however little of it is cut, is at most two fifths of
 *   what the pool holds once it is mapped.  A small array that comes first
 *   in a small call (under a quarter chunk, with little held) thus gets a
 *   block at its bytes instead of a chunk it would barely use. */
static int chunk_opens(size_t held, size_t need) {
    return need <= HUGE_ALIGN / 2 && (need >= HUGE_ALIGN / 4 || held >= HUGE_ALIGN + HUGE_ALIGN / 2);
}

/* Middle-sized blocks (REUSE_SMALL up to HUGE_MIN bytes: a grid's cell
 * tables, the counting sorts' counts) are cut one after another from 2 MiB
 * chunks of the pool, mapped as huge pages by huge_map: one fault for the
 * lot instead of one per 4 KiB page.  They go back to the pool's list like
 * any block, and their memory is unmapped with the pool.  NULL when the
 * pool has no chunk left or none can be mapped (the caller then uses
 * malloc), and when a chunk would hold more than the call needs
 * (chunk_opens). */
static void *chunk_get(hd__reuse_t *pool, size_t bytes) {
    size_t need = REUSE_HEADER + ((bytes + REUSE_HEADER - 1) & ~(size_t)(REUSE_HEADER - 1));
    if (!pool->n_chunks || HUGE_ALIGN - pool->chunk_used < need) {
        if (pool->n_chunks == HD__REUSE_CHUNKS || !chunk_opens(pool->held, need)) return NULL;
        /* Not prefaulted when the kernel gives small pages: only the
         * pieces cut from it are touched, each on first write. */
        void *c = huge_map(HUGE_ALIGN, 0);
        if (!c) return NULL;
        pool->chunk[pool->n_chunks++] = c;
        reuse_held(pool, reuse_span(c));
        pool->chunk_used = 0;
    }
    unsigned char *p = (unsigned char *)pool->chunk[pool->n_chunks - 1] + pool->chunk_used + REUSE_HEADER;
    pool->chunk_used += need;
    pool->cut_out++;
    reuse_head(p)->cut = 1;
    return p;
}

void hd__reuse_init(hd__reuse_t *pool) {
    pool->n = 0;
    pool->n_chunks = 0;
    pool->chunk_used = 0;
    pool->cut_out = 0;
    pool->held = 0;
    pool->peak = 0;
}

static size_t reuse_cap(const void *p) { return reuse_head(p)->cap; }

/* The kept block that a request of `bytes` gets (best fit), or -1. */
static int reuse_best(const hd__reuse_t *pool, size_t bytes) {
    int best = -1;
    for (int k = 0; pool && bytes >= REUSE_SMALL && k < pool->n; k++) {
        size_t cap = reuse_cap(pool->block[k]);
        if (cap >= bytes && cap / 3 <= bytes && (best < 0 || cap < reuse_cap(pool->block[best]))) best = k;
    }
    return best;
}

void *hd__reuse_get(hd__reuse_t *pool, size_t n, size_t size) {
    if (hd__mul_overflows(n, size) || n * size > SIZE_MAX - REUSE_HEADER) return NULL;
    size_t bytes = n * size;
    if (pool && bytes >= REUSE_SMALL) {
        int best = reuse_best(pool, bytes);
        if (best >= 0) {
            void *p = pool->block[best];
            pool->block[best] = pool->block[--pool->n];
            pool->cut_out += reuse_head(p)->cut;
            return p;
        }
    }
    unsigned char *p = NULL;
    if (pool && bytes >= REUSE_SMALL && bytes < HUGE_MIN) p = chunk_get(pool, bytes);
    if (!p) p = huge_map(bytes, 1);
    if (!p) {
        unsigned char *b = malloc(REUSE_HEADER + bytes);
        if (!b) return NULL;
        hd__prefault(b, REUSE_HEADER + bytes);
        p = b + REUSE_HEADER;
        reuse_head(p)->map = NULL;
        reuse_head(p)->cut = 0;
    }
    reuse_head(p)->cap = bytes;
    reuse_held(pool, reuse_span(p));
    return p;
}

void hd__reuse_put(hd__reuse_t *pool, void *p) {
    if (!p) return;
    if (pool) pool->cut_out -= reuse_head(p)->cut;
    if (pool && pool->n < HD__REUSE_KEEP && reuse_cap(p) >= REUSE_SMALL) {
        pool->block[pool->n++] = p;
        return;
    }
    reuse_release(pool, p);
}

void hd__reuse_trim(hd__reuse_t *pool) {
    if (!pool) return;
    int kept = 0;
    for (int k = 0; k < pool->n; k++) {
        if (reuse_head(pool->block[k])->cut && pool->cut_out) pool->block[kept++] = pool->block[k];
        else reuse_release(pool, pool->block[k]);
    }
    pool->n = kept;
    if (pool->cut_out) return;
    for (int k = 0; k < pool->n_chunks; k++) reuse_release(pool, pool->chunk[k]);
    pool->n_chunks = 0;
    pool->chunk_used = 0;
}

void *hd__reuse_take(hd__reuse_t *pool, size_t n, size_t size) {
    if (!pool || hd__mul_overflows(n, size)) return hd__reuse_get(pool, n, size);
    int best = reuse_best(pool, n * size);
    void *keep = best >= 0 ? pool->block[best] : NULL;
    /* The block that will serve counts as in use while the others go: a
     * block cut from a chunk keeps its chunk mapped (trim unmaps chunks
     * only when nothing cut from them is in use). */
    int cut = keep ? reuse_head(keep)->cut : 0;
    if (keep) pool->block[best] = pool->block[--pool->n];
    pool->cut_out += cut;
    hd__reuse_trim(pool);
    pool->cut_out -= cut;
    if (keep) pool->block[pool->n++] = keep; /* the one kept block left */
    return hd__reuse_get(pool, n, size);
}

void hd__reuse_shrink(hd__reuse_t *pool, void *p, size_t bytes) {
    reuse_head_t *h = reuse_head(p);
    long page = sysconf(_SC_PAGESIZE);
    if (!h->map || bytes > h->cap || page <= 0) return;
    uintptr_t pg = (uintptr_t)page, lo = (uintptr_t)h->map, end = lo + h->map_len;
    /* A 2 MiB page is never cut: unmapping part of it splits it into small
     * pages, and each of those then costs a fault (of the hypervisor, on
     * this virtual machine) when next touched, which made the trees' build
     * slower (docs/benchmarks.md, "The engine's memory peak").  So the pages
     * kept end at a 2 MiB boundary within the huge part. */
    size_t round = bytes < h->huge ? HUGE_ALIGN : (size_t)pg;
    uintptr_t keep = ((uintptr_t)p + bytes + round - 1) & ~(uintptr_t)(round - 1);
    h->cap = bytes;
    if (h->huge > keep - (uintptr_t)p) h->huge = keep - (uintptr_t)p;
    if (keep >= end) return;
    munmap((void *)keep, end - keep);
    h->map_len = keep - lo;
    if (pool) pool->held -= end - keep;
}

void hd__reuse_free(hd__reuse_t *pool) {
    for (int k = 0; k < pool->n; k++) reuse_release(pool, pool->block[k]);
    for (int k = 0; k < pool->n_chunks; k++) reuse_release(pool, pool->chunk[k]);
    size_t peak = pool->peak;
    hd__reuse_init(pool);
    pool->peak = peak; /* what the call held at most, for its caller */
}

void hd__arena_init(hd__arena_t *a, size_t block_size) {
    a->head = NULL;
    a->block_size = block_size < 4096 ? 4096 : block_size;
    a->total = 0;
}

void *hd__arena_alloc(hd__arena_t *a, size_t size) {
    size = (size + 15) & ~(size_t)15;
    struct hd__arena_block *b = a->head;
    if (!b || b->cap - b->used < size) {
        size_t cap = size > a->block_size ? size : a->block_size;
        if (cap > SIZE_MAX - sizeof *b) return NULL;
        b = malloc(sizeof *b + cap);
        if (!b) return NULL;
        b->next = a->head;
        b->used = 0;
        b->cap = cap;
        a->head = b;
        a->total += sizeof *b + cap;
    }
    void *p = b->data + b->used;
    b->used += size;
    return p;
}

void hd__arena_free(hd__arena_t *a) {
    struct hd__arena_block *b = a->head;
    while (b) {
        struct hd__arena_block *n = b->next;
        free(b);
        b = n;
    }
    a->head = NULL;
    a->total = 0;
}
