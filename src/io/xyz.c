/*
 * xyz.c -- plain text point lists: XYZ, TXT, CSV, PTS, ASC.
 *
 * One point per line: the first three numbers are x, y, z; further columns
 * (intensity, colour, normals) are ignored.  Numbers are separated by
 * blanks, commas or semicolons.  Blank lines and lines starting with '#' or
 * '//' are skipped.  The first line may be a header: if it does not start
 * with a number (a CSV header such as "x,y,z,intensity") it is skipped, and
 * so is a first line holding a single whole number (the point count of the
 * Leica PTS format).  Any other line with fewer than three numbers, or a
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

static int is_sep(int c) { return c == ' ' || c == ',' || c == '\t' || c == ';' || c == '\r' || c == '\f' || c == '\v'; }

static void chunk(void *ctx, hd__chunk_t *c) {
    (void)ctx;
    const char *p = c->begin, *end = c->end;
    long long line = 0;
    while (p < end) {
        line++;
        const char *eol = hd__eol(p, end), *q = p;
        p = eol + (eol < end);
        while (q < eol && is_sep((unsigned char)*q)) q++;
        if (q == eol || *q == '#' || (*q == '/' && q + 1 < eol && q[1] == '/')) continue;
        int first = c->index == 0 && line == 1;
        double v[3];
        int got = 0;
        while (got < 3) {
            while (q < eol && is_sep((unsigned char)*q)) q++;
            if (q == eol) break;
            const char *t = q, *e = hd__scan_double(q, eol, &v[got]);
            if (e && (e == eol || is_sep((unsigned char)*e))) {
                q = e; /* the fast path read the whole token */
                got++;
                continue;
            }
            while (q < eol && !is_sep((unsigned char)*q)) q++;
            if (!hd__parse_double(t, q, &v[got])) {
                if (first && got == 0) break; /* a header line */
                hd__chunk_fail(c, HD_EFORMAT, line, "'%.*s' is not a number (column %d)",
                               (int)(q - t > 40 ? 40 : q - t), t, got + 1);
                return;
            }
            got++;
        }
        if (first && got <= 1) {
            /* a header: words, or the single point count of PTS */
            if (got == 0) continue;
            while (q < eol && is_sep((unsigned char)*q)) q++;
            double n = v[0];
            if (q == eol && n >= 0 && n < 0x1p64 && n == floor(n)) continue;
        }
        if (got < 3) {
            hd__chunk_fail(c, HD_EFORMAT, line, "expected 3 numbers (x y z), found %d", got);
            return;
        }
        if (!hd__chunk_push(c, line, v)) return;
    }
    c->lines = line;
}

/* Lines whose first field can start a number (digits, sign, point, or the
 * inf/nan that strtod accepts and the point check then refuses). */
static size_t candidates(void *ctx, const char *p, const char *end) {
    (void)ctx;
    size_t n = 0;
    while (p < end) {
        const char *eol = hd__eol(p, end), *q = p;
        while (q < eol && is_sep((unsigned char)*q)) q++;
        unsigned char f = (unsigned char)(q < eol ? *q : 0);
        n += ((unsigned)f - (unsigned)'0' < 10u) || f == '-' || f == '+' || f == '.' || f == 'i' || f == 'I' || f == 'n' || f == 'N';
        p = eol + (eol < end);
    }
    return n;
}

int hd__read_xyz(hd__read_t *r) {
    const char *s = (const char *)r->f->data;
    /* the shortest point line is "0 0 0\n" */
    hd__text_job_t job = {chunk, NULL, candidates, 6, NULL};
    return hd__text_parallel(r, s, s + r->f->size, 1, &job, NULL);
}
