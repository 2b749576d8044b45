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
 * The header is not trusted.  libnifti2 computes the voxel count in int64
 * without overflow checks, reads the voxels from wherever vox_offset points
 * (even inside the header), allocates whatever the dimensions claim before
 * it finds the file short, and turns NaN or zero spacing into 1 silently.
 * So before it reads a single voxel:
 *  - the header is read (libnifti2's nifti_read_header, which knows gzip,
 *    asked not to check or swap anything) and decoded here field by field
 *    at the specification's offsets, in the byte order sizeof_hdr (348 or
 *    540) reveals;
 *  - check_header applies every rule of docs/analysis.md ("What the header
 *    must satisfy"): magic, dim[0] in 1..7, used dims >= 1, their product
 *    computed here with an overflow check, one volume, a mask's datatype,
 *    the data's size against the file (exactly for plain files, at most
 *    1032 times the compressed size for gzip), vox_offset whole and past
 *    the header, finite spacing (positive when no sform sets the
 *    coordinates), finite quaternion and offsets when qform_code > 0,
 *    finite srow when sform_code > 0.
 * After libnifti2 has read the voxels, its image must have our dimensions,
 * voxel count and type, or nothing is walked: every index below is < the
 * product computed here, which equals what was read.  The world box's eight
 * corners bound every voxel's coordinates (the map is affine), so checking
 * them keeps every point finite and within 1e153 (float range with
 * --float32).  Every refusal is "FILE: what is wrong", naming the field.
 *
 * libnifti2 writes its own complaints to stderr.  While it runs, fd 2 goes
 * to a temporary file (capture_begin/capture_end); its first message is
 * appended to ours when reading fails and dropped otherwise, so the user
 * sees one line.
 *
 * Which voxels become points (--mask-points):
 *  - surface (default): the foreground voxels that binary erosion removes,
 *    the image outside counting as background (border value 0): medpy's
 *    border (mask ^ binary_erosion(mask, generate_binary_structure(ndim,
 *    connectivity))), which MONAI uses too with connectivity 1, found by the
 *    library's hd_mask_points (src/masks/surface.c), as for Python.  The
 *    neighbourhood has --connectivity 1|2|3 (faces; and
 *    edges; and corners: 6, 18 or 26 neighbours in 3-D, 4 or 8 in 2-D) over
 *    the axes --mask-dims chooses: by default the axes of more than one
 *    voxel, so that a single slice (nz = 1, or dim[0] = 2) has the in-plane
 *    border medpy finds on the 2-D array, not "every voxel" (its z
 *    neighbours lie outside the image), and a mask of one voxel is its own
 *    surface; 2: i and j, each slice of constant k eroded on its own (a
 *    stack of contours); 3: all three, an axis of one voxel included (what
 *    medpy gives for the unsqueezed (nx, ny, 1) array).
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

#include <assert.h>
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
hd_cloud_t *cli_cloud_new(size_t count, hd_dtype_t dtype, const char *format) {
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

#include <float.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/stat.h>

int nifti_available(void) { return 1; }

/* ---- libnifti2's stderr ------------------------------------------------ */

/* libnifti2 reports failures with fprintf(stderr, "** ERROR ...") whatever
 * its debug level.  While it runs, fd 2 goes to an anonymous temporary file;
 * afterwards fd 2 is restored and the first line that reports an error is
 * kept, to be appended to our message.  Without a temporary file nothing is
 * captured and libnifti2's lines reach the terminal as before. */
typedef struct {
    int saved;
    FILE *tmp;
} captured_t;

static void capture_begin(captured_t *c) {
    fflush(stderr);
    c->saved = -1;
    c->tmp = tmpfile();
    if (!c->tmp) return;
    c->saved = dup(2);
    if (c->saved < 0 || dup2(fileno(c->tmp), 2) < 0) {
        if (c->saved >= 0) close(c->saved);
        c->saved = -1;
        fclose(c->tmp);
        c->tmp = NULL;
    }
}

/* Restore fd 2.  The first message libnifti2 wrote (a line that starts
 * with "** " or "++ ", its ERROR and WARNING prefixes, and the indented
 * lines after it) goes to line as one line: the prefix dropped, runs of blanks and control characters made one space,
 * continuation lines joined with "; ".  "" when it wrote none. */
static void capture_end(captured_t *c, char *line, size_t size) {
    line[0] = '\0';
    if (!c->tmp) return;
    fflush(stderr);
    dup2(c->saved, 2);
    close(c->saved);
    rewind(c->tmp);
    char buf[512];
    size_t n = 0;
    int in = 0;
    while (fgets(buf, sizeof buf, c->tmp)) {
        int indented = buf[0] == ' ' || buf[0] == '\t';
        if (in && !indented) break;
        const char *q = buf + strspn(buf, "\r");
        if (!in && strncmp(q, "** ", 3) != 0 && strncmp(q, "++ ", 3) != 0) continue;
        if (in && n && line[n - 1] != ':' && n + 2 < size) line[n++] = ';';
        in = 1;
        const char *p = buf;
        while (*p == '*' || *p == '+' || *p == '-' || *p == ' ' || *p == '\t' || *p == '\r') p++;
        if (n && n + 1 < size) line[n++] = ' ';
        for (; *p && n + 1 < size; p++) {
            int blank = (unsigned char)*p <= ' ';
            if (blank && (n == 0 || line[n - 1] == ' ')) continue;
            line[n++] = blank ? ' ' : *p;
        }
        while (n && line[n - 1] == ' ') n--;
    }
    line[n] = '\0';
    fclose(c->tmp);
}

/* fail() with libnifti2's line, when there is one, after ours. */
static int fail_lib(hd_error_t *err, int code, const char *path, const char *what,
                    const char *lib) {
    if (!lib[0]) return fail(err, code, path, what);
    char m[600];
    snprintf(m, sizeof m, "%s (libnifti2: %s)", what, lib);
    return fail(err, code, path, m);
}

/* ---- the header, as the file has it ------------------------------------ */

/* The fields we check, widened, in the machine's byte order. */
typedef struct {
    int version;       /* 1 or 2 */
    int swapped;       /* stored in the other byte order */
    size_t size;       /* 348 or 540 */
    int64_t dim[8];
    int datatype;
    double pixdim[8];
    double vox_offset; /* NIfTI-1: a float as stored; NIfTI-2: see vox_offset2 */
    int64_t vox_offset2;
    int qform_code, sform_code;
    double quatern[6]; /* quatern_b, c, d, qoffset_x, y, z */
    double srow[3][4];
    unsigned char magic[8];
} header_t;

static void get(const unsigned char *raw, size_t at, void *out, size_t n, int swap) {
    unsigned char b[8];
    for (size_t k = 0; k < n; k++) b[k] = raw[at + (swap ? n - 1 - k : k)];
    memcpy(out, b, n);
}
static int64_t get_i16(const unsigned char *r, size_t at, int sw) { int16_t v; get(r, at, &v, 2, sw); return v; }
static int64_t get_i32(const unsigned char *r, size_t at, int sw) { int32_t v; get(r, at, &v, 4, sw); return v; }
static int64_t get_i64(const unsigned char *r, size_t at, int sw) { int64_t v; get(r, at, &v, 8, sw); return v; }
static double get_f32(const unsigned char *r, size_t at, int sw) { float v; get(r, at, &v, 4, sw); return v; }
static double get_f64(const unsigned char *r, size_t at, int sw) { double v; get(r, at, &v, 8, sw); return v; }

/* The offsets below are the specification's; the library's structs agree. */
_Static_assert(sizeof(nifti_1_header) == 348 && sizeof(nifti_2_header) == 540, "NIfTI header sizes");
_Static_assert(offsetof(nifti_1_header, vox_offset) == 108 && offsetof(nifti_1_header, srow_x) == 280 &&
               offsetof(nifti_1_header, qform_code) == 252 && offsetof(nifti_1_header, magic) == 344,
               "NIfTI-1 offsets");
_Static_assert(offsetof(nifti_2_header, dim) == 16 && offsetof(nifti_2_header, vox_offset) == 168 &&
               offsetof(nifti_2_header, qform_code) == 344 && offsetof(nifti_2_header, srow_x) == 400,
               "NIfTI-2 offsets");

static void decode(const unsigned char *raw, int version, int sw, header_t *h) {
    memset(h, 0, sizeof *h);
    h->version = version;
    h->swapped = sw;
    if (version == 1) {
        h->size = 348;
        for (int k = 0; k < 8; k++) h->dim[k] = get_i16(raw, 40 + 2 * k, sw);
        h->datatype = (int)get_i16(raw, 70, sw);
        for (int k = 0; k < 8; k++) h->pixdim[k] = get_f32(raw, 76 + 4 * k, sw);
        h->vox_offset = get_f32(raw, 108, sw);
        h->qform_code = (int)get_i16(raw, 252, sw);
        h->sform_code = (int)get_i16(raw, 254, sw);
        for (int k = 0; k < 6; k++) h->quatern[k] = get_f32(raw, 256 + 4 * k, sw);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++) h->srow[r][c] = get_f32(raw, 280 + 16 * r + 4 * c, sw);
        memcpy(h->magic, raw + 344, 4);
    } else {
        h->size = 540;
        memcpy(h->magic, raw + 4, 8);
        h->datatype = (int)get_i16(raw, 12, sw);
        for (int k = 0; k < 8; k++) h->dim[k] = get_i64(raw, 16 + 8 * k, sw);
        for (int k = 0; k < 8; k++) h->pixdim[k] = get_f64(raw, 104 + 8 * k, sw);
        h->vox_offset2 = get_i64(raw, 168, sw);
        h->qform_code = (int)get_i32(raw, 344, sw);
        h->sform_code = (int)get_i32(raw, 348, sw);
        for (int k = 0; k < 6; k++) h->quatern[k] = get_f64(raw, 352 + 8 * k, sw);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++) h->srow[r][c] = get_f64(raw, 400 + 32 * r + 8 * c, sw);
    }
}

/* A header number as the messages show it: NaN and infinity spelled out. */
static const char *shown(double v, char buf[32]) {
    if (isnan(v)) return "NaN";
    if (isinf(v)) return v > 0 ? "infinite" : "minus infinity";
    snprintf(buf, 32, "%g", v);
    return buf;
}

/* Bytes per voxel of the types a mask can have; 0 for any other. */
static int voxel_bytes(int datatype) {
    switch (datatype) {
    case DT_UINT8: case DT_INT8: return 1;
    case DT_INT16: case DT_UINT16: return 2;
    case DT_INT32: case DT_UINT32: case DT_FLOAT32: return 4;
    case DT_INT64: case DT_UINT64: case DT_FLOAT64: return 8;
    default: return 0;
    }
}

/* What the checks leave for the reading. */
typedef struct {
    long long n[3];  /* voxels along i, j, k (1 for an axis beyond dim[0]) */
    int64_t nvox;    /* their product */
    int nbyper;
} geometry_t;

/* deflate expands at most about 1032:1 (258-byte matches coded in 2 bits),
 * so a gzip file of S bytes holds at most 1032 S bytes. */
#define GZIP_MAX_RATIO 1032

/* Every rule of docs/analysis.md, "What the header must satisfy", on the
 * header as stored; 0, or a refusal in err. */
static int check_header(const char *path, const header_t *h, long long file_size, int gzipped,
                        geometry_t *g, hd_error_t *err) {
    char m[256], b[32];
    static const char *const qnames[6] = {"quatern_b", "quatern_c", "quatern_d",
                                          "qoffset_x", "qoffset_y", "qoffset_z"};
    if (h->version == 1 ? memcmp(h->magic, "n+1\0", 4) != 0 : memcmp(h->magic, "n+2\0", 4) != 0) {
        char shown[16];
        size_t n = 0;
        for (int k = 0; k < 3; k++)
            if (h->magic[k] >= ' ' && h->magic[k] < 127) shown[n++] = (char)h->magic[k];
        shown[n] = '\0';
        snprintf(m, sizeof m,
                 "the header's magic is \"%s\", not \"n+%d\": only single-file NIfTI-%d (.nii) is read%s",
                 shown, h->version, h->version,
                 h->version == 1 && !memcmp(h->magic, "ni1", 3) ? " (ni1 keeps the voxels in a .img file)" : "");
        return fail(err, HD_EFORMAT, path, m);
    }
    int64_t nd = h->dim[0];
    if (nd < 1 || nd > 7) {
        snprintf(m, sizeof m, "dim[0] is %lld; the number of dimensions must be 1 to 7", (long long)nd);
        return fail(err, HD_EFORMAT, path, m);
    }
    for (int k = 1; k <= nd; k++)
        if (h->dim[k] < 1) {
            snprintf(m, sizeof m, "dim[%d] is %lld; every used dimension (dim[1..%d]) must be at least 1", k,
                     (long long)h->dim[k], (int)nd);
            return fail(err, HD_EFORMAT, path, m);
        }
    /* the voxel count, never trusting a product that overflows */
    int64_t nvox = 1;
    for (int k = 1; k <= nd; k++) {
        if (nvox > INT64_MAX / h->dim[k]) {
            snprintf(m, sizeof m,
                     "the dimensions dim[1..%d] multiply past 2^63 voxels at dim[%d] = %lld "
                     "(overflow): the header is corrupt",
                     (int)nd, k, (long long)h->dim[k]);
            return fail(err, HD_EOVERFLOW, path, m);
        }
        nvox *= h->dim[k];
    }
    int64_t volumes = 1;
    for (int k = 4; k <= nd; k++) volumes *= h->dim[k];
    if (volumes > 1) {
        snprintf(m, sizeof m, "has %lld volumes (dim[4..%d]); a mask is 3D", (long long)volumes, (int)nd);
        return fail(err, HD_EUNSUPPORTED, path, m);
    }
    int nbyper = voxel_bytes(h->datatype);
    if (!nbyper) {
        snprintf(m, sizeof m,
                 "datatype %d is not an integer or float type a mask can have "
                 "(2, 4, 8, 16, 64, 256, 512, 768, 1024, 1280)", h->datatype);
        return fail(err, HD_EUNSUPPORTED, path, m);
    }
    if (nvox > INT64_MAX / nbyper) {
        snprintf(m, sizeof m, "%lld voxels of %d bytes need more than 2^63 bytes (overflow)",
                 (long long)nvox, nbyper);
        return fail(err, HD_EOVERFLOW, path, m);
    }
    int64_t bytes = nvox * nbyper;
    /* where the voxels start */
    int64_t least = (int64_t)h->size + 4, off;
    if (h->version == 1) {
        if (!isfinite(h->vox_offset) || h->vox_offset != floor(h->vox_offset)) {
            snprintf(m, sizeof m, "vox_offset is %s, not a whole number of bytes", shown(h->vox_offset, b));
            return fail(err, HD_EFORMAT, path, m);
        }
        if (h->vox_offset < (double)least) {
            snprintf(m, sizeof m,
                     "vox_offset is %g, inside the 348-byte header and its 4 extension bytes "
                     "(the voxels of a .nii start at byte 352 or later)", h->vox_offset);
            return fail(err, HD_EFORMAT, path, m);
        }
        off = h->vox_offset > 0x1p62 ? INT64_C(1) << 62 : (int64_t)h->vox_offset;
    } else {
        off = h->vox_offset2;
        if (off < least) {
            snprintf(m, sizeof m,
                     "vox_offset is %lld, inside the 540-byte header and its 4 extension bytes "
                     "(the voxels of a NIfTI-2 .nii start at byte 544 or later)", (long long)off);
            return fail(err, HD_EFORMAT, path, m);
        }
    }
    if (!gzipped) {
        if (off > file_size) {
            snprintf(m, sizeof m, "vox_offset %lld is beyond the end of the file (%lld bytes)",
                     (long long)off, file_size);
            return fail(err, HD_EFORMAT, path, m);
        }
        if (bytes > file_size - off) {
            snprintf(m, sizeof m,
                     "holds %lld bytes of voxel data after vox_offset %lld, but the header's "
                     "%lld voxels of %d byte%s need %lld bytes",
                     file_size - off, (long long)off, (long long)nvox, nbyper, nbyper > 1 ? "s" : "",
                     (long long)bytes);
            return fail(err, HD_EFORMAT, path, m);
        }
    } else {
        long long most = file_size > INT64_MAX / GZIP_MAX_RATIO ? INT64_MAX : file_size * GZIP_MAX_RATIO;
        if (off > most || bytes > most - off) {
            snprintf(m, sizeof m,
                     "the header's %lld voxels of %d byte%s need %lld bytes after vox_offset %lld, "
                     "more than a gzip file of %lld bytes can hold (at most %d times its size)",
                     (long long)nvox, nbyper, nbyper > 1 ? "s" : "", (long long)bytes, (long long)off, file_size, GZIP_MAX_RATIO);
            return fail(err, HD_EFORMAT, path, m);
        }
    }
    /* the spacing and the transforms */
    for (int k = 1; k <= 3; k++)
        if (!isfinite(h->pixdim[k])) {
            snprintf(m, sizeof m, "pixdim[%d] (voxel spacing) is %s", k, shown(h->pixdim[k], b));
            return fail(err, HD_ENONFINITE, path, m);
        }
    if (h->sform_code <= 0)
        for (int k = 1; k <= 3 && k <= nd; k++)
            if (!(h->pixdim[k] > 0)) {
                snprintf(m, sizeof m,
                         "pixdim[%d] (voxel spacing) is %g; without an sform it sets the coordinates "
                         "and must be positive", k, h->pixdim[k]);
                return fail(err, HD_EFORMAT, path, m);
            }
    if (h->qform_code > 0) {
        if (isnan(h->pixdim[0])) {
            snprintf(m, sizeof m, "pixdim[0] (qfac, the qform's handedness) is NaN while qform_code is %d",
                     h->qform_code);
            return fail(err, HD_ENONFINITE, path, m);
        }
        for (int k = 0; k < 6; k++)
            if (!isfinite(h->quatern[k])) {
                snprintf(m, sizeof m, "%s is %s while qform_code is %d", qnames[k], shown(h->quatern[k], b),
                         h->qform_code);
                return fail(err, HD_ENONFINITE, path, m);
            }
    }
    if (h->sform_code > 0)
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++)
                if (!isfinite(h->srow[r][c])) {
                    snprintf(m, sizeof m, "srow_%c[%d] is %s while sform_code is %d", "xyz"[r], c,
                             shown(h->srow[r][c], b), h->sform_code);
                    return fail(err, HD_ENONFINITE, path, m);
                }
    g->n[0] = (long long)h->dim[1];
    g->n[1] = nd >= 2 ? (long long)h->dim[2] : 1;
    g->n[2] = nd >= 3 ? (long long)h->dim[3] : 1;
    g->nvox = nvox;
    g->nbyper = nbyper;
    return HD_OK;
}

/* Read and decode the header with libnifti2 (which knows gzip), then check
 * it; nothing of the voxels is read yet. */
static int read_header(const char *path, header_t *h, geometry_t *g, hd_error_t *err) {
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
        return fail(err, HD_EIO, path, "cannot open the mask (not a regular file)");
    int gzipped = 0;
    FILE *f = fopen(path, "rb");
    if (!f) return fail(err, HD_EIO, path, "cannot open the mask");
    unsigned char two[2];
    gzipped = fread(two, 1, 2, f) == 2 && two[0] == 0x1f && two[1] == 0x8b;
    fclose(f);

    captured_t cap;
    char lib[300];
    int nver = 0;
    nifti_set_debug_level(1); /* its default: it says why it failed */
    capture_begin(&cap);
    void *raw = nifti_read_header(path, &nver, 0);
    capture_end(&cap, lib, sizeof lib);
    if (raw && nver == 0) nver = 1; /* ANALYZE 7.5: NIfTI-1's layout, refused by its magic */
    if (!raw || (nver != 1 && nver != 2)) {
        free(raw);
        return fail_lib(err, HD_EFORMAT, path,
                        gzipped ? "not a readable NIfTI-1/2 image: no header could be read (sizeof_hdr "
                                  "must be 348 or 540, the magic n+1 or n+2), or the gzip stream is corrupt"
                                : "not a readable NIfTI-1/2 image: no header could be read (sizeof_hdr "
                                  "must be 348 or 540, the magic n+1 or n+2)", lib);
    }
    unsigned char bytes[540];
    memcpy(bytes, raw, nver == 1 ? 348 : 540);
    free(raw);
    int32_t sz;
    memcpy(&sz, bytes, 4);
    int want = nver == 1 ? 348 : 540;
    int sw = sz != want;
    if (sw && (int64_t)get_i32(bytes, 0, 1) != want)
        return fail(err, HD_EFORMAT, path, "not a readable NIfTI-1/2 image (sizeof_hdr is neither 348 nor 540)");
    decode(bytes, nver, sw, h);
    return check_header(path, h, (long long)st.st_size, gzipped, g, err);
}

/* ---- voxels to points -------------------------------------------------- */

/* The foreground of the image as one byte per voxel, or NULL. */
static unsigned char *foreground_of(const nifti_image *nim, size_t nvox, long long *count) {
    unsigned char *fg = malloc(nvox ? nvox : 1);
    if (!fg) return NULL;
    long long c = 0;
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
        default: { /* DT_FLOAT64: check_header admitted no other type */
            double f = ((const double *)nim->data)[v];
            on = f != 0 && !isnan(f);
            break;
        }
        }
        fg[v] = (unsigned char)on;
        c += on;
    }
    *count = c;
    return fg;
}

/* x = ((m0 i + m1 j) + m2 k) + m3, then the unit. */
static double world(const nifti_dmat44 *m, int c, double i, double j, double k, double to_mm) {
    double q = ((m->m[c][0] * i + m->m[c][1] * j) + m->m[c][2] * k) + m->m[c][3];
    return to_mm != 1.0 ? q * to_mm : q;
}

/* An image opened and checked: its header, the voxels libnifti2 read
 * (with our dimensions and type), the map and unit factor. */
typedef struct {
    header_t h;
    geometry_t g;
    nifti_image *nim;
    const nifti_dmat44 *m; /* sform when sform_code > 0, else qform */
    double to_mm;
} opened_t;

/* Read the header, check it, read the voxels, check the corners' world
 * coordinates against limit (float32: float range); on failure nothing is
 * held. */
static int open_image(const char *path, double limit, int float32, opened_t *o, hd_error_t *err) {
    memset(o, 0, sizeof *o);
    if (access(path, R_OK) != 0) return fail(err, HD_EIO, path, "cannot open the mask");
    header_t *h = &o->h;
    int rc = read_header(path, h, &o->g, err);
    if (rc) return rc;

    captured_t cap;
    char lib[300];
    capture_begin(&cap);
    nifti_image *nim = nifti_image_read(path, 1);
    capture_end(&cap, lib, sizeof lib);
    if (!nim || !nim->data) {
        if (nim) nifti_image_free(nim);
        return fail_lib(err, HD_EFORMAT, path,
                        "the voxels could not be read (fewer bytes than the header says, or a "
                        "corrupt gzip stream)", lib);
    }
    /* libnifti2 must have read what the header says, or we walk nothing */
    const long long *n = o->g.n;
    if ((int64_t)nim->nvox != o->g.nvox || nim->nx != n[0] || nim->ny != n[1] || nim->nz != n[2] ||
        nim->datatype != h->datatype || nim->nbyper != o->g.nbyper) {
        nifti_image_free(nim);
        return fail(err, HD_EFORMAT, path,
                    "libnifti2 read other dimensions or another voxel type than the header has");
    }
    const nifti_dmat44 *m = h->sform_code > 0 ? &nim->sto_xyz : &nim->qto_xyz;
    double to_mm = 1.0;
    if (nim->xyz_units == NIFTI_UNITS_METER) to_mm = 1000.0;
    else if (nim->xyz_units == NIFTI_UNITS_MICRON) to_mm = 0.001;
    /* the coordinates of the box's corners bound every voxel's */
    for (int corner = 0; corner < 8 && rc == HD_OK; corner++) {
        double i = corner & 1 ? (double)(n[0] - 1) : 0, j = corner & 2 ? (double)(n[1] - 1) : 0,
               k = corner & 4 ? (double)(n[2] - 1) : 0;
        for (int c = 0; c < 3; c++) {
            double q = world(m, c, i, j, k, to_mm);
            if (!(fabs(q) <= limit)) {
                char msg[256], b[32];
                snprintf(msg, sizeof msg, "the %s maps voxel (%.0f, %.0f, %.0f) to %c = %s mm, %s",
                         h->sform_code > 0 ? "sform" : h->qform_code > 0 ? "qform" : "pixdim scaling", i, j, k,
                         "xyz"[c], shown(q, b),
                         float32 ? "beyond float range (--float32)" : "beyond the limit 1e153 of coordinates");
                rc = fail(err, isnan(q) || isinf(q) ? HD_ENONFINITE : HD_ERANGE, path, msg);
                break;
            }
        }
    }
    if (rc) {
        nifti_image_free(nim);
        return rc;
    }
    o->nim = nim, o->m = m, o->to_mm = to_mm;
    return HD_OK;
}

/* What every read image tells the report. */
static void describe(const opened_t *o, long long foreground, mask_info_t *info) {
    memset(info, 0, sizeof *info);
    info->is_mask = 1;
    info->nifti_version = o->h.version;
    for (int a = 0; a < 3; a++) {
        info->dim[a] = o->g.n[a];
        info->spacing[a] = o->h.pixdim[a + 1];
    }
    info->foreground = foreground;
    info->transform = o->h.sform_code > 0 ? "sform" : o->h.qform_code > 0 ? "qform" : "pixdim";
    info->to_mm = o->to_mm;
    info->unit_known = o->nim->xyz_units == NIFTI_UNITS_METER || o->nim->xyz_units == NIFTI_UNITS_MM ||
                       o->nim->xyz_units == NIFTI_UNITS_MICRON;
}

static int read_mask(const char *path, const hd_read_options_t *ro,
                     const analysis_args_t *an, mask_info_t *info, hd_cloud_t **out,
                     hd_error_t *err) {
    mask_points_t which = an->mask_points;
    opened_t o;
    int rc = open_image(path, ro->dtype == HD_FLOAT32 ? FLT_MAX : HD_MAX_COORD, ro->dtype == HD_FLOAT32, &o, err);
    if (rc) return rc;
    const long long *n = o.g.n;
    unsigned char *fg = NULL;
    long long count = 0;
    if (!(fg = foreground_of(o.nim, (size_t)o.g.nvox, &count))) {
        nifti_image_free(o.nim);
        return fail(err, HD_ENOMEM, path, "out of memory");
    }
    describe(&o, count, info);
    /* the library finds the surface (medpy's and MONAI's erosion) and
     * places each voxel's centre as world() does */
    hd_mask_t mk;
    hd_mask_init(&mk, fg, (size_t)n[0], (size_t)n[1], (size_t)n[2], NULL);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++) mk.m[r][c] = o.m->m[r][c];
    mk.scale = o.to_mm;
    hd_mask_options_t mo;
    hd_mask_options_init(&mo);
    mo.points = which == MASK_ALL ? HD_MASK_ALL : HD_MASK_SURFACE;
    mo.connectivity = an->connectivity;
    mo.dims = an->mask_dims;
    mo.dtype = ro->dtype;
    hd_mask_info_t mi;
    rc = hd_mask_points(&mk, &mo, out, &mi, err);
    if (rc != HD_OK) {
        char m2[768];
        snprintf(m2, sizeof m2, "%.700s", err->message);
        fail(err, rc, path, m2);
    } else {
        snprintf((*out)->format, sizeof (*out)->format, "%s", which == MASK_ALL ? "nifti:all" : "nifti:surface");
        info->surface_dims = mi.surface_dims;
        info->connectivity = mi.connectivity;
    }
    size_t np = rc == HD_OK ? mi.points : 0;
    info->points = np;
    free(fg);
    nifti_image_free(o.nim);
    return rc;
}

/* The label type of a NIfTI integer datatype; -1 for a float type. */
static int label_type_of(int datatype) {
    switch (datatype) {
    case DT_UINT8: return HD_LABEL_U8;
    case DT_INT8: return HD_LABEL_I8;
    case DT_UINT16: return HD_LABEL_U16;
    case DT_INT16: return HD_LABEL_I16;
    case DT_UINT32: return HD_LABEL_U32;
    case DT_INT32: return HD_LABEL_I32;
    case DT_INT64: return HD_LABEL_I64;
    case DT_UINT64: return HD_LABEL_U64;
    default: return -1;
    }
}

/* Float voxels as int64 labels: each must be a whole number within
 * +-2^53 (labels stored as float are small integers); NaN is refused. */
static int64_t *whole_labels(const nifti_image *nim, size_t nvox, const char *path, hd_error_t *err) {
    int64_t *l = malloc(nvox ? nvox * sizeof *l : 1);
    if (!l) {
        fail(err, HD_ENOMEM, path, "out of memory");
        return NULL;
    }
    for (size_t v = 0; v < nvox; v++) {
        double f = nim->datatype == DT_FLOAT32 ? (double)((const float *)nim->data)[v]
                                               : ((const double *)nim->data)[v];
        if (!(f == floor(f) && fabs(f) <= 9007199254740992.0)) {
            char msg[160], b[32];
            snprintf(msg, sizeof msg, "voxel %zu holds %s: a label map of floats holds whole numbers only", v,
                     shown(f, b));
            free(l);
            fail(err, HD_EFORMAT, path, msg);
            return NULL;
        }
        l[v] = (int64_t)f;
    }
    return l;
}

int nifti_read_labels(const char *path, nifti_labels_t *out, hd_error_t *err) {
    memset(out, 0, sizeof *out);
    opened_t o;
    int rc = open_image(path, HD_MAX_COORD, 0, &o, err);
    if (rc) return rc;
    const long long *n = o.g.n;
    int type = label_type_of(o.nim->datatype);
    const void *values = o.nim->data;
    if (type < 0) {
        if (!(out->converted = whole_labels(o.nim, (size_t)o.g.nvox, path, err))) {
            nifti_image_free(o.nim);
            return err->code ? err->code : HD_ENOMEM;
        }
        values = out->converted;
        type = HD_LABEL_I64;
    }
    describe(&o, 0, &out->info);
    hd_label_image_init(&out->img, values, (hd_label_type_t)type, (size_t)n[0], (size_t)n[1], (size_t)n[2], NULL);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++) out->img.m[r][c] = o.m->m[r][c];
    out->img.scale = o.to_mm;
    out->image = o.nim;
    return HD_OK;
}

void nifti_labels_free(nifti_labels_t *l) {
    if (l->image) nifti_image_free(l->image);
    free(l->converted);
    memset(l, 0, sizeof *l);
}

#else

int nifti_available(void) { return 0; }

int nifti_read_labels(const char *path, nifti_labels_t *out, hd_error_t *err) {
    memset(out, 0, sizeof *out);
    return fail(err, HD_EUNSUPPORTED, path,
                "NIfTI label maps are unavailable: this hausdorff was built without libnifti2 "
                "(Debian: libnifti2-dev)");
}

void nifti_labels_free(nifti_labels_t *l) { memset(l, 0, sizeof *l); }

static int read_mask(const char *path, const hd_read_options_t *ro,
                     const analysis_args_t *an, mask_info_t *info, hd_cloud_t **out,
                     hd_error_t *err) {
    (void)ro, (void)an, (void)info, (void)out;
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
        rc = read_mask(path, ro, an, &an->mask[which], out, err);
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
    if (an->empty == HD_EMPTY_ERROR) {
        size_t len = strlen(err->message);
        snprintf(err->message + len, sizeof err->message - len,
                 " (an empty set has no distance; --empty inf|nan|zero|monai reports one)");
        return rc;
    }
    if (!(*out = cli_cloud_new(0, ro->dtype, "empty"))) return fail(err, HD_ENOMEM, path, "out of memory");
    return HD_OK;
}
