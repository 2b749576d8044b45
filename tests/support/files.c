/*
 * files.c -- the temporary files behind files.h.
 */
#include "files.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <dirent.h>

static char dir[512];
static char paths[8][1024];
static int next_path;

static void cleanup(void) {
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *e;
    char p[1100];
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        unlink(p);
    }
    closedir(d);
    rmdir(dir);
}

const char *tf_path(const char *name) {
    if (!dir[0]) {
        const char *t = getenv("TMPDIR");
        snprintf(dir, sizeof dir, "%s/hd-test-XXXXXX", t && *t ? t : "/tmp");
        if (!mkdtemp(dir)) {
            perror("mkdtemp");
            exit(2);
        }
        atexit(cleanup);
    }
    char *p = paths[next_path++ % 8];
    snprintf(p, sizeof paths[0], "%s/%s", dir, name);
    return p;
}

const char *tf_write(const char *name, const void *data, size_t n) {
    const char *p = tf_path(name);
    FILE *f = fopen(p, "wb");
    if (!f || (n && fwrite(data, 1, n, f) != n) || fclose(f) != 0) {
        perror(p);
        exit(2);
    }
    return p;
}

const char *tf_printf(const char *name, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    char *s = NULL;
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    s = malloc((size_t)n + 1);
    va_start(ap, fmt);
    vsnprintf(s, (size_t)n + 1, fmt, ap);
    va_end(ap);
    const char *p = tf_write(name, s, (size_t)n);
    free(s);
    return p;
}

void tf_put(tf_buf_t *b, const void *p, size_t n) {
    if (b->size + n > b->cap) {
        size_t cap = b->cap ? b->cap : 256;
        while (cap < b->size + n) cap *= 2;
        b->data = realloc(b->data, cap);
        if (!b->data) exit(2);
        b->cap = cap;
    }
    if (n) memcpy(b->data + b->size, p, n);
    b->size += n;
}

void tf_puts(tf_buf_t *b, const char *s) { tf_put(b, s, strlen(s)); }

void tf_putf(tf_buf_t *b, const char *fmt, ...) {
    char tmp[4096];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    tf_put(b, tmp, (size_t)n < sizeof tmp ? (size_t)n : sizeof tmp - 1);
}

static void put_bytes(tf_buf_t *b, uint64_t v, int n, int big) {
    unsigned char t[8];
    for (int k = 0; k < n; k++) t[big ? n - 1 - k : k] = (unsigned char)(v >> (8 * k));
    tf_put(b, t, (size_t)n);
}

void tf_u8(tf_buf_t *b, unsigned v) { put_bytes(b, v, 1, 0); }
void tf_u16(tf_buf_t *b, unsigned v, int big) { put_bytes(b, v, 2, big); }
void tf_u32(tf_buf_t *b, uint32_t v, int big) { put_bytes(b, v, 4, big); }
void tf_wide(tf_buf_t *b, const void *text, size_t n, int width, int big, int bom) {
    const unsigned char *t = text;
    if (bom) put_bytes(b, 0xfeff, width, big);
    for (size_t k = 0; k < n; k++) put_bytes(b, t[k], width, big);
}
void tf_u64(tf_buf_t *b, uint64_t v, int big) { put_bytes(b, v, 8, big); }
void tf_f32(tf_buf_t *b, float v, int big) {
    uint32_t u;
    memcpy(&u, &v, 4);
    put_bytes(b, u, 4, big);
}
void tf_f64(tf_buf_t *b, double v, int big) {
    uint64_t u;
    memcpy(&u, &v, 8);
    put_bytes(b, u, 8, big);
}
void tf_free(tf_buf_t *b) {
    free(b->data);
    b->data = NULL;
    b->size = b->cap = 0;
}

const char *tf_finish(tf_buf_t *b, const char *name) {
    const char *p = tf_write(name, b->data, b->size);
    tf_free(b);
    return p;
}

unsigned char *tf_read(const char *path, size_t *n) {
    FILE *f = fopen(path, "rb");
    *n = 0;
    if (!f) return NULL;
    unsigned char *d = NULL;
    long len = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    if (len >= 0 && fseek(f, 0, SEEK_SET) == 0 && (d = malloc((size_t)len + 1)) &&
        fread(d, 1, (size_t)len, f) == (size_t)len) {
        d[len] = 0;
        *n = (size_t)len;
    } else {
        free(d);
        d = NULL;
    }
    fclose(f);
    return d;
}
