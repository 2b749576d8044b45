/*
 * write_out.c -- what every writer of hd_write_fields (write*.c) shares:
 * appending bytes with the first failure kept, the shortest decimal of a
 * double, which points are written, the fields' bytes of a point in either
 * byte order and a field by its name.
 * A leaf: it calls no other file of src/io.
 */
#include "io.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

size_t hd__shortest(double v, char buf[32]) {
    /* DBL_DIG = 15: a value that a decimal of at most 15 digits reads back
     * to is printed as that decimal by %.15g, so 15, 16, 17 find the
     * shortest */
    int n = 0;
    for (int p = 15; p <= 17; p++) {
        n = snprintf(buf, 32, "%.*g", p, v);
        if (p == 17 || strtod(buf, NULL) == v) break;
    }
    return n < 0 ? 0 : (size_t)n;
}

void hd__w_put(hd__writer_t *w, const void *p, size_t n) {
    if (w->werr || n == 0) return;
    errno = 0;
    if (fwrite(p, 1, n, w->out) != n) w->werr = errno ? errno : EIO;
}

size_t hd__w_kept(const hd__writer_t *w) {
    if (w->keep == HD_KEEP_ALL) return w->n;
    size_t m = 0;
    for (size_t k = 0; k < w->n; k++) m += (size_t)hd__w_keep(w, k);
    return m;
}


long hd__w_field_named(const hd__writer_t *w, const char *s, size_t n) {
    for (size_t j = 0; j < w->nf; j++) {
        const char *name = w->f[j].name;
        if (n ? strlen(name) == n && memcmp(name, s, n) == 0 : strncmp(name, s, 32) == 0) return (long)j;
    }
    return -1;
}
