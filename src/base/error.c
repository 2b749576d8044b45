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
 */
#include "base/base.h"

#include <stdio.h>
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

int hd__verr(hd_error_t *err, int code, const char *fmt, va_list ap) {
    if (!err) return code;
    err->code = code;
    err->line = -1;
    err->offset = -1;
    if (fmt) vsnprintf(err->message, sizeof err->message, fmt, ap);
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

