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
 */
#include "cli.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

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
