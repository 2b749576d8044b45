/*
 * number.c -- text to double, correctly rounded, fast in the common case.
 *
 * Every text reader turns tokens into doubles here.  The contract is that
 * the value is exactly the double strtod() returns for the same token, so a
 * coordinate read from text is the nearest double to the decimal written,
 * and two files holding the same decimals give bit-identical distances.
 *
 * The fast path is Clinger's (1990): when the decimal significand m has at
 * most 19 digits and m <= 2^53, m is exactly a double; when in addition the
 * decimal exponent e satisfies |e| <= 22, 10^|e| is exactly a double too
 * (5^22 < 2^53).  Then m * 10^e or m / 10^e is ONE correctly rounded IEEE
 * operation on exact operands, which is by definition the correctly rounded
 * value of the decimal, i.e. what strtod returns.  The build uses
 * -ffp-contract=off and x86-64/AArch64 evaluate doubles in double precision
 * (FLT_EVAL_METHOD 0, asserted below), so nothing widens or fuses the one
 * operation.  A zero significand gives a signed zero, as strtod does.
 * Everything else (more digits, larger exponents, "inf", "nan", hex floats)
 * goes to strtod on a NUL-terminated copy of the token, and the token must be
 * consumed entirely.  strtod runs in the C locale whatever the program's
 * locale is (uselocale switches this thread to it for the call and back),
 * since files write a decimal point: a program that had set a German
 * locale once saw numbers of more than 19 digits refused.
 */
#include "io.h"

#include <float.h>
#include <locale.h>
#include <stdlib.h>
#include <string.h>

#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD != 0
#error "the Clinger fast path needs FLT_EVAL_METHOD == 0 (no extended precision)"
#endif

static const double pow10_exact[23] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

static int slow_path(const char *s, const char *end, double *out) {
    size_t n = (size_t)(end - s);
    char local[256];
    char *buf = n < sizeof local ? local : malloc(n + 1);
    if (!buf) return 0;
    memcpy(buf, s, n);
    buf[n] = '\0';
    char *e;
    /* glibc returns its static C locale object here: no allocation */
    locale_t c = newlocale(LC_ALL_MASK, "C", (locale_t)0);
    locale_t old = c ? uselocale(c) : (locale_t)0;
    *out = strtod(buf, &e);
    if (c) {
        uselocale(old);
        freelocale(c);
    }
    int ok = n > 0 && e == buf + n;
    if (buf != local) free(buf);
    return ok;
}

const char *hd__scan_double(const char *s, const char *end, double *out) {
    const char *p = s;
    int neg = 0;
    if (p < end && (*p == '-' || *p == '+')) neg = *p++ == '-';
    /* Leading zeros are not significant; the other digits accumulate in m,
     * which wraps only when there are more than 19 of them (then sig > 19
     * sends the token to strtod). */
    const char *z = p;
    while (p < end && *p == '0') p++;
    long digits = (long)(p - z), frac = 0, sig;
    uint64_t m = 0;
    const char *d = p;
    while (p < end && (unsigned)(*p - '0') < 10) m = m * 10 + (uint64_t)(*p++ - '0');
    sig = (long)(p - d);
    digits += sig;
    if (p < end && *p == '.') {
        const char *f = ++p;
        if (m == 0)
            while (p < end && *p == '0') p++;
        const char *fd = p;
        while (p < end && (unsigned)(*p - '0') < 10) m = m * 10 + (uint64_t)(*p++ - '0');
        frac = (long)(p - f);
        sig += (long)(p - fd);
        digits += frac;
    }
    if (digits == 0 || sig > 19) return NULL;
    long e10 = -frac;
    if (p < end && (*p == 'e' || *p == 'E')) {
        const char *q = p + 1;
        int eneg = 0;
        if (q < end && (*q == '-' || *q == '+')) eneg = *q++ == '-';
        if (q == end || (unsigned)(*q - '0') >= 10) return NULL;
        long x = 0;
        while (q < end && (unsigned)(*q - '0') < 10) {
            if (x < 100000) x = x * 10 + (*q - '0');
            q++;
        }
        e10 += eneg ? -x : x;
        p = q;
    }
    double v;
    if (m == 0) {
        v = 0.0;
    } else if (m <= (UINT64_C(1) << 53) && e10 >= -22 && e10 <= 22) {
        v = (double)m;
        if (e10 < 0) v /= pow10_exact[-e10];
        else v *= pow10_exact[e10];
    } else {
        return NULL;
    }
    *out = neg ? -v : v;
    return p;
}

int hd__parse_double(const char *s, const char *end, double *out) {
    if (hd__scan_double(s, end, out) == end) return 1;
    return slow_path(s, end, out);
}
