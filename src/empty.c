/*
 * empty.c -- the empty-set policies (hd_empty_policy_t): their names and
 * the value each gives every distance figure when A or B has no point.
 * The command-line tools and the Python module apply them; this is their
 * only definition.
 */
#include "hausdorff.h"

#include <math.h>
#include <string.h>

static const char *const policy_names[] = {"error", "inf", "nan", "zero", "monai", "skimage"};
enum { POLICY_COUNT = sizeof policy_names / sizeof policy_names[0] };

double hd_empty_value(hd_empty_policy_t policy, size_t n_a, size_t n_b) {
    int both = n_a == 0 && n_b == 0;
    switch (policy) {
    case HD_EMPTY_INF: return INFINITY;
    case HD_EMPTY_ZERO: return 0.0;
    case HD_EMPTY_MONAI: return both ? NAN : INFINITY;   /* MONAI: inf for one, NaN for both */
    case HD_EMPTY_SKIMAGE: return both ? 0.0 : INFINITY; /* skimage: inf for one, 0 for both */
    default: return NAN;                                 /* HD_EMPTY_NAN; no value otherwise */
    }
}

const char *hd_empty_policy_name(hd_empty_policy_t policy) {
    return (int)policy >= 0 && (int)policy < POLICY_COUNT ? policy_names[policy] : NULL;
}

int hd_empty_policy_from_name(const char *name, hd_empty_policy_t *out) {
    if (!name || !out) return HD_EINVAL;
    for (int k = 0; k < POLICY_COUNT; k++)
        if (strcmp(name, policy_names[k]) == 0) {
            *out = (hd_empty_policy_t)k;
            return HD_OK;
        }
    return HD_EINVAL;
}
