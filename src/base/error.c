/*
 * error.c -- the one table of result codes and the caller-supplied error
 * record.
 *
 * Result codes are defined once, by HD_ERRNO_MAP in the public header, as in
 * libuv; the functions here read that table and nothing else.  Context for a
 * failure ("cloud.ply:12: expected 3 numbers") goes into an hd_error_t that
 * the caller passes; there is no global or thread-local error state, so the
 * library is reentrant and two threads reading two files never see each
 * other's messages.
 *
 * A message longer than the record's 1023 bytes (a path can be 4095) is not
 * cut at its end, where the reason is: it is formatted again piece by piece
 * (the format's literal text and each conversion), and its string
 * arguments (file names, as a rule) are shortened in their middle, the
 * longest first, to the longest common length that fits; only when that
 * is not enough (each down to KEEP bytes) is the end cut.
 */
#include "base/base.h"

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *hd_strerror(int code) {
    switch (code) {
#define HD__ERRNO_TEXT(name, value, text) \
    case HD_##name:                       \
        return text;
        HD_ERRNO_MAP(HD__ERRNO_TEXT)
#undef HD__ERRNO_TEXT
    default:
        return "unknown error";
    }
}

const char *hd_err_name(int code) {
    switch (code) {
#define HD__ERRNO_NAME(name, value, text) \
    case HD_##name:                       \
        return "HD_" #name;
        HD_ERRNO_MAP(HD__ERRNO_NAME)
#undef HD__ERRNO_NAME
    default:
        return "HD_EUNKNOWN";
    }
}

const char *hd_version(void) { return HD_VERSION_STRING; }

void hd__err_clear(hd_error_t *err) {
    if (!err) return;
    err->code = HD_OK;
    err->line = -1;
    err->offset = -1;
    err->message[0] = '\0';
}

/* ---- messages longer than hd_error_t holds ------------------------------- */

/* A message formatted piece by piece: literal text and conversions, each
 * string conversion (%s, %.*s: a file name, as a rule) marked as one that
 * may be shortened. */
enum { PIECES = 64, FULL = 16384, KEEP = 24 };
typedef struct {
    size_t at, len;
    int str;
} piece_t;
typedef struct {
    char text[FULL];
    size_t len;
    int n;
    piece_t p[PIECES];
} pieces_t;

static void piece(pieces_t *m, const char *s, size_t n, int str) {
    if (n > FULL - 1 - m->len) n = FULL - 1 - m->len;
    if (m->n < PIECES) m->p[m->n++] = (piece_t){m->len, 0, str};
    else m->p[m->n - 1].str = 0; /* joined to the last: no longer one string */
    memcpy(m->text + m->len, s, n);
    m->len += n;
    m->p[m->n - 1].len += n;
}

/* Conversion spec[0..n) (from '%' to its letter, n < 32) with its
 * argument; *-width and *-precision take theirs first, as printf does. */
static void convert(pieces_t *m, const char *spec, size_t n, va_list *ap) {
    char f[32], out[512];
    memcpy(f, spec, n);
    f[n] = '\0';
    char c = f[n - 1];
    int star[2] = {0, 0}, stars = 0, prec = -1, width = 0, left = strchr(f, '-') != NULL;
    for (size_t k = 1; k + 1 < n; k++)
        if (f[k] == '*' && stars < 2) star[stars++] = va_arg(*ap, int);
    const char *dot = strchr(f, '.'), *d = f + 1 + strspn(f + 1, "-+ #0");
    if (*d == '*') width = star[0];
    else width = atoi(d);
    if (dot) prec = dot[1] == '*' ? star[stars - 1] : atoi(dot + 1);
    if (width < 0) width = -width, left = 1;
    if (c == 's') {
        const char *s = va_arg(*ap, const char *);
        if (!s) s = "(null)";
        size_t sl = strlen(s);
        if (prec >= 0 && (size_t)prec < sl) sl = (size_t)prec;
        for (size_t pad = sl; !left && pad < (size_t)width; pad++) piece(m, " ", 1, 0);
        piece(m, s, sl, 1);
        for (size_t pad = sl; left && pad < (size_t)width; pad++) piece(m, " ", 1, 0);
        return;
    }
    int len = 0, w;
    for (size_t k = n - 1; k > 0 && strchr("hlLqjzt", f[k - 1]); k--) len = len * 256 + f[k - 1];
#define HD__CONV(T) (stars == 2   ? snprintf(out, sizeof out, f, star[0], star[1], va_arg(*ap, T)) \
                     : stars == 1 ? snprintf(out, sizeof out, f, star[0], va_arg(*ap, T))          \
                                  : snprintf(out, sizeof out, f, va_arg(*ap, T)))
    if (strchr("diouxXc", c)) {
        if (c == 'c' || len == 0 || len == 'h' || len == 'h' * 256 + 'h') w = HD__CONV(int);
        else if (len == 'l') w = HD__CONV(long);
        else if (len == 'l' * 256 + 'l' || len == 'q') w = HD__CONV(long long);
        else if (len == 'z') w = HD__CONV(size_t);
        else if (len == 'j') w = HD__CONV(intmax_t);
        else w = HD__CONV(ptrdiff_t);
    } else if (strchr("fFeEgGaA", c)) {
        w = len == 'L' ? HD__CONV(long double) : HD__CONV(double);
    } else if (c == 'p') {
        w = HD__CONV(void *);
    } else { /* "%%" (and nothing else the library writes) */
        w = snprintf(out, sizeof out, "%s", c == '%' ? "%" : "");
    }
#undef HD__CONV
    piece(m, out, w < 0 ? 0 : (size_t)w < sizeof out ? (size_t)w : sizeof out - 1, 0);
}

static void split(pieces_t *m, const char *fmt, va_list ap) {
    va_list aq;
    va_copy(aq, ap);
    m->len = 0;
    m->n = 0;
    for (const char *s = fmt; *s;) {
        const char *pc = strchr(s, '%');
        if (!pc) pc = s + strlen(s);
        if (pc > s) piece(m, s, (size_t)(pc - s), 0);
        if (!*pc) break;
        size_t n = 1 + strspn(pc + 1, "-+ #0123456789.*hlLqjzt");
        if (!pc[n] || n + 1 >= 32) break; /* not a conversion the library writes */
        convert(m, pc, n + 1, &aq);
        s = pc + n + 1;
    }
    va_end(aq);
}

/* Bytes saved by shortening every string piece to at most cap bytes. */
static size_t saved(const pieces_t *m, size_t cap) {
    size_t t = 0;
    for (int k = 0; k < m->n; k++)
        if (m->p[k].str && m->p[k].len > cap) t += m->p[k].len - cap;
    return t;
}

/* Piece p of m into out[0..room) as at most cap bytes when it is a string:
 * its start, "...", its end (a third and two thirds: a file's name ends a
 * path), cut between UTF-8 characters; bytes written. */
static size_t put(const pieces_t *m, const piece_t *p, size_t cap, char *out, size_t room) {
    const char *s = m->text + p->at;
    size_t n = p->len, head = n, tail = 0;
    if (p->str && n > cap) {
        head = (cap - 3) / 3;
        tail = cap - 3 - head;
        while (head > 0 && ((unsigned char)s[head] & 0xc0) == 0x80) head--;
        while (tail > 0 && ((unsigned char)s[n - tail] & 0xc0) == 0x80) tail--;
    }
    size_t o = head < room ? head : room;
    memcpy(out, s, o);
    if (tail) {
        for (int k = 0; k < 3 && o < room; k++) out[o++] = '.';
        size_t t = tail < room - o ? tail : room - o;
        memcpy(out + o, s + n - tail, t);
        o += t;
    }
    return o;
}

/* fmt's message into out (size bytes): whole when it fits; else its string
 * arguments (file names, as a rule) shortened in their middle, the longest
 * first, each to no less than KEEP bytes, so that the rest (what went
 * wrong, and why) stays whole; cut at the end only when that is not
 * enough, or when there is no memory to do better. */
static void format_message(char *out, size_t size, const char *fmt, va_list ap) {
    va_list aq;
    va_copy(aq, ap);
    int n = vsnprintf(out, size, fmt, aq);
    va_end(aq);
    pieces_t *m;
    if (n < 0 || (size_t)n < size || size <= KEEP || !(m = malloc(sizeof *m))) return;
    split(m, fmt, ap);
    size_t excess = m->len > size - 1 ? m->len - (size - 1) : 0, lo = KEEP, hi = KEEP;
    for (int k = 0; k < m->n; k++)
        if (m->p[k].str && m->p[k].len > hi) hi = m->p[k].len;
    while (lo < hi) { /* the largest cap that saves enough (KEEP if none does) */
        size_t mid = lo + (hi - lo + 1) / 2;
        if (saved(m, mid) >= excess) lo = mid;
        else hi = mid - 1;
    }
    size_t o = 0;
    for (int k = 0; k < m->n; k++) o += put(m, &m->p[k], lo, out + o, size - 1 - o);
    out[o] = '\0';
    free(m);
}

int hd__verr(hd_error_t *err, int code, const char *fmt, va_list ap) {
    if (!err) return code;
    err->code = code;
    err->line = -1;
    err->offset = -1;
    if (fmt) format_message(err->message, sizeof err->message, fmt, ap);
    else snprintf(err->message, sizeof err->message, "%s", hd_strerror(code));
    return code;
}

int hd__err(hd_error_t *err, int code, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    hd__verr(err, code, fmt, ap);
    va_end(ap);
    return code;
}
