/*
 * json.c -- the few JSON writers the tool needs.  Doubles are printed as
 * the shortest text that reads back as the same double (num_text);
 * non-finite values, which JSON cannot hold, become null.
 */
#include "cli.h"

#include <math.h>

void json_number(FILE *out, double v) {
    if (isfinite(v)) num_print(out, v);
    else fputs("null", out);
}

void json_string(FILE *out, const char *s) {
    fputc('"', out);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') fprintf(out, "\\%c", c);
        else if (c < 0x20) fprintf(out, "\\u%04x", c);
        else fputc(c, out);
    }
    fputc('"', out);
}
