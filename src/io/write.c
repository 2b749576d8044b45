/*
 * write.c -- hd_write_fields and hd_write_field: per-point fields written
 * back into the input's own format (hausdorff.h has the contract, docs/formats.md the
 * formats).
 *
 * The input is read twice: first by hd_read_file, with the caller's read
 * options, which checks it as every read does and gives the number of
 * points the values must match; then mapped by the writer of its format,
 * which walks the same bytes again and copies them, point k being the k-th
 * point of that read.  Since the first read accepted the file, a writer's
 * walk meets only what the reader accepted; it still checks every bound it
 * relies on.  An input that is not a regular file (a pipe, standard input)
 * cannot be read twice and is refused before anything is read.
 *
 * Output: a temporary file beside out_path (same directory, so the rename
 * is atomic), written through one buffered stream whose first failing
 * write is kept (errno) and stops the writer's useful work; then fflush,
 * fsync and fclose are checked, and only then is it renamed over out_path.
 * On any failure the temporary is removed, so out_path is either the whole
 * result or as it was: a full disk (ENOSPC) and a file size limit (EFBIG,
 * SIGXFSZ being ignored by the caller or not: write() fails either way once
 * the signal is ignored, and a process killed by it leaves only the
 * temporary) are HD_EIO with the reason.
 */
#include "io.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

void hd_write_options_init(hd_write_options_t *opt) {
    memset(opt, 0, sizeof *opt);
    opt->name = "distance";
    opt->keep = HD_KEEP_ALL;
}

/* A name LAS, PLY and CSV all take as one token. */
static int good_name(const char *s) {
    size_t n = strlen(s);
    if (n > 31) return 0;
    for (size_t k = 0; k < n; k++) {
        unsigned char c = (unsigned char)s[k];
        if (!(c == '_' || (c >= '0' && c <= '9') || ((c | 0x20) >= 'a' && (c | 0x20) <= 'z'))) return 0;
    }
    return n == 0 || !(s[0] >= '0' && s[0] <= '9');
}

/* The input's format: the read options' name, else by content for PLY and
 * LAS/LAZ (their signatures), else by extension. */
static const char *input_format(const hd__file_t *f, const hd_read_options_t *ro) {
    if (f->size >= 4 && memcmp(f->data, "LASF", 4) == 0)
        return f->size > 104 && (f->data[104] & 0x80) ? "laz" : "las";
    if (f->size >= 3 && memcmp(f->data, "ply", 3) == 0) return "ply";
    if (ro->format) return ro->format;
    return hd_format_of_path(f->name);
}

/* Map the regular file at path into f (size 0: data points at a static
 * byte); HD_OK or the error. */
static int map_input(const char *path, hd__file_t *f, struct stat *st, hd_error_t *err) {
    if (strcmp(path, "-") == 0)
        return hd__err(err, HD_EUNSUPPORTED, "-: standard input cannot take a field: writing one reads the input twice; "
                                             "save it to a file first");
    int fd = open(path, O_RDONLY | O_NONBLOCK); /* a FIFO must not block here: it is refused below */
    if (fd < 0) return hd__err(err, HD_EIO, "%s: cannot open: %s", path, strerror(errno));
    if (fstat(fd, st) != 0 || !S_ISREG(st->st_mode)) {
        close(fd);
        return hd__err(err, HD_EUNSUPPORTED,
                       "%s: is not a regular file (a pipe, a device or standard input): writing a field reads the "
                       "input twice; save it to a file first",
                       path);
    }
    static const unsigned char empty[1];
    f->name = path;
    f->size = (size_t)st->st_size;
    f->data = empty;
    if (f->size) {
        void *m = mmap(NULL, f->size, PROT_READ, MAP_PRIVATE, fd, 0);
        if (m == MAP_FAILED) {
            int e = errno;
            close(fd);
            return hd__err(err, e == ENOMEM ? HD_ENOMEM : HD_EIO, "%s: cannot map: %s", path, strerror(e));
        }
        f->data = m;
    }
    close(fd);
    return HD_OK;
}

/* The temporary beside out_path: its name in *tmp (malloc'd) and a
 * buffered stream, or NULL with err set.  Created with open(O_EXCL, 0666),
 * so it gets a new file's permissions under the process's umask (mkstemp's
 * 0600 would need umask() to widen, which is not thread safe). */
static FILE *open_temp(const char *out_path, char **tmp, hd_error_t *err) {
    size_t n = strlen(out_path);
    *tmp = malloc(n + 32);
    if (!*tmp) {
        hd__err(err, HD_ENOMEM, "out of memory");
        return NULL;
    }
    static const char digits[] = "0123456789abcdefghijklmnopqrstuvwxyz";
    uint64_t seed = (uint64_t)getpid() * 0x9E3779B97F4A7C15ull ^ (uint64_t)(uintptr_t)tmp ^ (uint64_t)(hd__now() * 1e9);
    int fd = -1;
    for (int attempt = 0; attempt < 100 && fd < 0; attempt++) {
        char suffix[7];
        for (int k = 0; k < 6; k++) {
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            suffix[k] = digits[(seed >> 33) % 36];
        }
        suffix[6] = 0;
        snprintf(*tmp, n + 32, "%s.tmp-%s", out_path, suffix);
        fd = open(*tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0 && errno != EEXIST) break;
    }
    if (fd < 0) {
        hd__err(err, HD_EIO, "%s: cannot create: %s", out_path, strerror(errno));
        free(*tmp);
        *tmp = NULL;
        return NULL;
    }
    FILE *f = fdopen(fd, "wb");
    if (!f) {
        hd__err(err, HD_EIO, "%s: cannot open: %s", out_path, strerror(errno));
        close(fd);
        unlink(*tmp);
        free(*tmp);
        *tmp = NULL;
        return NULL;
    }
    setvbuf(f, NULL, _IOFBF, 1 << 20);
    return f;
}

/* Flush, sync and close w->out, and rename the temporary over out_path;
 * on any failure (a write's kept errno included) remove the temporary. */
static int finish(hd__writer_t *w, const char *tmp, const char *out_path, int rc) {
    int e = w->werr;
    errno = 0;
    if (fflush(w->out) != 0 && !e) e = errno ? errno : EIO;
    if (!e && ferror(w->out)) e = EIO;
    if (!e && rc == HD_OK && fsync(fileno(w->out)) != 0 && errno != EINVAL) e = errno;
    if (fclose(w->out) != 0 && !e) e = errno ? errno : EIO;
    if (rc == HD_OK && e) rc = hd__err(w->err, HD_EIO, "%s: cannot write: %s", out_path, strerror(e));
    if (rc == HD_OK && rename(tmp, out_path) != 0)
        rc = hd__err(w->err, HD_EIO, "%s: cannot rename the finished file to it: %s", out_path, strerror(errno));
    if (rc != HD_OK) unlink(tmp);
    return rc;
}

static int check_args(const char *in_path, const char *out_path, const hd_write_options_t *o, hd_error_t *err) {
    if (!in_path || !out_path) return hd__err(err, HD_EINVAL, "hd_write_fields: NULL argument");
    if (o->keep != HD_KEEP_ALL && o->keep != HD_KEEP_FARTHER && o->keep != HD_KEEP_NEARER)
        return hd__err(err, HD_EINVAL, "hd_write_fields: keep is %d (HD_KEEP_ALL, _FARTHER or _NEARER)", (int)o->keep);
    if (o->keep != HD_KEEP_ALL && !isfinite(o->threshold))
        return hd__err(err, HD_EINVAL, "the threshold %g is not a finite number", o->threshold);
    const hd_read_options_t *r = o->read;
    if (r && (r->range_count || r->mesh == HD_MESH_SAMPLE))
        return hd__err(err, HD_EINVAL, "%s: a field is written for every point of the file: a range read or mesh "
                                       "sampling does not number them",
                       in_path);
    return HD_OK;
}

/* The fields: their values given, names good and distinct. */
static int check_fields(const hd_field_t *f, size_t nf, size_t n, hd_error_t *err) {
    if (nf > HD__FIELDS_MAX)
        return hd__err(err, HD_EINVAL, "hd_write_fields: %zu fields, at most %d (8 bytes each in a record of 65535)", nf,
                       HD__FIELDS_MAX);
    for (size_t j = 0; j < nf; j++) {
        if (!f[j].name || (!f[j].values && n)) return hd__err(err, HD_EINVAL, "hd_write_fields: field %zu: NULL", j + 1);
        if (!f[j].name[0] || !good_name(f[j].name))
            return hd__err(err, HD_EINVAL, "field name '%.40s': letters, digits and '_' (not first a digit), 1 to 31",
                           f[j].name);
        for (size_t i = 0; i < j; i++)
            if (strcmp(f[i].name, f[j].name) == 0)
                return hd__err(err, HD_EINVAL, "fields %zu and %zu are both named '%s'", i + 1, j + 1, f[j].name);
    }
    return HD_OK;
}

/* The point count as hd_read_file gives it (the input checked as any read
 * checks it). */
static int count_points(const char *in_path, const hd_read_options_t *ro, size_t *count, hd_error_t *err) {
    hd_read_options_t r = *ro;
    r.dtype = HD_FLOAT64;
    hd_cloud_t *c = NULL;
    int rc = hd_read_file(in_path, &r, &c, err);
    if (rc == HD_EEMPTY) { /* no points: a file with no points is written as it is */
        *count = 0;
        return HD_OK;
    }
    if (rc) return rc;
    *count = hd_cloud_points(c).count;
    hd_cloud_free(c);
    return HD_OK;
}

static int dispatch(hd__writer_t *w, const char *fmt) {
    if (strcmp(fmt, "ply") == 0) return hd__write_ply(w);
    if (strcmp(fmt, "las") == 0) return hd__write_las(w);
    if (strcmp(fmt, "laz") == 0) return hd__write_laz(w);
    if (strcmp(fmt, "xyz") == 0 || strcmp(fmt, "obj") == 0) return hd__write_text(w, strcmp(fmt, "obj") == 0);
    return hd__err(w->err, HD_EUNSUPPORTED,
                   "%s: a field is written into PLY, LAS, LAZ and text (xyz, csv, pts) files, not into %s; write the "
                   "distances with their coordinates instead (.csv, .ply or .npy)",
                   w->in->name, fmt);
}

/* out_path's extension must name the input's format. */
static int check_output(const char *in_path, const char *out_path, const char *out_format, const char *fmt,
                        const struct stat *in_st, hd_error_t *err) {
    const char *ofmt = out_format ? out_format : hd_format_of_path(out_path);
    if (!ofmt || strcmp(ofmt, fmt) != 0)
        return hd__err(err, HD_EINVAL,
                       "%s: the input %s is %s, so the output is %s too: name it with the extension of that format "
                       "(%s is %s)",
                       out_path, in_path, fmt, fmt, out_path, ofmt ? ofmt : "no format the library knows");
    struct stat st;
    if (stat(out_path, &st) == 0 && st.st_dev == in_st->st_dev && st.st_ino == in_st->st_ino)
        return hd__err(err, HD_EINVAL, "%s: is the input itself; write to another file", out_path);
    if (lstat(out_path, &st) == 0 && !S_ISREG(st.st_mode) && !S_ISLNK(st.st_mode))
        return hd__err(err, HD_EINVAL, "%s: exists and is not a regular file (the result is renamed into place); "
                                       "name a file",
                       out_path);
    return HD_OK;
}

/* The write of nf fields (none: the points selected, as they are), the
 * points selected by `select`'s n values. */
static int write_fields(const char *in_path, const char *out_path, const double *select, const hd_field_t *fields,
                        size_t nf, size_t n, const hd_write_options_t *opt, size_t *written, hd_error_t *err) {
    hd_write_options_t o;
    hd_read_options_t ro;
    if (opt) o = *opt;
    else hd_write_options_init(&o);
    if (o.read) ro = *o.read;
    else hd_read_options_init(&ro);
    if (written) *written = 0;
    if (err) hd__err_clear(err);
    int rc = check_args(in_path, out_path, &o, err);
    if (rc == HD_OK && !select && n) rc = hd__err(err, HD_EINVAL, "hd_write_fields: NULL values");
    if (rc == HD_OK) rc = check_fields(fields, nf, n, err);
    if (rc) return rc;
    hd__file_t f;
    struct stat st;
    if ((rc = map_input(in_path, &f, &st, err))) return rc;
    const char *fmt = input_format(&f, &ro);
    size_t count = 0;
    if (!fmt)
        rc = hd__err(err, HD_EUNSUPPORTED, "%s: cannot tell the input's format from its name", in_path);
    if (rc == HD_OK) rc = check_output(in_path, out_path, o.format, fmt, &st, err);
    if (rc == HD_OK) rc = count_points(in_path, &ro, &count, err);
    if (rc == HD_OK && count != n)
        rc = hd__err(err, HD_EINVAL, "%s: %zu values for a file of %zu points", in_path, n, count);
    char *tmp = NULL;
    FILE *out = rc == HD_OK ? open_temp(out_path, &tmp, err) : NULL;
    if (rc == HD_OK && !out) rc = err ? err->code : HD_EIO;
    if (rc == HD_OK) {
        hd__writer_t w = {&f, out_path, out, select, n, fields, nf, o.keep, o.threshold, &ro, 0, 0, err};
        rc = dispatch(&w, fmt);
        rc = finish(&w, tmp, out_path, rc);
        if (rc == HD_OK && written) *written = w.written;
    }
    free(tmp);
    if (f.size) munmap((void *)f.data, f.size);
    return rc;
}

int hd_write_fields(const char *in_path, const char *out_path, const hd_field_t *fields, size_t n_fields, size_t n,
                    const hd_write_options_t *opt, size_t *written, hd_error_t *err) {
    if (written) *written = 0;
    if (!fields || n_fields == 0) {
        if (err) hd__err_clear(err);
        return hd__err(err, HD_EINVAL, "hd_write_fields: no fields (hd_write_field with the name \"\" writes none)");
    }
    return write_fields(in_path, out_path, fields[0].values, fields, n_fields, n, opt, written, err);
}

int hd_write_field(const char *in_path, const char *out_path, const double *values, size_t n,
                   const hd_write_options_t *opt, size_t *written, hd_error_t *err) {
    hd_field_t f = {opt && opt->name ? opt->name : "distance", values};
    if (!good_name(f.name)) {
        if (written) *written = 0;
        if (err) hd__err_clear(err);
        return hd__err(err, HD_EINVAL, "field name '%.40s': letters, digits and '_' (not first a digit), at most 31",
                       f.name);
    }
    return write_fields(in_path, out_path, values, &f, f.name[0] ? 1 : 0, n, opt, written, err);
}
