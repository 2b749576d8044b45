/*
 * tiles.c -- one side of the comparison as many files: a directory or a
 * list (@LIST) of tiles, read as one point set.
 *
 * Invariants:
 *  - Order.  A side's points are its tiles' points concatenated in tile
 *    order: list order, or the directory's names sorted by strcmp (bytes,
 *    not the locale, so every machine and every rank of hausdorff-mpi sees
 *    the same order).  Tile k's points are global indices [first, first +
 *    count), firsts non-decreasing, so tiles_locate is a binary search and
 *    the witness, the --distances rows and their nearest indices all name
 *    the same points whether a side is one file or its tiles.
 *  - Nothing is guessed.  A directory is not recursed; its entries that are
 *    not tiles (hidden, directories, other extensions, NIfTI masks, FIFOs
 *    and devices, a .txt or .csv without a line that starts with a number)
 *    are kept in `skipped` with the reason, for the report.  A text file
 *    with such a line stays a tile however its later lines read, so a
 *    malformed tile is an error, never a skip.  An entry named like a
 *    point file that cannot be stat'ed (a dangling link) stays a tile, so
 *    reading it fails with its name instead of the side silently losing
 *    points.  A list's missing or unsuitable file (a directory, a mask, a
 *    stream) is an error naming LIST:LINE before any point is read.
 *  - A tile is read as the file it was when listed.  A tile may be read
 *    more than once and by other processes (hausdorff-mpi counts points
 *    from headers, then other ranks read ranges), so a tile is a regular
 *    file: a stream (FIFO, device, standard input) is skipped in a
 *    directory and refused in a list, since the first read would use it
 *    up.  Each regular file's stat when listed is its stamp; reading
 *    compares the file's stat with it before and after (and a range's
 *    points with the count the header gave), so a tile rewritten, grown
 *    or replaced between the listing, the count and the read is "changed
 *    during the run", never read in part.
 *  - One side is one file when it is neither a directory nor @LIST; then
 *    tiles_read is exactly cli_read_points on it (masks, standard input,
 *    the --empty policy; seed + 0), and the cloud it returns is the
 *    reader's own: the first tile's cloud is never copied.
 *  - Memory.  Tiles are read one at a time and appended to one buffer that
 *    grows by half again when full (realloc: glibc moves large blocks with
 *    mremap, without copying) and is trimmed to the count at the end.  The
 *    first tile's own buffer becomes that buffer.  At the peak the process
 *    holds the points read so far, the unused growth (at most a third of
 *    the buffer, untouched pages) and one tile's cloud: never two copies of
 *    the side.  Counts and byte sizes are checked for overflow before each
 *    allocation.
 *  - Seeds.  With --sample, tile k of the side is drawn with seed + k: a
 *    side of one mesh is drawn exactly as that mesh alone, and tiles do
 *    not repeat each other's pattern.  k is the tile's place in the whole
 *    side, so reading a sub-range (another process) draws the same points.
 */
#include "tiles.h"
#include "cli.h"

#include <assert.h>
#include <dirent.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

static int fail(hd_error_t *err, int code, long line, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int fail(hd_error_t *err, int code, long line, const char *fmt, ...) {
    err->code = code;
    err->line = line > 0 ? line : -1;
    err->offset = -1;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
    return code;
}

const char *tiles_format_named(const char *s, size_t n) {
    static const char *const text_aliases[] = {"csv", "txt", "pts", "asc", NULL};
    for (const char *const *f = hd_formats(); *f; f++)
        if (strlen(*f) == n && strncasecmp(*f, s, n) == 0) return *f;
    for (const char *const *f = text_aliases; *f; f++)
        if (strlen(*f) == n && strncasecmp(*f, s, n) == 0) return "xyz";
    return NULL;
}

const char *tiles_split_format(const char *s, const char **format) {
    const char *colon = strchr(s, ':');
    *format = colon && colon != s ? tiles_format_named(s, (size_t)(colon - s)) : NULL;
    return *format ? colon + 1 : s;
}

/* dir/name, without doubling a '/' that ends dir; NULL when out of memory */
static char *join(const char *dir, size_t dirlen, const char *name) {
    size_t nl = strlen(name);
    int slash = dirlen > 0 && dir[dirlen - 1] != '/';
    char *p = malloc(dirlen + (size_t)slash + nl + 1);
    if (!p) return NULL;
    memcpy(p, dir, dirlen);
    if (slash) p[dirlen] = '/';
    memcpy(p + dirlen + (size_t)slash, name, nl + 1);
    return p;
}

static tile_stamp_t stamp_of(const struct stat *st) {
    return (tile_stamp_t){(uint64_t)st->st_dev,      (uint64_t)st->st_ino,   (uint64_t)st->st_size,
                          (int64_t)st->st_mtim.tv_sec, st->st_mtim.tv_nsec, (int64_t)st->st_ctim.tv_sec,
                          st->st_ctim.tv_nsec};
}

/* Whether path is still the regular file stamped t. */
static int unchanged(const tile_t *t) {
    struct stat st;
    if (stat(t->path, &st) != 0 || !S_ISREG(st.st_mode)) return 0;
    tile_stamp_t now = stamp_of(&st);
    return memcmp(&now, &t->stamp, sizeof now) == 0;
}

/* Append a tile (taking `path`, with its stat st when known); HD_ENOMEM
 * frees it. */
static int add_tile(tiles_t *s, size_t *cap, char *path, const char *format, long line, uint64_t bytes,
                    const struct stat *st, hd_error_t *err) {
    if (s->n == *cap) {
        size_t nc = *cap ? *cap * 2 : 16;
        tile_t *t = nc <= SIZE_MAX / sizeof *t ? realloc(s->t, nc * sizeof *t) : NULL;
        if (!t) {
            free(path);
            return fail(err, HD_ENOMEM, line, "%s: out of memory for the list of tiles", s->arg);
        }
        s->t = t;
        *cap = nc;
    }
    tile_t *t = &s->t[s->n++];
    *t = (tile_t){path, format, line, bytes, 0, 0, 0, {0, 0, 0, 0, 0, 0, 0}};
    if (st && S_ISREG(st->st_mode)) {
        t->stamped = 1;
        t->stamp = stamp_of(st);
    }
    return HD_OK;
}

static int by_name(const void *x, const void *y) { return strcmp(*(char *const *)x, *(char *const *)y); }

/* 1 when name ends with .txt or .csv (any case): extensions that other
 * documents share with text points. */
static int generic_text(const char *name) {
    const char *dot = strrchr(name, '.');
    return dot && (strcasecmp(dot, ".txt") == 0 || strcasecmp(dot, ".csv") == 0);
}

/* Why a directory entry is not a tile, or NULL when it is one (*st its
 * stat, *known whether stat succeeded). */
static const char *not_a_tile(const char *name, const char *path, struct stat *st, int *known) {
    if (name[0] == '.') return "hidden";
    *known = stat(path, st) == 0;
    if (*known && S_ISDIR(st->st_mode)) return "a directory, not recursed";
    if (nifti_is_mask_path(name)) return "a NIfTI mask, read alone and not as a tile";
    if (!hd_format_of_path(name)) return "no point format has this extension";
    if (*known && !S_ISREG(st->st_mode)) return "not a regular file";
    if (*known && generic_text(name) && tiles_text_has_numbers(path) == 0)
        return "text without a line that starts with a number";
    return NULL;
}

static int expand_dir(tiles_t *s, const char *format, hd_error_t *err) {
    DIR *d = opendir(s->arg);
    if (!d) return fail(err, HD_EIO, 0, "%s: cannot read the directory: %s", s->arg, strerror(errno));
    char **names = NULL;
    size_t n = 0, cap = 0;
    int rc = HD_OK;
    struct dirent *e;
    errno = 0;
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        if (n == cap) {
            size_t nc = cap ? cap * 2 : 64;
            char **p = nc <= SIZE_MAX / sizeof *p ? realloc(names, nc * sizeof *p) : NULL;
            if (!p) break;
            names = p;
            cap = nc;
        }
        if (!(names[n] = strdup(e->d_name))) break;
        n++;
        errno = 0;
    }
    if (e) rc = fail(err, HD_ENOMEM, 0, "%s: out of memory for the directory's names", s->arg);
    else if (errno) rc = fail(err, HD_EIO, 0, "%s: cannot read the directory: %s", s->arg, strerror(errno));
    closedir(d);
    if (rc == HD_OK && n) qsort(names, n, sizeof *names, by_name);
    size_t tcap = 0, scap = 0, dirlen = strlen(s->arg);
    for (size_t k = 0; k < n && rc == HD_OK; k++) {
        char *path = join(s->arg, dirlen, names[k]);
        if (!path) {
            rc = fail(err, HD_ENOMEM, 0, "%s: out of memory", s->arg);
            break;
        }
        struct stat st;
        int known = 0;
        const char *why = not_a_tile(names[k], path, &st, &known);
        if (!why) {
            rc = add_tile(s, &tcap, path, format, 0, known ? (uint64_t)st.st_size : 0, known ? &st : NULL, err);
            continue;
        }
        free(path);
        if (s->n_skipped == scap) {
            size_t nc = scap ? scap * 2 : 8;
            tile_skip_t *p = nc <= SIZE_MAX / sizeof *p ? realloc(s->skipped, nc * sizeof *p) : NULL;
            if (!p) {
                rc = fail(err, HD_ENOMEM, 0, "%s: out of memory", s->arg);
                break;
            }
            s->skipped = p;
            scap = nc;
        }
        s->skipped[s->n_skipped++] = (tile_skip_t){names[k], why};
        names[k] = NULL; /* now the skip's */
    }
    for (size_t k = 0; k < n; k++) free(names[k]);
    free(names);
    return rc;
}

/* One line of a list: blanks around it dropped; NULL for a blank or '#' line. */
static char *trim(char *line, size_t len) {
    while (len && (line[len - 1] == '\n' || line[len - 1] == '\r' || line[len - 1] == ' ' || line[len - 1] == '\t'))
        line[--len] = '\0';
    while (*line == ' ' || *line == '\t') line++;
    return *line && *line != '#' ? line : NULL;
}

/* 16 or 32 when a list's first line is UTF-16 or UTF-32 (by a byte-order
 * mark, or by the NUL bytes of its first characters: ASCII text has none),
 * else 0.  A UTF-8 byte-order mark is skipped instead. */
static int wide_text(const unsigned char *b, size_t n) {
    if (n >= 4 && ((b[0] == 0xff && b[1] == 0xfe && !b[2] && !b[3]) || (!b[0] && !b[1] && b[2] == 0xfe && b[3] == 0xff)))
        return 32;
    if (n >= 2 && ((b[0] == 0xff && b[1] == 0xfe) || (b[0] == 0xfe && b[1] == 0xff))) return 16;
    if (n < 4) return 0;
    if ((b[0] && !b[1] && !b[2] && !b[3]) || (!b[0] && !b[1] && !b[2] && b[3])) return 32;
    return (b[0] && !b[1] && b[2] && !b[3]) || (!b[0] && b[1] && !b[2] && b[3]) ? 16 : 0;
}

/* The longest line of a list: a path (PATH_MAX) and some blanks.  Longer
 * is not a list (a binary file given by mistake), and is refused before
 * getline grows its buffer to the size of the file. */
enum { LINE_MAX_ = 4096 + 64 };

/* What a file that is not regular nor a directory is, for a message. */
static const char *stream_kind(const struct stat *st) {
    if (S_ISFIFO(st->st_mode)) return "a FIFO or pipe";
    if (S_ISCHR(st->st_mode)) return "a character device";
    if (S_ISBLK(st->st_mode)) return "a block device";
    if (S_ISSOCK(st->st_mode)) return "a socket";
    return "not a file";
}

const char *tiles_stream(const char *path) {
    struct stat st;
    if (strcmp(path, "-") == 0) return "standard input";
    return stat(path, &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode) ? stream_kind(&st) : NULL;
}

static int expand_list(tiles_t *s, const char *list, const char *format, hd_error_t *err) {
    struct stat st;
    if (!list[0]) return fail(err, HD_EIO, 0, "'@' names no list (write @FILE; ./@x for a file named @x)");
    if (stat(list, &st) == 0 && S_ISDIR(st.st_mode))
        return fail(err, HD_EFORMAT, 0, "%s: is a directory, not a list of files (name a directory without '@')",
                    list);
    FILE *f = fopen(list, "r");
    if (!f) return fail(err, HD_EIO, 0, "%s: cannot open the list: %s", list, strerror(errno));
    const char *slash = strrchr(list, '/');
    size_t dirlen = slash ? (size_t)(slash - list) + 1 : 0; /* relative paths: from the list's folder */
    char *buf = NULL;
    size_t bufcap = 0, tcap = 0;
    long line = 0;
    ssize_t len;
    int rc = HD_OK;
    while (rc == HD_OK && (len = getline(&buf, &bufcap, f)) >= 0) {
        line++;
        int wide = line == 1 ? wide_text((const unsigned char *)buf, (size_t)len) : 0;
        if (wide || memchr(buf, '\0', (size_t)len) || len > LINE_MAX_) {
            rc = wide ? fail(err, HD_EFORMAT, line, "%s:%ld: UTF-%d text; convert to UTF-8 (a list is text, one path "
                             "per line)", list, line, wide)
                      : fail(err, HD_EFORMAT, line, "%s:%ld: %s (a list is text, one path per line)", list, line,
                             len > LINE_MAX_ ? "a line longer than 4096 bytes" : "a NUL byte");
            break;
        }
        size_t bom = line == 1 && len >= 3 && memcmp(buf, "\xef\xbb\xbf", 3) == 0 ? 3 : 0; /* UTF-8's mark */
        char *p = trim(buf + bom, (size_t)len - bom);
        if (!p) continue;
        const char *fmt;
        const char *name = tiles_split_format(p, &fmt);
        if (!fmt) fmt = format;
        if (strcmp(name, "-") == 0) {
            rc = fail(err, HD_EFORMAT, line, "%s:%ld: standard input ('-') cannot be a tile", list, line);
            break;
        }
        char *path = name[0] == '/' ? strdup(name) : join(list, dirlen, name);
        if (!path) {
            rc = fail(err, HD_ENOMEM, line, "%s:%ld: out of memory", list, line);
            break;
        }
        if (stat(path, &st) != 0)
            rc = fail(err, HD_EIO, line, "%s:%ld: %s: cannot open: %s", list, line, path, strerror(errno));
        else if (S_ISDIR(st.st_mode))
            rc = fail(err, HD_EFORMAT, line, "%s:%ld: %s is a directory (a list names files, one per line)", list,
                      line, path);
        else if (!S_ISREG(st.st_mode))
            rc = fail(err, HD_EFORMAT, line,
                      "%s:%ld: %s is %s, not a regular file: a tile may be read twice, and by other processes, "
                      "which would find a stream used up (save it to a file)",
                      list, line, path, stream_kind(&st));
        else if (!fmt && nifti_is_mask_path(path))
            rc = fail(err, HD_EFORMAT, line, "%s:%ld: %s: a NIfTI mask is read alone, not as a tile", list, line,
                      path);
        if (rc != HD_OK) {
            free(path);
            break;
        }
        rc = add_tile(s, &tcap, path, fmt, line, (uint64_t)st.st_size, &st, err);
    }
    if (rc == HD_OK && ferror(f)) rc = fail(err, HD_EIO, 0, "%s: cannot read the list: %s", list, strerror(errno));
    free(buf);
    fclose(f);
    return rc;
}

int tiles_expand(const char *arg, const char *format, tiles_t *out, hd_error_t *err) {
    memset(out, 0, sizeof *out);
    out->arg = arg;
    struct stat st;
    int rc;
    if (arg[0] == '@') {
        out->kind = TILES_LIST;
        rc = expand_list(out, arg + 1, format, err);
    } else if (strcmp(arg, "-") != 0 && stat(arg, &st) == 0 && S_ISDIR(st.st_mode)) {
        out->kind = TILES_DIR;
        rc = expand_dir(out, format, err);
    } else {
        out->kind = TILES_FILE;
        size_t cap = 0;
        char *p = strdup(arg);
        int known = strcmp(arg, "-") != 0 && stat(arg, &st) == 0; /* bytes 0: shared as before (tiles_share) */
        rc = p ? add_tile(out, &cap, p, format, 0, 0, known ? &st : NULL, err)
               : fail(err, HD_ENOMEM, 0, "%s: out of memory", arg);
    }
    if (rc != HD_OK) {
        tiles_free(out);
        out->arg = arg;
    }
    return rc;
}

void tiles_free(tiles_t *s) {
    for (size_t k = 0; k < s->n; k++) free(s->t[k].path);
    for (size_t k = 0; k < s->n_skipped; k++) free(s->skipped[k].name);
    free(s->t);
    free(s->skipped);
    memset(s, 0, sizeof *s);
}

/* ---- reading ------------------------------------------------------------------ */

/* Append c's points to *all (c freed either way). */
static int append(hd_cloud_t *all, size_t *cap, hd_cloud_t *c, const char *path, hd_error_t *err) {
    size_t el = all->dtype == HD_FLOAT32 ? 3 * sizeof(float) : 3 * sizeof(double);
    if (c->count > SIZE_MAX / el - all->count) {
        hd_cloud_free(c);
        return fail(err, HD_EOVERFLOW, 0, "%s: the side's points would number more than memory can index", path);
    }
    size_t need = all->count + c->count;
    if (need > *cap) {
        size_t grow = *cap + *cap / 2;
        size_t nc = grow > need && grow <= SIZE_MAX / el ? grow : need;
        void *p = realloc(all->data, nc * el);
        if (!p) {
            hd_cloud_free(c);
            return fail(err, HD_ENOMEM, 0, "%s: out of memory for the side's %zu points", path, need);
        }
        all->data = p;
        *cap = nc;
    }
    if (c->count) memcpy((char *)all->data + all->count * el, c->data, c->count * el);
    all->count = need;
    all->n_faces += c->n_faces;
    if (strcmp(all->format, c->format) != 0 && strcmp(c->format, "empty") != 0) {
        if (strcmp(all->format, "empty") == 0) snprintf(all->format, sizeof all->format, "%s", c->format);
        else snprintf(all->format, sizeof all->format, "mixed");
    }
    hd_cloud_free(c);
    return HD_OK;
}

/* The error of tile t, with the list line it came from. */
static int from_list(const tiles_t *s, const tile_t *t, int rc, hd_error_t *err) {
    if (s->kind == TILES_LIST) {
        size_t len = strlen(err->message);
        snprintf(err->message + len, sizeof err->message - len, " (listed at %s:%ld)", s->arg + 1, t->line);
    }
    return rc;
}

static int changed(const tile_t *t, hd_error_t *err) {
    return fail(err, HD_EIO, 0,
                "%s: changed during the run (not the file it was when the side was listed: its size, times or "
                "identity differ, or its points its header's count); run again once nothing writes it",
                t->path);
}

/* Read tile k (points [from, from + take) of it when take > 0) and append
 * it to *all (NULL at first: the first tile's buffer becomes the side's).
 * Fills the tile's count and first when it is read whole; a partial read
 * leaves them (tiles_read_points numbers from the header counts).  On
 * failure *all is freed and NULL. */
static int read_tile(tiles_t *s, size_t k, const hd_read_options_t *ro, analysis_args_t *an, int which, uint64_t from,
                    uint64_t take, hd_cloud_t **all, size_t *cap, hd_error_t *err) {
    tile_t *t = &s->t[k];
    hd_read_options_t r = *ro;
    if (t->format) r.format = t->format;
    r.seed = ro->seed + (uint64_t)k;
    r.range_first = from;
    r.range_count = take;
    hd_cloud_t *c = NULL;
    int rc = t->stamped && !unchanged(t) ? changed(t, err) : cli_read_points(t->path, &r, an, which, &c, err);
    if (rc == HD_OK && ((t->stamped && !unchanged(t)) || (take && c->count != take))) {
        hd_cloud_free(c);
        rc = changed(t, err);
    }
    if (rc != HD_OK) {
        hd_cloud_free(*all);
        *all = NULL;
        return from_list(s, t, rc, err);
    }
    if (!take) {
        t->first = *all ? (*all)->count : 0;
        t->count = c->count;
    } else if (from) {
        c->n_faces = 0; /* a tile's faces count once: in the piece that starts it */
    }
    if (!*all) {
        *all = c; /* its buffer becomes the side's */
        *cap = c->count;
    } else if ((rc = append(*all, cap, c, t->path, err)) != HD_OK) {
        hd_cloud_free(*all);
        *all = NULL;
        return rc;
    }
    return HD_OK;
}

/* The side's cloud without the growth's slack (cap points allocated). */
static hd_cloud_t *trimmed(hd_cloud_t *all, size_t cap) {
    size_t el = all->dtype == HD_FLOAT32 ? 3 * sizeof(float) : 3 * sizeof(double);
    if (cap > all->count && all->count) {
        void *p = realloc(all->data, all->count * el);
        if (p) all->data = p;
    }
    return all;
}

int tiles_read(tiles_t *s, size_t first, size_t n, const hd_read_options_t *ro, analysis_args_t *an, int which,
               hd_cloud_t **out, hd_error_t *err) {
    *out = NULL;
    if (first > s->n || n > s->n - first) return fail(err, HD_EINVAL, 0, "%s: tiles out of range", s->arg);
    if (n == 0) { /* no tiles: a share of none, or an empty side */
        if (s->n == 0 && an->empty == HD_EMPTY_ERROR) {
            char skipped[512];
            tiles_skipped_text(s, skipped, sizeof skipped);
            return fail(err, HD_EEMPTY, 0,
                        "%s: %s%s%s (an empty set has no distance; --empty inf|nan|zero|monai reports one)", s->arg,
                        s->kind == TILES_DIR ? "no point files in the directory" : "the list names no files",
                        skipped[0] ? "; " : "", skipped);
        }
        if (!(*out = cli_cloud_new(0, ro->dtype, "empty"))) return fail(err, HD_ENOMEM, 0, "out of memory");
        return HD_OK;
    }
    hd_cloud_t *all = NULL;
    size_t cap = 0;
    for (size_t k = first; k < first + n; k++) {
        int rc = read_tile(s, k, ro, an, which, 0, 0, &all, &cap, err);
        if (rc != HD_OK) return rc;
    }
    *out = trimmed(all, cap);
    return HD_OK;
}

int tiles_count(const tiles_t *s, int rank, int parts, const hd_read_options_t *ro, uint64_t *counts) {
    assert(parts >= 1 && rank >= 0 && rank < parts);
    for (size_t k = 0; k < s->n; k++) {
        counts[k] = 0;
        if (k % (size_t)parts != (size_t)rank) continue;
        if (!s->t[k].stamped || !unchanged(&s->t[k])) continue; /* a stream, or changed: reading tells */
        hd_read_options_t r = *ro;
        if (s->t[k].format) r.format = s->t[k].format;
        uint64_t c;
        hd_error_t e;
        if (hd_read_count(s->t[k].path, &r, &c, &e) == HD_OK && c < UINT64_MAX) counts[k] = c + 1;
    }
    return HD_OK;
}

int tiles_read_points(tiles_t *s, uint64_t g, uint64_t m, const hd_read_options_t *ro, analysis_args_t *an,
                      int which, hd_cloud_t **out, hd_error_t *err) {
    *out = NULL;
    hd_cloud_t *all = NULL;
    size_t cap = 0;
    for (size_t k = 0; k < s->n && m; k++) {
        tile_t *t = &s->t[k];
        if (g >= (uint64_t)t->first + t->count) continue; /* before the range */
        uint64_t from = g - t->first, take = t->count - from < m ? t->count - from : m;
        int rc = read_tile(s, k, ro, an, which, from, take, &all, &cap, err);
        if (rc != HD_OK) return rc;
        g += take;
        m -= take;
    }
    if (!all && !(all = cli_cloud_new(0, ro->dtype, "empty"))) return fail(err, HD_ENOMEM, 0, "out of memory");
    *out = trimmed(all, cap);
    return HD_OK;
}

int tiles_number(tiles_t *s, hd_error_t *err) {
    size_t at = 0;
    for (size_t k = 0; k < s->n; k++) {
        if (s->t[k].count > SIZE_MAX - at)
            return fail(err, HD_EOVERFLOW, 0, "%s: the side's points would number more than a size_t holds", s->arg);
        s->t[k].first = at;
        at += s->t[k].count;
    }
    return HD_OK;
}

void tiles_skipped_text(const tiles_t *s, char *buf, size_t size) {
    enum { SHOWN = 3 };
    size_t len = 0;
    buf[0] = '\0';
    if (!s->n_skipped) return;
    len += (size_t)snprintf(buf, size, "skipped %zu: ", s->n_skipped);
    for (size_t k = 0; k < s->n_skipped && k < SHOWN && len < size; k++)
        len += (size_t)snprintf(buf + len, size - len, "%s%s (%s)", k ? ", " : "", s->skipped[k].name,
                                s->skipped[k].reason);
    if (s->n_skipped > SHOWN && len < size) snprintf(buf + len, size - len, " and %zu more", s->n_skipped - SHOWN);
}

size_t tiles_locate(const tiles_t *s, size_t g, size_t *local) {
    /* the last tile whose first <= g: empty tiles share the next one's
     * first and come before it, so the tile found holds g */
    size_t lo = 0, hi = s->n; /* answer in [lo, hi) */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (s->t[mid].first <= g) lo = mid;
        else hi = mid;
    }
    *local = g - s->t[lo].first;
    return lo;
}

uint64_t tiles_bound(uint64_t total, int r, int parts) {
    assert(parts >= 1 && r >= 0 && r <= parts);
    uint64_t q = total / (uint64_t)parts, rem = total % (uint64_t)parts; /* rem * r < parts^2: no overflow */
    return (uint64_t)r * q + (uint64_t)r * rem / (uint64_t)parts;
}

void tiles_share(const tiles_t *s, int rank, int parts, size_t *first, size_t *n) {
    assert(parts >= 1 && rank >= 0 && rank < parts);
    uint64_t total = 0;
    for (size_t k = 0; k < s->n; k++) total += s->t[k].bytes;
    uint64_t lo = tiles_bound(total, rank, parts), hi = tiles_bound(total, rank + 1, parts), at = 0;
    int last = rank == parts - 1;
    *first = s->n;
    *n = 0;
    for (size_t k = 0; k < s->n; k++) {
        if (at >= lo && (last || at < hi)) {
            if (*first == s->n) *first = k;
            ++*n;
        }
        at += s->t[k].bytes;
    }
    if (*n == 0) *first = 0;
}

/* FNV-1a, 64 bits, of n bytes. */
static uint64_t fnv(uint64_t h, const void *p, size_t n) {
    const unsigned char *b = p;
    for (size_t k = 0; k < n; k++) h = (h ^ b[k]) * 0x100000001b3u;
    return h;
}

uint64_t tiles_digest(const tiles_t *s) {
    uint64_t h = 0xcbf29ce484222325u, n[3] = {(uint64_t)s->kind, s->n, s->n_skipped};
    h = fnv(h, n, sizeof n);
    for (size_t k = 0; k < s->n; k++) {
        const tile_t *t = &s->t[k];
        h = fnv(h, t->path, strlen(t->path) + 1);
        h = fnv(h, t->format ? t->format : "", t->format ? strlen(t->format) + 1 : 1);
        /* not st_dev: machines that mount one file system number it apart */
        const tile_stamp_t *m = &t->stamp;
        int64_t f[7] = {t->stamped, (int64_t)m->ino, (int64_t)m->size, m->mtime_s, m->mtime_ns, m->ctime_s,
                        m->ctime_ns};
        h = fnv(h, f, sizeof f);
    }
    for (size_t k = 0; k < s->n_skipped; k++) h = fnv(h, s->skipped[k].name, strlen(s->skipped[k].name) + 1);
    return h;
}

/* Whether the first n characters of a line (after its blanks) can start
 * a number, n of them at most 16. */
static int starts_number(const char *h, size_t n) {
    if (n > 1 && h[0] == '"') { /* a quoted number: the reader refuses it, never a skip */
        h++;
        n--;
    }
    size_t k = 0;
    if (k < n && (h[k] == '+' || h[k] == '-')) k++;
    if (k < n && h[k] == '.') k++;
    if (k < n && h[k] >= '0' && h[k] <= '9') return 1;
    if (k != (n && (h[0] == '+' || h[0] == '-'))) return 0; /* a point, then no digit */
    static const char *const words[] = {"infinity", "inf", "nan"};
    for (size_t w = 0; w < 3; w++) {
        size_t len = strlen(words[w]);
        if (n - k >= len && strncasecmp(h + k, words[w], len) == 0 &&
            (n - k == len || !((h[k + len] | 0x20) >= 'a' && (h[k + len] | 0x20) <= 'z')))
            return 1;
    }
    return 0;
}

int tiles_text_has_numbers(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    /* a byte-order mark is skipped, and so are NUL bytes: UTF-16 text is
     * judged by its characters (the reader then refuses it by name) */
    unsigned char bom[3] = {0, 0, 0};
    size_t got = fread(bom, 1, 3, f);
    int skip = got == 3 && memcmp(bom, "\xef\xbb\xbf", 3) == 0                                       ? 3
               : got >= 2 && ((bom[0] == 0xff && bom[1] == 0xfe) || (bom[0] == 0xfe && bom[1] == 0xff)) ? 2
                                                                                                        : 0;
    if (fseek(f, skip, SEEK_SET) != 0) {
        fclose(f);
        return -1;
    }
    char head[16]; /* the start of the line being read */
    size_t n = 0;
    int c, found = 0, open_line = 1; /* open_line: head is still being filled */
    while (!found && (c = getc(f)) != EOF) {
        if (c == 0) continue;
        if (c == '\n' || c == '\r') { /* '\r' too: a line of a file the reader may refuse, never a skip */
            found = n && starts_number(head, n);
            n = 0;
            open_line = 1;
        } else if (open_line && !(n == 0 && strchr(" \t\f\v,;", c))) {
            head[n++] = (char)c;
            if (n == sizeof head) {
                found = starts_number(head, n);
                open_line = 0;
            }
        }
    }
    if (!found && open_line && n) found = starts_number(head, n);
    int bad = ferror(f);
    fclose(f);
    return found ? 1 : bad ? -1 : 0;
}
