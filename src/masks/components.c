/*
 * components.c -- connected components of a window's foreground, by a
 * flood fill from each unlabelled foreground voxel in storage order, so
 * that components are numbered by their first voxel.  The stack holds
 * voxel indices; a neighbour is in the window when each of its indices is.
 */
#include "masks.h"

#include <stdlib.h>

long long hd__components(const uint8_t *fg, const size_t w[3], const hd__neighbourhood_t *nb, uint32_t *comp) {
    size_t nvox = w[0] * w[1] * w[2], cap = 1024, top = 0;
    size_t *stack = malloc(cap * sizeof *stack);
    if (!stack) return -1;
    long long n = 0;
    for (size_t v = 0; v < nvox; v++) comp[v] = 0;
    for (size_t s = 0; s < nvox; s++) {
        if (!fg[s] || comp[s]) continue;
        comp[s] = (uint32_t)++n;
        stack[top++] = s;
        while (top) {
            size_t v = stack[--top];
            size_t at[3] = {v % w[0], v / w[0] % w[1], v / w[0] / w[1]};
            for (int q = 0; q < nb->n; q++) {
                int inside = 1;
                for (int a = 0; a < 3; a++) {
                    ptrdiff_t c = (ptrdiff_t)at[a] + nb->d[q][a];
                    if (c < 0 || c >= (ptrdiff_t)w[a]) inside = 0;
                }
                size_t u = (size_t)((ptrdiff_t)v + nb->step[q]);
                if (!inside || !fg[u] || comp[u]) continue;
                comp[u] = (uint32_t)n;
                if (top == cap) {
                    size_t *bigger = realloc(stack, 2 * cap * sizeof *stack);
                    if (!bigger) {
                        free(stack);
                        return -1;
                    }
                    stack = bigger, cap *= 2;
                }
                stack[top++] = u;
            }
        }
    }
    free(stack);
    return n;
}
