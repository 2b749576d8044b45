/*
 * progress.c -- the phase progress line (see progress.h).
 *
 * One drawing thread sleeps in 100 ms steps and, while the current phase is
 * older than PROGRESS_DELAY seconds, redraws "\r[bar] name  12.3 s"
 * followed by an erase-to-end-of-line.  The main thread only swaps the
 * phase under a mutex; the drawing thread never touches stdout, so the
 * result on stdout is the same with or without a terminal.  When the phase
 * changes or reporting stops, a drawn line is erased with "\r\033[K".
 */
#include "progress.h"
#include "common.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#define PROGRESS_DELAY 1.0
#define BAR 20

static struct {
    int on, phases, done, drawn, stop;
    double since;
    char name[160];
    pthread_t tid;
    pthread_mutex_t mu;
    pthread_cond_t cv;
} P = {.mu = PTHREAD_MUTEX_INITIALIZER, .cv = PTHREAD_COND_INITIALIZER};

static void erase_locked(void) {
    if (P.drawn) {
        fputs("\r\033[K", stderr);
        fflush(stderr);
        P.drawn = 0;
    }
}

static void *run(void *arg) {
    (void)arg;
    static const char spin[] = "|/-\\";
    unsigned tick = 0;
    pthread_mutex_lock(&P.mu);
    while (!P.stop) {
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        until.tv_nsec += 100 * 1000 * 1000;
        if (until.tv_nsec >= 1000000000L) {
            until.tv_sec++;
            until.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&P.cv, &P.mu, &until);
        if (P.stop || !P.name[0]) continue;
        double age = cli_now() - P.since;
        if (age < PROGRESS_DELAY) continue;
        char bar[BAR + 1];
        int fill = P.phases > 0 ? P.done * BAR / P.phases : 0;
        for (int k = 0; k < BAR; k++) bar[k] = k < fill ? '=' : k == fill ? spin[tick % 4] : ' ';
        bar[BAR] = '\0';
        tick++;
        fprintf(stderr, "\r[%s] %d/%d %s  %.1f s\033[K", bar, P.done + 1, P.phases, P.name, age);
        fflush(stderr);
        P.drawn = 1;
    }
    erase_locked();
    pthread_mutex_unlock(&P.mu);
    return NULL;
}

int progress_start(int enabled, int phases) {
    if (!enabled) return 0;
    P.phases = phases;
    P.done = -1;
    P.stop = 0;
    P.name[0] = '\0';
    if (pthread_create(&P.tid, NULL, run, NULL) != 0) return -1;
    P.on = 1;
    return 0;
}

void progress_phase(const char *fmt, ...) {
    if (!P.on) return;
    pthread_mutex_lock(&P.mu);
    erase_locked();
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(P.name, sizeof P.name, fmt, ap);
    va_end(ap);
    P.done++;
    P.since = cli_now();
    pthread_mutex_unlock(&P.mu);
}

void progress_stop(void) {
    if (!P.on) return;
    pthread_mutex_lock(&P.mu);
    P.stop = 1;
    pthread_cond_signal(&P.cv);
    pthread_mutex_unlock(&P.mu);
    pthread_join(P.tid, NULL);
    P.on = 0;
}
