/*
 * test_io_streams.c -- inputs that are not regular files: a stream is read
 * to its end but never past opt->stream_limit (so /dev/zero is refused, not
 * read until memory runs out), a named FIFO waits for its writer at most
 * opt->fifo_wait_ms and is read whole once the writer comes, and an empty
 * stream leaves nothing allocated behind (LeakSanitizer checks that in the
 * ASan build).
 */
#include "check.h"
#include "files.h"

#include <pthread.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

TEST(a_device_that_never_ends_is_refused_at_the_stream_limit) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.stream_limit = 1 << 20;
    o.format = "xyz";
    hd_cloud_t *c = NULL;
    hd_error_t e;
    CHECK_RC(hd_read_file("/dev/zero", &o, &c, &e), HD_EFORMAT);
    CHECK(c == NULL);
    CHECK(strstr(e.message, "/dev/zero: more than 1048576 bytes from a stream") != NULL);
}

TEST(an_empty_stream_is_refused_and_frees_its_buffer) {
    hd_cloud_t *c = NULL;
    hd_error_t e;
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.format = "xyz";
    CHECK_RC(hd_read_file("/dev/null", &o, &c, &e), HD_EEMPTY);
    CHECK(strstr(e.message, "/dev/null: no points") != NULL);
}

static const char *fifo_path(const char *name) {
    const char *p = tf_path(name);
    unlink(p);
    if (mkfifo(p, 0600) != 0) hdt_fail(__FILE__, __LINE__, "mkfifo %s failed", p);
    return p;
}

TEST(a_fifo_without_a_writer_is_an_error_after_the_wait_not_a_hang) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.fifo_wait_ms = 200;
    hd_cloud_t *c = NULL;
    hd_error_t e;
    const char *p = fifo_path("lonely.xyz");
    double t0 = now();
    CHECK_RC(hd_read_file(p, &o, &c, &e), HD_EIO);
    CHECK(now() - t0 < 20);
    CHECK(strstr(e.message, "a FIFO that no writer opened within 200 ms") != NULL);
    unlink(p);
}

typedef struct {
    const char *path;
    int delay_ms;
    size_t repeat;
} writer_t;

static void *write_fifo(void *arg) {
    const writer_t *w = arg;
    usleep((useconds_t)w->delay_ms * 1000);
    FILE *f = fopen(w->path, "w");
    if (!f) return NULL;
    for (size_t k = 0; k < w->repeat; k++) fprintf(f, "%zu 0 0\n", k);
    fclose(f);
    return NULL;
}

/* hd_read_file of the FIFO w->path while a thread writes it (write_fifo). */
static int read_fifo(const writer_t *w, const hd_read_options_t *o, hd_cloud_t **c, hd_error_t *e) {
    pthread_t t;
    if (pthread_create(&t, NULL, write_fifo, (void *)w) != 0) {
        hdt_fail(__FILE__, __LINE__, "pthread_create failed");
        return HD_EIO;
    }
    int rc = hd_read_file(w->path, o, c, e);
    pthread_join(t, NULL);
    return rc;
}

TEST(a_fifo_is_read_whole_when_its_writer_comes_late) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.fifo_wait_ms = 20000;
    writer_t w = {fifo_path("late.xyz"), 300, 50000};
    hd_cloud_t *c = NULL;
    hd_error_t e;
    int rc = read_fifo(&w, &o, &c, &e);
    if (rc) hdt_fail(__FILE__, __LINE__, "refused: %s", e.message);
    CHECK_EQ(c->count, 50000);
    CHECK_BITS(((const double *)c->data)[3 * 49999], 49999.0);
    hd_cloud_free(c);
    unlink(w.path);
}

TEST(a_fifo_longer_than_the_stream_limit_is_refused) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.stream_limit = 1000;
    writer_t w = {fifo_path("long.xyz"), 0, 1000};
    hd_cloud_t *c = NULL;
    hd_error_t e;
    /* the reader stops early: the writer's next write fails with EPIPE */
    signal(SIGPIPE, SIG_IGN);
    CHECK_RC(read_fifo(&w, &o, &c, &e), HD_EFORMAT);
    CHECK(strstr(e.message, "more than 1000 bytes from a stream") != NULL);
    unlink(w.path);
}
