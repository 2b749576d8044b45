/*
 * writeback.c -- per-point distances written into the inputs' own files
 * (hd_write_field): --distances OUT when OUT names the side's format
 * (.las, .laz, text: a `distance` field added to every point, everything
 * else kept; .ply stays the table both tools write, byte for byte), and
 * --farther-than D OUT /
 * --nearer-than D OUT (the points whose distance is > D / <= D, in their
 * file's format, the field included).  A's file gets A's distances to B;
 * without --directed, B's file OUT_b.EXT gets B's to A.  What can be
 * written is checked before anything is read (a mismatch of formats is a
 * usage error, not a failure after the distances are computed).
 */
#include "cli.h"
#include "output.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

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

int analysis_writes_back(const char *out, const char *in_path, const char *format) {
    (void)in_path, (void)format;
    const char *e = ext_of(out);
    /* .csv, .npy and .ply are the tables hausdorff-mpi writes too, byte for
     * byte (a PLY side's own file with the field: --farther-than 0 /
     * --nearer-than, the library, Python) */
    if (strcasecmp(e, "csv") == 0 || strcasecmp(e, "npy") == 0 || strcasecmp(e, "ply") == 0) return 0;
    return hd_format_of_path(out) != NULL;
}

int analysis_writeback_format_known(const char *out) {
    const char *f = hd_format_of_path(out);
    return f && (strcmp(f, "ply") == 0 || strcmp(f, "las") == 0 || strcmp(f, "laz") == 0 || strcmp(f, "xyz") == 0 ||
                 strcmp(f, "obj") == 0);
}

static const char *const what[3] = {"--distances", "--farther-than", "--nearer-than"};

/* The output of kind k for side w (B's: OUT_b.EXT, malloc'd into *owned),
 * or NULL when that kind writes nothing for the side. */
static const char *output(const analysis_args_t *an, int k, int w, const char *path, char **owned) {
    const char *out = k == 0 ? an->distances_out : an->subset[k - 1].on ? an->subset[k - 1].out : NULL;
    *owned = NULL;
    if (!out || (k == 0 && !analysis_writes_back(out, path, an->format[w] ? an->format[w] : an->read.format)))
        return NULL;
    if (w == 0) return out;
    return *owned = path_with_suffix(out, "_b");
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

/* hd_write_field into out's temporary from output.c, so that out appears
 * with the run's other files when the run succeeds (out_finish) and not at
 * all when it fails (out_discard); its failures to write are output
 * failures (OUT_EFAIL: exit 3). */
static int write_staged(const char *in, const char *out, const double *d, size_t n, hd_write_options_t *o,
                        size_t *written, hd_error_t *err) {
    FILE *f = out_open(out, err);
    if (!f) return err->code;
    const char *tmp = out_file_path(f);
    char *name = tmp ? strdup(tmp) : NULL;
    int direct = out_is_direct(f), rc = out_close(f, 0, err);
    if (rc == HD_OK && (!name || direct)) {
        snprintf(err->message, sizeof err->message, "%s: %s", out,
                 direct ? "a device or FIFO cannot take a file written back (it is renamed into place); name a file"
                        : "out of memory");
        rc = err->code = direct ? HD_EINVAL : HD_ENOMEM;
    }
    o->format = hd_format_of_path(out);
    if (rc == HD_OK) rc = hd_write_field(in, name, d, n, o, written, err);
    if (rc == HD_EIO && name && strncmp(err->message, name, strlen(name)) == 0) {
        /* the temporary's name in the message is the output's */
        char reason[200];
        snprintf(reason, sizeof reason, "%s", err->message + strlen(name));
        snprintf(err->message, sizeof err->message, "%.800s%s", out, reason);
        rc = err->code = OUT_EFAIL;
    }
    free(name);
    return rc;
}

int analysis_write_back(const analysis_args_t *an, const char *path_a, const char *path_b, const double *d_ab,
                        size_t n_a, const double *d_ba, size_t n_b, int directed, analysis_result_t *r,
                        hd_error_t *err) {
    const char *path[2] = {path_a, path_b};
    const double *d[2] = {d_ab, d_ba};
    size_t n[2] = {n_a, n_b};
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
            if (k) {
                o.keep = k == 1 ? HD_KEEP_FARTHER : HD_KEEP_NEARER;
                o.threshold = an->subset[k - 1].d;
            }
            int rc = write_staged(path[w], out, d[w], n[w], &o, &r->wb_points[k][w], err);
            if (rc) return rc;
            r->wb_done[k] = 1;
        }
    return HD_OK;
}

void analysis_write_back_print(FILE *out, const analysis_args_t *an, const analysis_result_t *r) {
    char t[NUM_TEXT];
    for (int k = 0; k < 3; k++) {
        if (!r->wb_done[k]) continue;
        const char *a = k == 0 ? an->distances_out : an->subset[k - 1].out;
        if (k == 0) fprintf(out, "distances written into %s", safe_text(a));
        else fprintf(out, "points %s %s written: %zu of A's to %s", k == 1 ? "farther than" : "within",
                     num_text(an->subset[k - 1].d, t), r->wb_points[k][0], safe_text(a));
        if (!r->directed && r->wb_path_b[k]) {
            if (k == 0) fprintf(out, " and %s", safe_text(r->wb_path_b[k]));
            else fprintf(out, ", %zu of B's to %s", r->wb_points[k][1], safe_text(r->wb_path_b[k]));
        }
        fputc('\n', out);
    }
}

void analysis_write_back_json(FILE *out, const analysis_args_t *an, const analysis_result_t *r) {
    static const char *const key[3] = {"distances_written_back", "farther_than", "nearer_than"};
    for (int k = 0; k < 3; k++) {
        if (!r->wb_done[k]) continue;
        fprintf(out, ", \"%s\": {", key[k]);
        if (k) {
            fputs("\"d\": ", out);
            json_number(out, an->subset[k - 1].d);
            fputs(", ", out);
        }
        fputs("\"a\": {\"file\": ", out);
        json_string(out, k == 0 ? an->distances_out : an->subset[k - 1].out);
        fprintf(out, ", \"points\": %zu}, \"b\": ", r->wb_points[k][0]);
        if (r->directed || !r->wb_path_b[k]) {
            fputs("null", out);
        } else {
            fputs("{\"file\": ", out);
            json_string(out, r->wb_path_b[k]);
            fprintf(out, ", \"points\": %zu}", r->wb_points[k][1]);
        }
        fputc('}', out);
    }
}
