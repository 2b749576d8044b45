/*
 * reader.c -- the one entry point for files: load, pick the format, parse.
 *
 * A file is loaded whole (mapped read-only when it is a regular file, read
 * in blocks from a pipe or standard input), so every parser sees one byte
 * range and can check every count against the bytes that remain before it
 * allocates anything.  The format comes from --format, else the extension;
 * the parser then confirms it by the file's magic where the format has one.
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

void hd_read_options_init(hd_read_options_t *opt) {
    memset(opt, 0, sizeof *opt);
    opt->dtype = HD_FLOAT64;
    opt->mesh = HD_MESH_VERTICES;
}

void hd__sink_init(hd__sink_t *s, hd_dtype_t dtype) {
    s->data = NULL;
    s->count = s->cap = 0;
    s->dtype = dtype;
}

int hd__sink_reserve(hd__sink_t *s, size_t n) {
    if (n <= s->cap - s->count) return HD_OK;
    size_t want = s->count + n;
    if (want < s->count) return HD_EOVERFLOW;
    size_t cap = s->cap ? s->cap : 1024;
    while (cap < want) cap = cap > SIZE_MAX / 2 ? want : cap * 2;
    size_t el = s->dtype == HD_FLOAT32 ? 3 * sizeof(float) : 3 * sizeof(double);
    void *p = hd__realloc_array(s->data, cap, el);
    if (!p) return HD_ENOMEM;
    s->data = p;
    s->cap = cap;
    return HD_OK;
}

int hd__point_valid(const double p[3]) {
    for (int c = 0; c < 3; c++) {
        if (!isfinite(p[c])) return HD_ENONFINITE;
        if (fabs(p[c]) > HD_MAX_COORD) return HD_ERANGE;
    }
    return HD_OK;
}

int hd__sink_push(hd__sink_t *s, const double p[3]) {
    int rc = hd__point_valid(p);
    if (rc) return rc;
    if (s->count == s->cap && (rc = hd__sink_reserve(s, 1))) return rc;
    if (s->dtype == HD_FLOAT32) {
        float *d = (float *)s->data + 3 * s->count;
        for (int c = 0; c < 3; c++) d[c] = (float)p[c];
    } else {
        double *d = (double *)s->data + 3 * s->count;
        for (int c = 0; c < 3; c++) d[c] = p[c];
    }
    s->count++;
    return HD_OK;
}

void hd__sink_free(hd__sink_t *s) {
    free(s->data);
    s->data = NULL;
    s->count = s->cap = 0;
}

typedef struct {
    const char *name;
    const char *extensions; /* space separated */
    const char *description;
    hd__reader_fn read;
} format_t;

static const format_t formats[] = {
    {"xyz", "xyz txt csv pts asc", "text: x y z per line, whitespace or comma separated", hd__read_xyz},
};
#define N_FORMATS (sizeof formats / sizeof formats[0])

const char *const *hd_formats(void) {
    static const char *names[N_FORMATS + 1];
    for (size_t k = 0; k < N_FORMATS; k++) names[k] = formats[k].name;
    names[N_FORMATS] = NULL;
    return names;
}

const char *hd_format_description(const char *name) {
    for (size_t k = 0; k < N_FORMATS; k++)
        if (name && strcmp(name, formats[k].name) == 0) return formats[k].description;
    return NULL;
}

static const format_t *by_name(const char *name) {
    for (size_t k = 0; k < N_FORMATS; k++)
        if (strcasecmp(name, formats[k].name) == 0) return &formats[k];
    return NULL;
}

static const format_t *by_extension(const char *path) {
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash)) return NULL;
    dot++;
    size_t len = strlen(dot);
    for (size_t k = 0; k < N_FORMATS; k++) {
        const char *e = formats[k].extensions;
        while (*e) {
            size_t n = strcspn(e, " ");
            if (n == len && strncasecmp(e, dot, n) == 0) return &formats[k];
            e += n;
            while (*e == ' ') e++;
        }
    }
    return NULL;
}

/* Load a whole file.  *map is set when the bytes are a mapping. */
static int load(const char *path, hd__file_t *f, int *mapped, hd_error_t *err) {
    int fd = strcmp(path, "-") == 0 ? 0 : open(path, O_RDONLY);
    if (fd < 0)
        return hd__err(err, HD_EIO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    *mapped = 0;
    f->name = path;
    f->data = NULL;
    f->size = 0;
    if (fstat(fd, &st) == 0 && S_ISDIR(st.st_mode)) {
        if (fd) close(fd);
        return hd__err(err, HD_EIO, "%s: is a directory", path);
    }
    if (fd != 0 && fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) {
        if (st.st_size == 0) {
            close(fd);
            static const unsigned char empty[1];
            f->data = empty;
            return HD_OK;
        }
        void *p = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE, fd, 0);
        close(fd);
        if (p == MAP_FAILED)
            return hd__err(err, HD_EIO, "%s: cannot map: %s", path, strerror(errno));
        madvise(p, (size_t)st.st_size, MADV_SEQUENTIAL);
        f->data = p;
        f->size = (size_t)st.st_size;
        *mapped = 1;
        return HD_OK;
    }
    size_t cap = 1 << 16, size = 0;
    unsigned char *buf = malloc(cap);
    if (!buf) {
        if (fd) close(fd);
        return hd__err(err, HD_ENOMEM, "%s: out of memory", path);
    }
    for (;;) {
        if (size == cap) {
            if (cap > SIZE_MAX / 2) break;
            unsigned char *nb = realloc(buf, cap * 2);
            if (!nb) {
                free(buf);
                if (fd) close(fd);
                return hd__err(err, HD_ENOMEM, "%s: out of memory", path);
            }
            buf = nb;
            cap *= 2;
        }
        ssize_t got = read(fd, buf + size, cap - size);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) {
            int e = errno;
            free(buf);
            if (fd) close(fd);
            return hd__err(err, HD_EIO, "%s: cannot read: %s", path, strerror(e));
        }
        if (got == 0) break;
        size += (size_t)got;
    }
    if (fd) close(fd);
    f->data = buf;
    f->size = size;
    return HD_OK;
}

static void unload(hd__file_t *f, int mapped) {
    if (mapped) munmap((void *)f->data, f->size);
    else if (f->size) free((void *)f->data);
}

int hd_read_file(const char *path, const hd_read_options_t *opt,
                 hd_cloud_t **out, hd_error_t *err) {
    hd__err_clear(err);
    if (!path || !out) return hd__err(err, HD_EINVAL, "path or result pointer is NULL");
    *out = NULL;
    hd_read_options_t defaults;
    if (!opt) {
        hd_read_options_init(&defaults);
        opt = &defaults;
    }
    const format_t *fmt = NULL;
    if (opt->format) {
        fmt = by_name(opt->format);
        if (!fmt) return hd__err(err, HD_EUNSUPPORTED, "%s: unknown format '%s'", path, opt->format);
    } else {
        fmt = by_extension(path);
        if (!fmt)
            return hd__err(err, HD_EUNSUPPORTED,
                           "%s: cannot tell the format from the extension; use --format", path);
    }
    hd__file_t f;
    int mapped, rc = load(path, &f, &mapped, err);
    if (rc) return rc;
    hd__sink_t sink;
    hd__sink_init(&sink, opt->dtype);
    size_t faces = 0;
    rc = fmt->read(&f, opt, &sink, &faces, err);
    unload(&f, mapped);
    if (rc == HD_OK && sink.count == 0)
        rc = hd__err(err, HD_EEMPTY, "%s: no points", path);
    hd_cloud_t *c = NULL;
    if (rc == HD_OK && !(c = malloc(sizeof *c))) rc = hd__err(err, HD_ENOMEM, "%s: out of memory", path);
    if (rc) {
        hd__sink_free(&sink);
        return rc;
    }
    c->data = sink.data;
    c->count = sink.count;
    c->dtype = sink.dtype;
    c->n_faces = faces;
    snprintf(c->format, sizeof c->format, "%s", fmt->name);
    *out = c;
    return HD_OK;
}

void hd_cloud_free(hd_cloud_t *cloud) {
    if (!cloud) return;
    free(cloud->data);
    free(cloud);
}

hd_points_t hd_cloud_points(const hd_cloud_t *cloud) {
    hd_points_t p = hd_points_f64(NULL, 0);
    if (!cloud) return p;
    p.data = cloud->data;
    p.count = cloud->count;
    p.dtype = cloud->dtype;
    return p;
}
