/*
 * files.h -- small files for reader tests, written into one temporary
 * directory per test run (created on first use under $TMPDIR or /tmp,
 * removed with its files at exit).
 */
#ifndef HD_TEST_FILES_H
#define HD_TEST_FILES_H

#include <stddef.h>
#include <stdint.h>

/* Write n bytes to NAME in the temporary directory; returns the full path
 * (valid until the next 8 calls of tf_write / tf_printf / tf_path). */
const char *tf_write(const char *name, const void *data, size_t n);
/* Write formatted text to NAME; returns the full path. */
const char *tf_printf(const char *name, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* The full path NAME would have, without writing anything. */
const char *tf_path(const char *name);

/* A growing byte buffer, for building binary files. */
typedef struct tf_buf {
    unsigned char *data;
    size_t size, cap;
} tf_buf_t;
void tf_put(tf_buf_t *b, const void *p, size_t n);
void tf_puts(tf_buf_t *b, const char *s);
void tf_putf(tf_buf_t *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Little- (big = 0) or big-endian scalars. */
void tf_u8(tf_buf_t *b, unsigned v);
void tf_u16(tf_buf_t *b, unsigned v, int big);
void tf_u32(tf_buf_t *b, uint32_t v, int big);
void tf_u64(tf_buf_t *b, uint64_t v, int big);
/* The n bytes of text (ASCII) as UTF-16 (width 2) or UTF-32 (width 4) code
 * units, little- or big-endian, after a byte-order mark when bom is set. */
void tf_wide(tf_buf_t *b, const void *text, size_t n, int width, int big, int bom);
void tf_f32(tf_buf_t *b, float v, int big);
void tf_f64(tf_buf_t *b, double v, int big);
void tf_free(tf_buf_t *b);
/* The whole file at path, malloc'd with a NUL after its *n bytes; NULL
 * (and *n 0) when it cannot be read. */
unsigned char *tf_read(const char *path, size_t *n);
/* Write the buffer to NAME, free it, and return the path (as tf_write). */
const char *tf_finish(tf_buf_t *b, const char *name);

#endif
