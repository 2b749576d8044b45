/*
 * write_copc.c -- COPC files (Cloud Optimized Point Cloud, COPC 1.0
 * specification) written back by hd_write_fields.
 *
 * A COPC file is a layered LAZ 1.4 file whose first VLR (user "copc",
 * record 1, 160 bytes) holds the octree's centre and halfsize (4 f64), the
 * spacing (f64), the root hierarchy page's offset and size (u64 each),
 * the GPS time range (2 f64) and 88 reserved bytes; its hierarchy EVLR
 * (user "copc", record 1000) holds pages of 32-byte entries: the node's
 * key (level, x, y, z: 4 i32), offset (u64), byte size and point count
 * (i32 each).  An entry with points is exactly one chunk of the LAZ chunk
 * table (its offset the chunk's first byte, its byte size the chunk's);
 * point count -1 makes it a pointer to a child page (offset, byte size
 * the page's); 0 an empty node.
 *
 * Written back with every point (write_laz.c), each chunk keeps its points
 * and grows by the new BYTE14 layers, and everything after the chunk table
 * (the EVLRs) moves by one shift: each node's entry is moved to its
 * chunk's new place and size, each page pointer and the root page's
 * offset by the shift; nothing else changes.  An entry that does not
 * match a chunk, or a pointer outside the hierarchy, is an error (a
 * hierarchy that would be wrong is never written).
 *
 * A subset (write_lazpw.c) is encoded again a chunk per input chunk that
 * keeps a point, so each node's kept points are its own chunk: the entry
 * gets that chunk's place, size and count, an emptied node offset 0, byte
 * size 0 and count 0; pages and root move by the shift as above.  A
 * pointwise file that calls itself COPC (COPC is layered) is written as
 * plain LAZ, the info VLR and the hierarchy EVLR dropped.
 */
#include "io.h"
#include "lasfield.h"

#include <inttypes.h>
#include <stdlib.h>

enum { INFO_LEN = 160, ROOT_AT = 40, ENTRY = 32 };

static int check_hierarchy(hd__writer_t *w, const hd__las_plan_t *pl, const hd__laz_chunks_t *c);

int hd__copc_plan(hd__writer_t *w, hd__las_plan_t *pl, const hd__laz_chunks_t *c) {
    size_t table_end = c->table_end;
    const unsigned char *d = w->in->data;
    size_t size = w->in->size;
    if (!pl->copc_at) return HD_OK;
    if (pl->copc_len < INFO_LEN)
        return hd__err(w->err, HD_EFORMAT, "%s: byte %zu: the COPC info VLR has %zu bytes (%d expected)", w->in->name,
                       pl->copc_at, pl->copc_len, INFO_LEN);
    if (pl->minor < 4 || pl->header < 247) return HD_OK;
    uint64_t at = hd__ld_u64(d + 235, 0);
    uint32_t n = hd__ld_u32(d + 243, 0);
    for (uint32_t i = 0; i < n; i++) {
        if (at > size || size - at < 60 || hd__ld_u64(d + at + 20, 0) > size - at - 60)
            return hd__err(w->err, HD_EFORMAT, "%s: byte %" PRIu64 ": extended VLR %u of %u runs past the file's end",
                           w->in->name, at, i + 1, n);
        uint64_t len = hd__ld_u64(d + at + 20, 0);
        if (memcmp(d + at + 2, "copc\0", 5) == 0 && hd__ld_u16(d + at + 18, 0) == 1000 && !pl->hier_at) {
            if (at < table_end)
                return hd__err(w->err, HD_EUNSUPPORTED,
                               "%s: byte %" PRIu64 ": the COPC hierarchy EVLR lies before the end of the chunk table",
                               w->in->name, at);
            pl->hier_at = at;
            pl->hier_len = len;
        }
        at += 60 + len;
    }
    return check_hierarchy(w, pl, c);
}

void hd__copc_drop(hd__las_plan_t *pl) {
    if (!pl->copc_at) return;
    pl->copc_drop = 1;
    pl->vlr_added -= 54 + pl->copc_len; /* modulo 2^n: the VLRs shrink */
}

/* The chunk whose first byte is `offset`, or n_chunks. */
static size_t chunk_at(const hd__laz_chunks_t *c, uint64_t offset) {
    size_t lo = 0, hi = c->n_chunks;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (c->start[mid] < offset) lo = mid + 1;
        else hi = mid;
    }
    return lo < c->n_chunks && c->start[lo] == offset ? lo : c->n_chunks;
}

/* Where the chunks went: per input chunk its new first byte, byte size and
 * point count (0: every point left out; count NULL: every point kept). */
typedef struct {
    const uint64_t *start, *bytes, *count;
    uint64_t shift;
} moved_t;

/* Entry e (number i, input byte `byte`) checked against the chunks and,
 * with m, written moved into o; HD_OK or its error. */
static int entry(hd__writer_t *w, const hd__las_plan_t *pl, const hd__laz_chunks_t *c, const moved_t *m,
                 const unsigned char *e, unsigned char *o, size_t i, uint64_t byte) {
    uint64_t off = hd__ld_u64(e + 16, 0);
    uint32_t size = hd__ld_u32(e + 24, 0);
    int32_t count = (int32_t)hd__ld_u32(e + 28, 0);
    char key[112];
    snprintf(key, sizeof key, "entry %zu (level %" PRId32 ", x %" PRId32 ", y %" PRId32 ", z %" PRId32 ") at byte %" PRIu64,
             i + 1, (int32_t)hd__ld_u32(e, 0), (int32_t)hd__ld_u32(e + 4, 0), (int32_t)hd__ld_u32(e + 8, 0),
             (int32_t)hd__ld_u32(e + 12, 0), byte);
    uint64_t data = pl->hier_at + 60, end = data + pl->hier_len;
    if (count == 0) return HD_OK;
    if (count == -1) {
        if (off < data || off > end || size > end - off)
            return hd__err(w->err, HD_EFORMAT, "%s: COPC hierarchy %s: its child page (offset %" PRIu64 ", %" PRIu32
                                               " bytes) is not inside the hierarchy EVLR",
                           w->in->name, key, off, size);
        if (m) hd__st_u64(o + 16, off + m->shift);
        return HD_OK;
    }
    size_t k = chunk_at(c, off);
    if (count < 0 || k == c->n_chunks)
        return hd__err(w->err, HD_EFORMAT, "%s: COPC hierarchy %s: offset %" PRIu64 " (point count %" PRId32
                                           ") is not the start of a chunk",
                       w->in->name, key, off, count);
    if (size != c->start[k + 1] - c->start[k] || (uint64_t)count != c->first[k + 1] - c->first[k])
        return hd__err(w->err, HD_EFORMAT, "%s: COPC hierarchy %s: %" PRIu32 " bytes and %" PRId32
                                           " points, chunk %zu has %" PRIu64 " and %" PRIu64,
                       w->in->name, key, size, count, k + 1, c->start[k + 1] - c->start[k], c->first[k + 1] - c->first[k]);
    if (!m) return HD_OK;
    if (m->bytes[k] > INT32_MAX)
        return hd__err(w->err, HD_EUNSUPPORTED, "%s: COPC hierarchy %s: its chunk would grow past 2 GiB, more than an "
                                                "entry's byte size holds",
                       w->in->name, key);
    uint64_t n = m->count ? m->count[k] : (uint64_t)count; /* 0: a node emptied, offset 0, byte size 0 */
    hd__st_u64(o + 16, n ? m->start[k] : 0);
    for (int q = 0; q < 4; q++) {
        o[24 + q] = (unsigned char)((n ? m->bytes[k] : 0) >> (8 * q));
        o[28 + q] = (unsigned char)(n >> (8 * q));
    }
    return HD_OK;
}

/* Every entry of the input's hierarchy EVLR checked and, with m, written
 * moved into out (its copy); HD_OK or the first error. */
static int entries(hd__writer_t *w, const hd__las_plan_t *pl, const hd__laz_chunks_t *c, const moved_t *m,
                   unsigned char *out) {
    const unsigned char *h = w->in->data + pl->hier_at + 60;
    uint64_t data = pl->hier_at + 60;
    for (size_t i = 0; i < pl->hier_len / ENTRY; i++) {
        int rc = entry(w, pl, c, m, h + ENTRY * i, out ? out + ENTRY * i : NULL, i, data + ENTRY * i);
        if (rc) return rc;
    }
    return HD_OK;
}

static int check_hierarchy(hd__writer_t *w, const hd__las_plan_t *pl, const hd__laz_chunks_t *c) {
    const unsigned char *d = w->in->data;
    if (!pl->hier_at)
        return hd__err(w->err, HD_EFORMAT, "%s: a COPC info VLR without a hierarchy EVLR (user \"copc\", record 1000)",
                       w->in->name);
    if (pl->hier_len % ENTRY)
        return hd__err(w->err, HD_EFORMAT, "%s: byte %" PRIu64 ": the COPC hierarchy EVLR's %" PRIu64
                                           " bytes are not whole 32-byte entries",
                       w->in->name, pl->hier_at, pl->hier_len);
    uint64_t root = hd__ld_u64(d + pl->copc_at + 54 + ROOT_AT, 0), root_size = hd__ld_u64(d + pl->copc_at + 54 + ROOT_AT + 8, 0);
    uint64_t data = pl->hier_at + 60, end = data + pl->hier_len;
    if (root < data || root > end || root_size > end - root)
        return hd__err(w->err, HD_EFORMAT, "%s: byte %zu: the COPC root hierarchy page (offset %" PRIu64 ", %" PRIu64
                                           " bytes) is not inside the hierarchy EVLR",
                       w->in->name, pl->copc_at + 54 + ROOT_AT, root, root_size);
    return entries(w, pl, c, NULL, NULL);
}

int hd__copc_move(hd__writer_t *w, hd__las_plan_t *pl, const hd__laz_chunks_t *c, const uint64_t *new_start,
                  const uint64_t *bytes, const uint64_t *count, uint64_t shift, unsigned char **info, unsigned char **hier) {
    const unsigned char *d = w->in->data;
    *info = *hier = NULL;
    if (!pl->copc_at || pl->copc_drop) return HD_OK;
    *info = malloc(pl->copc_len);
    *hier = malloc((size_t)pl->hier_len + 1);
    if (!*info || !*hier) return hd__err(w->err, HD_ENOMEM, "out of memory");
    memcpy(*info, d + pl->copc_at + 54, pl->copc_len);
    memcpy(*hier, d + pl->hier_at + 60, (size_t)pl->hier_len);
    hd__st_u64(*info + ROOT_AT, hd__ld_u64(*info + ROOT_AT, 0) + shift);
    moved_t m = {new_start, bytes, count, shift};
    int rc = entries(w, pl, c, &m, *hier);
    if (rc) return rc;
    pl->copc_info = *info;
    pl->copc_hier = *hier;
    return HD_OK;
}
