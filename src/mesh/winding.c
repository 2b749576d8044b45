/*
 * winding.c -- the winding number of a closed triangle mesh around a point,
 * decided exactly: the sign of a signed distance.
 *
 * Closedness.  Corners with equal coordinates (bit-equal once -0 is taken
 * as +0) are one vertex.  A triangle with two corners on one vertex has no
 * area and no edge; every other triangle uses its three edges in its corner
 * order.  The mesh is closed and consistently oriented when every edge
 * {u, v} is used as often from u to v as from v to u (a manifold edge: once
 * each way; a non-manifold edge shared by 2k triangles: k each way).  Then
 * the triangles form a 2-cycle without boundary and the winding number
 * w(p), the solid angle of the surface seen from p over 4 pi (the
 * generalised winding number of Jacobson et al. 2013), is an integer at
 * every point off the surface, constant on each connected part of the
 * complement and 0 far away.
 *
 * The winding number, exactly.  For such a cycle, w(p) is the signed number
 * of crossings of any ray from p with the triangles (the intersection
 * number of the ray with the cycle).  The ray here is p + t (1, 0, 0),
 * t > 0, from p moved by the infinitesimal (0, e, e^2) (simulation of
 * simplicity): the moved point has the same winding number as p (w is
 * constant near a point off the surface) and the moved ray meets no edge and
 * no vertex of the mesh, so every crossing is through a triangle's
 * interior.  A triangle abc is crossed when the (y, z) projection of the
 * moved point lies strictly inside abc's projection, i.e. the three signs
 * orient2(a, b, p), orient2(b, c, p), orient2(c, a, p) equal the sign s of
 * n_x = orient2(a, b, c) (n = (b - a) x (c - a)), and the triangle lies
 * ahead of p along x, i.e. orient3 = (p - a) . n has the sign -s; it adds s
 * (its normal's direction along the ray).  A triangle with n_x = 0 (its
 * plane contains the ray's direction) is never crossed by the moved ray.
 *
 * Each orient2 of the moved point is orient2(a, b, p) + e (a_z - b_z) +
 * e^2 (b_y - a_y): its sign is the first nonzero of the three, and the
 * last two are comparisons of doubles.  An edge shared by two triangles is
 * seen with opposite signs from both, perturbation included, so no crossing
 * is counted twice or missed.  Every sign is exact: computed in doubles and
 * accepted when it exceeds a bound on its rounding error, otherwise
 * computed with the kernel's exact integers (mesh_int.h).  The bound is the
 * sum of the absolute values of the products times 8u for orient2 (two
 * differences, a product and the difference of two: at most 4u and its
 * square) and 16u for orient3 (seven roundings on a term's path: Shewchuk
 * 1997 proves 7u + 56u^2), u = 2^-53, plus UFL = 2^-1070 for each product
 * that may underflow (a subnormal result errs by at most 2^-1075; a
 * difference of doubles that is subnormal is exact), times the largest
 * factor a product of orient3 is later multiplied by (lever).  Coordinates
 * are below 1e153, so orient2's products are finite; orient3's may
 * overflow, and an infinite or NaN bound or value goes to the exact path.
 *
 * If orient3 is exactly 0 for a crossed triangle, p lies on that (closed)
 * triangle: p is on the surface and has no winding number; the caller is
 * told.  A triangle is tested only when p's (y, z) lies in its closed (y, z)
 * box and p_x is below the box's largest x: outside that box no moved point
 * is inside the projection, and a triangle whose largest x is at most p_x
 * is not ahead of p unless p is on it, so the search over a tree of (y, z)
 * boxes gives the same count as a loop over every triangle.
 */
#include "mesh/mesh.h"
#include "mesh/mesh_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define U 0x1p-53
#define UFL 0x1p-1070 /* more than the error of a product that underflows */
#define LEAF 4

/* ---- exact signs -------------------------------------------------------- */

/* The smallest exponent of the last significant bit among the nonzero
 * values (0 when all are zero). */
static int low_exp(const double *x, int n) {
    int e0 = 0, any = 0;
    for (int k = 0; k < n; k++)
        if (x[k] != 0) {
            int e = hd__ulp_exp(x[k]);
            if (!any || e < e0) e0 = e;
            any = 1;
        }
    return e0;
}

/* (ay - py)(bz - pz) - (az - pz)(by - py) exactly. */
static int orient2_exact(const double *a, const double *b, const double *p) {
    double x[6] = {a[1], a[2], b[1], b[2], p[1], p[2]};
    int e0 = low_exp(x, 6);
    hd__big_t v[6], d[4], t1, t2, r;
    for (int k = 0; k < 6; k++) hd__big_set_double(&v[k], x[k], e0);
    hd__big_sub(&d[0], &v[0], &v[4]); /* ay - py */
    hd__big_sub(&d[1], &v[3], &v[5]); /* bz - pz */
    hd__big_sub(&d[2], &v[1], &v[5]); /* az - pz */
    hd__big_sub(&d[3], &v[2], &v[4]); /* by - py */
    hd__big_mul(&t1, &d[0], &d[1]);
    hd__big_mul(&t2, &d[2], &d[3]);
    hd__big_sub(&r, &t1, &t2);
    return hd__big_sign(&r);
}

static int orient2(const double *a, const double *b, const double *p) {
    double t1 = (a[1] - p[1]) * (b[2] - p[2]), t2 = (a[2] - p[2]) * (b[1] - p[1]);
    double f = t1 - t2, bound = 8 * U * (fabs(t1) + fabs(t2)) + UFL;
    if (fabs(f) > bound && isfinite(bound)) return f > 0 ? 1 : -1;
    return orient2_exact(a, b, p);
}

/* orient2 of the moved point (the first nonzero of the expansion). */
static int orient2_moved(const double *a, const double *b, const double *p) {
    int s = orient2(a, b, p);
    if (s) return s;
    if (a[2] != b[2]) return a[2] > b[2] ? 1 : -1;
    return (b[1] > a[1]) - (b[1] < a[1]);
}

/* (p - a) . ((b - a) x (c - a)) = -det[a - p, b - p, c - p], exactly. */
static int orient3_exact(const double *a, const double *b, const double *c, const double *p) {
    const double *pts[4] = {a, b, c, p};
    double x[12];
    for (int i = 0; i < 4; i++) memcpy(x + 3 * i, pts[i], 3 * sizeof(double));
    int e0 = low_exp(x, 12);
    hd__big_t v[12], d[9], m1, m2, cr, t, acc, s;
    for (int k = 0; k < 12; k++) hd__big_set_double(&v[k], x[k], e0);
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) hd__big_sub(&d[3 * i + k], &v[3 * i + k], &v[9 + k]); /* X - p */
    acc.n = 0, acc.neg = 0;
    for (int k = 0; k < 3; k++) { /* a_k (b x c)_k with the minus folded in */
        int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        hd__big_mul(&m1, &d[3 + k1], &d[6 + k2]);
        hd__big_mul(&m2, &d[3 + k2], &d[6 + k1]);
        hd__big_sub(&cr, &m1, &m2);
        hd__big_mul(&t, &d[k], &cr);
        hd__big_add(&s, &acc, &t);
        acc = s;
    }
    return -hd__big_sign(&acc);
}

static int orient3(const double *a, const double *b, const double *c, const double *p) {
    double ad[3], bd[3], cd[3];
    for (int k = 0; k < 3; k++) ad[k] = a[k] - p[k], bd[k] = b[k] - p[k], cd[k] = c[k] - p[k];
    double det = 0, perm = 0, lever = 1;
    for (int k = 0; k < 3; k++) {
        int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        double m1 = bd[k1] * cd[k2], m2 = bd[k2] * cd[k1];
        det += ad[k] * (m1 - m2);
        perm += fabs(ad[k]) * (fabs(m1) + fabs(m2));
        lever += fabs(ad[k]);
    }
    double bound = 16 * U * perm + 4 * UFL * lever;
    if (fabs(det) > bound && isfinite(bound)) return det > 0 ? -1 : 1;
    return orient3_exact(a, b, c, p);
}

/* ---- the prepared surface ------------------------------------------------ */

typedef struct {
    double v[3][3];
    int s; /* the sign of n_x, never 0 */
} rtri_t;

typedef struct {
    double lo[2], hi[2], xmax; /* the (y, z) box and the largest x */
    uint32_t first_or_second, count;
} rnode_t;

struct hd__solid {
    rtri_t *tris;
    rnode_t *nodes;
    size_t n_tris, n_nodes;
};

static void rnode_box(rnode_t *nd, const rtri_t *t, size_t n) {
    nd->lo[0] = nd->lo[1] = INFINITY;
    nd->hi[0] = nd->hi[1] = nd->xmax = -INFINITY;
    for (size_t i = 0; i < n; i++)
        for (int j = 0; j < 3; j++) {
            const double *v = t[i].v[j];
            for (int k = 0; k < 2; k++) {
                nd->lo[k] = v[k + 1] < nd->lo[k] ? v[k + 1] : nd->lo[k];
                nd->hi[k] = v[k + 1] > nd->hi[k] ? v[k + 1] : nd->hi[k];
            }
            nd->xmax = v[0] > nd->xmax ? v[0] : nd->xmax;
        }
}

static double centre(const rtri_t *t, int k) { return t->v[0][k] + t->v[1][k] + t->v[2][k]; }

/* Put the element of rank mid (by centre along axis k) at mid, smaller
 * ones before it and larger after (quickselect, middle pivot). */
static void select_mid(rtri_t *t, size_t n, size_t mid, int k) {
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        double pivot = centre(&t[lo + (hi - lo) / 2], k);
        size_t i = lo, j = hi;
        while (i <= j) {
            while (centre(&t[i], k) < pivot) i++;
            while (centre(&t[j], k) > pivot) j--;
            if (i <= j) {
                rtri_t x = t[i];
                t[i] = t[j], t[j] = x;
                i++;
                if (j == 0) break;
                j--;
            }
        }
        if (mid <= j) hi = j;
        else if (mid >= i) lo = i;
        else break;
    }
}

static size_t build_node(struct hd__solid *S, size_t first, size_t n) {
    size_t at = S->n_nodes++;
    rnode_t *nd = &S->nodes[at];
    rnode_box(nd, S->tris + first, n);
    if (n <= LEAF) {
        nd->first_or_second = (uint32_t)first;
        nd->count = (uint32_t)n;
        return at;
    }
    int k = nd->hi[1] - nd->lo[1] > nd->hi[0] - nd->lo[0] ? 2 : 1;
    size_t half = n / 2;
    select_mid(S->tris + first, n, half, k);
    build_node(S, first, half);
    size_t second = build_node(S, first + half, n - half);
    S->nodes[at].first_or_second = (uint32_t)second;
    S->nodes[at].count = 0;
    return at;
}

/* ---- closedness ---------------------------------------------------------- */

typedef struct {
    double xyz[3];
    uint64_t vertex; /* the caller's vertex index */
    size_t slot;     /* 3 * triangle + corner */
} corner_t;

static int cmp_corner(const void *x, const void *y) {
    const corner_t *a = x, *b = y;
    int c = memcmp(a->xyz, b->xyz, sizeof a->xyz);
    if (c) return c;
    return (a->vertex > b->vertex) - (a->vertex < b->vertex);
}

static void corner_of(const hd__wtri_t *t, size_t slot, corner_t *c) {
    for (int k = 0; k < 3; k++) c->xyz[k] = t[slot / 3].v[slot % 3][k] + 0.0; /* -0 -> +0 */
    c->vertex = t[slot / 3].vi[slot % 3];
    c->slot = slot;
}

/* 30 bits of the corner's coordinates: equal coordinates, equal bits. */
static uint64_t corner_hash(const corner_t *c) {
    uint64_t h = 0x9e3779b97f4a7c15u, b;
    for (int k = 0; k < 3; k++) {
        memcpy(&b, &c->xyz[k], 8);
        h = (h ^ b) * 0xff51afd7ed558ccdu;
        h ^= h >> 33;
    }
    return h >> 34;
}

/* The vertex id of every corner (id[3t + j]) and, per id, a representative:
 * the smallest caller index with those coordinates (rep[id]).  The corners
 * are radix-sorted by a hash of their coordinates; each run of one hash
 * (the corners of one vertex, and rarely a colliding other) is sorted by
 * coordinates and caller index, so equal coordinates are grouped exactly. */
static int vertex_ids(const hd__wtri_t *t, size_t n, size_t *id, uint64_t *rep, size_t *n_ids) {
    size_t m = 3 * n;
    uint64_t *key = hd__malloc_array(m, sizeof *key), *tmp = hd__malloc_array(m, sizeof *tmp);
    corner_t *run = NULL;
    size_t cap = 0;
    int rc = key && tmp ? HD_OK : HD_ENOMEM;
    for (size_t s = 0; rc == HD_OK && s < m; s++) {
        corner_t c;
        corner_of(t, s, &c);
        key[s] = corner_hash(&c) << 32 | (uint64_t)s;
    }
    if (rc == HD_OK) rc = hd__radix_sort(&key, &tmp, m, 1);
    size_t ids = 0;
    for (size_t a = 0; rc == HD_OK && a < m;) {
        size_t b = a + 1;
        while (b < m && key[b] >> 32 == key[a] >> 32) b++;
        if (b - a > cap) {
            free(run);
            cap = 2 * (b - a);
            if (!(run = hd__malloc_array(cap, sizeof *run))) rc = HD_ENOMEM;
        }
        for (size_t k = a; rc == HD_OK && k < b; k++) corner_of(t, (size_t)(key[k] & 0xffffffffu), &run[k - a]);
        if (rc == HD_OK && b - a > 1) qsort(run, b - a, sizeof *run, cmp_corner);
        for (size_t x = 0; rc == HD_OK && x < b - a;) {
            size_t y = x + 1;
            while (y < b - a && memcmp(run[x].xyz, run[y].xyz, sizeof run[x].xyz) == 0) y++;
            rep[ids] = run[x].vertex;
            for (size_t k = x; k < y; k++) id[run[k].slot] = ids;
            ids++;
            x = y;
        }
        a = b;
    }
    free(key), free(tmp), free(run);
    *n_ids = ids;
    return rc;
}

typedef struct {
    size_t hi;  /* the other vertex id, above the bucket's */
    size_t tri;
    int dir;    /* +1: used from the bucket's vertex to hi */
} edge_t;

static int cmp_edge(const void *x, const void *y) {
    const edge_t *a = x, *b = y;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return (a->tri > b->tri) - (a->tri < b->tri);
}

/* An unbalanced edge e[0 .. n) between ids lo and e->hi named in the error. */
static int open_edge(const edge_t *e, size_t n, size_t lo, const uint64_t *rep, hd_error_t *err) {
    size_t fwd = 0, back = 0, tf = SIZE_MAX, tb = SIZE_MAX;
    for (size_t k = 0; k < n; k++) {
        if (e[k].dir > 0) fwd++, tf = tf == SIZE_MAX ? e[k].tri : tf;
        else back++, tb = tb == SIZE_MAX ? e[k].tri : tb;
    }
    unsigned long long u = rep[lo], v = rep[e->hi]; /* dir > 0: used from u to v */
    if (n == 1)
        return hd__err(err, HD_EINVAL,
                       "mesh is not closed: the edge between vertices %llu and %llu is used by triangle %zu "
                       "alone (a boundary); a signed distance needs a closed, consistently oriented mesh",
                       u < v ? u : v, u < v ? v : u, e->tri);
    if (fwd == 0 || back == 0)
        return hd__err(err, HD_EINVAL,
                       "mesh is not consistently oriented: triangles %zu and %zu both use the edge from "
                       "vertex %llu to vertex %llu (a flipped face?); a signed distance needs a closed, "
                       "consistently oriented mesh",
                       e[0].tri, e[1].tri, fwd ? u : v, fwd ? v : u);
    return hd__err(err, HD_EINVAL,
                   "mesh is not closed: the edge between vertices %llu and %llu is used %zu times from %llu "
                   "and %zu times from %llu (triangles %zu and %zu among them); a signed distance needs "
                   "every edge used as often each way",
                   u, v, fwd, u, back, v, tf, tb);
}

/* Every edge balanced: the edges are put in buckets by their lower vertex
 * id (a counting sort), each bucket sorted by the other id and triangle,
 * and each run of one edge summed.  The first unbalanced edge in that
 * order is named. */
static int balanced(const size_t *id, size_t n, size_t ids, const uint64_t *rep, hd_error_t *err) {
    size_t *start = hd__calloc_array(ids + 1, sizeof *start);
    edge_t *e = hd__malloc_array(3 * n, sizeof *e);
    int rc = start && e ? HD_OK : HD_ENOMEM;
    for (int pass = 0; rc == HD_OK && pass < 2; pass++) {
        for (size_t k = 0; k < n; k++) {
            const size_t *f = id + 3 * k;
            if (f[0] == f[1] || f[1] == f[2] || f[2] == f[0]) continue; /* no area, no edge */
            for (int j = 0; j < 3; j++) {
                size_t u = f[j], v = f[(j + 1) % 3], lo = u < v ? u : v;
                if (pass == 0) start[lo + 1]++;
                else e[start[lo]++] = (edge_t){u < v ? v : u, k, u < v ? 1 : -1};
            }
        }
        if (pass == 0)
            for (size_t x = 0; x < ids; x++) start[x + 1] += start[x];
        else
            for (size_t x = ids; x > 0; x--) start[x] = start[x - 1]; /* back to the bucket starts */
        if (pass == 1) start[0] = 0;
    }
    for (size_t lo = 0; rc == HD_OK && lo < ids; lo++) {
        edge_t *b = e + start[lo];
        size_t nb = start[lo + 1] - start[lo];
        qsort(b, nb, sizeof *b, cmp_edge);
        for (size_t x = 0; rc == HD_OK && x < nb;) {
            size_t y = x;
            long sum = 0;
            while (y < nb && b[y].hi == b[x].hi) sum += b[y++].dir;
            if (sum != 0) rc = open_edge(b + x, y - x, lo, rep, err);
            x = y;
        }
    }
    if (rc == HD_ENOMEM) hd__err(err, rc, "mesh: out of memory checking the edges of %zu triangles", n);
    free(start), free(e);
    return rc;
}

static int check_closed(const hd__wtri_t *t, size_t n, hd_error_t *err) {
    size_t *id = hd__malloc_array(3 * n, sizeof *id), ids = 0;
    uint64_t *rep = hd__malloc_array(3 * n, sizeof *rep);
    int rc = id && rep ? vertex_ids(t, n, id, rep, &ids) : HD_ENOMEM;
    if (rc == HD_OK) rc = balanced(id, n, ids, rep, err);
    else hd__err(err, rc, "mesh: out of memory merging the corners of %zu triangles", n);
    free(id), free(rep);
    return rc;
}

/* ---- the entry points ---------------------------------------------------- */

int hd__solid_build(hd__solid_t **out, const hd__wtri_t *t, size_t n, hd_error_t *err) {
    *out = NULL;
    if (n > UINT32_MAX / 3) /* corners are numbered in 32 bits */
        return hd__err(err, HD_EOVERFLOW, "mesh: %zu triangles, more than the %u a signed distance takes", n,
                       (unsigned)(UINT32_MAX / 3));
    int rc = check_closed(t, n, err);
    if (rc) return rc;
    struct hd__solid *S = calloc(1, sizeof *S);
    if (S) S->tris = hd__malloc_array(n ? n : 1, sizeof *S->tris);
    if (S && S->tris) S->nodes = hd__malloc_array(n ? 2 * n : 1, sizeof *S->nodes);
    if (!S || !S->tris || !S->nodes) {
        hd__solid_free(S);
        return hd__err(err, HD_ENOMEM, "mesh: out of memory for the winding tree of %zu triangles", n);
    }
    for (size_t k = 0; k < n; k++) { /* triangles whose plane holds the ray's direction never count */
        int s = orient2(t[k].v[0], t[k].v[1], t[k].v[2]);
        if (!s) continue;
        memcpy(S->tris[S->n_tris].v, t[k].v, sizeof t[k].v);
        S->tris[S->n_tris++].s = s;
    }
    if (S->n_tris) build_node(S, 0, S->n_tris);
    *out = S;
    return HD_OK;
}

void hd__solid_free(hd__solid_t *s) {
    if (!s) return;
    free(s->tris);
    free(s->nodes);
    free(s);
}

/* What triangle t adds to the crossing count; *on = 1 when p is on it. */
static int crossing(const rtri_t *t, const double *p, int *on) {
    const double *a = t->v[0], *b = t->v[1], *c = t->v[2];
    if (orient2_moved(a, b, p) != t->s || orient2_moved(b, c, p) != t->s || orient2_moved(c, a, p) != t->s)
        return 0;
    int o = orient3(a, b, c, p);
    if (o == 0) *on = 1;
    return o == -t->s ? t->s : 0;
}

long hd__solid_winding(const hd__solid_t *S, const double p[3], int *on_surface) {
    *on_surface = 0;
    if (!S->n_tris) return 0;
    uint32_t stack[64];
    int top = 0;
    long w = 0;
    stack[top++] = 0;
    while (top) {
        const rnode_t *nd = &S->nodes[stack[--top]];
        if (p[1] < nd->lo[0] || p[1] > nd->hi[0] || p[2] < nd->lo[1] || p[2] > nd->hi[1] || !(p[0] < nd->xmax))
            continue;
        if (nd->count) {
            for (uint32_t k = 0; k < nd->count; k++) w += crossing(&S->tris[nd->first_or_second + k], p, on_surface);
            continue;
        }
        stack[top++] = nd->first_or_second;
        stack[top++] = (uint32_t)(nd - S->nodes) + 1;
    }
    return w;
}
