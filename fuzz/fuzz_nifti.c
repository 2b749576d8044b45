/*
 * fuzz_nifti.c -- a libFuzzer target for NIfTI masks: the input is written
 * to a temporary file and read the way the command line reads a mask,
 * through cli_read_points() (cli/nifti.c: libnifti2, then the voxels to
 * points).  Inputs that start with gzip's magic bytes are written as
 * m.nii.gz, every other input as m.nii, so both of libnifti2's paths run.
 *
 * The size of the input picks the options, so that a reproducer replays
 * the same way: odd sizes store float32 (even: float64); bit 1 of the size
 * chooses --mask-points all (else surface); bit 2 --empty zero (else an
 * empty mask is an error); (size >> 3) % 3 + 1 is --connectivity and
 * (size >> 5) % 3 picks --mask-dims auto, 2 or 3.
 *
 * Besides "no crash, no leak, no undefined behaviour" the target checks the
 * contract of cli_read_points: a failure leaves no cloud and a message that
 * starts with the path; a success gives a cloud of the storage asked for,
 * with points only when the mask has a foreground (none only under an
 * --empty policy), and as many points as the mask's record says, every one
 * of which is read (so a short buffer is caught by AddressSanitizer).
 * Coordinates are not required to be finite here: a NaN or infinite sform
 * makes non-finite points, which hd_hausdorff refuses later with its own
 * message (HD_ENONFINITE).
 */
#include "analysis.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[4096], path_nii[4200], path_gz[4200];

static void cleanup(void) {
    unlink(path_nii);
    unlink(path_gz);
    rmdir(dir);
}

int LLVMFuzzerInitialize(int *argc, char ***argv) {
    (void)argc, (void)argv;
    const char *tmp = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/fuzz_nifti.XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(dir)) {
        perror("fuzz_nifti: mkdtemp");
        abort();
    }
    snprintf(path_nii, sizeof path_nii, "%s/m.nii", dir);
    snprintf(path_gz, sizeof path_gz, "%s/m.nii.gz", dir);
    atexit(cleanup);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const char *path = size >= 2 && data[0] == 0x1f && data[1] == 0x8b ? path_gz : path_nii;
    FILE *f = fopen(path, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0) {
        perror("fuzz_nifti: cannot write the input");
        abort();
    }
    hd_read_options_t ro;
    hd_read_options_init(&ro);
    ro.dtype = size & 1 ? HD_FLOAT32 : HD_FLOAT64;
    analysis_args_t an;
    memset(&an, 0, sizeof an);
    an.mask_points = size & 2 ? MASK_ALL : MASK_SURFACE;
    an.empty = size & 4 ? HD_EMPTY_ZERO : HD_EMPTY_ERROR;
    an.connectivity = (int)((size >> 3) % 3) + 1;
    an.mask_dims = (int[]){0, 2, 3}[(size >> 5) % 3];
    hd_cloud_t *c = (hd_cloud_t *)&an; /* must become NULL on failure */
    hd_error_t e;
    int rc = cli_read_points(path, &ro, &an, 0, &c, &e);
    unlink(path);
    if (rc != HD_OK) {
        if (c != NULL || e.code != rc || strncmp(e.message, path, strlen(path)) != 0) abort();
        return 0;
    }
    if (!c || c->dtype != ro.dtype) abort();
    if (c->count == 0) {
        if (an.empty == HD_EMPTY_ERROR) abort();
    } else {
        const mask_info_t *m = &an.mask[0];
        if (!m->is_mask || m->points != c->count || m->foreground < 1 ||
            (unsigned long long)m->foreground < c->count ||
            (an.mask_points == MASK_ALL && (unsigned long long)m->foreground != c->count) ||
            (m->nifti_version != 1 && m->nifti_version != 2) || m->dim[0] < 1 || m->dim[1] < 1 ||
            m->dim[2] < 1)
            abort();
        hd_points_t p = hd_cloud_points(c);
        volatile double sink = 0;
        for (size_t k = 0; k < c->count; k++) {
            double q[3];
            hd_points_get(&p, k, q);
            sink += q[0] + q[1] + q[2];
        }
        (void)sink;
    }
    hd_cloud_free(c);
    return 0;
}
