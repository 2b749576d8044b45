/*
 * render.c -- pictures for a report, drawn in memory and written as PNG
 * (libpng), so that no display, GPU or plotting library is needed.
 *
 * render_distances draws A three times, in orthographic views from +z
 * ("front"), from +x ("side") and from +y ("top"), all at one scale so that
 * lengths compare across views.  Each point of A is a small square splat
 * coloured by its distance to B (viridis, clipped at the scale's top) and
 * shaded slightly darker with depth; a depth buffer per view keeps the
 * nearest splat.  Points at a quarter of the colour scale or more are then
 * drawn again over everything, in increasing order of distance, so that no
 * deviation hides behind the surface in front of it.  B is drawn in light grey only where no point of A covers
 * the pixel, which shows where B reaches beyond A.  The witness pair of the
 * Hausdorff distance (the farthest point and its nearest point in the other
 * set) is drawn on top in every view: a red dot in a white ring for the
 * point that realises the distance, an orange one for its nearest point, a
 * line between them, and labels with their indices.  A colour bar with
 * ticks and a title line with the distance complete the picture.  The
 * markers' pixel positions are returned so that a test can look at them.
 *
 * render_histogram draws the per-point distance histograms (A->B and B->A
 * side by side in each bin) with the percentile and the means marked.
 *
 * Built without libpng, both refuse with a message that says so.
 *
 * A picture is written through output.c (write_png): into a temporary
 * beside its name, every write checked, renamed into place only when the
 * whole run succeeds; a failure removes it and the run exits with 3.
 */
#include "analysis.h"
#include "cli.h"
#include "output.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <strings.h>

int render_path_ok(const char *path) {
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    const char *dot = strrchr(base, '.');
    return !dot || dot == base || strcasecmp(dot, ".png") == 0;
}

#ifdef HD_HAVE_PNG
#include <png.h>

int render_available(void) { return 1; }

/* ---- a canvas ---------------------------------------------------------------- */

typedef struct {
    int w, h;
    unsigned char *rgb;
} canvas_t;

static const unsigned char WHITE[3] = {255, 255, 255}, BLACK[3] = {0, 0, 0}, GREY[3] = {205, 205, 205},
                           FRAME[3] = {170, 170, 170}, DARK[3] = {60, 60, 60}, RED[3] = {255, 0, 0},
                           ORANGE[3] = {255, 140, 0}, BLUE[3] = {49, 104, 142}, AMBER[3] = {230, 150, 30};

static int no_memory(hd_error_t *err) {
    snprintf(err->message, sizeof err->message, "out of memory for the picture");
    return err->code = HD_ENOMEM;
}

static int canvas_init(canvas_t *c, int w, int h) {
    c->w = w;
    c->h = h;
    c->rgb = malloc((size_t)w * (size_t)h * 3);
    if (!c->rgb) return -1;
    memset(c->rgb, 255, (size_t)w * (size_t)h * 3);
    return 0;
}

static void put(canvas_t *c, int x, int y, const unsigned char col[3]) {
    if (x < 0 || y < 0 || x >= c->w || y >= c->h) return;
    memcpy(c->rgb + 3 * ((size_t)y * (size_t)c->w + (size_t)x), col, 3);
}

static void fill_rect(canvas_t *c, int x0, int y0, int x1, int y1, const unsigned char col[3]) {
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) put(c, x, y, col);
}

static void frame_rect(canvas_t *c, int x0, int y0, int x1, int y1, const unsigned char col[3]) {
    for (int x = x0; x < x1; x++) put(c, x, y0, col), put(c, x, y1 - 1, col);
    for (int y = y0; y < y1; y++) put(c, x0, y, col), put(c, x1 - 1, y, col);
}

/* Pixels whose centre lies within [r0, r1] of (x, y). */
static void ring(canvas_t *c, int x, int y, double r0, double r1, const unsigned char col[3]) {
    int R = (int)ceil(r1);
    for (int dy = -R; dy <= R; dy++)
        for (int dx = -R; dx <= R; dx++) {
            double d = sqrt((double)(dx * dx + dy * dy));
            if (d >= r0 && d <= r1) put(c, x + dx, y + dy, col);
        }
}

static void line(canvas_t *c, int x0, int y0, int x1, int y1, int thick, const unsigned char col[3]) {
    int n = abs(x1 - x0) > abs(y1 - y0) ? abs(x1 - x0) : abs(y1 - y0);
    for (int k = 0; k <= n; k++) {
        double t = n ? (double)k / n : 0.0;
        int x = (int)lround(x0 + (x1 - x0) * t), y = (int)lround(y0 + (y1 - y0) * t);
        for (int dy = 0; dy < thick; dy++)
            for (int dx = 0; dx < thick; dx++) put(c, x + dx - thick / 2, y + dy - thick / 2, col);
    }
}

static void text(canvas_t *c, int x, int y, int scale, const char *s, const unsigned char col[3]) {
    font_draw(c->rgb, c->w, c->h, x, y, scale, s, col);
}

/* Text with a one-pixel white halo, readable over points. */
static void label(canvas_t *c, int x, int y, int scale, const char *s, const unsigned char col[3]) {
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++)
            if (dx || dy) text(c, x + dx, y + dy, scale, s, WHITE);
    text(c, x, y, scale, s, col);
}

/* libpng's errors: the errno of the write that failed (libpng's own
 * write function calls png_error after a short fwrite), kept for the
 * message, and a jump back to write_png -- never libpng's default
 * handler, which would print to stderr. */
typedef struct {
    int werr;
} png_failure_t;

static void png_fail(png_structp png, png_const_charp msg) {
    png_failure_t *pf = png_get_error_ptr(png);
    (void)msg;
    if (!pf->werr) pf->werr = errno ? errno : -1; /* -1: reason unknown */
    png_longjmp(png, 1);
}

static void png_warn(png_structp png, png_const_charp msg) { (void)png, (void)msg; }

/* Through output.c: a temporary, renamed into place only when the run
 * succeeds; any failure removes it and is an output failure (exit 3). */
static int write_png(const char *path, const canvas_t *c, hd_error_t *err) {
    FILE *f = out_open(path, err);
    if (!f) return err->code;
    static png_failure_t pf; /* static: untouched by the longjmp */
    memset(&pf, 0, sizeof pf);
    errno = 0;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &pf, png_fail, png_warn);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        if (!pf.werr) pf.werr = ENOMEM; /* no struct: libpng could not allocate */
        return out_close(f, pf.werr, err);
    }
    png_init_io(png, f);
    /* unfiltered rows: the pictures are mostly flat colour, which deflate
     * packs well anyway, and any reader decodes them trivially */
    png_set_filter(png, 0, PNG_FILTER_NONE);
    png_set_IHDR(png, info, (png_uint_32)c->w, (png_uint_32)c->h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_text meta;
    memset(&meta, 0, sizeof meta);
    meta.compression = PNG_TEXT_COMPRESSION_NONE;
    meta.key = (png_charp) "Software";
    meta.text = (png_charp) "hausdorff";
    png_set_text(png, info, &meta, 1);
    png_write_info(png, info);
    for (int y = 0; y < c->h; y++) png_write_row(png, c->rgb + 3 * (size_t)y * (size_t)c->w);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return out_close(f, 0, err);
}

static void fmt_num(char *buf, size_t size, double v) { snprintf(buf, size, "%.4g", v); }

/* ---- the three views ------------------------------------------------------------- */

enum { PANEL = RENDER_PANEL, GAP = 24, TOP = 92, BOTTOM = 44, BAR_W = 26, BAR_LABELS = 110 };

/* Screen axes and depth of each view: u right, v up, depth towards the eye. */
static void project(int view, const double p[3], double *u, double *v, double *depth) {
    if (view == 0) { /* from +z */
        *u = p[0], *v = p[1], *depth = p[2];
    } else if (view == 1) { /* from +x */
        *u = -p[2], *v = p[1], *depth = p[0];
    } else { /* from +y */
        *u = p[0], *v = -p[2], *depth = p[1];
    }
}

typedef struct {
    double u0, v0, s;  /* screen = (u - u0) * s + offset, centred */
    int x0, y0;        /* panel's top-left pixel */
} view_t;

static void to_pixel(const view_t *vw, int view, const double p[3], int *x, int *y, double *depth) {
    double u, v, d;
    project(view, p, &u, &v, &d);
    *x = vw->x0 + PANEL / 2 + (int)lround((u - vw->u0) * vw->s);
    *y = vw->y0 + PANEL / 2 - (int)lround((v - vw->v0) * vw->s);
    if (depth) *depth = d;
}

static void bounds(const hd_points_t *P, double lo[3], double hi[3]) {
    for (size_t k = 0; k < P->count; k++) {
        double q[3];
        hd_points_get(P, k, q);
        for (int a = 0; a < 3; a++) {
            if (q[a] < lo[a]) lo[a] = q[a];
            if (q[a] > hi[a]) hi[a] = q[a];
        }
    }
}

void render_scene_bounds(render_scene_t *sc, const hd_points_t *A, const hd_points_t *B) {
    for (int a = 0; a < 3; a++) sc->lo[a] = INFINITY, sc->hi[a] = -INFINITY;
    bounds(A, sc->lo, sc->hi);
    bounds(B, sc->lo, sc->hi);
}

/* ---- the layers: what the points leave in each pixel ------------------------------ */

int render_layers_init(render_layers_t *L) {
    L->n = 3 * (size_t)PANEL * PANEL;
    L->near = malloc(L->n * sizeof *L->near);
    L->far = malloc(L->n * sizeof *L->far);
    L->b = calloc(L->n, 1);
    if (!L->near || !L->far || !L->b) {
        render_layers_free(L);
        return -1;
    }
    for (size_t k = 0; k < L->n; k++) {
        L->near[k] = (render_px_t){UINT64_MAX, -INFINITY, 0};
        L->far[k] = (render_far_t){INFINITY, UINT64_MAX, 0, 0};
    }
    return 0;
}

void render_layers_free(render_layers_t *L) {
    free(L->near);
    free(L->far);
    free(L->b);
    L->near = NULL, L->far = NULL, L->b = NULL;
}

/* The nearest splat: the larger depth, then the smaller index (the first
 * drawn of equal depths, points being drawn in index order). */
static int near_better(const render_px_t *x, const render_px_t *y) {
    return x->depth > y->depth || (x->depth == y->depth && x->k < y->k);
}

/* The far splat drawn over the surface: the first in order of (distance,
 * index); later ones fail the depth test against its infinite depth. */
static int far_better(const render_far_t *x, const render_far_t *y) {
    return x->d < y->d || (x->d == y->d && x->k < y->k);
}

void render_near_merge(render_px_t *dst, const render_px_t *src, size_t n) {
    for (size_t k = 0; k < n; k++)
        if (near_better(&src[k], &dst[k])) dst[k] = src[k];
}

void render_far_merge(render_far_t *dst, const render_far_t *src, size_t n) {
    for (size_t k = 0; k < n; k++)
        if (far_better(&src[k], &dst[k])) dst[k] = src[k];
}

/* Where the views are, on the scene's bounds. */
typedef struct {
    view_t vw[3];
    double zlo[3], zhi[3]; /* depth range of each view, for shading */
    int r;                 /* splat radius */
} geometry_t;

static void geometry(const render_scene_t *sc, geometry_t *g) {
    double extent = 0, centre[3];
    for (int a = 0; a < 3; a++) {
        if (sc->hi[a] - sc->lo[a] > extent) extent = sc->hi[a] - sc->lo[a];
        centre[a] = sc->lo[a] + (sc->hi[a] - sc->lo[a]) / 2;
    }
    if (!(extent > 0)) extent = 1;
    double s = (PANEL - 40) / extent, u, v, dd;
    for (int view = 0; view < 3; view++) {
        project(view, sc->lo, &u, &v, &g->zlo[view]);
        project(view, sc->hi, &u, &v, &g->zhi[view]);
        project(view, centre, &u, &v, &dd);
        g->vw[view] = (view_t){u, v, s, GAP + view * (PANEL + GAP), TOP};
    }
    g->r = (int)lround(0.35 * PANEL / sqrt((double)(sc->n_a + 1)));
    if (g->r < 1) g->r = 1;
    if (g->r > 4) g->r = 4;
}

void render_splat(const render_scene_t *sc, const hd_points_t *A, size_t first, const double *d_a,
                  const hd_points_t *B, render_layers_t *L) {
    geometry_t g;
    geometry(sc, &g);
    double dmax = sc->dmax;
    for (int view = 0; view < 3; view++) {
        const view_t *vw = &g.vw[view];
        size_t base = (size_t)view * PANEL * PANEL;
        for (size_t k = 0; k < A->count; k++) {
            double q[3], depth;
            int x, y;
            hd_points_get(A, k, q);
            to_pixel(vw, view, q, &x, &y, &depth);
            unsigned char col[3];
            colormap_viridis(dmax > 0 ? d_a[k] / dmax : 0.0, col);
            double span = g.zhi[view] - g.zlo[view], shade = span > 0 ? 0.72 + 0.28 * (depth - g.zlo[view]) / span : 1.0;
            if (shade < 0.72) shade = 0.72; /* the side view's depth runs the other way */
            if (shade > 1.0) shade = 1.0;
            for (int ch = 0; ch < 3; ch++) col[ch] = (unsigned char)(col[ch] * shade + 0.5);
            uint32_t rgb = (uint32_t)col[0] << 16 | (uint32_t)col[1] << 8 | col[2];
            render_px_t me = {first + k, (float)depth, rgb};
            render_far_t fm = {d_a[k], first + k, rgb, 0};
            int is_far = dmax > 0 && d_a[k] >= 0.25 * dmax;
            for (int dy = -g.r; dy <= g.r; dy++)
                for (int dx = -g.r; dx <= g.r; dx++) {
                    int px = x + dx, py = y + dy;
                    if (px < vw->x0 || py < vw->y0 || px >= vw->x0 + PANEL || py >= vw->y0 + PANEL) continue;
                    size_t at = base + (size_t)(py - vw->y0) * PANEL + (size_t)(px - vw->x0);
                    if (near_better(&me, &L->near[at])) L->near[at] = me;
                    if (is_far && far_better(&fm, &L->far[at])) L->far[at] = fm;
                }
        }
        for (size_t k = 0; k < B->count; k++) {
            double q[3];
            int x, y;
            hd_points_get(B, k, q);
            to_pixel(vw, view, q, &x, &y, NULL);
            for (int dy = -g.r; dy <= g.r; dy++)
                for (int dx = -g.r; dx <= g.r; dx++) {
                    int px = x + dx, py = y + dy;
                    if (px < vw->x0 || py < vw->y0 || px >= vw->x0 + PANEL || py >= vw->y0 + PANEL) continue;
                    L->b[base + (size_t)(py - vw->y0) * PANEL + (size_t)(px - vw->x0)] = 1;
                }
        }
    }
}

static void unpack(uint32_t rgb, unsigned char col[3]) {
    col[0] = (unsigned char)(rgb >> 16), col[1] = (unsigned char)(rgb >> 8), col[2] = (unsigned char)rgb;
}

int render_compose(const char *path, const render_scene_t *sc, const render_layers_t *L, const double wp[3],
                   const double wq[3], const hd_symmetric_t *s, int directed, const render_notes_t *notes,
                   const char *title, render_marker_t markers[6], int *n_markers, render_info_t *info, int *width,
                   int *height, hd_error_t *err) {
    memset(info, 0, sizeof *info);
    info->pct_y = -1;
    canvas_t c = {0, 0, NULL};
    int W = GAP + 3 * (PANEL + GAP) + BAR_W + BAR_LABELS, H = TOP + PANEL + BOTTOM;
    if (canvas_init(&c, W, H)) return no_memory(err);
    double dmax = sc->dmax;
    int clipped = sc->clipped; /* some distance beyond the scale (--max-distance) */
    geometry_t g;
    geometry(sc, &g);
    /* the witness pair: the point realising H and its nearest point */
    int from_a = directed || s->ab.distance2 >= s->ba.distance2;
    const hd_result_t *w = from_a ? &s->ab : &s->ba;

    static const char *const names[3] = {"front (from +z): x right, y up", "side (from +x): -z right, y up",
                                         "top (from +y): x right, -z up"};
    *n_markers = 0;
    for (int view = 0; view < 3; view++) {
        const view_t vw = g.vw[view];
        size_t base = (size_t)view * PANEL * PANEL;
        /* every point with the depth test, then the far ones over the
         * surface (unless it lies at an infinite depth itself), then B in
         * grey where no point of A is */
        for (int py = vw.y0; py < vw.y0 + PANEL; py++)
            for (int px = vw.x0; px < vw.x0 + PANEL; px++) {
                size_t at = base + (size_t)(py - vw.y0) * PANEL + (size_t)(px - vw.x0);
                const render_px_t *n = &L->near[at];
                const render_far_t *f = &L->far[at];
                unsigned char col[3];
                if (f->k != UINT64_MAX && n->depth != INFINITY) unpack(f->rgb, col), put(&c, px, py, col);
                else if (n->depth != -INFINITY) unpack(n->rgb, col), put(&c, px, py, col);
                else if (f->k == UINT64_MAX && L->b[at]) put(&c, px, py, GREY);
            }
        frame_rect(&c, vw.x0 - 1, vw.y0 - 1, vw.x0 + PANEL + 1, vw.y0 + PANEL + 1, FRAME);
        text(&c, vw.x0, vw.y0 + PANEL + 10, 2, names[view], DARK);

        int px, py, qx, qy;
        to_pixel(&vw, view, wp, &px, &py, NULL);
        to_pixel(&vw, view, wq, &qx, &qy, NULL);
        line(&c, px, py, qx, qy, 2, RED);
        ring(&c, qx, qy, 0, 4.5, ORANGE);
        ring(&c, qx, qy, 4.5, 7.5, WHITE);
        ring(&c, px, py, 0, 5.5, RED);
        ring(&c, px, py, 5.5, 8.5, WHITE);
        ring(&c, px, py, 8.5, 9.8, RED);
        char lp[64], lq[64];
        snprintf(lp, sizeof lp, "%c[%zu]", from_a ? 'A' : 'B', w->i);
        if (notes->surface) snprintf(lq, sizeof lq, "triangle %zu", w->j);
        else snprintf(lq, sizeof lq, "%c[%zu]", from_a ? 'B' : 'A', w->j);
        int side = qx >= px ? -1 : 1; /* labels away from each other */
        int lpx = side > 0 ? px + 13 : px - 13 - 2 * font_width(lp);
        int lqx = side > 0 ? qx - 11 - 2 * font_width(lq) : qx + 11;
        label(&c, lpx, py - 9, 2, lp, RED);
        label(&c, lqx, qy - 9, 2, lq, ORANGE);
        markers[(*n_markers)++] = (render_marker_t){view, from_a ? 'A' : 'B', w->i, px, py};
        markers[(*n_markers)++] = (render_marker_t){view, from_a ? 'B' : 'A', w->j, qx, qy};
    }

    /* colour bar */
    int bx = GAP + 3 * (PANEL + GAP), by = TOP;
    for (int y = 0; y < PANEL; y++) {
        unsigned char col[3];
        colormap_viridis(1.0 - (double)y / (PANEL - 1), col);
        fill_rect(&c, bx, by + y, bx + BAR_W, by + y + 1, col);
    }
    frame_rect(&c, bx - 1, by - 1, bx + BAR_W + 1, by + PANEL + 1, DARK);
    /* the percentile of the coloured distances (A's to B) on the bar: a
     * white line with red edges across it and a red tick on each side,
     * labelled "P95" (or the P asked for) on the right; a tick label it
     * would cover is left out */
    int py = -1;
    char plabel[NUM_TEXT + 1] = "";
    if (notes->percentile_on && dmax > 0) {
        double t = notes->pct.ab / dmax;
        if (t > 1) t = 1;
        py = by + (int)lround((PANEL - 1) * (1.0 - t));
        plabel[0] = 'P';
        num_text(notes->pct.p, plabel + 1);
    }
    for (int t = 0; t <= 4; t++) {
        int y = by + (int)lround((PANEL - 1) * (1.0 - t / 4.0));
        char buf[64];
        buf[0] = '>'; /* the top colour stands for everything above */
        buf[1] = '=';
        int at = t == 4 && clipped ? 2 : 0;
        fmt_num(buf + at, sizeof buf - (size_t)at, dmax * t / 4.0);
        fill_rect(&c, bx + BAR_W, y, bx + BAR_W + 6, y + 1, DARK);
        if (py < 0 || abs(y - py) >= 22) text(&c, bx + BAR_W + 9, y - 8, 2, buf, DARK);
    }
    if (py >= 0) {
        fill_rect(&c, bx - 8, py - 2, bx + BAR_W + 8, py + 3, RED);
        fill_rect(&c, bx, py - 1, bx + BAR_W, py + 2, WHITE);
        label(&c, bx + BAR_W + 11, py - 8, 2, plabel, RED);
        info->pct_y = py;
        info->pct_x0 = bx;
        info->pct_x1 = bx + BAR_W;
    }
    if (notes->unit) snprintf(info->bar_title, sizeof info->bar_title, "distance (%.40s)", notes->unit);
    else snprintf(info->bar_title, sizeof info->bar_title, "distance");
    int tx = bx - 4;
    if (tx + 2 * font_width(info->bar_title) > W - 4) tx = W - 4 - 2 * font_width(info->bar_title);
    text(&c, tx, by - 30, 2, info->bar_title, DARK);

    /* title lines: what is drawn, H and its witnesses, the percentile */
    char hv[64];
    fmt_num(hv, sizeof hv, w->distance);
    const char *u = notes->unit ? notes->unit : "";
    snprintf(info->caption[0], sizeof info->caption[0], "%s", title);
    if (notes->surface)
        snprintf(info->caption[1], sizeof info->caption[1],
                 "h(A, surface of B) = %s%s%s between A[%zu] (red) and its closest point on triangle %zu "
                 "(orange); grey: B's vertices", hv, *u ? " " : "", u, w->i, w->j);
    else
        snprintf(info->caption[1], sizeof info->caption[1],
                 "%s = %s%s%s between %c[%zu] (red) and %c[%zu] (orange); grey: B only",
                 directed ? "h(A,B)" : "H(A,B)", hv, *u ? " " : "", u, from_a ? 'A' : 'B', w->i,
                 from_a ? 'B' : 'A', w->j);
    if (py >= 0) {
        char ab[64], sym[64], pooled[64];
        fmt_num(ab, sizeof ab, notes->pct.ab);
        fmt_num(sym, sizeof sym, notes->pct.symmetric);
        fmt_num(pooled, sizeof pooled, notes->pct.pooled);
        if (directed)
            snprintf(info->caption[2], sizeof info->caption[2], "%s: A->B %s%s%s (marked on the colour bar)",
                     plabel, ab, *u ? " " : "", u);
        else
            snprintf(info->caption[2], sizeof info->caption[2],
                     "%s: A->B %s (marked on the colour bar), symmetric (MONAI) %s, pooled (medpy) %s%s%s",
                     plabel, ab, sym, pooled, *u ? " " : "", u);
    }
    text(&c, GAP, 10, 2, info->caption[0], BLACK);
    text(&c, GAP, 34, 2, info->caption[1], DARK);
    if (info->caption[2][0]) text(&c, GAP, 58, 2, info->caption[2], DARK);

    int rc = write_png(path, &c, err);
    *width = W;
    *height = H;
    free(c.rgb);
    return rc;
}

int render_distances(const char *path, const hd_points_t *A,
                     const hd_points_t *B, const double *d_a, double dmax,
                     const hd_symmetric_t *s, const double *wq_at, int directed,
                     const render_notes_t *notes, const char *title,
                     render_marker_t markers[6], int *n_markers,
                     render_info_t *info, int *width, int *height,
                     hd_error_t *err) {
    render_scene_t sc;
    render_scene_bounds(&sc, A, B);
    sc.n_a = A->count;
    sc.dmax = dmax;
    sc.clipped = 0;
    for (size_t k = 0; k < A->count; k++) sc.clipped |= d_a[k] > dmax;
    render_layers_t L;
    if (render_layers_init(&L)) {
        memset(info, 0, sizeof *info);
        info->pct_y = -1;
        *n_markers = 0;
        return no_memory(err);
    }
    render_splat(&sc, A, 0, d_a, B, &L);
    int from_a = directed || s->ab.distance2 >= s->ba.distance2;
    const hd_result_t *w = from_a ? &s->ab : &s->ba;
    double wp[3], wq[3];
    hd_points_get(from_a ? A : B, w->i, wp);
    if (wq_at) memcpy(wq, wq_at, sizeof wq);
    else hd_points_get(from_a ? B : A, w->j, wq);
    int rc = render_compose(path, &sc, &L, wp, wq, s, directed, notes, title, markers, n_markers, info, width,
                            height, err);
    render_layers_free(&L);
    return rc;
}

/* ---- the histogram ----------------------------------------------------------------- */

int render_histogram(const char *path, const analysis_result_t *r,
                     const render_notes_t *notes, size_t bins,
                     hist_marker_t marks[4], int *n_marks, hd_error_t *err) {
    *n_marks = 0;
    enum { HW = 1000, HH = 580, L = 110, R = 30, T = 104, B = 80 };
    canvas_t c;
    if (canvas_init(&c, HW, HH)) return no_memory(err);
    int pw = HW - L - R, ph = HH - T - B;
    uint64_t top = 1;
    for (size_t k = 0; k < bins; k++) {
        if (r->hist_ab[k] > top) top = r->hist_ab[k];
        if (r->hist_ba && r->hist_ba[k] > top) top = r->hist_ba[k];
    }
    double lo = hd_histogram_edge(r->hist_lo, r->hist_hi, bins, 0);
    double hi = hd_histogram_edge(r->hist_lo, r->hist_hi, bins, bins);
    int series = r->hist_ba ? 2 : 1;
    /* A long tail (the usual case: most points agree, a few deviate) would
     * be invisible on a linear axis; then the counts go on a log axis. */
    uint64_t least = top;
    for (size_t k = 0; k < bins; k++) {
        if (r->hist_ab[k] && r->hist_ab[k] < least) least = r->hist_ab[k];
        if (r->hist_ba && r->hist_ba[k] && r->hist_ba[k] < least) least = r->hist_ba[k];
    }
    int logy = top >= 50 * least;
    for (size_t k = 0; k < bins; k++) {
        int x0 = L + (int)((double)pw * k / bins), x1 = L + (int)((double)pw * (k + 1) / bins);
        int bw = (x1 - x0 - 2) / series;
        if (bw < 1) bw = 1;
        for (int sidx = 0; sidx < series; sidx++) {
            uint64_t n = sidx ? r->hist_ba[k] : r->hist_ab[k];
            int hgt = (int)lround(logy ? (double)ph * log10(1.0 + (double)n) / log10(1.0 + (double)top)
                                       : (double)ph * (double)n / (double)top);
            int bx0 = x0 + 1 + sidx * bw;
            fill_rect(&c, bx0, T + ph - hgt, bx0 + bw, T + ph, sidx ? AMBER : BLUE);
        }
    }
    /* axes and ticks */
    fill_rect(&c, L, T + ph, L + pw, T + ph + 2, DARK);
    fill_rect(&c, L - 2, T, L, T + ph + 2, DARK);
    for (int t = 0; t <= 5; t++) {
        char buf[64];
        int x = L + (int)lround((double)pw * t / 5.0);
        fmt_num(buf, sizeof buf, lo + (hi - lo) * t / 5.0);
        fill_rect(&c, x, T + ph + 2, x + 1, T + ph + 8, DARK);
        int tx = x - font_width(buf);
        if (tx + 2 * font_width(buf) > HW - 4) tx = HW - 4 - 2 * font_width(buf);
        text(&c, tx, T + ph + 12, 2, buf, DARK);
    }
    for (double v = 0; v <= (double)top;) { /* count ticks: 0..top in fifths, or powers of ten */
        char buf[64];
        double f = logy ? log10(1.0 + v) / log10(1.0 + (double)top) : v / (double)top;
        int y = T + ph - (int)lround((double)ph * f);
        snprintf(buf, sizeof buf, "%.0f", v);
        fill_rect(&c, L - 8, y, L - 2, y + 1, DARK);
        if (!logy || v > 0) text(&c, L - 12 - 2 * font_width(buf), y - 8, 2, buf, DARK);
        if (logy) v = v == 0 ? 1 : v * 10;
        else v += (double)top / 5.0;
        if (!logy && v > (double)top + 0.5) break;
    }
    text(&c, 8, T - 26, 2, logy ? "count (log scale)" : "count", DARK);
    const char *unit = notes->unit;
    char buf[256];
    snprintf(buf, sizeof buf, "distance to the nearest point of the other set%s%s%s", unit ? " (" : "",
             unit ? unit : "", unit ? ")" : "");
    text(&c, L + pw / 2 - font_width(buf), HH - 34, 2, buf, DARK);
    /* markers: percentile (dashed) and mean (solid) per direction, in the
     * direction's colour with a dark edge on each side, so that a line stays
     * visible where it crosses a bar of its own colour (a mean usually lies
     * in the tallest bar). */
    for (int sidx = 0; sidx < series; sidx++) {
        const unsigned char *col = sidx ? AMBER : BLUE;
        double v[2] = {sidx ? r->sum.mean_ba : r->sum.mean_ab, sidx ? r->pct.ba : r->pct.ab};
        for (int kind = 0; kind < 2; kind++) {
            if ((kind == 1 && !notes->percentile_on) || !(v[kind] >= lo && v[kind] <= hi)) continue;
            int x = L + (int)lround(pw * (v[kind] - lo) / (hi - lo));
            int dash = kind ? 6 : ph, period = kind ? 12 : ph;
            for (int y = T; y < T + ph; y += period) {
                int y1 = y + dash < T + ph ? y + dash : T + ph;
                fill_rect(&c, x - 2, y, x + 2, y1, DARK);
                fill_rect(&c, x - 1, y, x + 1, y1, col);
            }
            hist_marker_t *mk = &marks[(*n_marks)++];
            *mk = (hist_marker_t){kind ? 'p' : 'm', sidx, x, T, T + ph, {col[0], col[1], col[2]}};
        }
    }
    /* legend and title */
    if (r->hist_ba)
        snprintf(buf, sizeof buf, "distances of A's %zu points to B and of B's %zu points to A", r->n_a, r->n_b);
    else
        snprintf(buf, sizeof buf, "distances of A's %zu points to B", r->n_a);
    text(&c, L, 14, 2, buf, BLACK);
    int lx = L, ly = 44;
    fill_rect(&c, lx, ly, lx + 16, ly + 14, BLUE);
    text(&c, lx + 22, ly - 1, 2, "A->B", DARK);
    lx += 22 + 2 * font_width("A->B") + 24;
    if (r->hist_ba) {
        fill_rect(&c, lx, ly, lx + 16, ly + 14, AMBER);
        text(&c, lx + 22, ly - 1, 2, "B->A", DARK);
        lx += 22 + 2 * font_width("B->A") + 24;
    }
    fill_rect(&c, lx, ly + 6, lx + 24, ly + 8, DARK);
    text(&c, lx + 30, ly - 1, 2, "mean", DARK);
    lx += 30 + 2 * font_width("mean") + 24;
    if (notes->percentile_on) {
        for (int x = 0; x < 24; x += 8) fill_rect(&c, lx + x, ly + 6, lx + x + 4, ly + 8, DARK);
        snprintf(buf, sizeof buf, "percentile %g", notes->pct.p);
        text(&c, lx + 30, ly - 1, 2, buf, DARK);
    }
    if (r->above_ab || r->above_ba) {
        snprintf(buf, sizeof buf, "beyond %.4g: %zu", hi, r->above_ab + r->above_ba);
        text(&c, L + pw - 2 * font_width(buf), 44, 2, buf, RED);
    }
    int rc = write_png(path, &c, err);
    free(c.rgb);
    return rc;
}

#else

int render_available(void) { return 0; }

static int unavailable(hd_error_t *err) {
    snprintf(err->message, sizeof err->message,
             "pictures are unavailable: this hausdorff was built without libpng (Debian: libpng-dev)");
    return err->code = HD_EUNSUPPORTED;
}

int render_distances(const char *path, const hd_points_t *A,
                     const hd_points_t *B, const double *d_a, double dmax,
                     const hd_symmetric_t *s, const double *wq_at, int directed,
                     const render_notes_t *notes, const char *title,
                     render_marker_t markers[6], int *n_markers,
                     render_info_t *info, int *width, int *height,
                     hd_error_t *err) {
    (void)path, (void)A, (void)B, (void)d_a, (void)dmax, (void)s, (void)directed, (void)notes, (void)title;
    (void)wq_at;
    (void)markers, (void)width, (void)height;
    memset(info, 0, sizeof *info);
    info->pct_y = -1;
    *n_markers = 0;
    return unavailable(err);
}

int render_histogram(const char *path, const analysis_result_t *r,
                     const render_notes_t *notes, size_t bins,
                     hist_marker_t marks[4], int *n_marks, hd_error_t *err) {
    (void)path, (void)r, (void)notes, (void)bins, (void)marks;
    *n_marks = 0;
    return unavailable(err);
}

/* The halves of render_distances: never called without libpng (the
 * options are refused first); here so that the tools link. */
void render_scene_bounds(render_scene_t *sc, const hd_points_t *A, const hd_points_t *B) {
    (void)A, (void)B;
    memset(sc, 0, sizeof *sc);
}
int render_layers_init(render_layers_t *L) {
    memset(L, 0, sizeof *L);
    return -1;
}
void render_layers_free(render_layers_t *L) { (void)L; }
void render_near_merge(render_px_t *dst, const render_px_t *src, size_t n) { (void)dst, (void)src, (void)n; }
void render_far_merge(render_far_t *dst, const render_far_t *src, size_t n) { (void)dst, (void)src, (void)n; }
void render_splat(const render_scene_t *sc, const hd_points_t *A, size_t first, const double *d_a,
                  const hd_points_t *B, render_layers_t *L) {
    (void)sc, (void)A, (void)first, (void)d_a, (void)B, (void)L;
}
int render_compose(const char *path, const render_scene_t *sc, const render_layers_t *L, const double wp[3],
                   const double wq[3], const hd_symmetric_t *s, int directed, const render_notes_t *notes,
                   const char *title, render_marker_t markers[6], int *n_markers, render_info_t *info, int *width,
                   int *height, hd_error_t *err) {
    (void)path, (void)sc, (void)L, (void)wp, (void)wq, (void)s, (void)directed, (void)notes, (void)title;
    (void)markers, (void)width, (void)height;
    memset(info, 0, sizeof *info);
    info->pct_y = -1;
    *n_markers = 0;
    return unavailable(err);
}

#endif
