/*
 * reader.c -- the one entry point for files: load, pick the format, parse.
 *
 * A file is loaded whole (mapped read-only when it is a regular file, read
 * in blocks from a pipe or standard input), so every parser sees one byte
 * range and can check every count against the bytes that remain before it
 * allocates anything.  The format comes from opt->format, else the
 * extension, else (standard input, unknown extension) the content.  A format
 * with a signature (PLY "ply", LAS "LASF", NPY "\x93NUMPY", PCD's header,
 * binary STL's size) is confirmed by it; when the extension and the content
 * disagree the message says what the content looks like, so the user can
 * pass --format.  The library never prints: progress, if any, is the
 * caller's business (the CLI reports by phases).
 *
 * Inputs that are not regular files (standard input, pipes, FIFOs,
 * devices) are read in blocks up to opt->stream_limit bytes (default
 * HD_STREAM_LIMIT, 2 GiB), so /dev/zero or /dev/urandom is refused with a
 * message instead of growing until memory runs out.  A named FIFO is opened
 * without blocking and its first writer is awaited at most
 * opt->fifo_wait_ms (default HD_FIFO_WAIT_MS, 30 s): a FIFO nobody writes
 * to is an error, never a hang.  Once a writer has come, the FIFO is read
 * like a pipe, to its end.
 *
 * Meshes (PLY, OBJ, OFF, STL) are read as their vertices by default; with
 * HD_MESH_SAMPLE the reader also collects the faces as triangles and
 * mesh.c draws the requested number of points on the surface.  A format
 * that cannot hold faces (LAS, LAZ, XYZ, PCD, NPY) is read as its points
 * in either mode, so one option serves a mesh compared with a scan; a mesh
 * format whose file has no faces is refused under HD_MESH_SAMPLE.
 */
#include "io.h"

#include <assert.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
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

/* ---- signatures ------------------------------------------------------------ */
static int starts(const unsigned char *d, size_t n, const char *s) {
    size_t k = strlen(s);
    return n >= k && memcmp(d, s, k) == 0;
}

/* The first byte at or after k that is not a space, tab, CR or newline. */
static size_t skip_space(const unsigned char *d, size_t n, size_t k) {
    while (k < n && (d[k] == ' ' || d[k] == '\t' || d[k] == '\r' || d[k] == '\n')) k++;
    return k;
}

/* The first byte that is neither white space nor in a '#' comment line: where
 * the content of a header-less text file (OBJ) or of a PCD header starts. */
static size_t skip_comments(const unsigned char *d, size_t n) {
    size_t k = skip_space(d, n, 0);
    while (k < n && d[k] == '#') {
        while (k < n && d[k] != '\n') k++;
        k = skip_space(d, n, k);
    }
    return k;
}

static int magic_ply(const unsigned char *d, size_t n) {
    return starts(d, n, "ply\n") || starts(d, n, "ply\r\n") || starts(d, n, "ply ");
}
static int magic_las(const unsigned char *d, size_t n) { return starts(d, n, "LASF"); }
static int magic_npy(const unsigned char *d, size_t n) { return starts(d, n, "\x93NUMPY"); }
static int magic_pcd(const unsigned char *d, size_t n) {
    /* the header opens with comments and VERSION, or FIELDS directly */
    size_t k = skip_comments(d, n);
    return starts(d + k, n - k, "VERSION") || starts(d + k, n - k, "FIELDS");
}
static int magic_off(const unsigned char *d, size_t n) {
    size_t k = skip_space(d, n, 0);
    static const char *const kw[] = {"OFF", "COFF", "NOFF", "CNOFF", "NCOFF", NULL};
    for (int j = 0; kw[j]; j++) {
        size_t l = strlen(kw[j]);
        if (n - k >= l && memcmp(d + k, kw[j], l) == 0 &&
            (n - k == l || d[k + l] == ' ' || d[k + l] == '\t' || d[k + l] == '\r' || d[k + l] == '\n'))
            return 1;
    }
    return 0;
}
static int magic_stl(const unsigned char *d, size_t n) {
    if (n >= 84) {
        uint32_t tri = hd__ld_u32(d + 80, 0);
        if ((uint64_t)84 + (uint64_t)50 * tri == n) return 1;
    }
    size_t k = skip_space(d, n, 0);
    if (!starts(d + k, n - k, "solid")) return 0;
    for (size_t j = k; j + 5 <= n && j < 4096; j++)
        if (memcmp(d + j, "facet", 5) == 0) return 1;
    return 0;
}
static int magic_obj(const unsigned char *d, size_t n) {
    /* first line that is not a comment or blank starts with an OBJ keyword */
    size_t k = skip_comments(d, n);
    static const char *const kw[] = {"v ", "v\t", "vn ", "vt ", "o ", "g ", "mtllib ", "usemtl ", "s ", NULL};
    for (int j = 0; kw[j]; j++)
        if (starts(d + k, n - k, kw[j])) return 1;
    return 0;
}

/* ---- the table --------------------------------------------------------------- */
typedef struct {
    const char *name;
    const char *extensions; /* space separated */
    const char *description;
    hd__reader_fn read;
    int (*magic)(const unsigned char *, size_t); /* NULL: no signature to confirm */
    int faces;                                   /* a mesh format */
    int counted; /* its header gives the point count (hd_read_count); its
                    ascii variants, if any, refuse in hd__text_parallel */
} format_t;

static const format_t formats[] = {
    {"ply", "ply", "Stanford PLY: ascii, binary little/big endian; x y z of any type; faces", hd__read_ply, magic_ply, 1, 1},
    {"obj", "obj", "Wavefront OBJ: 'v' lines; 'f' lines are the faces", hd__read_obj, NULL, 1, 0},
    {"off", "off coff noff", "Object File Format: OFF, COFF, NOFF, CNOFF; faces", hd__read_off, magic_off, 1, 0},
    {"stl", "stl", "STL: ascii or binary triangles (their corners are the vertices)", hd__read_stl, magic_stl, 1, 1},
    {"xyz", "xyz txt csv pts asc", "text: x y z per line, separated by blanks and commas (or semicolons); decimal commas with the decimal-comma option; extra columns ignored",
     hd__read_xyz, NULL, 0, 0},
    {"pcd", "pcd", "Point Cloud Library PCD v0.7: ascii, binary, binary_compressed; x y z of type F/I/U",
     hd__read_pcd, magic_pcd, 0, 1},
    {"las", "las", "ASPRS LAS 1.0-1.4, point formats 0-10 (compressed ones too, as for laz)", hd__read_las, magic_las,
     0, 1},
    {"laz", "laz", "LAZ (LASzip-compressed LAS), point formats 0-10: chunked pointwise and layered, COPC included",
     hd__read_las, magic_las, 0, 1},
    {"npy", "npy", "NumPy .npy: float32/float64 array of shape (N, 3), either byte order, C or Fortran order",
     hd__read_npy, magic_npy, 0, 1},
};
#define N_FORMATS (sizeof formats / sizeof formats[0])

const char *const *hd_formats(void) {
    static const char *const names[] = {"ply", "obj", "off", "stl", "xyz", "pcd", "las", "laz", "npy", NULL};
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

static const char *extension(const char *path) {
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash)) return NULL;
    return dot + 1;
}

static const format_t *by_extension(const char *path) {
    const char *ext = extension(path);
    if (!ext) return NULL;
    size_t len = strlen(ext);
    for (size_t k = 0; k < N_FORMATS; k++) {
        const char *e = formats[k].extensions;
        while (*e) {
            size_t n = strcspn(e, " ");
            if (n == len && strncasecmp(e, ext, n) == 0) return &formats[k];
            e += n;
            while (*e == ' ') e++;
        }
    }
    return NULL;
}

const char *hd_format_of_path(const char *path) {
    const format_t *f = path ? by_extension(path) : NULL;
    return f ? f->name : NULL;
}

/* The format the content looks like: signatures first, then OBJ keywords,
 * then text that starts with a number (xyz). */
static const format_t *by_content(const hd__file_t *f) {
    for (size_t k = 0; k < N_FORMATS; k++)
        if (formats[k].magic && formats[k].magic(f->data, f->size)) return &formats[k];
    if (magic_obj(f->data, f->size)) return by_name("obj");
    size_t k = 0;
    while (k < f->size && (f->data[k] == ' ' || f->data[k] == '\t' || f->data[k] == '\n' || f->data[k] == '\r')) k++;
    if (k < f->size && f->data[k] && (strchr("+-.0123456789", f->data[k]) || f->data[k] == '#')) return by_name("xyz");
    /* a header line of printable text ("x,y,z") over a line that starts
     * with a number: a CSV with its header */
    size_t e = k;
    while (e < f->size && f->data[e] >= 0x20 && f->data[e] < 0x7f) e++;
    if (e > k && e + 1 < f->size && f->data[e] == '\r') e++;
    if (e > k && e < f->size && f->data[e] == '\n') {
        size_t n = e + 1;
        while (n < f->size && (f->data[n] == ' ' || f->data[n] == '\t' || f->data[n] == '\r')) n++;
        if (n < f->size && f->data[n] && strchr("+-.0123456789", f->data[n])) return by_name("xyz");
    }
    return NULL;
}

/* ---- loading ------------------------------------------------------------------ */

/* Wait until fd (non-blocking) is readable or its writers are gone: 1, or 0
 * when ms (> 0) pass first, -1 on a poll error (errno). */
static int wait_readable(int fd, int ms) {
    struct pollfd p = {fd, POLLIN, 0};
    for (;;) {
        int r = poll(&p, 1, ms);
        if (r < 0 && errno == EINTR) continue;
        return r < 0 ? -1 : r > 0;
    }
}

/* Read fd to its end into a malloc'd buffer of at most `limit` bytes.  With
 * fifo_ms > 0, fd is a FIFO opened with O_NONBLOCK: its first writer is
 * awaited at most fifo_ms, then it is read as a pipe. */
static int read_stream(int fd, const char *path, uint64_t limit, int fifo_ms, hd__file_t *f, hd_error_t *err) {
    size_t cap = 1 << 16, size = 0;
    unsigned char *buf = malloc(cap);
    if (!buf) return hd__err(err, HD_ENOMEM, "%s: out of memory", path);
    int waiting = fifo_ms > 0;
    for (;;) {
        if (size == cap) {
            if (size >= limit) {
                free(buf);
                return hd__err(err, HD_EFORMAT,
                               "%s: more than %llu bytes from a stream (not a regular file); "
                               "--max-stream-size raises the limit",
                               path, (unsigned long long)limit);
            }
            size_t want = cap > SIZE_MAX / 2 ? SIZE_MAX : cap * 2;
            if (want > limit) want = (size_t)limit + 1; /* one byte more tells "too long" */
            unsigned char *nb = realloc(buf, want);
            if (!nb) {
                free(buf);
                return hd__err(err, HD_ENOMEM, "%s: out of memory after %zu bytes", path, size);
            }
            buf = nb;
            cap = want;
        }
        if (fifo_ms > 0) {
            int w = wait_readable(fd, waiting ? fifo_ms : -1);
            if (w == 0) {
                free(buf);
                return hd__err(err, HD_EIO, "%s: a FIFO that no writer opened within %d ms", path, fifo_ms);
            }
        }
        ssize_t got = read(fd, buf + size, cap - size);
        if (got < 0 && (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK)) continue;
        if (got < 0) {
            int e = errno;
            free(buf);
            return hd__err(err, HD_EIO, "%s: cannot read: %s", path, strerror(e));
        }
        if (got == 0) break;
        waiting = 0;
        size += (size_t)got;
    }
    if (size > limit) {
        free(buf);
        return hd__err(err, HD_EFORMAT,
                       "%s: more than %llu bytes from a stream (not a regular file); --max-stream-size raises the limit",
                       path, (unsigned long long)limit);
    }
    if (size == 0) {
        free(buf);
        static const unsigned char empty[1];
        f->data = empty;
    } else {
        f->data = buf;
    }
    f->size = size;
    return HD_OK;
}

static int load(const char *path, const hd_read_options_t *opt, hd__file_t *f, int *mapped, hd_error_t *err) {
    int is_stdin = strcmp(path, "-") == 0;
    struct stat st;
    int fifo = !is_stdin && stat(path, &st) == 0 && S_ISFIFO(st.st_mode);
    int fd = is_stdin ? 0 : open(path, O_RDONLY | (fifo ? O_NONBLOCK : 0));
    if (fd < 0)
        return hd__err(err, HD_EIO, "%s: cannot open: %s", path, strerror(errno));
    *mapped = 0;
    f->name = is_stdin ? "(standard input)" : path;
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
        if ((unsigned long long)st.st_size > SIZE_MAX) {
            close(fd);
            return hd__err(err, HD_EOVERFLOW, "%s: too large to map", path);
        }
        void *p = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
        close(fd);
        if (p == MAP_FAILED) {
            /* ENOMEM: no address space (RLIMIT_AS, or the mappings' count);
             * EAGAIN: too much memory locked (RLIMIT_MEMLOCK under
             * mlockall): a lack of memory, not a bad file */
            int e = errno, nomem = e == ENOMEM || e == EAGAIN;
            return hd__err(err, nomem ? HD_ENOMEM : HD_EIO, "%s: cannot map its %llu bytes: %s%s", path,
                           (unsigned long long)st.st_size, strerror(e), nomem ? " (out of memory)" : "");
        }
        madvise(p, (size_t)st.st_size, MADV_SEQUENTIAL | MADV_WILLNEED);
        f->data = p;
        f->size = (size_t)st.st_size;
        *mapped = 1;
        return HD_OK;
    }
    uint64_t limit = opt->stream_limit ? opt->stream_limit : HD_STREAM_LIMIT;
    int wait_ms = opt->fifo_wait_ms > 0 ? opt->fifo_wait_ms : HD_FIFO_WAIT_MS;
    int rc = read_stream(fd, f->name, limit, fifo ? wait_ms : 0, f, err);
    if (fd) close(fd);
    return rc;
}

static void unload(hd__file_t *f, int mapped) {
    if (mapped) munmap((void *)f->data, f->size);
    else if (f->size) free((void *)f->data);
}

/* Run the reader; with sampling, read vertices as doubles and the faces,
 * then draw the sample into `out`. */
/* Keep points [first, first + n) of a sink read whole (a range read of a
 * format or mode whose reader cannot skip: text, variable-size PLY
 * vertices, sampled meshes). */
static int slice(hd__sink_t *s, const hd_read_options_t *opt, const char *name, hd_error_t *err) {
    if (opt->range_first > s->count || opt->range_count > s->count - opt->range_first)
        return hd__err(err, HD_ERANGE, "%s: points [%llu, %llu) asked of a file of %zu points", name,
                       (unsigned long long)opt->range_first,
                       (unsigned long long)(opt->range_first + opt->range_count), s->count);
    size_t el = s->dtype == HD_FLOAT32 ? 3 * sizeof(float) : 3 * sizeof(double);
    memmove(s->data, (char *)s->data + (size_t)opt->range_first * el, (size_t)opt->range_count * el);
    s->count = (size_t)opt->range_count;
    return HD_OK;
}

/* Read with fmt; *total (when not NULL) asks for the count alone
 * (hd_read_count). */
static int parse(const format_t *fmt, const hd__file_t *f, const hd_read_options_t *opt,
                 hd__sink_t *out, size_t *n_faces, uint64_t *total, hd_error_t *err) {
    int sample = opt->mesh == HD_MESH_SAMPLE;
    hd__sink_t verts;
    hd__tris_t tris;
    hd__sink_init(&verts, sample ? HD_FLOAT64 : opt->dtype);
    hd__tris_init(&tris);
    hd__read_t r = {f, opt, hd__thread_count(opt->threads, 1024), &verts, sample ? &tris : NULL, 0, err,
                    total != NULL, 0, 0};
    int rc = fmt->read(&r);
    if (total) { /* only hd__binary_read and the LAZ reader answer a count */
        hd__tris_free(&tris);
        hd__sink_free(&verts);
        if (rc == HD__COUNTED) {
            *total = r.total;
            return HD_OK;
        }
        return rc ? rc
                  : hd__err(err, HD_EUNSUPPORTED, "%s: the point count of this %s variant needs reading it whole",
                            f->name, fmt->name);
    }
    assert(rc != HD__COUNTED);
    if (rc == HD_OK && verts.count == 0) rc = hd__err(err, HD_EEMPTY, "%s: no points", f->name);
    if (rc == HD_OK && sample)
        rc = hd__mesh_sample(verts.data, verts.count, &tris, opt->sample, opt->seed, out, f->name, err);
    *n_faces = r.n_faces;
    hd__tris_free(&tris);
    if (rc == HD_OK && opt->range_count && !r.ranged) rc = slice(sample ? out : &verts, opt, f->name, err);
    if (rc == HD_OK && !sample) {
        *out = verts;
        return HD_OK;
    }
    hd__sink_free(&verts);
    return rc;
}

static int check_options(const char *path, const hd_read_options_t *opt, hd_error_t *err) {
    if (opt->dtype != HD_FLOAT64 && opt->dtype != HD_FLOAT32)
        return hd__err(err, HD_EINVAL, "%s: unknown storage type %d", path, (int)opt->dtype);
    if (opt->mesh != HD_MESH_VERTICES && opt->mesh != HD_MESH_SAMPLE)
        return hd__err(err, HD_EINVAL, "%s: unknown mesh mode %d", path, (int)opt->mesh);
    if (opt->mesh == HD_MESH_SAMPLE && opt->sample == 0)
        return hd__err(err, HD_EINVAL, "%s: sampling needs a positive number of points", path);
    if (opt->range_first && !opt->range_count)
        return hd__err(err, HD_EINVAL, "%s: range_first %llu without range_count", path,
                       (unsigned long long)opt->range_first);
    if (opt->range_count > UINT64_MAX - opt->range_first)
        return hd__err(err, HD_EINVAL, "%s: the range's end overflows", path);
    if (opt->decimal_comma != 0 && opt->decimal_comma != 1)
        return hd__err(err, HD_EINVAL, "%s: decimal_comma must be 0 or 1, not %d", path, opt->decimal_comma);
    return HD_OK;
}

/* The format named by the option, else by the extension (NULL when
 * neither says; *from_extension tells which). */
static int choose(const char *path, const hd_read_options_t *opt, const format_t **fmt, int *from_extension,
                  hd_error_t *err) {
    *fmt = NULL;
    *from_extension = 0;
    if (opt->format) {
        *fmt = by_name(opt->format);
        if (!*fmt) return hd__err(err, HD_EUNSUPPORTED, "%s: unknown format '%s'", path, opt->format);
    } else if (strcmp(path, "-") != 0) {
        *fmt = by_extension(path);
        *from_extension = *fmt != NULL;
    }
    return HD_OK;
}

/* The format of loaded content: fmt when the content confirms it, else
 * the content's (*fmt set), or an error.  Text after a UTF-8 byte-order mark
 * is sniffed without it (the readers skip it too); UTF-16 and UTF-32 text has
 * no format of its own: the reader the name chose refuses it by its encoding. */
static int confirm(const hd__file_t *f, const format_t **pfmt, int from_extension, hd_error_t *err) {
    const format_t *fmt = *pfmt;
    size_t bom;
    int bits = hd__text_encoding(f->data, f->size, &bom);
    hd__file_t text = {f->name, f->data + bom, f->size - bom};
    if (!fmt) {
        fmt = by_content(f);
        if (!fmt && bom) fmt = by_content(&text);
        if (!fmt && bits != 8)
            return hd__err(err, HD_EFORMAT, "%s: UTF-%d text; convert to UTF-8 (iconv -f UTF-%d -t UTF-8)", f->name,
                           bits, bits);
        if (!fmt)
            return hd__err(err, HD_EUNSUPPORTED, "%s: cannot tell the format from the %s; use --format (see --formats)",
                           f->name, from_extension < 0 ? "content" : "extension or the content");
    } else if (from_extension > 0 && bits == 8 &&
               !(fmt->magic && (fmt->magic(f->data, f->size) || (bom && fmt->magic(text.data, text.size))))) {
        /* The content must confirm the extension.  A format with a
         * signature that is missing is refused when the content has another
         * format's signature; a format without one (OBJ, text) is refused
         * when the content looks like any other format, so an OFF or a PLY
         * named .xyz is never read as a list of numbers. */
        const format_t *seems = by_content(f);
        if (!seems && bom) seems = by_content(&text);
        if (seems && seems != fmt && (seems->magic || !fmt->magic))
            return hd__err(err, HD_EFORMAT, "%s: the name says %s but the content is %s; use --format %s", f->name,
                           fmt->name, seems->name, seems->name);
    }
    *pfmt = fmt;
    return HD_OK;
}

/* Everything after loading: confirm the format, parse, make the cloud. */
static int read_loaded(const hd__file_t *f, const format_t *fmt, int from_extension,
                       const hd_read_options_t *opt, hd_cloud_t **out, uint64_t *total, hd_error_t *err) {
    int rc0 = confirm(f, &fmt, from_extension, err);
    if (rc0) return rc0;
    hd_read_options_t as_points; /* sampling draws on faces: a format without them is read as its points */
    if (opt->mesh == HD_MESH_SAMPLE && !fmt->faces) {
        as_points = *opt;
        as_points.mesh = HD_MESH_VERTICES;
        opt = &as_points;
    }
    hd__sink_t sink;
    hd__sink_init(&sink, opt->dtype);
    size_t faces = 0;
    if (total) {
        if (!fmt->counted || opt->mesh == HD_MESH_SAMPLE)
            return hd__err(err, HD_EUNSUPPORTED, "%s: the point count of %s needs reading it whole", f->name,
                           opt->mesh == HD_MESH_SAMPLE ? "a sampled mesh" : fmt->name);
        return parse(fmt, f, opt, &sink, &faces, total, err);
    }
    int rc = parse(fmt, f, opt, &sink, &faces, NULL, err);
    hd_cloud_t *c = NULL;
    if (rc == HD_OK && !(c = malloc(sizeof *c))) rc = hd__err(err, HD_ENOMEM, "%s: out of memory", f->name);
    if (rc) {
        hd__sink_free(&sink);
        return rc;
    }
    if (sink.cap > sink.count + sink.count / 8) {
        /* give back what an over-estimate reserved */
        void *p = hd__realloc_array(sink.data, sink.count, sink.dtype == HD_FLOAT32 ? 12 : 24);
        if (p) sink.data = p;
    }
    c->data = sink.data;
    c->count = sink.count;
    c->dtype = sink.dtype;
    c->n_faces = faces;
    snprintf(c->format, sizeof c->format, "%s", fmt->name);
    *out = c;
    return HD_OK;
}

/* The options checked, the format the name or --format gives (if any) and
 * the file loaded: what every read of a path starts with.  On success the
 * caller unloads f. */
static int open_input(const char *path, const hd_read_options_t *opt, const format_t **fmt, int *from_extension,
                      hd__file_t *f, int *mapped, hd_error_t *err) {
    int rc = check_options(path, opt, err);
    if (rc || (rc = choose(path, opt, fmt, from_extension, err))) return rc;
    if (!*fmt && strcmp(path, "-") == 0) *from_extension = -1;
    return load(path, opt, f, mapped, err);
}

/* hd_read_file, or hd_read_count when total is not NULL. */
static int read_path(const char *path, const hd_read_options_t *opt, hd_cloud_t **out, uint64_t *total,
                     hd_error_t *err) {
    hd_read_options_t defaults;
    if (!opt) {
        hd_read_options_init(&defaults);
        opt = &defaults;
    }
    const format_t *fmt;
    int from_extension, mapped;
    hd__file_t f;
    int rc = open_input(path, opt, &fmt, &from_extension, &f, &mapped, err);
    if (rc) return rc;
    rc = read_loaded(&f, fmt, from_extension, opt, out, total, err);
    unload(&f, mapped);
    return rc;
}

int hd_read_file(const char *path, const hd_read_options_t *opt,
                 hd_cloud_t **out, hd_error_t *err) {
    hd__err_clear(err);
    if (!path || !out) return hd__err(err, HD_EINVAL, "path or result pointer is NULL");
    *out = NULL;
    return read_path(path, opt, out, NULL, err);
}

int hd_read_count(const char *path, const hd_read_options_t *opt,
                  uint64_t *count, hd_error_t *err) {
    hd__err_clear(err);
    if (!path || !count) return hd__err(err, HD_EINVAL, "path or result pointer is NULL");
    *count = 0;
    if (strcmp(path, "-") == 0)
        return hd__err(err, HD_EUNSUPPORTED, "-: the point count of standard input needs reading it whole");
    hd_cloud_t *unused = NULL;
    return read_path(path, opt, &unused, count, err);
}

static int read_buffer(const void *data, size_t size, const char *name, const hd_read_options_t *opt,
                       hd_cloud_t **out, uint64_t *total, hd_error_t *err) {
    hd__err_clear(err);
    *out = NULL;
    const format_t *fmt;
    int from_extension;
    int rc = check_options(name, opt, err);
    if (rc || (rc = choose(name, opt, &fmt, &from_extension, err))) return rc;
    static const unsigned char empty[1];
    hd__file_t f = {name, size ? data : empty, size};
    return read_loaded(&f, fmt, from_extension, opt, out, total, err);
}

int hd__read_buffer(const void *data, size_t size, const char *name,
                    const hd_read_options_t *opt, hd_cloud_t **out, hd_error_t *err) {
    return read_buffer(data, size, name, opt, out, NULL, err);
}

int hd__count_buffer(const void *data, size_t size, const char *name,
                     const hd_read_options_t *opt, uint64_t *total, hd_error_t *err) {
    hd_cloud_t *unused = NULL;
    *total = 0;
    return read_buffer(data, size, name, opt, &unused, total, err);
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

int hd__read_faces(const char *path, const hd_read_options_t *opt, hd__sink_t *verts, hd__tris_t *tris,
                   size_t *n_faces, const char **format, hd_error_t *err) {
    const format_t *fmt;
    int from_extension, mapped;
    hd__file_t f;
    int rc = open_input(path, opt, &fmt, &from_extension, &f, &mapped, err);
    if (rc) return rc;
    rc = confirm(&f, &fmt, from_extension, err);
    if (rc == HD_OK && !fmt->faces)
        rc = hd__err(err, HD_EUNSUPPORTED, "%s: %s has no faces (meshes are read from PLY, OBJ, OFF and STL)", f.name,
                     fmt->name);
    if (rc == HD_OK) {
        hd__read_t r = {&f, opt, hd__thread_count(opt->threads, 1024), verts, tris, 0, err, 0, 0, 0};
        rc = fmt->read(&r);
        *n_faces = r.n_faces;
        *format = fmt->name;
    }
    unload(&f, mapped);
    return rc;
}
