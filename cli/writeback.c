/*
 * writeback.c -- per-point distances written into the inputs' own files
 * (hd_write_fields): --distances OUT when OUT names the side's format
 * (.las, .laz, .ply, text: a `distance` field added to every point,
 * everything else kept), and --farther-than D OUT / --nearer-than D OUT
 * (the points whose distance is > D / <= D, in their file's format, the
 * field included).  A's file gets A's distances to B; without --directed,
 * B's file OUT_b.EXT gets B's to A.  What can be written is checked before
 * anything is read (a mismatch of formats is a usage error, not a failure
 * after the distances are computed).
 *
 * .csv and .npy are always the per-point tables (writers.c).  .ply is the
 * side's own PLY with the fields when that side was read from one regular
 * PLY file as its points (not sampled, not a mask, not standard input, not
 * tiles); otherwise the table.  So a PLY written back holds what the table held
 * for each point: `distance`, then the table's index column as a double
 * (`nearest`, -1 with an empty other side; `face` with --surface), and
 * `sign` with --signed.  Other formats get `distance` (and `sign`) only.
 *
 * Every field of a file is written by one hd_write_fields call, in one pass
 * over the input, into the output's temporary.
 * A FIFO or device as OUT (hd_write_fields renames its result into place)
 * gets the bytes of the finished file, made under $TMPDIR and removed.
 */
#include "cli.h"
#include "output.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *ext_of(const char *path) {
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    return dot && (!slash || dot > slash) ? dot + 1 : "";
}

/* The side's format as the reader chooses it from its name. */
static const char *side_format(const char *in_path, const char *format, const hd_read_options_t *ro) {
    if (format) return format;
    if (ro->format) return ro->format;
    return hd_format_of_path(in_path);
}

/* 1 when path exists and is not a regular file (a FIFO, a device): it is
 * written in place, not renamed into place. */
static int is_special(const char *path) {
    struct stat st;
    return stat(path, &st) == 0 && !S_ISREG(st.st_mode);
}

/* 1 when side w's points are its one regular file's own points, numbered
 * as the file holds them (not drawn on faces, not a mask's voxels, not a
 * pipe or standard input, not a directory of tiles). */
static int own_points(const analysis_args_t *an, int w, const char *in_path) {
    struct stat st;
    return an->read.mesh != HD_MESH_SAMPLE && !an->mask[w].is_mask && !nifti_is_mask_path(in_path) &&
           strcmp(in_path, "-") != 0 && stat(in_path, &st) == 0 && S_ISREG(st.st_mode);
}

int analysis_writes_back(const analysis_args_t *an, int w, const char *out, const char *in_path) {
    const char *e = ext_of(out);
    if (strcasecmp(e, "csv") == 0 || strcasecmp(e, "npy") == 0) return 0;
    if (strcasecmp(e, "ply") == 0) {
        const char *in = side_format(in_path, an->format[w], &an->read);
        return in && strcmp(in, "ply") == 0 && own_points(an, w, in_path);
    }
    return hd_format_of_path(out) != NULL;
}

int analysis_writeback_format_known(const char *out) {
    const char *f = hd_format_of_path(out);
    return f && (strcmp(f, "ply") == 0 || strcmp(f, "las") == 0 || strcmp(f, "laz") == 0 || strcmp(f, "xyz") == 0 ||
                 strcmp(f, "obj") == 0);
}

static const char *const what[3] = {"--distances", "--farther-than", "--nearer-than"};

/* The output of kind k for side w (B's: OUT_b.EXT, malloc'd into *owned),
 * or NULL when that kind writes nothing into the side's format. */
static const char *output(const analysis_args_t *an, int k, int w, const char *path, char **owned) {
    const char *out = k == 0 ? an->distances_out : an->subset[k - 1].on ? an->subset[k - 1].out : NULL;
    *owned = NULL;
    if (!out) return NULL;
    if (w && !(out = *owned = path_with_suffix(out, "_b"))) return NULL;
    if (k == 0 && !analysis_writes_back(an, w, out, path)) {
        free(*owned);
        return *owned = NULL;
    }
    return out;
}

static int check_side(const analysis_args_t *an, int k, const char *out, const char *path, int w, hd_error_t *err) {
    const char *in = side_format(path, an->format[w], &an->read), *of = hd_format_of_path(out);
    const char *side = w ? "B" : "A";
    int code = HD_EINVAL;
    if (an->read.mesh == HD_MESH_SAMPLE)
        snprintf(err->message, sizeof err->message,
                 "%s %s: with --sample the points are drawn on the faces, not the file's own: nothing to write "
                 "back (write the distances as .csv, .ply or .npy)",
                 what[k], out);
    else if (an->mask[w].is_mask || nifti_is_mask_path(path))
        snprintf(err->message, sizeof err->message,
                 "%s %s: %s (%s) is a NIfTI mask, whose points are voxel centres: nothing to write back (write the "
                 "distances as .csv, .ply or .npy)",
                 what[k], out, side, path);
    else if (!in || !of || strcmp(in, of) != 0)
        snprintf(err->message, sizeof err->message,
                 "%s %s: a file written back has its input's format, and %s (%s) is %s, %s is %s; name it with "
                 "%s's extension%s",
                 what[k], out, side, path, in ? in : "no single file of a known format", out,
                 of ? of : "no format", side, k == 0 ? " (or .csv, .ply, .npy for the coordinates with their distances)" : "");
    else
        code = HD_OK;
    if (code) err->code = code;
    return code;
}

int analysis_check_outputs(const analysis_args_t *an, const char *path_a, const char *path_b, int directed,
                           hd_error_t *err) {
    const char *path[2] = {path_a, path_b};
    for (int k = 0; k < 3; k++)
        for (int w = 0; w < (directed ? 1 : 2); w++) {
            char *owned;
            const char *out = output(an, k, w, path[w], &owned);
            int rc = out ? check_side(an, k, out, path[w], w, err) : HD_OK;
            free(owned);
            if (rc) return rc;
        }
    return HD_OK;
}

/* ---- the fields of one file ---------------------------------------------- */

enum { MAX_FIELDS = 3 };
typedef struct {
    hd_field_t f[MAX_FIELDS]; /* f[0]: the distances, which select the points */
    double *owned[MAX_FIELDS];
    int count;
} fields_t;

static void fields_free(fields_t *f) {
    for (int i = 0; i < f->count; i++) free(f->owned[i]);
}

/* One more field of every point: index (as double, -1 for none) or sign. */
static int add_field(fields_t *f, const char *name, const writeback_side_t *s, int is_sign, hd_error_t *err) {
    double *v = malloc((s->n ? s->n : 1) * sizeof *v);
    if (!v) {
        snprintf(err->message, sizeof err->message, "out of memory for %zu values of '%s'", s->n, name);
        return err->code = HD_ENOMEM;
    }
    for (size_t k = 0; k < s->n; k++) v[k] = is_sign ? (double)s->sign[k] : s->index ? (double)s->index[k] : -1.0;
    f->f[f->count].name = name, f->f[f->count].values = v, f->owned[f->count++] = v;
    return HD_OK;
}

/* The fields of kind k's file for side s: distance; in a PLY written by
 * --distances the table's index column; with --signed the sign. */
static int side_fields(int k, const char *out, const writeback_side_t *s, int surface, fields_t *f, hd_error_t *err) {
    memset(f, 0, sizeof *f);
    f->f[0].name = "distance", f->f[0].values = s->d, f->count = 1;
    const char *fmt = hd_format_of_path(out);
    int rc = HD_OK;
    if (k == 0 && fmt && strcmp(fmt, "ply") == 0) rc = add_field(f, surface ? "face" : "nearest", s, 0, err);
    if (rc == HD_OK && s->sign) rc = add_field(f, "sign", s, 1, err);
    return rc;
}

/* ---- writing ------------------------------------------------------------- */

/* The name of out's temporary from output.c (malloc'd), so that out
 * appears with the run's other files when the run succeeds (out_finish)
 * and not at all when it fails (out_discard); NULL with err set. */
static char *stage(const char *out, hd_error_t *err) {
    FILE *f = out_open(out, err);
    if (!f) return NULL;
    const char *tmp = out_file_path(f);
    char *name = tmp ? strdup(tmp) : NULL;
    int direct = out_is_direct(f), rc = out_close(f, 0, err);
    if (rc == HD_OK && (!name || direct)) {
        snprintf(err->message, sizeof err->message, "%s: %s", out,
                 direct ? "a device or FIFO cannot take a file written back (it is renamed into place); name a file"
                        : "out of memory");
        err->code = direct ? HD_EINVAL : HD_ENOMEM;
        rc = err->code;
    }
    if (rc != HD_OK) {
        free(name);
        return NULL;
    }
    return name;
}

/* A failure to write a file of ours is the output's (OUT_EFAIL: exit 3),
 * named as the output. */
static int as_output(int rc, const char *name, const char *out, hd_error_t *err) {
    if (rc == HD_EIO && strncmp(err->message, name, strlen(name)) == 0) {
        char reason[200];
        snprintf(reason, sizeof reason, "%s", err->message + strlen(name));
        snprintf(err->message, sizeof err->message, "%.800s%s", out, reason);
        rc = err->code = OUT_EFAIL;
    }
    return rc;
}

/* A new empty file under $TMPDIR (else /tmp), for a FIFO's or device's
 * file: its name (malloc'd), or NULL with err set. */
static char *scratch(const char *out, hd_error_t *err) {
    const char *dir = getenv("TMPDIR");
    if (!dir || !*dir) dir = "/tmp";
    size_t len = strlen(dir) + 32;
    char *name = malloc(len);
    int fd = -1;
    if (name) {
        snprintf(name, len, "%s/hausdorff-XXXXXX", dir);
        fd = mkstemp(name);
    }
    if (fd < 0) {
        snprintf(err->message, sizeof err->message, "%.600s: cannot make a file in %.300s to write it from: %s", out,
                 dir, name ? strerror(errno) : "out of memory");
        err->code = OUT_EFAIL;
        free(name);
        return NULL;
    }
    close(fd);
    return name;
}

/* The finished file's bytes into out, a FIFO or device (out_open writes
 * it in place). */
static int copy_into(const char *from, const char *out, hd_error_t *err) {
    FILE *f = out_open(out, err);
    if (!f) return err->code;
    FILE *in = fopen(from, "rb");
    int werr = in ? 0 : errno ? errno : -1;
    static char buf[1 << 16];
    for (size_t n; !werr && (n = fread(buf, 1, sizeof buf, in)) > 0;)
        if (fwrite(buf, 1, n, f) != n) werr = errno ? errno : -1;
    if (in && ferror(in) && !werr) werr = EIO;
    if (in) fclose(in);
    return out_close(f, werr, err);
}

/* The fields into out in one hd_write_fields call, written to out's
 * temporary from output.c; for a FIFO or device, to a scratch file whose
 * bytes are then copied into it. */
static int write_out(const char *in, const char *out, const fields_t *f, const hd_write_options_t *o, size_t n,
                     size_t *written, hd_error_t *err) {
    int special = is_special(out);
    char *name = special ? scratch(out, err) : stage(out, err);
    if (!name) return err->code;
    int rc = hd_write_fields(in, name, f->f, (size_t)f->count, n, o, written, err);
    rc = as_output(rc, name, out, err);
    if (special) {
        if (rc == HD_OK) rc = copy_into(name, out, err);
        unlink(name);
    }
    free(name);
    return rc;
}

int analysis_write_back(const analysis_args_t *an, const char *path_a, const char *path_b,
                        const writeback_side_t side[2], int directed, int surface, analysis_result_t *r,
                        hd_error_t *err) {
    const char *path[2] = {path_a, path_b};
    for (int k = 0; k < 3; k++)
        for (int w = 0; w < (directed ? 1 : 2); w++) {
            char *owned;
            const char *out = output(an, k, w, path[w], &owned);
            if (!out) continue;
            if (w) r->wb_path_b[k] = owned;
            hd_read_options_t ro = an->read;
            if (an->format[w]) ro.format = an->format[w];
            hd_write_options_t o;
            hd_write_options_init(&o);
            o.read = &ro;
            o.format = hd_format_of_path(out);
            if (k) {
                o.keep = k == 1 ? HD_KEEP_FARTHER : HD_KEEP_NEARER;
                o.threshold = an->subset[k - 1].d;
            }
            fields_t f;
            int rc = side_fields(k, out, &side[w], surface, &f, err);
            if (rc == HD_OK) rc = write_out(path[w], out, &f, &o, side[w].n, &r->wb_points[k][w], err);
            fields_free(&f);
            if (rc) return rc;
            r->wb_sides[k] |= 1 << w;
        }
    return HD_OK;
}

/* The file side w got from kind k. */
static const char *side_out(const analysis_args_t *an, const analysis_result_t *r, int k, int w) {
    return w ? r->wb_path_b[k] : k == 0 ? an->distances_out : an->subset[k - 1].out;
}

void analysis_write_back_print(FILE *out, const analysis_args_t *an, const analysis_result_t *r) {
    char t[NUM_TEXT];
    for (int k = 0; k < 3; k++) {
        int sides = r->wb_sides[k];
        if (!sides) continue;
        if (k == 0) {
            fprintf(out, "distances written into %s", safe_text(side_out(an, r, 0, !(sides & 1))));
            if (sides == 3) fprintf(out, " and %s", safe_text(side_out(an, r, 0, 1)));
        } else {
            fprintf(out, "points %s %s written: %zu of A's to %s", k == 1 ? "farther than" : "within",
                    num_text(an->subset[k - 1].d, t), r->wb_points[k][0], safe_text(side_out(an, r, k, 0)));
            if (sides & 2) fprintf(out, ", %zu of B's to %s", r->wb_points[k][1], safe_text(side_out(an, r, k, 1)));
        }
        fputc('\n', out);
    }
}

void analysis_write_back_json(FILE *out, const analysis_args_t *an, const analysis_result_t *r) {
    static const char *const key[3] = {"distances_written_back", "farther_than", "nearer_than"};
    for (int k = 0; k < 3; k++) {
        if (!r->wb_sides[k]) continue;
        fprintf(out, ", \"%s\": {", key[k]);
        if (k) {
            fputs("\"d\": ", out);
            json_number(out, an->subset[k - 1].d);
            fputs(", ", out);
        }
        for (int w = 0; w < 2; w++) {
            fputs(w ? ", \"b\": " : "\"a\": ", out);
            if (!(r->wb_sides[k] >> w & 1)) {
                fputs("null", out);
                continue;
            }
            fputs("{\"file\": ", out);
            json_string(out, side_out(an, r, k, w));
            fprintf(out, ", \"points\": %zu}", r->wb_points[k][w]);
        }
        fputc('}', out);
    }
}
