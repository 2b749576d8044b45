/*
 * io.h -- what the readers share: the loaded file, the growing cloud, the
 * triangles of a mesh, the text-chunk machinery, byte-order helpers and the
 * error helpers that put the file name and line or byte offset first.
 */
#ifndef HD_IO_H
#define HD_IO_H

#include "points/points.h"

#include <stdio.h>
#include <string.h>

/* A function kept out of its callers: a rare step (a model set's creation)
 * that, inlined, would change a hot loop's code around it. */
#if defined(__GNUC__)
#define HD__NOINLINE __attribute__((noinline))
#else
#define HD__NOINLINE
#endif

/* A whole input file in memory (mapped when it is a regular file). */
typedef struct hd__file {
    const char *name;          /* as given by the caller, for messages */
    const unsigned char *data; /* size bytes, followed by no terminator */
    size_t size;
} hd__file_t;

/* ---- points being collected, stored as the caller asked ---------------- */
typedef struct hd__sink {
    void *data;
    size_t count, cap;
    hd_dtype_t dtype;
    int fixed; /* a window into another sink's array: never reallocated */
} hd__sink_t;

void hd__sink_init(hd__sink_t *s, hd_dtype_t dtype);
/* Reserve room for n more points; the caller has checked n against the
 * file's size so that no reader allocates more than the file can hold. */
int hd__sink_reserve(hd__sink_t *s, size_t n);
/* Append one point after checking it (hd__point_valid). */
int hd__sink_push(hd__sink_t *s, const double p[3]);
/* Store point k (< cap) without checking; for parallel fills. */
HD__INLINE void hd__sink_set(hd__sink_t *s, size_t k, const double p[3]) {
    if (s->dtype == HD_FLOAT32) {
        float *d = (float *)s->data + 3 * k;
        d[0] = (float)p[0];
        d[1] = (float)p[1];
        d[2] = (float)p[2];
    } else {
        double *d = (double *)s->data + 3 * k;
        d[0] = p[0];
        d[1] = p[1];
        d[2] = p[2];
    }
}
void hd__sink_free(hd__sink_t *s);

/* Check one coordinate triple: HD_ENONFINITE, HD_ERANGE (beyond
 * HD_MAX_COORD, or beyond FLT_MAX when stored as float), or HD_OK. */
int hd__point_valid(const double p[3], hd_dtype_t dtype);
/* "coordinate is NaN or infinite" etc., for a code from hd__point_valid. */
const char *hd__point_problem(int code);

/* ---- triangles of a mesh, for --sample ------------------------------- */
typedef struct hd__tris {
    uint64_t *v; /* 3 vertex indices (0-based) per triangle */
    size_t count, cap;
} hd__tris_t;

void hd__tris_init(hd__tris_t *t);
/* Add a polygon of n >= 3 vertices as a fan of n-2 triangles. */
int hd__tris_add(hd__tris_t *t, const uint64_t *v, size_t n);
void hd__tris_free(hd__tris_t *t);
/* Move all triangles of src to the end of t (src is emptied). */
int hd__tris_append(hd__tris_t *t, hd__tris_t *src);

/* `n` points uniformly by area on the triangles (vertices: nv packed
 * doubles), seeded; appended to out.  Every index must be < nv and the
 * total area positive (the caller reports which). */
int hd__mesh_sample(const double *xyz, size_t nv, const hd__tris_t *t,
                    size_t n, uint64_t seed, hd__sink_t *out,
                    const char *name, hd_error_t *err);

/* hd_read_file on bytes already in memory: `name` names them in messages
 * and gives the extension; opt must not be NULL.  For the fuzzers. */
int hd__read_buffer(const void *data, size_t size, const char *name,
                    const hd_read_options_t *opt, hd_cloud_t **out, hd_error_t *err);
/* hd_read_count on bytes in memory (for the fuzzers). */
int hd__count_buffer(const void *data, size_t size, const char *name,
                     const hd_read_options_t *opt, uint64_t *total, hd_error_t *err);

/* The vertices (into verts, whose dtype the caller chose) and the faces
 * (into tris) of the mesh file at path, as hd_read_file would find and
 * confirm its format; a format without faces is HD_EUNSUPPORTED.  *format
 * is the format's name.  For hd_read_mesh (src/surface.c). */
int hd__read_faces(const char *path, const hd_read_options_t *opt, hd__sink_t *verts, hd__tris_t *tris,
                   size_t *n_faces, const char **format, hd_error_t *err);

/* ---- one reader call --------------------------------------------------- */
typedef struct hd__read {
    const hd__file_t *f;
    const hd_read_options_t *opt;
    int threads;       /* resolved thread count for parallel parsing */
    hd__sink_t *sink;  /* the vertices or points */
    hd__tris_t *tris;  /* NULL, or collect faces here (for --sample) */
    size_t n_faces;    /* faces seen (mesh formats) */
    hd_error_t *err;
    int count_only;    /* hd_read_count: hd__binary_read stores L->n in
                          total and returns HD__COUNTED; text parsers
                          refuse (HD_EUNSUPPORTED) */
    uint64_t total;
    int ranged;        /* hd__binary_read applied opt's range */
} hd__read_t;

/* Returned by hd__binary_read in count_only mode; readers pass any nonzero
 * code up, and reader.c turns it into HD_OK.  Never leaves the library. */
#define HD__COUNTED 1

typedef int (*hd__reader_fn)(hd__read_t *r);

int hd__read_xyz(hd__read_t *r);
int hd__read_ply(hd__read_t *r);
int hd__read_obj(hd__read_t *r);
int hd__read_off(hd__read_t *r);
int hd__read_stl(hd__read_t *r);
int hd__read_pcd(hd__read_t *r);
int hd__read_las(hd__read_t *r);
int hd__read_npy(hd__read_t *r);

/* A LAS header as las.c checked it: version minor, header size, offset to
 * the points, point format (compression bit cleared), record length, point
 * count (the 64-bit one in 1.4), VLR count, extended VLRs, scale and offset per axis
 * (finite).  The points start at `offset`. */
typedef struct hd__las_header {
    unsigned minor, fmt;
    size_t header, offset, rec;
    uint64_t count;
    uint32_t n_vlr;
    uint64_t evlr; /* 1.4: where the extended VLRs start (0: none) */
    double scale[3], shift[3];
} hd__las_header_t;
/* The points of a LAZ (LASzip-compressed) file: laz.c.  A chunk may not
 * claim more than the read options' laz_points_per_byte (default
 * HD_LAZ_POINTS_PER_BYTE, at most HD_LAZ_POINTS_PER_BYTE_MAX) points per
 * byte of it: the bound on the allocation a LAZ file can cause. */
/* Up to this many points per compressed byte the LAZ reader allocates the
 * result at once; above, it grows it as points are decoded (laz.c). */
#define HD__LAZ_EAGER_PER_BYTE 64
int hd__read_laz(hd__read_t *r, const hd__las_header_t *h);
/* Whether the VLRs of h (lying in d) hold a LASzip VLR (user "laszip
 * encoded", record 22204): the sign of a LAZ file whose point format byte
 * lost its compression bit. */
int hd__laz_vlr_present(const unsigned char *d, const hd__las_header_t *h);

/* ---- writing fields back (write.c, hd_write_fields) ---------------------- */
/* The most fields: 8 bytes each in a LAS record of at most 65535 bytes. */
#define HD__FIELDS_MAX 8191
typedef struct hd__writer {
    const hd__file_t *in;    /* the input, mapped */
    const char *out_name;    /* for messages */
    FILE *out;               /* the temporary being written */
    const double *v;         /* n values selecting the points (keep,
                                threshold): point k's is v[k] */
    size_t n;
    const hd_field_t *f;     /* the fields added, nf of them (0: none),
                                each of n values */
    size_t nf;
    hd_keep_t keep;
    double threshold;
    const hd_read_options_t *ropt;
    size_t written;          /* points written */
    int werr;                /* errno of the first failed write (0: none) */
    hd_error_t *err;
} hd__writer_t;

/* Whether point k is written. */
HD__INLINE int hd__w_keep(const hd__writer_t *w, size_t k) {
    return w->keep == HD_KEEP_ALL || (w->keep == HD_KEEP_FARTHER ? w->v[k] > w->threshold : w->v[k] <= w->threshold);
}
/* How many points are written. */
size_t hd__w_kept(const hd__writer_t *w);
/* Append n bytes (nothing once a write has failed: w->werr). */
void hd__w_put(hd__writer_t *w, const void *p, size_t n);
/* Point k's nf values, in the given byte order, into b (8 * nf bytes). */
HD__INLINE void hd__w_values(const hd__writer_t *w, size_t k, int big, unsigned char *b) {
    const hd_field_t *f = w->f;
    for (size_t j = 0, nf = w->nf; j < nf; j++, b += 8) {
        uint64_t u;
        memcpy(&u, &f[j].values[k], 8);
        if (big)
            for (int i = 0; i < 8; i++) b[7 - i] = (unsigned char)(u >> (8 * i));
        else
            for (int i = 0; i < 8; i++) b[i] = (unsigned char)(u >> (8 * i));
    }
}
/* The index of the first field whose name equals the n bytes at s
 * (n = 0: s is NUL-terminated; at most 32 bytes compared), or -1. */
long hd__w_field_named(const hd__writer_t *w, const char *s, size_t n);
/* The shortest decimal text that reads back (strtod) to v; its length. */
size_t hd__shortest(double v, char buf[32]);

/* The writers of each format: HD_OK, or an error for what they cannot
 * write (their write failures are in w->werr). */
int hd__write_ply(hd__writer_t *w);
int hd__write_las(hd__writer_t *w);
int hd__write_laz(hd__writer_t *w);
int hd__write_text(hd__writer_t *w, int obj);
/* The first data line of the xyz text in [p, end) as its reader finds it
 * (the lines before it are the header; end when there is none) and the
 * field separator of its dialect (';' or ','; ',' also when blanks alone
 * separate). */
const char *hd__xyz_data_start(const char *p, const char *end, int decimal_comma, int *semicolon);

/* A LAZ file's LASzip VLR and chunks, for the LAZ writer (laz.c): the
 * VLR's data at vlr_at (vlr_len bytes), its items, and per chunk its first
 * byte (start[c], start[n_chunks] the end of the last) and its first
 * point's number (first[c]); the chunk table at [table, table_end). */
typedef struct hd__laz_chunks {
    int layered, chunked;
    unsigned n_layers, n_items;
    unsigned type[32], size[32], version[32];
    uint32_t chunk_size;
    size_t vlr_at, vlr_len;
    size_t n_chunks;
    uint64_t *start, *first;
    size_t table, table_end;
} hd__laz_chunks_t;
/* Checks as the reader does; HD_OK or its error. */
int hd__laz_chunks(hd__read_t *r, const hd__las_header_t *h, hd__laz_chunks_t *out);
void hd__laz_chunks_free(hd__laz_chunks_t *c);
/* The scanner channel of every point of layered chunk `chunk` into chan
 * (its point count of them), from decoding its x/y layer. */
int hd__laz_chunk_channels(hd__read_t *r, const hd__las_header_t *h, const hd__laz_chunks_t *c, size_t chunk,
                           unsigned char *chan);
/* Every whole record of chunk `chunk` (pointwise: items of version 2;
 * layered: every layer, laz14.c) into recs (its point count times the
 * record length). */
int hd__laz_chunk_records(hd__read_t *r, const hd__las_header_t *h, const hd__laz_chunks_t *c, size_t chunk,
                          unsigned char *recs);

/* ---- errors with a place --------------------------------------------------- */
/* "NAME:LINE: what" with err->line set. */
int hd__io_err_line(hd__read_t *r, int code, long long line, const char *fmt,
                    ...) HD__PRINTF(4, 5);
/* "NAME: byte OFFSET: what" with err->offset set. */
int hd__io_err_at(hd__read_t *r, int code, long long offset, const char *fmt,
                  ...) HD__PRINTF(4, 5);
/* "NAME: what" (no place). */
int hd__io_err(hd__read_t *r, int code, const char *fmt, ...) HD__PRINTF(3, 4);

/* ---- text ------------------------------------------------------------------ */
/* The number in [s, end), entirely: 1 and *out (exactly strtod's value), or 0
 * when the token is not a number. */
int hd__parse_double(const char *s, const char *end, double *out);
/* The fast path alone: the decimal number at s (sign, digits, point,
 * exponent), when Clinger's condition holds; returns the end of the number
 * and sets *out, or NULL (then delimit the token and call
 * hd__parse_double, which falls back to strtod).  The caller must check
 * that the number ends where the token ends. */
const char *hd__scan_double(const char *s, const char *end, double *out);
/* A non-negative decimal integer in [s, end) without sign or exponent; 0 on
 * failure or overflow of uint64_t. */
int hd__parse_u64(const char *s, const char *end, uint64_t *out);

/* The encoding of text starting at d[0..n): 8 (UTF-8 or ASCII; *bom is 3
 * after a UTF-8 byte-order mark, else 0), 16 or 32 (UTF-16 or UTF-32, by
 * their byte-order marks FF FE, FE FF, FF FE 00 00, 00 00 FE FF or, without
 * one, by the NUL bytes of a first line of printable ASCII characters, each
 * 2 or 4 bytes wide).  ASCII text has no NUL byte, so it is never taken for
 * UTF-16 or UTF-32. */
int hd__text_encoding(const unsigned char *d, size_t n, size_t *bom);
/* Where r's file's text starts: *start past a UTF-8 byte-order mark (the
 * file's first byte otherwise), and HD_OK; UTF-16 or UTF-32 text is refused
 * with HD_EFORMAT, "NAME:1: UTF-16 text; convert to UTF-8 ...".  Every text
 * reader starts here. */
int hd__text_begin(hd__read_t *r, const char **start);

HD__INLINE int hd__is_blank(int c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/* End of the line starting at p (the '\n', or end). */
HD__INLINE const char *hd__eol(const char *p, const char *end) {
    const char *e = (const char *)memchr(p, '\n', (size_t)(end - p));
    return e ? e : end;
}

/* Steps through [*p, end) a line at a time: sets *line to the line's first
 * byte and *eol to its end (its '\n', or end), moves *p past the '\n', and
 * returns 1; returns 0, changing nothing, once *p reaches end.  A loop
 * `for (const char *q, *eol; hd__next_line(&p, end, &q, &eol);)` visits
 * every line, the last one too when it has no '\n'. */
HD__INLINE int hd__next_line(const char **p, const char *end, const char **line, const char **eol) {
    if (*p >= end) return 0;
    *line = *p;
    *eol = hd__eol(*p, end);
    *p = *eol + (*eol < end);
    return 1;
}

/* The next whitespace-separated token in [*p, eol): sets [*tb, *te) and
 * advances *p; 0 when the line has no more tokens. */
HD__INLINE int hd__token(const char **p, const char *eol, const char **tb,
                         const char **te) {
    const char *s = *p;
    while (s < eol && hd__is_blank((unsigned char)*s)) s++;
    if (s == eol) {
        *p = s;
        return 0;
    }
    const char *e = s;
    while (e < eol && !hd__is_blank((unsigned char)*e)) e++;
    *tb = s;
    *te = e;
    *p = e;
    return 1;
}

/* The next blank-separated token of [*q, eol) as a double: 1 (and *q past
 * it), 0 when the line has no more tokens, -1 when the token [*tb, *te) is
 * not a number.  One pass over the digits in the common case. */
HD__INLINE int hd__next_double(const char **q, const char *eol, double *v,
                               const char **tb, const char **te) {
    const char *s = *q;
    while (s < eol && hd__is_blank((unsigned char)*s)) s++;
    if (s == eol) {
        *q = s;
        return 0;
    }
    const char *e = hd__scan_double(s, eol, v);
    if (e && (e == eol || hd__is_blank((unsigned char)*e))) {
        *q = e;
        return 1;
    }
    e = s;
    while (e < eol && !hd__is_blank((unsigned char)*e)) e++;
    *tb = s;
    *te = e;
    *q = e;
    return hd__parse_double(s, e, v) ? 1 : -1;
}

/* Text parsed in parallel.  [begin, end) is cut at line ends into chunks
 * of about a megabyte.  First every chunk counts its candidate lines (the
 * lines that may hold a point; job->candidates, or every line), bounded by
 * bytes / job->min_line, and r->sink reserves the total once; then every
 * chunk parses its whole lines, writing its points straight into its own
 * window of that array (c->pts is the window) and its triangles into
 * c->tris, and sets c->lines to the number of lines it parsed.  On the
 * first problem a chunk records a code, the 1-based line within the chunk
 * and a message, and stops.  Finally the chunks are visited in file order:
 * the first problem is THE error, reported with its absolute line
 * (`first_line` is the number of the line at `begin`); otherwise each
 * window is moved down to follow the previous one. */
typedef struct hd__chunk {
    const char *begin, *end; /* whole lines */
    int index;               /* 0 for the chunk at `begin` */
    long long lines;         /* lines parsed: set by the parser when it finishes */
    size_t room;             /* candidate lines: the window's size */
    const char *lone_cr;     /* the chunk's first '\r' that ends no line (NULL: none) */
    hd__sink_t pts;          /* the window */
    hd__tris_t tris;
    uint64_t aux;            /* free for the reader (e.g. faces counted) */
    int rc;
    long long err_line;      /* 1-based within the chunk */
    char msg[256];
} hd__chunk_t;

/* Record a problem in a chunk (message without file or line). */
/* Read "x y z" from *q..eol into the chunk's points.  On failure it reports
 * "<prefix>'tok' is not a number" or "<expected>, found N numbers" (or the
 * point's problem) through hd__chunk_fail and returns 0.  With comment_ends,
 * a token starting with '#' ends the numbers (OFF allows trailing comments). */
int hd__chunk_vertex(hd__chunk_t *c, const char **q, const char *eol, long long line,
                     const char *prefix, const char *expected, int comment_ends);
void hd__chunk_fail(hd__chunk_t *c, int code, long long line, const char *fmt,
                    ...) HD__PRINTF(4, 5);
/* Add the face of n vertex indices ix to the chunk's triangles and count
 * it (c->aux); ix is freed unless it is the caller's buffer idx.  1, or 0
 * with the chunk failed at `line` (out of memory). */
int hd__chunk_face(hd__chunk_t *c, uint64_t *ix, const uint64_t *idx, size_t n, long long line);
/* Append the point v to the chunk's window (hd__sink_push): 1, or 0 with the
 * point's problem recorded through hd__chunk_fail. */
HD__INLINE int hd__chunk_push(hd__chunk_t *c, long long line, const double v[3]) {
    int rc = hd__sink_push(&c->pts, v);
    if (rc) hd__chunk_fail(c, rc, line, "%s", hd__point_problem(rc));
    return rc == HD_OK;
}

typedef struct hd__text_job {
    void (*parse)(void *ctx, hd__chunk_t *c);
    /* Called in file order before a chunk's results are kept, with the
     * number of points kept before it (to resolve relative references);
     * may be NULL. */
    void (*fix)(void *ctx, hd__chunk_t *c, size_t points_before);
    /* Lines of [begin, end) that may hold a point; NULL: every line. */
    size_t (*candidates)(void *ctx, const char *begin, const char *end);
    size_t min_line; /* bytes of the shortest line holding a point, '\n' included */
    void *ctx;
} hd__text_job_t;

/* Candidate counters for hd__text_job_t: none (a pass that reads faces
 * only) and content lines (neither blank nor starting with '#'). */
size_t hd__no_candidates(void *ctx, const char *begin, const char *end);
size_t hd__content_lines(void *ctx, const char *begin, const char *end);
/* Lines of [p, end) whose first word is `word`. */
size_t hd__keyword_lines(const char *p, const char *end, const char *word);

/* Run job over [begin, end), appending the points to r->sink and the
 * triangles to r->tris (when not NULL).  *aux_total receives the sum of the
 * chunks' aux (may be NULL). */
int hd__text_parallel(hd__read_t *r, const char *begin, const char *end,
                      long long first_line, const hd__text_job_t *job,
                      uint64_t *aux_total);

/* Skip n lines from p: returns the start of line n+1 (or end) and sets
 * *skipped to the number of lines actually skipped. */
const char *hd__skip_lines(const char *p, const char *end, uint64_t n,
                           uint64_t *skipped);

/* Skip n content lines (neither blank nor starting with '#') from p: returns
 * the start of the line after the n-th, or end; *found is the number of
 * content lines skipped and *lines the number of lines of any kind. */
const char *hd__skip_content_lines(const char *p, const char *end, uint64_t n,
                                   uint64_t *found, uint64_t *lines);

/* ---- binary ----------------------------------------------------------- */
/* LZF (liblzf format) from in[0..in_len) into exactly out_len bytes of out:
 * 0, or -1 with *bad_at the input offset of the first bad command. */
int hd__lzf_decompress(const unsigned char *in, size_t in_len, unsigned char *out,
                       size_t out_len, size_t *bad_at);

HD__INLINE uint16_t hd__ld_u16(const unsigned char *p, int big) {
    return big ? (uint16_t)(p[0] << 8 | p[1]) : (uint16_t)(p[1] << 8 | p[0]);
}
HD__INLINE uint32_t hd__ld_u32(const unsigned char *p, int big) {
    return big ? (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]
               : (uint32_t)p[3] << 24 | (uint32_t)p[2] << 16 | (uint32_t)p[1] << 8 | p[0];
}
HD__INLINE uint64_t hd__ld_u64(const unsigned char *p, int big) {
    uint64_t a = hd__ld_u32(p, big), b = hd__ld_u32(p + 4, big);
    return big ? a << 32 | b : b << 32 | a;
}

/* Scalar element types of binary formats. */
typedef enum hd__type {
    HD__T_NONE = 0,
    HD__T_I8, HD__T_U8, HD__T_I16, HD__T_U16, HD__T_I32, HD__T_U32,
    HD__T_I64, HD__T_U64, HD__T_F32, HD__T_F64
} hd__type_t;

HD__INLINE size_t hd__type_size(hd__type_t t) {
    static const unsigned char sz[] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
    return sz[t];
}

/* One value of type t at p, widened to double (exactly for every type but
 * 64-bit integers beyond 2^53, which round to nearest). */
HD__INLINE double hd__ld_value(const unsigned char *p, hd__type_t t, int big) {
    switch (t) {
    case HD__T_I8: return (double)(int8_t)p[0];
    case HD__T_U8: return (double)p[0];
    case HD__T_I16: return (double)(int16_t)hd__ld_u16(p, big);
    case HD__T_U16: return (double)hd__ld_u16(p, big);
    case HD__T_I32: return (double)(int32_t)hd__ld_u32(p, big);
    case HD__T_U32: return (double)hd__ld_u32(p, big);
    case HD__T_I64: return (double)(int64_t)hd__ld_u64(p, big);
    case HD__T_U64: return (double)hd__ld_u64(p, big);
    case HD__T_F32: {
        uint32_t u = hd__ld_u32(p, big);
        float v;
        memcpy(&v, &u, sizeof v);
        return (double)v;
    }
    case HD__T_F64: {
        uint64_t u = hd__ld_u64(p, big);
        double v;
        memcpy(&v, &u, sizeof v);
        return v;
    }
    default: return 0.0;
    }
}

/* Where the points are in a binary block: point k is in record k / per,
 * sub * (k % per) bytes into it; coordinate c at byte off[c] of type[c];
 * big: big-endian; scale/offset (both NULL, or 3 each): c * scale + offset.
 * file_offset: where the block starts in the file (for messages). */
typedef struct hd__layout {
    size_t n, per, stride, sub;
    size_t off[3];
    hd__type_t type[3];
    int big;
    const double *scale, *offset;
    size_t file_offset;
} hd__layout_t;

/* Convert the n points of L from base into r->sink (reserved here, which
 * must be empty) in parallel, checking each point.  On a bad point the
 * first one is reported as "NAME: byte OFFSET: ...". */
int hd__binary_read(hd__read_t *r, const unsigned char *base, const hd__layout_t *L);

/* The common case: one point per record of `stride` bytes, no scaling. */
int hd__binary_points(hd__read_t *r, const unsigned char *base, size_t n,
                      size_t stride, const size_t off[3],
                      const hd__type_t type[3], int big, size_t file_offset);

#endif
