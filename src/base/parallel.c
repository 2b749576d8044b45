/*
 * parallel.c -- the one way the library uses threads.
 *
 * Work over A is cut into tasks (slices of A, or buckets); threads take the
 * next task from an atomic counter, so a slow slice never idles the others.
 * Each task writes its own partial result; the caller merges partials with
 * hd__best_offer, whose tie rule (smaller index wins) makes the merged
 * witness independent of which thread did what.  A task is a plain function
 * of (slice of A, index of B) -> (distance, witness): the same cut could
 * serve processes on several machines.
 *
 * The caller's thread is worker 0, so threads = 1 runs serially with no
 * thread created at all.  Every task has run when hd__parallel_for
 * returns, whatever fails: when the thread handles cannot be allocated or
 * a thread cannot be started, the threads that exist (at least the
 * caller's) take all the tasks, and the failure costs only speed.
 */
#include "base/base.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

int hd__thread_count(int requested, size_t work_items) {
    long n = requested;
    if (n <= 0) {
        n = sysconf(_SC_NPROCESSORS_ONLN);
        if (n < 1) n = 1;
    }
    if (n > 256) n = 256;
    if ((size_t)n > work_items) n = work_items ? (long)work_items : 1;
    return (int)n;
}

typedef struct {
    hd__task_fn fn;
    void *ctx;
    size_t n_tasks;
    atomic_size_t next;
} hd__pool_t;

typedef struct {
    hd__pool_t *pool;
    int worker;
} hd__worker_t;

static void run_tasks(hd__pool_t *pool, int worker) {
    for (;;) {
        size_t t = atomic_fetch_add_explicit(&pool->next, 1, memory_order_relaxed);
        if (t >= pool->n_tasks) break;
        pool->fn(pool->ctx, t, worker);
    }
}

static void *worker_main(void *arg) {
    hd__worker_t *w = arg;
    run_tasks(w->pool, w->worker);
    return NULL;
}

void hd__parallel_for(int threads, size_t n_tasks, hd__task_fn fn, void *ctx) {
    hd__pool_t pool;
    pool.fn = fn;
    pool.ctx = ctx;
    pool.n_tasks = n_tasks;
    atomic_init(&pool.next, 0);
    if (threads < 1) threads = 1;
    if ((size_t)threads > n_tasks) threads = n_tasks ? (int)n_tasks : 1;
    if (threads == 1) {
        run_tasks(&pool, 0);
        return;
    }
    pthread_t *tid = hd__malloc_array((size_t)threads, sizeof *tid);
    hd__worker_t *w = hd__malloc_array((size_t)threads, sizeof *w);
    if (!tid || !w) {
        /* No memory for the thread handles: this thread takes every task,
         * as when threads cannot be started (below).  Callers rely on every
         * task having run once this returns. */
        free(tid);
        free(w);
        run_tasks(&pool, 0);
        return;
    }
    int started = 0;
    for (int k = 1; k < threads; k++) {
        w[k].pool = &pool;
        w[k].worker = k;
        if (pthread_create(&tid[k], NULL, worker_main, &w[k]) != 0) break;
        started = k;
    }
    /* Worker 0 is this thread.  If a thread failed to start, the ones that
     * did and this one still take every task, so the result is complete and
     * the failure costs only speed. */
    run_tasks(&pool, 0);
    for (int k = 1; k <= started; k++) pthread_join(tid[k], NULL);
    free(tid);
    free(w);
}

double hd__now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
