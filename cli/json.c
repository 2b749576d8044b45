/*
 * json.c -- the few JSON writers the tool needs, and names made safe to
 * print.  Doubles are printed as the shortest text that reads back as the
 * same double (num_text); non-finite values, which JSON cannot hold, become
 * null.
 *
 * File names are bytes, not always UTF-8 (a Latin-1 "Z\xfcrich.xyz").
 *  - JSON strings: valid UTF-8 is written as it is; every byte that is not
 *    part of a valid UTF-8 sequence (a stray continuation byte, a truncated
 *    or overlong sequence, an encoded surrogate, beyond U+10FFFF) is
 *    written as \udcXX, XX its value: Python's "surrogateescape" (PEP 383),
 *    the way Python itself turns such names into text, so the JSON is
 *    valid and the name's bytes come back with os.fsencode(name) (parsers
 *    that refuse lone surrogates see U+FFFD, as jq and Go do).  Control
 *    characters (C0, DEL and the C1 range U+0080..U+009F) are written as
 *    \u00XX, so that the JSON printed on a terminal cannot drive it.
 *  - Text for a person (the report, messages): control characters and
 *    bytes that are not valid UTF-8 are written as \xXX, so a name cannot
 *    hold an escape sequence that a terminal would obey; a name with
 *    neither is printed as it is.
 */
#include "common.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void json_number(FILE *out, double v) {
    if (isfinite(v)) num_print(out, v);
    else fputs("null", out);
}

/* The length of the valid UTF-8 sequence at s (1 to 4; 1 for ASCII), or 0
 * when s[0] does not start one (RFC 3629's table: no overlong form, no
 * surrogate, nothing beyond U+10FFFF). */
static int utf8_len(const unsigned char *s) {
    unsigned c = s[0];
    if (c < 0x80) return 1;
    int n = c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
    if (!n) return 0;
    unsigned lo = c == 0xe0 ? 0xa0 : c == 0xf0 ? 0x90 : 0x80;
    unsigned hi = c == 0xed ? 0x9f : c == 0xf4 ? 0x8f : 0xbf;
    if (s[1] < lo || s[1] > hi) return 0;
    for (int k = 2; k < n; k++)
        if ((s[k] & 0xc0) != 0x80) return 0;
    return n;
}

/* A control character: C0, DEL, or C1 (U+0080..U+009F, "\xc2\x80".."\xc2\x9f"). */
static int control_at(const unsigned char *s, int n) {
    return n == 1 ? s[0] < 0x20 || s[0] == 0x7f : n == 2 && s[0] == 0xc2 && s[1] < 0xa0;
}

void json_string(FILE *out, const char *s) {
    const unsigned char *p = (const unsigned char *)s;
    fputc('"', out);
    for (int n; *p; p += n) {
        n = utf8_len(p);
        if (n == 0) {
            fprintf(out, "\\udc%02x", *p);
            n = 1;
        } else if (*p == '"' || *p == '\\') {
            fprintf(out, "\\%c", *p);
        } else if (control_at(p, n)) {
            fprintf(out, "\\u%04x", n == 1 ? p[0] : p[1]);
        } else {
            fwrite(p, 1, (size_t)n, out);
        }
    }
    fputc('"', out);
}

/* Whether the character at p (*len bytes; a byte that is not valid UTF-8
 * counts as one) is written as \xXX bytes in text. */
static int unsafe_at(const unsigned char *p, int *len) {
    int n = utf8_len(p);
    *len = n ? n : 1;
    return n == 0 || control_at(p, n);
}

const char *safe_text(const char *s) {
    enum { SLOTS = 4 };
    static char *slot[SLOTS];
    static int next;
    size_t extra = 0;
    int n;
    for (const unsigned char *p = (const unsigned char *)s; *p; p += n)
        if (unsafe_at(p, &n)) extra += 3 * (size_t)n;
    if (!extra) return s;
    size_t len = strlen(s);
    char *t = malloc(len + extra + 1);
    if (!t) return "(a name that cannot be shown: out of memory)";
    char *o = t;
    for (const unsigned char *p = (const unsigned char *)s; *p; p += n) {
        if (unsafe_at(p, &n)) {
            for (int k = 0; k < n; k++) o += sprintf(o, "\\x%02x", p[k]);
        } else {
            memcpy(o, p, (size_t)n);
            o += n;
        }
    }
    *o = '\0';
    free(slot[next]);
    slot[next] = t;
    next = (next + 1) % SLOTS;
    return t;
}
