/*
 * signed.c -- the signed distance from every point of a cloud to a closed
 * triangle surface (hd_mesh_signed_distances).
 *
 * The distances, triangles, closest points and weights are hd_mesh_distances'
 * (bit for bit).  The sign of point k is 0 where its distance is 0, and
 * otherwise -1 inside (the winding number of the surface around the point
 * is nonzero) and +1 outside (it is 0); the winding number is decided
 * exactly by mesh/winding.c, which first refuses a mesh that is not closed
 * and consistently oriented.  A distance above 0 means the true distance is
 * above 0, so the point is off the surface and its winding number exists.
 */
#include "mesh/mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define RUN 512

/* The triangles' corners and indices when the mesh looks well formed
 * (indices in range, finite corners); *t = NULL when it does not, so that
 * hd_mesh_distances reports the defect with its own message. */
static int corners(const hd_mesh_t *M, hd__wtri_t **t, hd_error_t *err) {
    *t = NULL;
    const hd_points_t *V = &M->vertices;
    size_t isz = M->index_type == HD_INDEX_U32 ? sizeof(uint32_t) : sizeof(uint64_t);
    if ((M->index_type != HD_INDEX_U32 && M->index_type != HD_INDEX_U64) || !M->n_triangles || !V->count ||
        !M->triangles || !V->data || (V->dtype != HD_FLOAT64 && V->dtype != HD_FLOAT32) ||
        (uintptr_t)M->triangles % isz || hd__points_aligned(V, "of the mesh vertices", NULL))
        return HD_OK;
    hd__wtri_t *w = hd__malloc_array(M->n_triangles, sizeof *w);
    if (!w) return hd__err(err, HD_ENOMEM, "mesh: out of memory for %zu triangles", M->n_triangles);
    hd__src_t src;
    hd__src_init(&src, V, NULL);
    for (size_t k = 0; k < M->n_triangles; k++)
        for (int j = 0; j < 3; j++) {
            uint64_t v = M->index_type == HD_INDEX_U32 ? ((const uint32_t *)M->triangles)[3 * k + j]
                                                       : ((const uint64_t *)M->triangles)[3 * k + j];
            if (v >= V->count) goto malformed;
            w[k].vi[j] = v;
            hd__src_get(&src, (size_t)v, w[k].v[j]);
            for (int c = 0; c < 3; c++)
                if (!(fabs(w[k].v[j][c]) <= HD_MAX_COORD)) goto malformed;
        }
    *t = w;
    return HD_OK;
malformed:
    free(w);
    return HD_OK;
}

typedef struct {
    const hd__solid_t *solid;
    hd__src_t src;
    size_t n;
    const double *dist;
    int8_t *sign;
} job_t;

static void run(void *ctx, size_t task, int worker) {
    (void)worker;
    job_t *J = ctx;
    size_t lo = task * RUN, hi = lo + RUN < J->n ? lo + RUN : J->n;
    for (size_t i = lo; i < hi; i++) {
        if (J->dist[i] == 0) {
            J->sign[i] = 0;
            continue;
        }
        double p[3];
        int on;
        hd__src_get(&J->src, i, p);
        long w = hd__solid_winding(J->solid, p, &on);
        J->sign[i] = on ? 0 : w != 0 ? -1 : 1; /* on: unreachable for a distance above 0 */
    }
}

int hd_mesh_signed_distances(const hd_points_t *P, const hd_mesh_t *M, const hd_options_t *opt, double *dist,
                             size_t *triangle, double *closest, double *bary, int8_t *sign,
                             hd_surface_result_t *out, hd_error_t *err) {
    hd__err_clear(err);
    double t0 = hd__now();
    if (out) memset(out, 0, sizeof *out);
    if (!P || !M) return hd__err(err, HD_EINVAL, "point set or mesh is NULL");
    hd__wtri_t *t;
    int rc = corners(M, &t, err);
    if (rc) return rc;
    hd__solid_t *solid = NULL;
    if (t) {
        rc = hd__solid_build(&solid, t, M->n_triangles, err);
        free(t);
        if (rc) return rc;
    }
    double *d = dist ? dist : hd__malloc_array(P->count ? P->count : 1, sizeof *d);
    if (!d) {
        hd__solid_free(solid);
        return hd__err(err, HD_ENOMEM, "out of memory for %zu distances", P->count);
    }
    hd_surface_result_t res;
    rc = hd_mesh_distances(P, M, opt, d, triangle, closest, bary, &res, err);
    if (rc == HD_OK && sign && !solid) /* corners() and hd_mesh_distances accept the same meshes */
        rc = hd__err(err, HD_EINVAL, "mesh: its corners could not be read for the sign");
    if (rc == HD_OK && sign) {
        job_t J = {.solid = solid, .n = P->count, .dist = d, .sign = sign};
        hd__src_init(&J.src, P, NULL);
        size_t runs = (P->count + RUN - 1) / RUN;
        hd__parallel_for(hd__thread_count(opt ? opt->threads : 0, runs), runs, run, &J);
    }
    if (d != dist) free(d);
    hd__solid_free(solid);
    if (rc == HD_OK && out) {
        *out = res;
        out->seconds = hd__now() - t0;
    }
    return rc;
}
