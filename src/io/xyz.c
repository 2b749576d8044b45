/*
 * xyz.c -- whitespace- or comma-separated text: x y z per line.
 *
 * Extra columns after z are ignored; a first line that does not start with
 * a number is taken as a header; blank lines and lines starting with '#' are
 * skipped.  Numbers are converted with strtod, which rounds correctly, so
 * the double read is the double the text denotes.
 */
#include "io.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

static int is_space(int c) { return c == ' ' || c == '\t' || c == '\r'; }

int hd__read_xyz(const hd__file_t *f, const hd_read_options_t *opt,
                 hd__sink_t *sink, size_t *n_faces, hd_error_t *err) {
    (void)opt;
    (void)n_faces;
    const char *p = (const char *)f->data, *end = p + f->size;
    long long line = 0;
    char tmp[128];
    while (p < end) {
        line++;
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        if (!eol) eol = end;
        const char *s = p;
        while (s < eol && is_space((unsigned char)*s)) s++;
        if (s == eol || *s == '#') {
            p = eol + 1;
            continue;
        }
        double v[3];
        int got = 0;
        const char *q = s;
        while (got < 3 && q < eol) {
            while (q < eol && (is_space((unsigned char)*q) || *q == ',' || *q == ';')) q++;
            if (q == eol) break;
            size_t n = 0;
            while (q + n < eol && !is_space((unsigned char)q[n]) && q[n] != ',' && q[n] != ';') n++;
            if (n >= sizeof tmp) n = sizeof tmp - 1;
            memcpy(tmp, q, n);
            tmp[n] = '\0';
            char *e;
            errno = 0;
            v[got] = strtod(tmp, &e);
            if (e == tmp || *e != '\0') {
                if (line == 1 && got == 0 && sink->count == 0) break; /* header */
                return hd__err_line(err, HD_EFORMAT, line, "%s:%lld: '%s' is not a number",
                                    f->name, line, tmp);
            }
            got++;
            q += n;
        }
        if (got == 0 && line == 1) {
            p = eol + 1;
            continue;
        }
        if (got < 3)
            return hd__err_line(err, HD_EFORMAT, line, "%s:%lld: expected 3 numbers, found %d",
                                f->name, line, got);
        int rc = hd__sink_push(sink, v);
        if (rc == HD_ENONFINITE)
            return hd__err_line(err, rc, line, "%s:%lld: coordinate is NaN or infinite", f->name, line);
        if (rc == HD_ERANGE)
            return hd__err_line(err, rc, line, "%s:%lld: coordinate beyond 1e153", f->name, line);
        if (rc) return hd__err_line(err, rc, line, "%s:%lld: %s", f->name, line, hd_strerror(rc));
        p = eol + 1;
    }
    return HD_OK;
}
