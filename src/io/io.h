/*
 * io.h -- what the readers share: the loaded file, the growing cloud, and
 * the error helpers that put the file name and line or byte offset first.
 */
#ifndef HD_IO_H
#define HD_IO_H

#include "../internal.h"

/* A whole input file in memory (mapped when it is a regular file). */
typedef struct hd__file {
    const char *name;          /* as given by the caller, for messages */
    const unsigned char *data; /* size bytes, followed by no terminator */
    size_t size;
} hd__file_t;

/* Points being collected, stored as the caller asked (double or float). */
typedef struct hd__sink {
    void *data;
    size_t count, cap;
    hd_dtype_t dtype;
} hd__sink_t;

void hd__sink_init(hd__sink_t *s, hd_dtype_t dtype);
/* Reserve room for n more points; the caller has checked n against the
 * file's size so that no reader allocates more than the file can hold. */
int hd__sink_reserve(hd__sink_t *s, size_t n);
/* Append one point after checking it is finite and within HD_MAX_COORD. */
int hd__sink_push(hd__sink_t *s, const double p[3]);
void hd__sink_free(hd__sink_t *s);

/* Check one coordinate triple (finite, in range); returns HD_OK or the code. */
int hd__point_valid(const double p[3]);

/* Each reader fills `sink` from `f`, reporting errors as
 * "NAME:LINE: what" (text) or "NAME: byte OFFSET: what" (binary). */
typedef int (*hd__reader_fn)(const hd__file_t *f, const hd_read_options_t *opt,
                             hd__sink_t *sink, size_t *n_faces, hd_error_t *err);

int hd__read_xyz(const hd__file_t *f, const hd_read_options_t *opt,
                 hd__sink_t *sink, size_t *n_faces, hd_error_t *err);

#endif
