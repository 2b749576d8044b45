/*
 * tri_cases.c -- the kernel as a filter for tests/tri_reference.py: reads
 * cases of twelve little-endian doubles (p, a, b, c) from standard input and
 * writes for each the distance's eight bytes, then one byte: 1 when the
 * exact path decided, 0 when the fast path did, 2 when the call failed;
 * then the eight bytes of each of hd__tri_bounds' lo2 and hi2.  With
 * --exact every case goes through the exact path alone.
 */
#include <stdio.h>
#include <string.h>

#include "mesh/mesh.h"

int main(int argc, char **argv) {
    int exact_only = argc > 1 && strcmp(argv[1], "--exact") == 0;
    double v[12];
    while (fread(v, sizeof v[0], 12, stdin) == 12) {
        hd__tri_near_t o;
        int rc = exact_only ? hd__tri_nearest_exact(v, v + 3, v + 6, v + 9, &o)
                            : hd__tri_nearest(v, v + 3, v + 6, v + 9, &o);
        unsigned char flag = rc != HD_OK ? 2 : (unsigned char)o.exact;
        double b[2];
        if (rc != HD_OK) o.d = 0;
        hd__tri_bounds(v, v + 3, v + 6, v + 9, &b[0], &b[1]);
        if (fwrite(&o.d, sizeof o.d, 1, stdout) != 1 || fwrite(&flag, 1, 1, stdout) != 1 ||
            fwrite(b, sizeof b[0], 2, stdout) != 2)
            return 1;
    }
    return ferror(stdin) ? 1 : 0;
}
