/*
 * write_text.c -- a field written back into text point lists (XYZ, CSV,
 * TXT, PTS, ASC) and OBJ vertices (hd_write_field).
 *
 * The point lines are the ones the readers take: for xyz text, from the
 * first data line on (xyz.c decides where it is and the dialect), every
 * line that is not blank, made of separators only, or a comment ('#',
 * '//'); for OBJ, the lines whose first token is `v`.  Every line is kept
 * as it is (its terminator too); a kept point line gets the separator of
 * the file's dialect and the value's shortest decimal (with a decimal
 * comma when the file is read with one) before its terminator, after its
 * trailing blanks are dropped.  Header lines stay; the one that names the
 * columns (the last header line that is neither a comment nor a number,
 * with as many fields as the first data line) gets the field's name, and a
 * PTS count line (a lone number on line 1) a subset's count.  A subset
 * leaves out the point lines not kept and keeps the others.
 * OBJ has no column for a value (a fourth number is the vertex weight w),
 * so nothing is added; a subset leaves out the vertices not kept and the
 * faces, lines and points (`f`, `l`, `p`), which refer to vertices by
 * their place.
 */
#include "io.h"

#include <stdlib.h>

static int is_sep(int c) { return hd__is_blank(c) || c == ',' || c == ';'; }

/* Skip separators; the first character that is not one (or eol). */
static const char *skip_seps(const char *q, const char *eol) {
    while (q < eol && is_sep((unsigned char)*q)) q++;
    return q;
}

static int is_comment(const char *q, const char *eol) {
    return q == eol || *q == '#' || (*q == '/' && q + 1 < eol && q[1] == '/');
}

/* Fields of [q, eol) separated by runs of separators. */
static int fields(const char *q, const char *eol) {
    int n = 0;
    for (q = skip_seps(q, eol); q < eol; q = skip_seps(q, eol)) {
        n++;
        while (q < eol && !is_sep((unsigned char)*q)) q++;
    }
    return n;
}

/* [line, eol) without its trailing blanks ('\r' included). */
static const char *trimmed(const char *line, const char *eol) {
    while (eol > line && hd__is_blank((unsigned char)eol[-1])) eol--;
    return eol;
}

static const char *terminator(const char *line, const char *eol, const char *end) {
    if (eol == end) return "\n";
    return eol > line && eol[-1] == '\r' ? "\r\n" : "\n";
}

/* Line, trimmed, then sep and text, then its terminator. */
static void put_with(hd__writer_t *w, const char *line, const char *eol, const char *end, char sep, const char *text,
                     size_t n) {
    const char *t = trimmed(line, eol);
    hd__w_put(w, line, (size_t)(t - line));
    hd__w_put(w, &sep, 1);
    hd__w_put(w, text, n);
    const char *nl = terminator(line, eol, end);
    hd__w_put(w, nl, strlen(nl));
}

/* The fields' names, separated by sep, into row; its length. */
static size_t names_row(const hd__writer_t *w, char sep, char *row) {
    size_t n = 0;
    for (size_t j = 0; j < w->nf; j++) {
        if (j) row[n++] = sep;
        size_t len = strlen(w->f[j].name);
        memcpy(row + n, w->f[j].name, len);
        n += len;
    }
    return n;
}

/* Point k's values as their shortest decimals (a decimal comma with dc),
 * separated by sep, into row; its length. */
static size_t values_row(const hd__writer_t *w, size_t k, char sep, int dc, char *row) {
    size_t n = 0;
    for (size_t j = 0; j < w->nf; j++) {
        if (j) row[n++] = sep;
        char *num = row + n;
        size_t len = hd__shortest(w->f[j].values[k], num);
        char *dot = dc ? memchr(num, '.', len) : NULL;
        if (dot) *dot = ',';
        n += len;
    }
    return n;
}

static int write_obj(hd__writer_t *w) {
    const char *s = (const char *)w->in->data, *end = s + w->in->size, *p = s, *line, *eol;
    if (w->keep == HD_KEEP_ALL && w->nf)
        return hd__err(w->err, HD_EUNSUPPORTED,
                       "%s: OBJ has no place for a per-vertex value (a fourth number is the weight w); write the "
                       "distances as .csv, .ply or .npy, or a subset of the OBJ",
                       w->in->name);
    size_t k = 0;
    while (hd__next_line(&p, end, &line, &eol)) {
        const char *q = line, *tb, *te;
        int tok = hd__token(&q, eol, &tb, &te) && te - tb == 1;
        if (tok && *tb == 'v') {
            if (k >= w->n) return hd__err(w->err, HD_EINVAL, "%s: more vertices than the %zu values", w->in->name, w->n);
            if (hd__w_keep(w, k)) {
                hd__w_put(w, line, (size_t)(p - line));
                w->written++;
            }
            k++;
            continue;
        }
        if (tok && w->keep != HD_KEEP_ALL && (*tb == 'f' || *tb == 'l' || *tb == 'p')) continue;
        hd__w_put(w, line, (size_t)(p - line));
    }
    return k == w->n ? HD_OK : hd__err(w->err, HD_EINVAL, "%s: %zu vertices for %zu values", w->in->name, k, w->n);
}

/* The column separator of the data line [q, eol). */
static char separator(int semicolon, const char *q, const char *eol) {
    if (semicolon) return ';';
    if (memchr(q, ',', (size_t)(eol - q))) return ',';
    if (memchr(q, '\t', (size_t)(eol - q)) && !memchr(q, ' ', (size_t)(eol - q))) return '\t';
    return ' ';
}

static int write_xyz(hd__writer_t *w) {
    const char *s = (const char *)w->in->data, *end = s + w->in->size, *begin = s;
    size_t bom = 0;
    if (hd__text_encoding(w->in->data, w->in->size, &bom) == 8) begin = s + bom;
    int semicolon = 0, dc = w->ropt->decimal_comma;
    const char *data = hd__xyz_data_start(begin, end, dc, &semicolon);
    const char *deol = hd__eol(data, end);
    char sep = separator(semicolon, data, deol);
    int data_fields = fields(data, deol);
    /* the header line that names the columns, and a PTS count line */
    const char *names = NULL, *count_line = NULL, *p = begin, *line, *eol;
    for (long long ln = 1; p < data && hd__next_line(&p, end, &line, &eol); ln++) {
        const char *q = skip_seps(line, eol);
        if (is_comment(q, eol)) continue;
        if (ln == 1 && fields(q, eol) == 1 && ((*q >= '0' && *q <= '9') || *q == '+')) count_line = line;
        else if (fields(q, eol) == data_fields) names = line;
    }
    size_t k = 0, kept = hd__w_kept(w);
    char num[40], *row = malloc(40 * w->nf + 1); /* the fields' texts, sep between them */
    if (!row) return hd__err(w->err, HD_ENOMEM, "out of memory");
    hd__w_put(w, s, (size_t)(begin - s));
    for (p = begin; hd__next_line(&p, end, &line, &eol);) {
        const char *q = skip_seps(line, eol);
        if (line == count_line && w->keep != HD_KEEP_ALL) {
            size_t n = (size_t)snprintf(num, sizeof num, "%zu", kept);
            hd__w_put(w, num, n);
            const char *nl = terminator(line, eol, end);
            hd__w_put(w, nl, strlen(nl));
            continue;
        }
        if (line < data || is_comment(q, eol)) {
            if (line == names && w->nf) put_with(w, line, eol, end, sep, row, names_row(w, sep, row));
            else hd__w_put(w, line, (size_t)(p - line));
            continue;
        }
        if (k >= w->n) {
            free(row);
            return hd__err(w->err, HD_EINVAL, "%s: more points than the %zu values", w->in->name, w->n);
        }
        if (hd__w_keep(w, k)) {
            if (w->nf) {
                put_with(w, line, eol, end, sep, row, values_row(w, k, sep, dc, row));
            } else {
                hd__w_put(w, line, (size_t)(p - line));
            }
            w->written++;
        }
        k++;
    }
    free(row);
    return k == w->n ? HD_OK : hd__err(w->err, HD_EINVAL, "%s: %zu points for %zu values", w->in->name, k, w->n);
}

int hd__write_text(hd__writer_t *w, int obj) { return obj ? write_obj(w) : write_xyz(w); }
