/*
 * xyz.c -- plain text point lists: XYZ, TXT, CSV, PTS, ASC.
 *
 * One point per line: the first three numbers are x, y, z; further columns
 * (intensity, colour, normals) are ignored.  Which characters separate the
 * numbers is decided once per file:
 *  - with the decimal_comma option, commas are decimal separators and
 *    fields are separated by ';' and blanks: the dialect European
 *    spreadsheets write ("4,25;5,5;6,75" is 4.25 5.5 6.75); a field
 *    holding a point is refused, since there a point is a thousands
 *    separator ("1.234" is 1234, once read as 1.234);
 *  - otherwise the first data line (the first line whose first field can
 *    start a number, the same test as the candidate count below) decides:
 *    if it holds a ';', fields are separated by ';' and blanks, and a
 *    field holding a comma is refused with its line, since "1,500" is 1.5
 *    written in one locale and 1500 in another and only the user knows
 *    which (the message names the option); if it holds none, fields are
 *    separated by blanks and commas, and a ';' on a later line is refused
 *    naming that line (the file mixes dialects, and any reading of it could
 *    be the wrong one), and so is a line whose numbers blanks separate and
 *    a comma between digits splits ("4,25<TAB>5,5<TAB>6,75", "1,234.5
 *    2,345.6 3,456.7": decimal commas or thousands separators; see row()).
 * Reading "1,5;2,5;3,5" as blank/comma/semicolon-separated once gave the
 * silent wrong answer (1, 5, 2), and the tab-separated "4,25 5,5 6,75"
 * gave (4, 25, 5).  A comma-separated file whose numbers use decimal
 * commas ("1,5,2,5,3,5") cannot be told from six columns and is read as
 * six columns; docs/formats.md says so.
 * When the first point row holds whole numbers only, every point row must
 * have as many fields as it: that is the pattern of a mesh without its
 * keyword (an OFF named .xyz: a counts row "8356 16674 0", vertex rows of 3
 * fields, face rows "3 i j k" of 4), which was once read as points, faces
 * included, and answered.  Other files may have ragged extra columns.
 * A UTF-8 byte-order mark is skipped; UTF-16 and UTF-32 are refused
 * (hd__text_begin).  Blank lines and lines starting with '#' or '//' are
 * skipped.  The lines before the first data line are the header and are
 * skipped: their first field cannot start a number (starts_number: "x",
 * "X,Y,Z,intensity"), so no number is ever skipped; a malformed number
 * ("1.#QNAN", "1.5D+03", "3.14abc") starts a data line and is refused
 * there, on line 1 as on any other.  The one exception is a first line
 * holding a single whole number, the point count of the Leica PTS format,
 * which must then equal the number of points read (a count lower or higher
 * than the data is an error, never a partial read).
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
    const char *data_at; /* the first data line (the end when there is none) */
    long long data_line; /* its line (for messages) */
    int fields;          /* fields of the first point row */
    long long fields_line; /* that row's line */
    int first_int;       /* that row holds whole numbers only */
} dialect_t;

static int is_blank_sep(int c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/* Any character that may separate fields in either dialect: what the
 * candidate count and the dialect check skip. */
static int is_sep(int c) { return is_blank_sep(c) || c == ',' || c == ';'; }

static int is_field_sep(const dialect_t *d, int c) { return is_blank_sep(c) || c == (d->semicolon ? ';' : ','); }

static int is_digit(int c) { return (unsigned)c - (unsigned)'0' < 10u; }

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

/* Whether the field at t (ending at a separator or eol) can start a number:
 * after an optional sign, a digit or a point first, or nothing (so the
 * malformed "1.#QNAN", "1.5D+03", "3.14abc", "-" and "+.5e" can), or
 * strtod's words inf, infinity and nan before anything but a letter.  A
 * field that cannot ("x", "-x", "X,Y,Z", "index", "infrared") heads a
 * header line.  A double quote first is passed over: "\"1.5\",\"2\",\"3\""
 * is a line of numbers, refused since quotes are not read, where taking it
 * for a header once read a file of quoted numbers as no points (and with
 * --empty zero as the distance 0). */
static int starts_number(const char *t, const char *eol) {
    if (*t == '"' && t + 1 < eol) t++; /* a quoted number starts a number too, and is then refused as one */
    if (is_digit((unsigned char)*t)) return 1;
    if (t < eol && (*t == '+' || *t == '-')) t++;
    if (t == eol || *t == '.' || is_digit((unsigned char)*t) || is_sep((unsigned char)*t)) return 1;
    char w[9];
    size_t n = 0;
    for (; t < eol && n < sizeof w && ((*t | 0x20) >= 'a' && (*t | 0x20) <= 'z'); t++) w[n++] = (char)(*t | 0x20);
    if (t < eol && ((*t | 0x20) >= 'a' && (*t | 0x20) <= 'z')) return 0;
    return (n == 3 && (memcmp(w, "inf", 3) == 0 || memcmp(w, "nan", 3) == 0)) || (n == 8 && memcmp(w, "infinity", 8) == 0);
}

/* Whether the line [p, eol) may hold a point: its first field can start a
 * number.  The lines before the first one that may (comments and blank
 * lines aside) are the header. */
static int candidate(const char *p, const char *eol) {
    while (p < eol && is_sep((unsigned char)*p)) p++;
    return p < eol && starts_number(p, eol);
}

/* Line 1 holding one field that can start a number: the point count of the
 * PTS format, a whole number kept in c->aux (plus one) and checked at the
 * end; 1, or 0 with the problem recorded. */
static int pts_count(hd__chunk_t *c, long long line, const char *q, const char *eol) {
    const char *e = q;
    while (e < eol && !is_sep((unsigned char)*e)) e++;
    double n;
    if (!hd__parse_double(q, e, &n)) {
        hd__chunk_fail(c, HD_EFORMAT, line, "'%.*s' is not a number (column 1)", (int)(e - q > 40 ? 40 : e - q), q);
        return 0;
    }
    if (!(n >= 0 && n < 0x1p64 && n == floor(n))) {
        hd__chunk_fail(c, HD_EFORMAT, line, "expected 3 numbers (x y z), found 1");
        return 0;
    }
    c->aux = (uint64_t)n + 1;
    return 1;
}

/* Whether the comma at p is a lone comma between digits ("4,25",
 * "1,234.5"): a decimal comma or a thousands separator, if blanks also
 * separate fields. */
static int digit_comma(const char *p, const char *eol) {
    return *p == ',' && p + 1 < eol && is_digit((unsigned char)p[-1]) && is_digit((unsigned char)p[1]);
}

/* The first lone comma between digits among the separator runs of [p,
 * end) when a run of blanks alone is among them too, else NULL (p at a
 * field; a run that starts before end is followed to its end, and counts
 * only when a field follows it). */
static const char *digit_comma_among_blanks(const dialect_t *d, const char *p, const char *end, const char *eol) {
    const char *comma = NULL;
    int blank = 0;
    while (p < end) {
        if (!is_field_sep(d, (unsigned char)*p)) {
            p++;
            continue;
        }
        const char *rs = p;
        int has_comma = 0;
        while (p < eol && is_field_sep(d, (unsigned char)*p)) has_comma |= *p++ == ',';
        if (p == eol) break;
        if (!has_comma) blank = 1;
        else if (p - rs == 1 && !comma && digit_comma(rs, eol)) comma = rs;
    }
    return blank ? comma : NULL;
}

/* Records that field `col` (1-based), [t, e), is refused: the message
 * quotes its first 40 characters, says `what` it is and `why` it is
 * refused; returns 0. */
static int refuse_field(hd__chunk_t *c, long long line, int col, const char *t, const char *e, const char *what,
                        const char *why) {
    hd__chunk_fail(c, HD_EFORMAT, line, "'%.*s' %s (column %d)%s", (int)(e - t > 40 ? 40 : e - t), t, what, col, why);
    return 0;
}

/* Field `col` (1-based) at *q that the fast path could not read whole: its
 * value in *v and *q past it (1), or 0 with the problem recorded. */
static int slow_field(hd__chunk_t *c, const dialect_t *d, long long line, int col, const char **q, const char *eol,
                      double *v) {
    const char *t = *q, *e = t;
    while (e < eol && !is_field_sep(d, (unsigned char)*e)) e++;
    *q = e;
    if (!hd__parse_double(t, e, v) && !(d->semicolon && parse_decimal_comma(t, e, v)))
        return refuse_field(c, line, col, t, e, "is not a number",
                            *t == '"' ? ": quoted numbers are not read (write the file without quotes around numbers)"
                                      : "");
    if (d->decimal_comma && memchr(t, '.', (size_t)(e - t)))
        return refuse_field(c, line, col, t, e, "has a point",
                            " where the decimal_comma read option makes commas the decimal points: a thousands "
                            "separator (1.234 is 1234 where 1,5 is 1.5)? write the numbers without one");
    if (d->semicolon && !d->decimal_comma && memchr(t, ',', (size_t)(e - t)))
        return refuse_field(c, line, col, t, e, "has a decimal comma",
                            ": 1,500 is 1.5 in one locale and 1500 in another; to read commas as decimal points, "
                            "give the decimal_comma read option (--decimal-comma in the tool, decimal_comma=True "
                            "in Python)");
    return 1;
}

/* x y z from [*qp, eol) into v: 1 (and *qp past z), or 0 with the problem
 * recorded.  In the blank-and-comma dialect, when the separators between
 * x, y, z and the next field include both a lone comma between digits and
 * blanks alone, the comma is a decimal comma ("4,25<TAB>5,5<TAB>6,75") or
 * a thousands separator ("1,234.5 2,345.6 3,456.7", "1,234,567.5 2 3"),
 * not a separator: the line is refused, since reading the comma as one
 * gave (4, 25, 5) and (1, 234.5, 2).  "1,2,3", "1, 2, 3" and "1 2 3 4,5"
 * (a decimal comma after z, in a column not read) are read.  The runs are
 * looked at only when the numbers ended at a comma and at a blank both (in
 * the semicolon dialect no number ends at a comma): a line separated by
 * blanks alone or by commas alone costs a comparison a field. */
static int row(hd__chunk_t *c, const dialect_t *d, long long line, const char **qp, const char *eol, double v[3]) {
    const char *q = *qp, *comma;
    int got = 0;
    unsigned ends = 0; /* what the numbers ended at */
    while (got < 3) {
        while (q < eol && is_field_sep(d, (unsigned char)*q)) q++;
        if (q == eol) break;
        const char *e = hd__scan_double(q, eol, &v[got]);
        if (e && (e == eol || is_field_sep(d, (unsigned char)*e)) && !(d->decimal_comma && memchr(q, '.', (size_t)(e - q))))
            q = e; /* the fast path read the whole token */
        else if (!slow_field(c, d, line, got + 1, &q, eol, &v[got])) return 0;
        got++;
        if (q == eol) break;
        ends |= 1u << (*q == ','); /* 1: a blank, 2: a comma */
    }
    if (got < 3) {
        hd__chunk_fail(c, HD_EFORMAT, line, "expected 3 numbers (x y z), found %d", got);
        return 0;
    }
    if (ends == 3 && (comma = digit_comma_among_blanks(d, *qp, q < eol ? q + 1 : q, eol)) != NULL) {
        const char *t = comma, *e = comma;
        while (t > *qp && !is_blank_sep((unsigned char)t[-1])) t--;
        while (e < eol && !is_blank_sep((unsigned char)*e)) e++;
        hd__chunk_fail(c, HD_EFORMAT, line,
                       "'%.*s' has a comma between digits where blanks separate fields: a decimal comma or a "
                       "thousands separator; to read decimal commas, give the decimal_comma read option "
                       "(--decimal-comma in the tool, decimal_comma=True in Python)",
                       (int)(e - t > 30 ? 30 : e - t), t);
        return 0;
    }
    *qp = q;
    return 1;
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
        if (ls < d->data_at) {
            /* the header; a candidate here is line 1's PTS count (dialect_of) */
            if (candidate(q, eol) && !pts_count(c, line, q, eol)) return;
            continue;
        }
        if (!d->semicolon && memchr(ls, ';', (size_t)(eol - ls))) {
            hd__chunk_fail(c, HD_EFORMAT, line,
                           "a ';' in a file whose first data line (line %lld) has none: mixed separators",
                           d->data_line);
            return;
        }
        double v[3];
        if (!row(c, d, line, &q, eol, v)) return;
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

static size_t candidates(void *ctx, const char *p, const char *end) {
    (void)ctx;
    size_t n = 0;
    for (const char *q, *eol; hd__next_line(&p, end, &q, &eol);) n += (size_t)candidate(q, eol);
    return n;
}

/* The dialect and the number of fields, from the first data line: the
 * first candidate line, or the next one when the first line is a PTS count
 * (a single field).  Serial; it stops there. */
static dialect_t dialect_of(const char *p, const char *end, int decimal_comma) {
    dialect_t d = {decimal_comma, decimal_comma, end, 0, 0, 0, 0};
    for (long long line = 1; p < end; line++) {
        const char *eol = hd__eol(p, end);
        if (candidate(p, eol)) {
            const char *q = p;
            while (q < eol && is_sep((unsigned char)*q)) q++;
            while (q < eol && !is_sep((unsigned char)*q)) q++;
            while (q < eol && is_sep((unsigned char)*q)) q++;
            if (!(line == 1 && q == eol)) { /* not a PTS count line */
                d.semicolon = decimal_comma || memchr(p, ';', (size_t)(eol - p)) != NULL;
                d.data_at = p;
                d.data_line = d.fields_line = line;
                d.fields = count_fields(&d, p, eol);
                d.first_int = 1;
                for (const char *t = p; t < eol && d.first_int; t++)
                    d.first_int = is_digit((unsigned char)*t) || *t == '-' || *t == '+' || is_field_sep(&d, (unsigned char)*t);
                break;
            }
        }
        p = eol + (eol < end);
    }
    return d;
}

int hd__read_xyz(hd__read_t *r) {
    const char *s, *end = (const char *)r->f->data + r->f->size;
    int rc = hd__text_begin(r, &s);
    if (rc) return rc;
    dialect_t d = dialect_of(s, end, r->opt->decimal_comma);
    /* the shortest point line is "0 0 0\n" */
    hd__text_job_t job = {chunk, NULL, candidates, 6, &d};
    uint64_t count = 0; /* only the first chunk sets it: the PTS count + 1 */
    rc = hd__text_parallel(r, s, end, 1, &job, &count);
    if (rc == HD_OK && count && count - 1 != r->sink->count)
        return hd__io_err_line(r, HD_EFORMAT, 1, "the count line says %llu points, the file holds %zu",
                               (unsigned long long)(count - 1), r->sink->count);
    return rc;
}

const char *hd__xyz_data_start(const char *p, const char *end, int decimal_comma, int *semicolon) {
    dialect_t d = dialect_of(p, end, decimal_comma);
    *semicolon = d.semicolon;
    return d.data_at;
}
