/*
 * test_mesh_read.c -- hd_read_mesh: the faces of PLY, OBJ, OFF and STL,
 * polygons as fans, STL's corners merged when bit-equal, degenerate
 * triangles counted, and a clear error for a face out of range, a
 * non-finite vertex, a file without faces or without vertices, and a
 * format that has no faces.
 */
#include "check.h"
#include "files.h"

#include <stdlib.h>

static hd_mesh_file_t *read_ok(const char *path) {
    hd_mesh_file_t *m = NULL;
    hd_error_t err;
    int rc = hd_read_mesh(path, NULL, &m, &err);
    CONTEXT("%s", path);
    CHECK_RC(rc, HD_OK);
    if (rc) printf("%s\n", err.message);
    return m;
}

static void read_fails(const char *path, int code, const char *says) {
    hd_mesh_file_t *m = (hd_mesh_file_t *)1;
    hd_error_t err;
    CONTEXT("%s", path);
    CHECK_RC(hd_read_mesh(path, NULL, &m, &err), code);
    CHECK(m == NULL);
    if (!strstr(err.message, says)) {
        CONTEXT("%s: message '%s' lacks '%s'", path, err.message, says);
        CHECK(strstr(err.message, says) != NULL);
    }
}

TEST(polygons_become_fans_in_file_order) {
    hd_mesh_file_t *m = read_ok("tests/corpus/off/noff_quads.off");
    if (!m) return;
    CHECK_EQ(m->n_vertices, 5);
    CHECK_EQ(m->n_faces, 3);
    CHECK_EQ(m->n_triangles, 2 + 1 + 3); /* a quad, a triangle, a pentagon */
    const uint64_t want[] = {0, 1, 2, 0, 2, 3, 0, 1, 4, 0, 1, 2, 0, 2, 3, 0, 3, 4};
    CHECK(memcmp(m->triangles, want, sizeof want) == 0);
    CHECK(strcmp(m->format, "off") == 0);
    hd_mesh_t v = hd_mesh_file_view(m);
    CHECK_EQ(v.n_triangles, 6);
    CHECK_EQ(v.vertices.count, 5);
    hd_mesh_file_free(m);
}

TEST(stl_corners_merge_when_bit_equal) {
    /* the same model as OBJ text and as float32 STL: 2117 vertices */
    hd_mesh_file_t *stl = read_ok("data/orig/Wuson.stl"), *obj = read_ok("data/orig/WusonOBJ.obj");
    if (!stl || !obj) return;
    CHECK_EQ(stl->n_vertices, 2117);
    CHECK_EQ(stl->n_merged, 3 * stl->n_triangles - 2117);
    CHECK_EQ(stl->n_triangles, stl->n_faces);
    CHECK_EQ(obj->n_vertices, 2117);
    CHECK_EQ(obj->n_merged, 0);
    /* every triangle's corners are distinct vertices after the merge */
    size_t repeated = 0;
    for (size_t t = 0; t < stl->n_triangles; t++) {
        const uint64_t *f = stl->triangles + 3 * t;
        repeated += f[0] == f[1] || f[1] == f[2] || f[0] == f[2];
    }
    CHECK_EQ(repeated, 0);
    hd_mesh_file_free(stl);
    hd_mesh_file_free(obj);
}

TEST(merged_stl_keeps_distinct_corners_apart) {
    /* two facets sharing an edge, one corner -0.0 where the other has 0.0 */
    const char *p = tf_printf("two.stl",
                              "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                              "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\n"
                              "vertex 0 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex -0 0 0\n"
                              "vertex 1 0 0\nvertex 1 1 0\nendloop\nendfacet\nendsolid s\n");
    hd_mesh_file_t *m = read_ok(p);
    if (!m) return;
    CHECK_EQ(m->n_triangles, 3);
    CHECK_EQ(m->n_vertices, 5); /* (0,0,0) (1,0,0) (0,1,0) (1,1,0) (-0,0,0) */
    const uint64_t want[] = {0, 1, 2, 1, 3, 2, 4, 1, 3};
    CHECK(memcmp(m->triangles, want, sizeof want) == 0);
    hd_mesh_file_free(m);
}

TEST(degenerate_faces_are_counted_not_refused) {
    const char *p = tf_printf("deg.off", "OFF\n5 4 0\n0 0 0\n1 0 0\n2 0 0\n0 1 0\n0 0 0\n"
                                         "3 0 1 2\n3 0 0 3\n3 0 4 1\n3 0 1 3\n");
    hd_mesh_file_t *m = read_ok(p);
    if (!m) return;
    CHECK_EQ(m->n_triangles, 4);
    CHECK_EQ(m->n_degenerate, 3); /* collinear, repeated index, coincident corners */
    hd_mesh_file_free(m);
}

TEST(bundled_meshes_read_with_their_faces) {
    const char *files[] = {"data/orig/pinion.off", "data/orig/cow.off", "data/orig/stanford_bunny_reduced.ply"};
    for (int f = 0; f < 3; f++) {
        hd_mesh_file_t *m = read_ok(files[f]);
        if (!m) continue;
        CHECK(m->n_triangles >= m->n_faces && m->n_faces > 0);
        for (size_t k = 0; k < 3 * m->n_triangles; k++) CHECK(m->triangles[k] < m->n_vertices);
        hd_mesh_file_free(m);
    }
}

TEST(bad_meshes_are_refused_with_the_file_and_the_face) {
    read_fails(tf_printf("range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), HD_EFORMAT,
               "face refers to vertex 3, but there are 3 vertices");
    read_fails(tf_printf("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), HD_EFORMAT, "range.obj:4");
    read_fails(tf_printf("nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n"), HD_ENONFINITE, "nan.off:4");
    read_fails(tf_printf("nofaces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"), HD_EEMPTY, "no faces");
    read_fails(tf_printf("empty.off", "OFF\n0 0 0\n"), HD_EEMPTY, "empty.off");
    read_fails(tf_printf("onlyfaces.obj", "f 1 2 3\n"), HD_EFORMAT, "onlyfaces.obj");
    read_fails(tf_printf("points.xyz", "0 0 0\n1 0 0\n0 1 0\n"), HD_EUNSUPPORTED, "has no faces");
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.range_count = 2;
    hd_mesh_file_t *m;
    CHECK_RC(hd_read_mesh("data/orig/pinion.off", &o, &m, NULL), HD_EINVAL);
}
