/*
 * m2m_shared.c -- the faces two meshes share (hd__m2m_shared): a face of
 * X is dropped from h(X, Y) when its three corners are bit for bit those
 * of a face of Y (d = 0 on it), and the same for Y against X, from one
 * hash table of Y's faces.
 *
 * A face's hash is a function of its corners as a multiset (its corners'
 * words summed coordinate by coordinate), so no face is put in order before
 * it is hashed;
 * the table keeps each slot's hash beside its face, and only faces with
 * equal hashes are compared, in full (their corners sorted in one fixed
 * order and compared bit for bit): the hash decides the cost, never the
 * answer (bench/m2m_run, `shared` and `through`).
 */
#include "mesh/mesh.h"

#include <stdlib.h>
#include <string.h>

/* A function of the corners' bits as a multiset: each coordinate's three
 * words summed (the sums do not depend on the corners' order), the sums
 * weighted by odd constants and mixed. */
static uint64_t face_hash(const hd__tri_t *t) {
    uint64_t w[3][3], s[3];
    memcpy(w, t->v, sizeof w);
    for (int d = 0; d < 3; d++) s[d] = w[0][d] + w[1][d] + w[2][d];
    uint64_t h = s[0] * 0x9e3779b97f4a7c15u + s[1] * 0xff51afd7ed558ccdu + s[2] * 0xc4ceb9fe1a85ec53u;
    h = (h ^ (h >> 29)) * 0xbf58476d1ce4e5b9u;
    return h ^ (h >> 32);
}

/* The corners' bits as words, each corner's three in order. */
typedef struct key {
    uint64_t w[3][3];
} facekey_t;

/* a before b in the words' lexicographic order (a total order on bits) */
static int before(const uint64_t a[3], const uint64_t b[3]) {
    return a[0] != b[0] ? a[0] < b[0] : a[1] != b[1] ? a[1] < b[1] : a[2] < b[2];
}

static void swap_if(uint64_t a[3], uint64_t b[3]) {
    if (before(b, a))
        for (int i = 0; i < 3; i++) {
            uint64_t t = a[i];
            a[i] = b[i], b[i] = t;
        }
}

/* The corners in that order (three compare-exchanges). */
static void key_of(const hd__tri_t *t, facekey_t *k) {
    memcpy(k->w, t->v, sizeof k->w);
    swap_if(k->w[0], k->w[1]);
    swap_if(k->w[1], k->w[2]);
    swap_if(k->w[0], k->w[1]);
}

/* The same three corners, as a multiset, bit for bit. */
static int same_face(const hd__tri_t *s, const hd__tri_t *t) {
    facekey_t a, b;
    key_of(s, &a);
    key_of(t, &b);
    return memcmp(&a, &b, sizeof a) == 0;
}

int hd__m2m_shared(const hd__tri_t *x, size_t nx, const hd__tri_t *y, size_t ny, unsigned char *drop_x,
                   unsigned char *drop_y, size_t *count_x, size_t *count_y) {
    *count_x = *count_y = 0;
    size_t size = 16;
    while (size < 2 * ny) size *= 2;
    /* slot: Y's first face with that key (SIZE_MAX: empty), with its hash;
     * at[k]: the slot of face k's key (equal keys share the first one's) */
    size_t *slot = hd__malloc_array(size, sizeof *slot), *at = hd__malloc_array(ny ? ny : 1, sizeof *at);
    uint64_t *hash = hd__malloc_array(size, sizeof *hash);
    unsigned char *hit = hd__calloc_array(size, 1);
    if (!slot || !at || !hash || !hit) {
        free(slot), free(at), free(hash), free(hit);
        return HD_ENOMEM;
    }
    for (size_t k = 0; k < size; k++) slot[k] = SIZE_MAX;
    for (size_t k = 0; k < ny; k++) {
        uint64_t g = face_hash(&y[k]);
        size_t h = (size_t)g & (size - 1);
        while (slot[h] != SIZE_MAX && !(hash[h] == g && same_face(&y[slot[h]], &y[k]))) h = (h + 1) & (size - 1);
        if (slot[h] == SIZE_MAX) slot[h] = k, hash[h] = g;
        at[k] = h;
    }
    /* X's faces looked up; the keys they meet are Y's shared faces */
    for (size_t k = 0; k < nx; k++) {
        uint64_t g = face_hash(&x[k]);
        size_t h = (size_t)g & (size - 1);
        while (slot[h] != SIZE_MAX && !(hash[h] == g && same_face(&y[slot[h]], &x[k]))) h = (h + 1) & (size - 1);
        drop_x[k] = slot[h] != SIZE_MAX;
        hit[h] |= drop_x[k];
        *count_x += drop_x[k];
    }
    for (size_t k = 0; drop_y && k < ny; k++) {
        drop_y[k] = hit[at[k]];
        *count_y += drop_y[k];
    }
    free(slot), free(at), free(hash), free(hit);
    return HD_OK;
}
