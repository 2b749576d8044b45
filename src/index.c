/* index.c -- placeholder until the engine's index lands. */
#include "internal.h"

int hd_index_build(const hd_points_t *B, const hd_options_t *opt,
                   hd_index_t **out, hd_error_t *err) {
    (void)B;
    (void)opt;
    if (out) *out = NULL;
    return hd__err(err, HD_EUNSUPPORTED, "indexes are not built yet");
}
void hd_index_free(hd_index_t *idx) { (void)idx; }
size_t hd_index_count(const hd_index_t *idx) { (void)idx; return 0; }
size_t hd_index_memory(const hd_index_t *idx) { (void)idx; return 0; }
int hd_index_directed(const hd_index_t *idx, const hd_points_t *A,
                      const hd_transform_t *T, const hd_options_t *opt,
                      hd_result_t *out, hd_error_t *err) {
    (void)idx; (void)A; (void)T; (void)opt; (void)out;
    return hd__err(err, HD_EUNSUPPORTED, "indexes are not built yet");
}
int hd_index_nearest(const hd_index_t *idx, const hd_points_t *Q,
                     const hd_transform_t *T, const hd_options_t *opt,
                     double *dist, size_t *nearest, hd_error_t *err) {
    (void)idx; (void)Q; (void)T; (void)opt; (void)dist; (void)nearest;
    return hd__err(err, HD_EUNSUPPORTED, "indexes are not built yet");
}
