/*
 * m2m_dense -- the independent dense check of a surface-to-surface
 * enclosure as a program (tests/m2m_dense_check.h says what it proves):
 *
 *   m2m_dense A B [--upper U] [--witness X,Y,Z,D[,E]]...
 *             [--samples N | --level K] [--threads T]
 *
 * Reads the meshes A and B (any format hd_read_mesh reads), measures A's
 * vertices and a grid on each of its triangles (level K, or the level that
 * gives about N points; 10^6 by default) against B exactly, and prints one
 * JSON line: the largest lower bound on h(A, B) found, its point and face,
 * and with --upper whether it stays at or below U ("holds").  Each
 * --witness is a claimed witness point (X, Y, Z) of A with its claimed
 * exact distance D to B and, optionally, the claimed bound E on its
 * distance from the exact point of A it stands for: the program measures
 * the point's distance to B (equal to D bit for bit?) and to A (at most
 * E?).  Exit 0 when every check given holds, 1 when one fails, 2 on bad
 * arguments or unreadable meshes.
 */
#include "m2m_dense_check.h"

#include <hausdorff.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_WITNESSES = 64 };

typedef struct {
    double p[3], distance, error; /* error NAN: not claimed */
} witness_t;

static int usage(void) {
    fprintf(stderr, "usage: m2m_dense A B [--upper U] [--witness X,Y,Z,D[,E]]... "
                    "[--samples N | --level K] [--threads T]\n");
    return 2;
}

static int number(const char *s, double *out) {
    char *end;
    *out = strtod(s, &end);
    return *s && !*end;
}

static int parse_witness(const char *s, witness_t *w) {
    double v[5];
    int n = 0;
    char *end;
    for (;;) {
        v[n++] = strtod(s, &end);
        if (end == s) return 0;
        if (!*end) break;
        if (*end != ',' || n == 5) return 0;
        s = end + 1;
    }
    if (n < 4) return 0;
    *w = (witness_t){{v[0], v[1], v[2]}, v[3], n == 5 ? v[4] : NAN};
    return 1;
}

/* Each witness measured against B and A; 1 when every claim holds. */
static int check_witnesses(const witness_t *w, int n, const hd_mesh_t *A, const hd_mesh_t *B, int threads) {
    int all = 1;
    hd_error_t err;
    printf(", \"witnesses\": [");
    for (int k = 0; k < n; k++) {
        double d = m2m_dense_point(w[k].p, B, threads, &err), off = m2m_dense_point(w[k].p, A, threads, &err);
        int equal = d == w[k].distance, near = isnan(w[k].error) || off <= w[k].error;
        printf("%s{\"distance\": %.17g, \"claimed\": %.17g, \"equal\": %s, \"off\": %.17g, \"off_within\": %s}",
               k ? ", " : "", d, w[k].distance, equal ? "true" : "false", off, near ? "true" : "false");
        all &= equal && near;
    }
    printf("]");
    return all;
}

int main(int argc, char **argv) {
    if (argc < 3) return usage();
    double upper = NAN, samples = 1e6, level = 0, threads = 0;
    static witness_t w[MAX_WITNESSES];
    int nw = 0;
    for (int k = 3; k < argc; k += 2) {
        const char *o = argv[k], *v = k + 1 < argc ? argv[k + 1] : NULL;
        int ok;
        if (!v) return usage();
        if (!strcmp(o, "--upper")) ok = number(v, &upper);
        else if (!strcmp(o, "--samples")) ok = number(v, &samples) && samples >= 1;
        else if (!strcmp(o, "--level")) ok = number(v, &level) && level >= 1 && level <= 4096;
        else if (!strcmp(o, "--threads")) ok = number(v, &threads) && threads >= 0 && threads <= 1024;
        else if (!strcmp(o, "--witness")) ok = nw < MAX_WITNESSES && parse_witness(v, &w[nw++]);
        else ok = 0;
        if (!ok) return usage();
    }
    hd_mesh_file_t *fa = NULL, *fb = NULL;
    hd_error_t err;
    if (hd_read_mesh(argv[1], NULL, &fa, &err) || hd_read_mesh(argv[2], NULL, &fb, &err)) {
        fprintf(stderr, "m2m_dense: %s\n", err.message);
        hd_mesh_file_free(fa);
        return 2;
    }
    hd_mesh_t A = hd_mesh_file_view(fa), B = hd_mesh_file_view(fb);
    int lv = level ? (int)level : m2m_dense_level(A.n_triangles, (size_t)samples);
    m2m_dense_t r;
    int status = 0;
    if (m2m_dense_run(&A, &B, lv, (int)threads, &r, &err)) {
        fprintf(stderr, "m2m_dense: %s\n", err.message);
        status = 2;
    } else {
        printf("{\"samples\": %zu, \"level\": %d, \"largest\": %.17g, \"at\": [%.17g, %.17g, %.17g], ", r.samples,
               r.level, r.largest, r.at[0], r.at[1], r.at[2]);
        if (r.face == SIZE_MAX) printf("\"face\": null, ");
        else printf("\"face\": %zu, ", r.face);
        printf("\"off\": %.17g", r.off);
        if (!isnan(upper)) {
            int holds = r.largest <= upper;
            printf(", \"upper\": %.17g, \"holds\": %s", upper, holds ? "true" : "false");
            if (!holds) status = 1;
        }
        if (nw && !check_witnesses(w, nw, &A, &B, (int)threads)) status = 1;
        printf("}\n");
    }
    hd_mesh_file_free(fa), hd_mesh_file_free(fb);
    return status;
}
