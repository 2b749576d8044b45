/*
 * numtext.c -- a double as the shortest text that reads back as the same
 * double (what Python's repr prints), for every number the tool shows a
 * person or a script: the report, JSON, CSV cells, PLY comments.
 *
 * Why this finds the shortest.  "%.Pg" prints the double rounded correctly
 * to P significant digits, trailing zeros removed.  For a normal double v
 * whose shortest round-tripping decimal d has k <= 15 digits, v lies within
 * half an ulp of d, less than half a unit of the 15th digit (2^-53 <
 * 10^-15 / 2), so "%.15g" rounds v back to d exactly: trying 15, then 16,
 * then 17 digits and keeping the first that reads back gives the shortest
 * text (17 always reads back).  Subnormals carry fewer significant bits,
 * so there every precision from 1 up is tried.  Reading back uses strtod,
 * so the C locale is assumed, as everywhere in the tool (it never calls
 * setlocale).  Non-finite values print as "inf", "-inf" and "nan"; JSON
 * writes null for them itself.
 *
 * The other numbers a person reads: a coordinate of a float32 input as the
 * shortest text of its float (num_text_single), ratios to four significant
 * digits (num_ratio) and times in seconds to three significant digits,
 * never in exponent form (num_seconds).
 */
#include "common.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int reads_back(const char *s, double v) { return strtod(s, NULL) == v; }

const char *num_text(double v, char buf[NUM_TEXT]) {
    if (!isfinite(v)) {
        snprintf(buf, NUM_TEXT, "%s", isnan(v) ? "nan" : v > 0 ? "inf" : "-inf");
        return buf;
    }
    if (v == 0) {
        snprintf(buf, NUM_TEXT, "%s", signbit(v) ? "-0" : "0");
        return buf;
    }
    int p = fabs(v) >= DBL_MIN ? 15 : 1;
    for (; p < 17; p++) {
        snprintf(buf, NUM_TEXT, "%.*g", p, v);
        if (reads_back(buf, v)) return buf;
    }
    snprintf(buf, NUM_TEXT, "%.17g", v);
    return buf;
}

void num_print(FILE *out, double v) {
    char buf[NUM_TEXT];
    fputs(num_text(v, buf), out);
}

const char *num_text_single(double v, char buf[NUM_TEXT]) {
    if (!isfinite(v) || v == 0 || fabs(v) > FLT_MAX) return num_text(v, buf); /* not a float's */
    float f = (float)v;
    /* 9 significant digits always read back as the same float */
    for (int p = 1; p <= 9; p++) {
        snprintf(buf, NUM_TEXT, "%.*g", p, (double)f);
        if (strtof(buf, NULL) == f) break;
    }
    return buf;
}

const char *num_ratio(double v, char buf[NUM_TEXT]) {
    if (!isfinite(v)) return num_text(v, buf);
    snprintf(buf, NUM_TEXT, "%.4g", v);
    return buf;
}

const char *num_seconds(double s, char buf[NUM_TEXT]) {
    if (!isfinite(s) || s < 0) return num_text(s, buf);
    /* three significant digits as decimals, at most to the microsecond:
     * 0.000614, 0.000098, 0.0131, 1.25, 125 */
    int decimals = 6;
    if (s >= 0.0000995) decimals = 2 - (int)floor(log10(s));
    if (decimals < 0) decimals = 0;
    if (decimals > 6) decimals = 6;
    snprintf(buf, NUM_TEXT, "%.*f", decimals, s);
    /* a trailing zero after the point says nothing: 0.0170 -> 0.017, 2.00 -> 2 */
    char *end = buf + strlen(buf);
    if (strchr(buf, '.')) {
        while (end[-1] == '0') *--end = '\0';
        if (end[-1] == '.') *--end = '\0';
    }
    return buf;
}
