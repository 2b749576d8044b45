/*
 * nifti.c -- medical segmentation masks as point sets, and the one entry
 * point the tool reads its inputs through.
 *
 * A NIfTI-1 or NIfTI-2 image (.nii, .nii.gz; read by Debian's nifti C
 * library, libnifti2, which understands both versions and gzip) is a mask
 * when it is 3D (a 4th dimension of size 1 is allowed) and of an integer or
 * floating type.  A voxel is foreground when its stored value is nonzero
 * and not NaN; scl_slope/scl_inter are ignored, since they cannot turn a
 * zero into a label or a label into a zero in any mask we have seen.
 *
 * Which voxels become points (--mask-points):
 *  - surface (default): foreground voxels with at least one of their six
 *    face neighbours in the background or outside the image.  This is the
 *    border that medpy (binary erosion with a connectivity-1 structure,
 *    border value 0) and MONAI use for surface distances, HD and HD95.
 *  - all: every foreground voxel.
 * A point is the world coordinate of the voxel's centre (i, j, k):
 *     x = ((m00*i + m01*j) + m02*k) + m03, likewise y and z,
 * in double, in this order (the build has no fused multiply-add), where m
 * is the sform matrix when sform_code > 0, else the qform matrix (which the
 * library builds from the quaternion, or from pixdim alone when qform_code
 * is 0).  That honours anisotropic spacing and any orientation.  When the
 * header's spatial unit is metres or micrometres each coordinate is then
 * multiplied by 1000 or 0.001, so distances are in millimetres; an unknown
 * unit is taken as millimetres.  Points are in storage order (i fastest,
 * then j, then k), so the `nearest` indices of --distances name voxels.
 *
 * When the tool is built without libnifti2 the masks are refused with a
 * message that says so; every other file goes to hd_read_file unchanged.
 */
#include "analysis.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

int nifti_is_mask_path(const char *path) {
    size_t n = strlen(path);
    return (n > 4 && strcasecmp(path + n - 4, ".nii") == 0) ||
           (n > 7 && strcasecmp(path + n - 7, ".nii.gz") == 0);
}

static int fail(hd_error_t *err, int code, const char *path, const char *what) {
    err->code = code;
    err->line = err->offset = -1;
    snprintf(err->message, sizeof err->message, "%s: %s", path, what);
    return code;
}

/* A cloud the tool made itself; hd_cloud_free releases it (free() of the
 * data and of the struct, as for the library's own clouds). */
static hd_cloud_t *new_cloud(size_t count, hd_dtype_t dtype, const char *format) {
    hd_cloud_t *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    size_t el = dtype == HD_FLOAT32 ? 3 * sizeof(float) : 3 * sizeof(double);
    if (count && count > SIZE_MAX / el) {
        free(c);
        return NULL;
    }
    c->data = count ? malloc(count * el) : NULL;
    if (count && !c->data) {
        free(c);
        return NULL;
    }
    c->count = count;
    c->dtype = dtype;
    snprintf(c->format, sizeof c->format, "%s", format);
    return c;
}

#ifdef HD_HAVE_NIFTI
#include <nifti2_io.h>

int nifti_available(void) { return 1; }

/* The foreground of the image as one byte per voxel, or NULL. */
static unsigned char *foreground_of(const nifti_image *nim, size_t nvox,
                                    long long *count, int *unsupported) {
    unsigned char *fg = malloc(nvox ? nvox : 1);
    if (!fg) return NULL;
    long long c = 0;
    *unsupported = 0;
    for (size_t v = 0; v < nvox; v++) {
        int on;
        switch (nim->datatype) {
        case DT_UINT8: on = ((const uint8_t *)nim->data)[v] != 0; break;
        case DT_INT8: on = ((const int8_t *)nim->data)[v] != 0; break;
        case DT_INT16: on = ((const int16_t *)nim->data)[v] != 0; break;
        case DT_UINT16: on = ((const uint16_t *)nim->data)[v] != 0; break;
        case DT_INT32: on = ((const int32_t *)nim->data)[v] != 0; break;
        case DT_UINT32: on = ((const uint32_t *)nim->data)[v] != 0; break;
        case DT_INT64: on = ((const int64_t *)nim->data)[v] != 0; break;
        case DT_UINT64: on = ((const uint64_t *)nim->data)[v] != 0; break;
        case DT_FLOAT32: {
            float f = ((const float *)nim->data)[v];
            on = f != 0 && !isnan(f);
            break;
        }
        case DT_FLOAT64: {
            double f = ((const double *)nim->data)[v];
            on = f != 0 && !isnan(f);
            break;
        }
        default:
            free(fg);
            *unsupported = 1;
            return NULL;
        }
        fg[v] = (unsigned char)on;
        c += on;
    }
    *count = c;
    return fg;
}

static int on_surface(const unsigned char *fg, long long nx, long long ny,
                      long long nz, long long i, long long j, long long k) {
    size_t v = (size_t)((k * ny + j) * nx + i);
    if (i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1) return 1;
    size_t sx = 1, sy = (size_t)nx, sz = (size_t)(nx * ny);
    return !fg[v - sx] || !fg[v + sx] || !fg[v - sy] || !fg[v + sy] || !fg[v - sz] || !fg[v + sz];
}

static int read_mask(const char *path, const hd_read_options_t *ro,
                     mask_points_t which, mask_info_t *info, hd_cloud_t **out,
                     hd_error_t *err) {
    if (access(path, R_OK) != 0) return fail(err, HD_EIO, path, "cannot open the mask");
    nifti_set_debug_level(0);
    nifti_image *nim = nifti_image_read(path, 1);
    if (!nim || !nim->data) {
        if (nim) nifti_image_free(nim);
        return fail(err, HD_EFORMAT, path, "not a readable NIfTI-1/2 image");
    }
    int rc = HD_OK;
    long long nx = nim->nx, ny = nim->ny, nz = nim->nz;
    if (nim->ndim > 3 && (long long)nim->nvox != nx * ny * nz)
        rc = fail(err, HD_EUNSUPPORTED, path, "has more than one volume; a mask is 3D");
    if (rc == HD_OK && (nx < 1 || ny < 1 || nz < 1))
        rc = fail(err, HD_EFORMAT, path, "has an empty dimension");
    unsigned char *fg = NULL;
    long long count = 0;
    if (rc == HD_OK) {
        int unsupported;
        fg = foreground_of(nim, (size_t)nim->nvox, &count, &unsupported);
        if (!fg)
            rc = unsupported ? fail(err, HD_EUNSUPPORTED, path,
                                    "voxel type is not an integer or float type a mask can have")
                             : fail(err, HD_ENOMEM, path, "out of memory");
    }
    if (rc) {
        nifti_image_free(nim);
        return rc;
    }
    const nifti_dmat44 *m = nim->sform_code > 0 ? &nim->sto_xyz : &nim->qto_xyz;
    double to_mm = 1.0;
    if (nim->xyz_units == NIFTI_UNITS_METER) to_mm = 1000.0;
    else if (nim->xyz_units == NIFTI_UNITS_MICRON) to_mm = 0.001;
    memset(info, 0, sizeof *info);
    info->is_mask = 1;
    /* nifti_image keeps no trace of the version it was read from */
    int nver = 1;
    void *hdr = nifti_read_header(path, &nver, 0);
    free(hdr);
    info->nifti_version = nver == 2 ? 2 : 1;
    info->dim[0] = nx;
    info->dim[1] = ny;
    info->dim[2] = nz;
    info->spacing[0] = nim->dx;
    info->spacing[1] = nim->dy;
    info->spacing[2] = nim->dz;
    info->foreground = count;
    info->transform = nim->sform_code > 0 ? "sform" : nim->qform_code > 0 ? "qform" : "pixdim";
    info->to_mm = to_mm;
    /* count the points, then fill exactly that many */
    size_t n = 0;
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1 && !(*out = new_cloud(n, ro->dtype, which == MASK_ALL ? "nifti:all" : "nifti:surface"))) {
            rc = fail(err, HD_ENOMEM, path, "out of memory for the mask's points");
            break;
        }
        size_t p = 0;
        for (long long k = 0; k < nz; k++)
            for (long long j = 0; j < ny; j++)
                for (long long i = 0; i < nx; i++) {
                    size_t v = (size_t)((k * ny + j) * nx + i);
                    if (!fg[v] || (which == MASK_SURFACE && !on_surface(fg, nx, ny, nz, i, j, k))) continue;
                    if (pass == 1) {
                        double q[3], di = (double)i, dj = (double)j, dk = (double)k;
                        for (int c = 0; c < 3; c++) {
                            q[c] = ((m->m[c][0] * di + m->m[c][1] * dj) + m->m[c][2] * dk) + m->m[c][3];
                            if (to_mm != 1.0) q[c] = q[c] * to_mm;
                        }
                        if (ro->dtype == HD_FLOAT32)
                            for (int c = 0; c < 3; c++) ((float *)(*out)->data)[3 * p + c] = (float)q[c];
                        else
                            memcpy((double *)(*out)->data + 3 * p, q, sizeof q);
                    }
                    p++;
                }
        n = p;
    }
    info->points = n;
    free(fg);
    nifti_image_free(nim);
    return rc;
}

#else

int nifti_available(void) { return 0; }

static int read_mask(const char *path, const hd_read_options_t *ro,
                     mask_points_t which, mask_info_t *info, hd_cloud_t **out,
                     hd_error_t *err) {
    (void)ro, (void)which, (void)info, (void)out;
    return fail(err, HD_EUNSUPPORTED, path,
                "NIfTI masks are unavailable: this hausdorff was built without libnifti2 "
                "(Debian: libnifti2-dev)");
}

#endif

int cli_read_points(const char *path, const hd_read_options_t *ro,
                    analysis_args_t *an, int which, hd_cloud_t **out,
                    hd_error_t *err) {
    *out = NULL;
    hd_read_options_t defaults;
    if (!ro) {
        hd_read_options_init(&defaults);
        ro = &defaults;
    }
    int rc;
    if (nifti_is_mask_path(path) && !ro->format) {
        rc = read_mask(path, ro, an->mask_points, &an->mask[which], out, err);
        if (rc == HD_OK && (*out)->count == 0) {
            hd_cloud_free(*out);
            *out = NULL;
            rc = fail(err, HD_EEMPTY, path,
                      an->mask_points == MASK_ALL ? "the mask has no foreground voxels"
                                                  : "the mask has no foreground (surface) voxels");
        }
    } else {
        rc = hd_read_file(path, ro, out, err);
    }
    if (rc != HD_EEMPTY) return rc;
    if (an->empty == EMPTY_ERROR) {
        size_t len = strlen(err->message);
        snprintf(err->message + len, sizeof err->message - len,
                 " (an empty set has no distance; --empty inf|nan|zero reports one)");
        return rc;
    }
    if (!(*out = new_cloud(0, ro->dtype, "empty"))) return fail(err, HD_ENOMEM, path, "out of memory");
    return HD_OK;
}
