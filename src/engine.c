/* engine.c -- placeholder: the auto engine runs NAIVEHDD until it lands. */
#include "internal.h"

int hd__engine(const hd__job_t *job, hd_result_t *out, hd_error_t *err) {
    int rc = hd__naive(job, out, err);
    out->algorithm = HD_ALG_NAIVE;
    return rc;
}
