/* earlybreak.c -- placeholder until the algorithm lands (refuses to run). */
#include "internal.h"

int hd__earlybreak(const hd__job_t *job, hd_result_t *out, hd_error_t *err) {
    (void)job;
    (void)out;
    return hd__err(err, HD_EUNSUPPORTED, "algorithm earlybreak is not built yet");
}
