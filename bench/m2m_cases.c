/*
 * m2m_cases -- writes the mesh pairs of the surface-to-surface benchmark
 * (bench/m2m_bench.py, docs/benchmarks.md "Surface to surface") as OFF
 * files, from the bundled models in data/orig/, without network.
 *
 *   m2m_cases DATA_DIR OUT_DIR [--quick]
 *
 * Writes OUT_DIR/NAME_a.off and OUT_DIR/NAME_b.off per case and the list
 * OUT_DIR/cases.tsv (name, A, B, triangles of A and B, what the case is).
 * The cases:
 *  - decimated:  a model against its vertex-clustering decimation (about a
 *                tenth of its triangles);
 *  - subdivided: a model subdivided twice (Loop) against it subdivided once
 *                (four times fewer triangles, the same limit surface);
 *  - nearzero:   a model against a remeshed copy (every triangle split in
 *                four at its edge midpoints) whose vertices are moved by
 *                up to 1e-7 of the bounding-box diagonal (Kang's hard case:
 *                a distance near zero);
 *  - through:    a model against a copy turned by 15 degrees about the
 *                vertical axis through its centre and moved by 5 % of the
 *                diagonal (Tang's benchmark: the two pass through each
 *                other);
 *  - degenerate: a model and its decimation, both with added zero-area
 *                faces: repeated indices (a, a, b) and (a, a, a), and
 *                exactly collinear corners (new vertices a, a + d e_x,
 *                a + 2d e_x, the first coinciding with a under another
 *                index);
 *  - shared:     the CGAL lion head against the lion (every lion face is
 *                in the head: faces shared by both meshes).
 * --quick uses smaller models.  Everything is seeded; the files are the
 * same on every run.
 */
#include <hausdorff.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    double *v;
    uint64_t *t;
    size_t nv, nt;
} mesh_t;

static void *xmalloc(size_t n) {
    void *p = malloc(n ? n : 1);
    if (!p) {
        fprintf(stderr, "m2m_cases: out of memory\n");
        exit(3);
    }
    return p;
}

static uint64_t rng_state;
static double unit(void) {
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return (double)((z ^ (z >> 31)) >> 11) * 0x1p-53;
}

static mesh_t load(const char *dir, const char *name) {
    char path[4096];
    snprintf(path, sizeof path, "%s/orig/%s", dir, name);
    hd_mesh_file_t *f;
    hd_error_t err;
    if (hd_read_mesh(path, NULL, &f, &err)) {
        fprintf(stderr, "m2m_cases: %s\n", err.message);
        exit(1);
    }
    mesh_t m = {xmalloc(3 * f->n_vertices * sizeof(double)), xmalloc(3 * f->n_triangles * sizeof(uint64_t)),
                f->n_vertices, f->n_triangles};
    memcpy(m.v, f->vertices, 3 * m.nv * sizeof(double));
    memcpy(m.t, f->triangles, 3 * m.nt * sizeof(uint64_t));
    hd_mesh_file_free(f);
    return m;
}

static mesh_t copy(const mesh_t *m) {
    mesh_t c = {xmalloc(3 * m->nv * sizeof(double)), xmalloc(3 * m->nt * sizeof(uint64_t)), m->nv, m->nt};
    memcpy(c.v, m->v, 3 * m->nv * sizeof(double));
    memcpy(c.t, m->t, 3 * m->nt * sizeof(uint64_t));
    return c;
}

static void release(mesh_t *m) {
    free(m->v), free(m->t);
    m->v = NULL, m->t = NULL;
}

static void box(const mesh_t *m, double lo[3], double hi[3]) {
    for (int c = 0; c < 3; c++) lo[c] = INFINITY, hi[c] = -INFINITY;
    for (size_t i = 0; i < m->nv; i++)
        for (int c = 0; c < 3; c++) lo[c] = fmin(lo[c], m->v[3 * i + c]), hi[c] = fmax(hi[c], m->v[3 * i + c]);
}

static double diagonal(const mesh_t *m) {
    double lo[3], hi[3];
    box(m, lo, hi);
    return sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

/* ---- edges: each triangle side once, with its faces ---- */
typedef struct {
    uint64_t key; /* min * nv + max */
    size_t face;
    int side;     /* side s joins corners s and s + 1 */
} half_t;

static int cmp_half(const void *x, const void *y) {
    const half_t *a = x, *b = y;
    if (a->key != b->key) return a->key < b->key ? -1 : 1;
    return (a->face > b->face) - (a->face < b->face);
}

typedef struct {
    size_t n;            /* distinct edges */
    uint64_t (*ends)[2]; /* their corners */
    uint64_t (*opp)[2];  /* the corners opposite, on the first two faces */
    int *faces;          /* faces on the edge */
    size_t *of_side;     /* edge of side s of face k: of_side[3k + s] */
} edges_t;

static edges_t edges_of(const mesh_t *m) {
    half_t *h = xmalloc(3 * m->nt * sizeof *h);
    for (size_t k = 0; k < m->nt; k++)
        for (int s = 0; s < 3; s++) {
            uint64_t a = m->t[3 * k + s], b = m->t[3 * k + (s + 1) % 3];
            uint64_t lo = a < b ? a : b, hi = a < b ? b : a;
            h[3 * k + s] = (half_t){lo * m->nv + hi, k, s};
        }
    qsort(h, 3 * m->nt, sizeof *h, cmp_half);
    edges_t e = {0, xmalloc(3 * m->nt * sizeof *e.ends), xmalloc(3 * m->nt * sizeof *e.opp),
                 xmalloc(3 * m->nt * sizeof *e.faces), xmalloc(3 * m->nt * sizeof *e.of_side)};
    for (size_t i = 0; i < 3 * m->nt; i++) {
        if (i == 0 || h[i].key != h[i - 1].key) {
            e.ends[e.n][0] = h[i].key / m->nv, e.ends[e.n][1] = h[i].key % m->nv;
            e.faces[e.n++] = 0;
        }
        size_t id = e.n - 1;
        if (e.faces[id] < 2) e.opp[id][e.faces[id]] = m->t[3 * h[i].face + (h[i].side + 2) % 3];
        e.faces[id]++;
        e.of_side[3 * h[i].face + h[i].side] = id;
    }
    free(h);
    return e;
}

static void edges_free(edges_t *e) {
    free(e->ends), free(e->opp), free(e->faces), free(e->of_side);
}

/* Every triangle split in four at new edge vertices.  loop = 0: the
 * vertices stay and the new ones are the edge midpoints (the same surface
 * up to the midpoints' rounding); loop = 1: Loop's rules (Warren's weights)
 * on interior vertices and edges, boundary and non-manifold ones kept or
 * halved. */
static mesh_t split(const mesh_t *m, int loop) {
    edges_t e = edges_of(m);
    mesh_t s = {xmalloc(3 * (m->nv + e.n) * sizeof(double)), xmalloc(12 * m->nt * sizeof(uint64_t)),
                m->nv + e.n, 4 * m->nt};
    memcpy(s.v, m->v, 3 * m->nv * sizeof(double));
    if (loop) {
        double *sum = calloc(3 * m->nv, sizeof *sum);
        int *valence = calloc(m->nv, sizeof *valence);
        char *border = calloc(m->nv, 1);
        if (!sum || !valence || !border) exit(3);
        for (size_t i = 0; i < e.n; i++) {
            uint64_t a = e.ends[i][0], b = e.ends[i][1];
            for (int c = 0; c < 3; c++) sum[3 * a + c] += m->v[3 * b + c], sum[3 * b + c] += m->v[3 * a + c];
            valence[a]++, valence[b]++;
            if (e.faces[i] != 2) border[a] = border[b] = 1;
        }
        for (size_t i = 0; i < m->nv; i++) {
            if (border[i] || valence[i] < 3) continue;
            double n = valence[i], beta = valence[i] == 3 ? 3.0 / 16 : 3.0 / (8 * n);
            for (int c = 0; c < 3; c++) s.v[3 * i + c] = (1 - n * beta) * m->v[3 * i + c] + beta * sum[3 * i + c];
        }
        free(sum), free(valence), free(border);
    }
    for (size_t i = 0; i < e.n; i++) {
        const double *a = m->v + 3 * e.ends[i][0], *b = m->v + 3 * e.ends[i][1];
        double *p = s.v + 3 * (m->nv + i);
        if (loop && e.faces[i] == 2) {
            const double *c = m->v + 3 * e.opp[i][0], *d = m->v + 3 * e.opp[i][1];
            for (int k = 0; k < 3; k++) p[k] = 0.375 * (a[k] + b[k]) + 0.125 * (c[k] + d[k]);
        } else {
            for (int k = 0; k < 3; k++) p[k] = 0.5 * (a[k] + b[k]);
        }
    }
    for (size_t k = 0; k < m->nt; k++) {
        const uint64_t *f = m->t + 3 * k;
        uint64_t m0 = m->nv + e.of_side[3 * k], m1 = m->nv + e.of_side[3 * k + 1],
                 m2 = m->nv + e.of_side[3 * k + 2];
        uint64_t q[12] = {f[0], m0, m2, m0, f[1], m1, m2, m1, f[2], m0, m1, m2};
        memcpy(s.t + 12 * k, q, sizeof q);
    }
    edges_free(&e);
    return s;
}

/* ---- vertex clustering ---- */
typedef struct {
    uint64_t key;
    size_t i;
} keyed_t;

static int cmp_keyed(const void *x, const void *y) {
    const keyed_t *a = x, *b = y;
    if (a->key != b->key) return a->key < b->key ? -1 : 1;
    return (a->i > b->i) - (a->i < b->i);
}

static int cmp_tri(const void *x, const void *y) {
    const uint64_t *a = x, *b = y;
    for (int c = 0; c < 3; c++)
        if (a[c] != b[c]) return a[c] < b[c] ? -1 : 1;
    return 0;
}

static int cmp_tri4(const void *x, const void *y) {
    const uint64_t *a = x, *b = y;
    int r = cmp_tri(a, b);
    return r ? r : (a[3] > b[3]) - (a[3] < b[3]);
}

/* The vertices in each cube of side `cell` of a grid over the box merged
 * into their mean; triangles that lose a corner dropped, as are repeats of
 * a triangle (the same corners in any order). */
static mesh_t cluster(const mesh_t *m, double cell) {
    double lo[3], hi[3];
    box(m, lo, hi);
    uint64_t dim[3];
    for (int c = 0; c < 3; c++) dim[c] = (uint64_t)((hi[c] - lo[c]) / cell) + 1;
    keyed_t *kv = xmalloc(m->nv * sizeof *kv);
    for (size_t i = 0; i < m->nv; i++) {
        uint64_t g[3];
        for (int c = 0; c < 3; c++) {
            g[c] = (uint64_t)((m->v[3 * i + c] - lo[c]) / cell);
            if (g[c] >= dim[c]) g[c] = dim[c] - 1;
        }
        kv[i] = (keyed_t){g[0] + dim[0] * (g[1] + dim[1] * g[2]), i};
    }
    qsort(kv, m->nv, sizeof *kv, cmp_keyed);
    uint64_t *rep = xmalloc(m->nv * sizeof *rep);
    mesh_t d = {xmalloc(3 * m->nv * sizeof(double)), xmalloc(3 * m->nt * sizeof(uint64_t)), 0, 0};
    for (size_t j = 0; j < m->nv;) {
        size_t k = j;
        double s[3] = {0, 0, 0};
        for (; k < m->nv && kv[k].key == kv[j].key; k++) {
            rep[kv[k].i] = d.nv;
            for (int c = 0; c < 3; c++) s[c] += m->v[3 * kv[k].i + c];
        }
        for (int c = 0; c < 3; c++) d.v[3 * d.nv + c] = s[c] / (double)(k - j);
        d.nv++;
        j = k;
    }
    uint64_t *sorted = xmalloc(3 * m->nt * sizeof *sorted);
    size_t ns = 0;
    for (size_t k = 0; k < m->nt; k++) {
        uint64_t a = rep[m->t[3 * k]], b = rep[m->t[3 * k + 1]], c = rep[m->t[3 * k + 2]];
        if (a == b || b == c || a == c) continue;
        uint64_t x[3] = {a, b, c};
        for (int p = 0; p < 2; p++)
            for (int q = 0; q < 2 - p; q++)
                if (x[q] > x[q + 1]) {
                    uint64_t t = x[q];
                    x[q] = x[q + 1], x[q + 1] = t;
                }
        memcpy(sorted + 3 * ns, x, sizeof x);
        memcpy(d.t + 3 * ns, (uint64_t[3]){a, b, c}, 3 * sizeof(uint64_t));
        ns++;
    }
    /* Repeats: the first of each set of corners is kept ((corners, index)
     * tuples sorted, so the result does not depend on qsort's order). */
    uint64_t *tup = xmalloc(4 * (ns ? ns : 1) * sizeof *tup);
    for (size_t k = 0; k < ns; k++) memcpy(tup + 4 * k, sorted + 3 * k, 3 * sizeof(uint64_t)), tup[4 * k + 3] = k;
    qsort(tup, ns, 4 * sizeof(uint64_t), cmp_tri4);
    char *keep = calloc(ns ? ns : 1, 1);
    if (!keep) exit(3);
    for (size_t k = 0; k < ns; k++)
        if (k == 0 || cmp_tri(tup + 4 * k, tup + 4 * (k - 1))) keep[tup[4 * k + 3]] = 1;
    for (size_t k = 0; k < ns; k++)
        if (keep[k]) memmove(d.t + 3 * d.nt++, d.t + 3 * k, 3 * sizeof(uint64_t));
    free(tup), free(keep);
    free(sorted), free(kv), free(rep);
    return d;
}

/* The clustering whose triangle count is nearest `target` among a
 * bisection's tries on the cell size. */
static mesh_t decimate(const mesh_t *m, size_t target) {
    double lo = diagonal(m) * 1e-4, hi = diagonal(m) * 0.5;
    mesh_t best = {0};
    double best_gap = INFINITY;
    for (int it = 0; it < 30 && best_gap > 0.01 * (double)target; it++) {
        double cell = sqrt(lo * hi);
        mesh_t d = cluster(m, cell);
        if (d.nt > target) lo = cell; /* cells too small: too many triangles */
        else hi = cell;
        double gap = fabs((double)d.nt - (double)target);
        if (gap < best_gap) {
            release(&best);
            best = d, best_gap = gap;
        } else {
            release(&d);
        }
    }
    return best;
}

/* Every vertex moved by a uniform offset in [-amp, amp] per coordinate. */
static void perturb(mesh_t *m, double amp) {
    for (size_t i = 0; i < 3 * m->nv; i++) m->v[i] += amp * (2 * unit() - 1);
}

/* Turned by `degrees` about the z axis through the box's centre, then moved
 * by `shift` in every coordinate. */
static void move(mesh_t *m, double degrees, double shift) {
    double lo[3], hi[3], c[3];
    box(m, lo, hi);
    for (int k = 0; k < 3; k++) c[k] = (lo[k] + hi[k]) / 2;
    double a = degrees * 3.14159265358979323846 / 180, cs = cos(a), sn = sin(a);
    for (size_t i = 0; i < m->nv; i++) {
        double *p = m->v + 3 * i, x = p[0] - c[0], y = p[1] - c[1];
        p[0] = c[0] + cs * x - sn * y + shift;
        p[1] = c[1] + sn * x + cs * y + shift;
        p[2] += shift;
    }
}

/* `count` zero-area faces of each kind added after the others: (a, a, b)
 * on a side (a, b) of a random face; (b, b, b); (a, a', b) with a new
 * vertex a' at a's coordinates; and three new vertices q, q + d e_x,
 * q + 2d e_x, q next to a, exactly collinear (d is a power of two and q's
 * x a multiple of it, so the sums are exact). */
static void add_degenerate(mesh_t *m, size_t count) {
    size_t nv = m->nv + 4 * count, nt = m->nt + 4 * count;
    m->v = realloc(m->v, 3 * nv * sizeof(double));
    m->t = realloc(m->t, 3 * nt * sizeof(uint64_t));
    if (!m->v || !m->t) exit(3);
    double d = exp2(floor(log2(diagonal(m) * 1e-3)));
    for (size_t k = 0; k < count; k++) {
        size_t f = (size_t)(unit() * (double)m->nt) % m->nt;
        uint64_t a = m->t[3 * f], b = m->t[3 * f + 1], n = m->nv;
        double *p = m->v + 3 * n;
        for (int c = 0; c < 3; c++) p[c] = p[3 + c] = p[6 + c] = p[9 + c] = m->v[3 * a + c];
        p[3] = nearbyint(p[3] / d) * d, p[6] = p[3] + d, p[9] = p[3] + 2 * d;
        uint64_t faces[12] = {a, a, b, b, b, b, a, n, b, n + 1, n + 2, n + 3};
        memcpy(m->t + 3 * m->nt, faces, sizeof faces);
        m->nv += 4, m->nt += 4;
    }
}

static void write_off(const char *dir, const char *name, const char *side, const mesh_t *m, char *path,
                      size_t size) {
    snprintf(path, size, "%s/%s_%s.off", dir, name, side);
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        exit(1);
    }
    fprintf(f, "OFF\n%zu %zu 0\n", m->nv, m->nt);
    for (size_t i = 0; i < m->nv; i++) fprintf(f, "%.17g %.17g %.17g\n", m->v[3 * i], m->v[3 * i + 1], m->v[3 * i + 2]);
    for (size_t k = 0; k < m->nt; k++)
        fprintf(f, "3 %llu %llu %llu\n", (unsigned long long)m->t[3 * k], (unsigned long long)m->t[3 * k + 1],
                (unsigned long long)m->t[3 * k + 2]);
    if (fclose(f)) {
        perror(path);
        exit(1);
    }
}

static FILE *list;
static const char *out_dir;

/* Writes the pair and its line in cases.tsv; frees both meshes. */
static void emit(const char *name, mesh_t *a, mesh_t *b, const char *what) {
    char pa[4096], pb[4096];
    write_off(out_dir, name, "a", a, pa, sizeof pa);
    write_off(out_dir, name, "b", b, pb, sizeof pb);
    fprintf(list, "%s\t%s\t%s\t%zu\t%zu\t%s\n", name, pa, pb, a->nt, b->nt, what);
    printf("%-11s %8zu against %8zu triangles: %s\n", name, a->nt, b->nt, what);
    release(a), release(b);
}

int main(int argc, char **argv) {
    if (argc < 3 || (argc > 3 && strcmp(argv[3], "--quick"))) {
        fprintf(stderr, "usage: m2m_cases DATA_DIR OUT_DIR [--quick]\n");
        return 2;
    }
    const char *data = argv[1];
    int quick = argc > 3;
    out_dir = argv[2];
    char path[4096];
    snprintf(path, sizeof path, "%s/cases.tsv", out_dir);
    list = fopen(path, "w");
    if (!list) {
        perror(path);
        return 1;
    }
    rng_state = 38;

    mesh_t arma = load(data, "armadillo.off"), cow = load(data, "cow.off");
    mesh_t a, b;
    if (quick) {
        a = copy(&arma), b = decimate(&arma, arma.nt / 10);
    } else {
        a = split(&arma, 1), b = decimate(&arma, arma.nt * 4 / 10);
    }
    emit("decimated", &a, &b, "a model against its vertex-clustering decimation");

    mesh_t base = quick ? copy(&cow) : copy(&arma), once = split(&base, 1);
    a = split(&once, 1), b = once;
    release(&base);
    emit("subdivided", &a, &b, "Loop-subdivided twice against once");

    mesh_t fan = load(data, quick ? "cow.off" : "fandisk_large.off");
    a = copy(&fan), b = split(&fan, 0);
    perturb(&b, 1e-7 * diagonal(&fan));
    release(&fan);
    emit("nearzero", &a, &b, "a model against a remeshed copy moved by up to 1e-7 of the diagonal");

    mesh_t head = load(data, "lion-head.off");
    a = copy(quick ? &head : &arma), b = copy(&a);
    move(&b, 15, 0.05 * diagonal(&a) / sqrt(3));
    emit("through", &a, &b, "a model against a turned and moved copy passing through it");

    mesh_t small = quick ? load(data, "pinion.off") : copy(&cow);
    a = copy(&small), b = decimate(&small, small.nt / 4);
    add_degenerate(&a, a.nt / 50 + 1), add_degenerate(&b, b.nt / 50 + 1);
    release(&small);
    emit("degenerate", &a, &b, "a model and its decimation, both with zero-area faces");

    a = head, b = load(data, "lion.off");
    emit("shared", &a, &b, "the lion head against the lion (shared faces)");

    release(&arma), release(&cow);
    return fclose(list) ? 1 : 0;
}
