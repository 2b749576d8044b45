/*
 * xyz.c -- plain text point lists: XYZ, TXT, CSV, PTS, ASC.
 *
 * One point per line: the first three numbers are x, y, z; further columns
 * (intensity, colour, normals) are ignored.  Which characters separate the
 * numbers is decided once per file:
 *  - with the decimal_comma option, commas are decimal separators and
 *    fields are separated by ';' and blanks: the dialect European
 *    spreadsheets write ("4,25;5,5;6,75" is 4.25 5.5 6.75);
 *  - otherwise the first data line (the first line whose first field can
 *    start a number, the same test as the candidate count below) decides:
 *    if it holds a ';', fields are separated by ';' and blanks, and a
 *    field holding a comma is refused with its line, since "1,500" is 1.5
 *    written in one locale and 1500 in another and only the user knows
 *    which (the message names the option); if it holds none, fields are
 *    separated by blanks and commas, and a ';' on a later line is refused
 *    naming that line (the file mixes dialects, and any reading of it could
 *    be the wrong one).
 * Reading "1,5;2,5;3,5" as blank/comma/semicolon-separated once gave the
 * silent wrong answer (1, 5, 2).  A comma-separated file whose numbers use
 * decimal commas ("1,5,2,5,3,5") cannot be told from six columns and is
 * read as six columns; docs/formats.md says so.
 * When the first point row holds whole numbers only, every point row must
 * have as many fields as it: that is the pattern of a mesh without its
 * keyword (an OFF named .xyz: a counts row "8356 16674 0", vertex rows of 3
 * fields, face rows "3 i j k" of 4), which was once read as points, faces
 * included, and answered.  Other files may have ragged extra columns.
 * Blank lines and lines starting with '#' or
 * '//' are skipped.  The first line may be a header: if it does not start
 * with a number (a CSV header such as "x,y,z,intensity") it is skipped, and
 * so is a first line holding a single whole number (the point count of the
 * Leica PTS format), which must then equal the number of points read (a
 * count lower or higher than the data is an error, never a partial read).
 * Any other line with fewer than three numbers, or a
 * token among the first three that is not a number, is an error naming the
 * line.
 *
 * The file is cut into chunks of whole lines parsed in parallel
 * (hd__text_parallel), each number converted exactly as strtod would
 * (hd__parse_double), so the points and any error are the same at every
 * thread count.
 */
#include "io.h"

#include <math.h>

typedef struct {
    int semicolon;       /* fields separated by ';' and blanks, not ',' */
    int decimal_comma;   /* the option: a comma in a field is its decimal point */
    long long data_line; /* the line that decided (for messages) */
    int fields;          /* fields of the first point row */
    long long fields_line; /* that row's line */
    int first_int;       /* that row holds whole numbers only */
} dialect_t;

static int is_blank_sep(int c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/* Any character that may separate fields in either dialect: what the
 * candidate count and the dialect check skip. */
static int is_sep(int c) { return is_blank_sep(c) || c == ',' || c == ';'; }

static int is_field_sep(const dialect_t *d, int c) { return is_blank_sep(c) || c == (d->semicolon ? ';' : ','); }

/* A field with a decimal comma, [t, e), as a double: 1 and *v, or 0.  The
 * comma is replaced by a point in a copy; a field holding a point too, or
 * two commas, is not a number. */
static int parse_decimal_comma(const char *t, const char *e, double *v) {
    char buf[128];
    size_t n = (size_t)(e - t);
    if (n >= sizeof buf || memchr(t, '.', n)) return 0;
    memcpy(buf, t, n);
    char *comma = memchr(buf, ',', n);
    if (!comma || memchr(comma + 1, ',', n - (size_t)(comma - buf) - 1)) return 0;
    *comma = '.';
    return hd__parse_double(buf, buf + n, v);
}

/* Fields in [q, eol): maximal runs of characters that separate nothing. */
static int count_fields(const dialect_t *d, const char *q, const char *eol) {
    int n = 0;
    while (q < eol) {
        while (q < eol && is_field_sep(d, (unsigned char)*q)) q++;
        if (q == eol) break;
        n++;
        while (q < eol && !is_field_sep(d, (unsigned char)*q)) q++;
    }
    return n;
}

static void chunk(void *ctx, hd__chunk_t *c) {
    const dialect_t *d = ctx;
    const char *p = c->begin, *end = c->end;
    long long line = 0;
    for (const char *q, *eol; hd__next_line(&p, end, &q, &eol);) {
        line++;
        const char *ls = q;
        while (q < eol && is_sep((unsigned char)*q)) q++;
        if (q == eol || *q == '#' || (*q == '/' && q + 1 < eol && q[1] == '/')) continue;
        int first = c->index == 0 && line == 1;
        double v[3];
        int got = 0;
        /* lines before the deciding one are a header, whatever they hold */
        if (!d->semicolon && !(c->index == 0 && line < d->data_line)) {
            const char *semi = memchr(ls, ';', (size_t)(eol - ls));
            if (semi) {
                hd__chunk_fail(c, HD_EFORMAT, line,
                               "a ';' in a file whose first data line (line %lld) has none: mixed separators",
                               d->data_line);
                return;
            }
        }
        while (got < 3) {
            while (q < eol && is_field_sep(d, (unsigned char)*q)) q++;
            if (q == eol) break;
            const char *t = q, *e = hd__scan_double(q, eol, &v[got]);
            if (e && (e == eol || is_field_sep(d, (unsigned char)*e))) {
                q = e; /* the fast path read the whole token */
                got++;
                continue;
            }
            while (q < eol && !is_field_sep(d, (unsigned char)*q)) q++;
            if (!hd__parse_double(t, q, &v[got]) && !(d->semicolon && parse_decimal_comma(t, q, &v[got]))) {
                if (first && got == 0) break; /* a header line */
                hd__chunk_fail(c, HD_EFORMAT, line, "'%.*s' is not a number (column %d)",
                               (int)(q - t > 40 ? 40 : q - t), t, got + 1);
                return;
            }
            if (d->semicolon && !d->decimal_comma && memchr(t, ',', (size_t)(q - t))) {
                hd__chunk_fail(c, HD_EFORMAT, line,
                               "'%.*s' has a decimal comma (column %d): 1,500 is 1.5 in one locale and 1500 in "
                               "another; to read commas as decimal points, give the decimal_comma read option "
                               "(--decimal-comma in the tool, decimal_comma=True in Python)",
                               (int)(q - t > 40 ? 40 : q - t), t, got + 1);
                return;
            }
            got++;
        }
        if (first && got <= 1) {
            /* a header: words, or the single point count of PTS */
            if (got == 0) continue;
            while (q < eol && is_field_sep(d, (unsigned char)*q)) q++;
            double n = v[0];
            if (q == eol && n >= 0 && n < 0x1p64 && n == floor(n)) {
                c->aux = (uint64_t)n + 1; /* the PTS count, checked at the end */
                continue;
            }
        }
        if (got < 3) {
            hd__chunk_fail(c, HD_EFORMAT, line, "expected 3 numbers (x y z), found %d", got);
            return;
        }
        int fields = d->first_int ? 3 + count_fields(d, q, eol) : d->fields;
        if (fields != d->fields) {
            hd__chunk_fail(c, HD_EFORMAT, line,
                           "%d fields where the first row (line %lld), whole numbers only, has %d: a count "
                           "line and rows of indices, not a list of points (a mesh without its keyword?)",
                           fields, d->fields_line, d->fields);
            return;
        }
        if (!hd__chunk_push(c, line, v)) return;
    }
    c->lines = line;
}

/* Whether the line [p, eol) may hold a point: its first field can start a
 * number (digits, sign, point, or the inf/nan that strtod accepts and the
 * point check then refuses). */
static int candidate(const char *p, const char *eol) {
    while (p < eol && is_sep((unsigned char)*p)) p++;
    unsigned char f = (unsigned char)(p < eol ? *p : 0);
    return ((unsigned)f - (unsigned)'0' < 10u) || f == '-' || f == '+' || f == '.' || f == 'i' || f == 'I' ||
           f == 'n' || f == 'N';
}

static size_t candidates(void *ctx, const char *p, const char *end) {
    (void)ctx;
    size_t n = 0;
    for (const char *q, *eol; hd__next_line(&p, end, &q, &eol);) n += (size_t)candidate(q, eol);
    return n;
}

/* The dialect, from the first candidate line (serial; it stops there). */
/* The dialect and the number of fields, from the first point row: the
 * first candidate line, or the next one when the first line is a PTS count
 * (a single field).  Serial; it stops there. */
static dialect_t dialect_of(const char *p, const char *end, int decimal_comma) {
    dialect_t d = {decimal_comma, decimal_comma, 0, 0, 0, 0};
    for (long long line = 1; p < end; line++) {
        const char *eol = hd__eol(p, end);
        if (candidate(p, eol)) {
            const char *q = p;
            while (q < eol && is_sep((unsigned char)*q)) q++;
            while (q < eol && !is_sep((unsigned char)*q)) q++;
            while (q < eol && is_sep((unsigned char)*q)) q++;
            if (!(line == 1 && q == eol)) { /* not a PTS count line */
                d.semicolon = decimal_comma || memchr(p, ';', (size_t)(eol - p)) != NULL;
                d.data_line = d.fields_line = line;
                d.fields = count_fields(&d, p, eol);
                d.first_int = 1;
                for (const char *t = p; t < eol && d.first_int; t++)
                    d.first_int = (*t >= '0' && *t <= '9') || *t == '-' || *t == '+' || is_field_sep(&d, (unsigned char)*t);
                break;
            }
        }
        p = eol + (eol < end);
    }
    return d;
}

int hd__read_xyz(hd__read_t *r) {
    const char *s = (const char *)r->f->data;
    dialect_t d = dialect_of(s, s + r->f->size, r->opt->decimal_comma);
    /* the shortest point line is "0 0 0\n" */
    hd__text_job_t job = {chunk, NULL, candidates, 6, &d};
    uint64_t count = 0; /* only the first chunk sets it: the PTS count + 1 */
    int rc = hd__text_parallel(r, s, s + r->f->size, 1, &job, &count);
    if (rc == HD_OK && count && count - 1 != r->sink->count)
        return hd__io_err_line(r, HD_EFORMAT, 1, "the count line says %llu points, the file holds %zu",
                               (unsigned long long)(count - 1), r->sink->count);
    return rc;
}
