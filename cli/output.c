/*
 * output.c -- lost output is a failure: everything the tool writes is
 * checked, and a file appears under its name only when all of it was
 * written and the run succeeded.
 *
 * Invariants:
 *  - Standard output.  Its errors (a full disk, /dev/full, a descriptor
 *    open only for reading, a pipe whose reader left while SIGPIPE is
 *    ignored) are found at the end, in out_finish: fflush, ferror, then
 *    fclose, each checked.  A closed descriptor 1 (`>&-`) cannot be found
 *    that way -- the first file the tool opens would get number 1, and the
 *    report would go into it -- so out_guard_std, the first thing main
 *    does, opens /dev/null on each of 0, 1 and 2 that is closed and
 *    remembers that 1 was: the run then fails at the end with "standard
 *    output: Bad file descriptor".
 *  - Files.  out_open creates a temporary with mkstemp in the directory of
 *    the final file (".NAME.tmp.XXXXXX": same file system, so the rename is
 *    atomic), with the permissions fopen would have given (0666 less the
 *    umask) or those of the file it replaces.  out_close flushes and checks
 *    the first failed write, fflush, ferror and fclose, and removes the
 *    temporary on any failure.  Nothing is renamed before out_finish, which
 *    first flushes and closes standard output; only when that succeeded
 *    are the files renamed over their names.  A run that fails, at any
 *    point, removes every temporary (out_discard, also registered with
 *    atexit): none of its files appears, and a file that existed keeps its
 *    old content.
 *  - All or none.  Before the first rename every target is checked again
 *    (a directory cannot be replaced); when more than one file is renamed,
 *    a hard link to each file about to be replaced is kept until all are
 *    in place, so a rename that fails half-way puts back what the earlier
 *    ones replaced (the old file, or no file).  The signals below are
 *    blocked while the renames run.
 *  - Symbolic links are followed: the file a link names is replaced and the
 *    link stays.  A target that exists and is not a regular file
 *    (/dev/null, a FIFO, /dev/stdout) is written in place and checked the
 *    same way; it cannot be staged.  A FIFO's reader is awaited as long as
 *    an input FIFO's writer (--fifo-wait, 30 s by default): without one the
 *    run fails (exit 3) instead of blocking for ever.
 *  - Signals: while temporaries exist, SIGINT, SIGTERM, SIGHUP and SIGPIPE
 *    (those not ignored) remove them before the tool dies of the signal,
 *    and SIGXFSZ is ignored, so that a file beyond `ulimit -f` is a write
 *    that fails with EFBIG (reported, exit 3) rather than a crash.
 *  - Inputs are never overwritten: out_check_paths compares every output
 *    with every input (each tile of A and B, and a list of tiles), and
 *    with the other outputs, by literal path and by identity (st_dev and
 *    st_ino, through links; standard input by fstat when it is a regular
 *    file), before anything is read, and refuses with the usage exit
 *    status 1 and a message naming both.
 * A failure prints "hausdorff: WHAT: strerror" and the run exits with 3.
 * Files are not fsync'ed: a rename makes a complete file appear, but a
 * machine that crashes right after may still lose it.
 */
#include "output.h"
#include "cli.h"
#include "tiles.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#ifndef PATH_MAX
#define PATH_MAX 4096
#endif

enum { MAX_STAGED = 8 };

typedef struct {
    char name[PATH_MAX];       /* as given, for messages */
    char target[PATH_MAX];     /* the name, or the file its link names */
    char tmp[PATH_MAX];        /* the temporary beside target */
    char old[PATH_MAX + 8];    /* during a commit: a link to the old file */
    FILE *f;                   /* open between out_open and out_close */
    int direct;                /* not a regular file: written in place */
    int had;                   /* during a commit: target existed */
    int renamed;               /* during a commit: tmp is now target */
    volatile sig_atomic_t live_tmp, live_old; /* tmp, old exist on disk */
} staged_t;

static staged_t S[MAX_STAGED];
static volatile sig_atomic_t n_staged;
static int stdout_closed, installed;
static int fifo_wait_ms; /* how long an output FIFO's reader is awaited (--fifo-wait; 0: the default) */
static const int SIGNALS[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};

/* ---- standard descriptors ------------------------------------------------- */

void out_guard_std(void) {
    /* the report in one piece: written by the final fflush, whose errno
     * then says why it failed (after a write that failed half-way, glibc
     * drops the buffer and the reason is lost) */
    static char buf[1 << 16];
    setvbuf(stdout, buf, _IOFBF, sizeof buf);
    for (int fd = 0; fd <= 2; fd++) {
        if (fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
        if (fd == 1) stdout_closed = 1;
        int g = open("/dev/null", fd ? O_WRONLY : O_RDONLY);
        if (g >= 0 && g != fd) { /* only when a lower one could not be filled */
            dup2(g, fd);
            close(g);
        }
    }
}

/* ---- inputs and outputs ------------------------------------------------------ */

static int is_stdin(const char *path, int input) { return input && strcmp(path, "-") == 0; }

/* The directory entry a path names: its directory resolved (realpath), then
 * its last component; 0, or -1 when the directory cannot be resolved. */
static int entry_of(const char *path, char out[PATH_MAX]) {
    char dir[PATH_MAX], real[PATH_MAX];
    const char *slash = strrchr(path, '/');
    size_t dirlen = slash ? (size_t)(slash - path) + 1 : 0;
    if (dirlen >= sizeof dir) return -1;
    memcpy(dir, path, dirlen);
    dir[dirlen] = '\0';
    if (!realpath(dirlen ? dir : ".", real)) return -1;
    size_t rl = strlen(real), bl = strlen(path + dirlen);
    if (rl + 1 + bl >= PATH_MAX) return -1;
    memcpy(out, real, rl);
    out[rl] = '/';
    memcpy(out + rl + 1, path + dirlen, bl + 1);
    return 0;
}

/* 1 when writing `out` would overwrite `other` (an input when input): the
 * same literal path, the same directory entry, or the same file. */
static int clash(const char *out, const char *other, int input) {
    struct stat so, st;
    int exists = stat(out, &so) == 0;
    if (exists && !S_ISREG(so.st_mode)) return 0; /* /dev/null and the like: written in place, nothing lost */
    if (is_stdin(other, input))
        return exists && fstat(0, &st) == 0 && S_ISREG(st.st_mode) && so.st_dev == st.st_dev &&
               so.st_ino == st.st_ino;
    if (strcmp(out, other) == 0) return 1;
    if (exists && stat(other, &st) == 0) return so.st_dev == st.st_dev && so.st_ino == st.st_ino;
    static char eo[PATH_MAX], et[PATH_MAX]; /* not on the stack: 8 KiB */
    return entry_of(out, eo) == 0 && entry_of(other, et) == 0 && strcmp(eo, et) == 0;
}

int out_check_paths(const char *const *outs, const char *const *what, int n,
                    const char *const *inputs, const char *side, size_t n_inputs) {
    for (int k = 0; k < n; k++) {
        if (!outs[k]) continue;
        for (size_t w = 0; w < n_inputs; w++)
            if (clash(outs[k], inputs[w], 1)) {
                fprintf(stderr, "%s: %s %s would overwrite input %c (%s); name another file\n", cli_prog(), what[k],
                        safe_text(outs[k]), side[w], is_stdin(inputs[w], 1) ? "standard input" : safe_text(inputs[w]));
                return EXIT_USAGE;
            }
        for (int j = 0; j < k; j++)
            if (outs[j] && clash(outs[k], outs[j], 0)) {
                fprintf(stderr, "%s: %s %s and %s %s are the same file; name another file\n", cli_prog(), what[j],
                        safe_text(outs[j]), what[k], safe_text(outs[k]));
                return EXIT_USAGE;
            }
    }
    return 0;
}

/* Refuse an output that would overwrite an input (any tile, or a list of
 * them) or another output. */
int out_check_outputs(const cli_args_t *a, const tiles_t *side) {
    fifo_wait_ms = a->read.fifo_wait_ms; /* outputs await a reader as inputs await a writer */
    char *path_b[3] = {NULL, NULL, NULL};
    const char *outs[8] = {a->an.distances_out, NULL, a->an.render_out, a->an.histogram_png,
                           a->an.subset[0].on ? a->an.subset[0].out : NULL, NULL,
                           a->an.subset[1].on ? a->an.subset[1].out : NULL, NULL};
    const char *const what[8] = {"--distances", "--distances (B's rows)", "--render", "--histogram-png",
                                 "--farther-than", "--farther-than (B's points)", "--nearer-than",
                                 "--nearer-than (B's points)"};
    static const int with_b[3] = {0, 4, 6};
    for (int k = 0; k < 3; k++)
        if (outs[with_b[k]] && !a->directed && !(outs[with_b[k] + 1] = path_b[k] = path_with_suffix(outs[with_b[k]], "_b"))) {
            fprintf(stderr, "%s: out of memory\n", cli_prog());
            free(path_b[0]), free(path_b[1]);
            return EXIT_FAILURE_;
        }
    int any = 0;
    for (int k = 0; k < 8; k++) any |= outs[k] != NULL;
    if (!any) return 0;
    size_t n = side[0].n + side[1].n + 2, m = 0;
    const char **in = malloc(n * sizeof *in);
    char *which = malloc(n);
    int rc = EXIT_FAILURE_;
    if (!in || !which) {
        fprintf(stderr, "%s: out of memory\n", cli_prog());
    } else {
        for (int w = 0; w < 2; w++) {
            if (side[w].kind == TILES_LIST) in[m] = side[w].arg + 1, which[m++] = "AB"[w];
            for (size_t k = 0; k < side[w].n; k++) in[m] = side[w].t[k].path, which[m++] = "AB"[w];
        }
        rc = out_check_paths(outs, what, 8, in, which, m);
    }
    free(in);
    free(which);
    for (int k = 0; k < 3; k++) free(path_b[k]);
    return rc;
}

/* ---- temporaries -------------------------------------------------------------- */

static void on_signal(int sig) {
    for (int k = 0; k < n_staged; k++) {
        if (S[k].live_tmp) unlink(S[k].tmp);
        if (S[k].live_old) unlink(S[k].old);
    }
    signal(sig, SIG_DFL);
    raise(sig); /* delivered, by default, when this handler returns */
}

static void install(void) {
    if (installed) return;
    installed = 1;
    atexit(out_discard);
    for (size_t k = 0; k < sizeof SIGNALS / sizeof SIGNALS[0]; k++) {
        struct sigaction old, sa;
        if (sigaction(SIGNALS[k], NULL, &old) != 0 || old.sa_handler == SIG_IGN) continue;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigemptyset(&sa.sa_mask);
        sigaction(SIGNALS[k], &sa, NULL);
    }
    /* a file beyond the size limit (ulimit -f): EFBIG, reported, instead of
     * a death by SIGXFSZ that would leave the temporary behind */
    signal(SIGXFSZ, SIG_IGN);
}

/* strerror, or "write error" when the reason is unknown (e < 0) */
static const char *reason(int e) { return e > 0 ? strerror(e) : "write error"; }

static int fail(hd_error_t *err, const char *name, const char *what, int e) {
    snprintf(err->message, sizeof err->message, "%.800s: %s: %s", name, what, reason(e));
    return err->code = OUT_EFAIL;
}

static void drop_tmp(staged_t *s) {
    if (s->live_tmp) {
        unlink(s->tmp);
        s->live_tmp = 0;
    }
}

/* A FIFO opened for writing once a reader has opened it, awaited at most
 * fifo_wait_ms (a FIFO without a reader would block open() for ever): an
 * open without blocking fails with ENXIO while no reader is there, so it
 * is tried again every 10 ms; the descriptor then blocks as a pipe does. */
static FILE *open_fifo(const char *target, const char *path, hd_error_t *err) {
    int ms = fifo_wait_ms > 0 ? fifo_wait_ms : HD_FIFO_WAIT_MS, fd;
    for (int waited = 0;; waited += 10) {
        if ((fd = open(target, O_WRONLY | O_NONBLOCK)) >= 0 || errno != ENXIO) break;
        if (waited >= ms) {
            snprintf(err->message, sizeof err->message, "%.800s: a FIFO that no reader opened within %d s (--fifo-wait)",
                     path, ms / 1000);
            err->code = OUT_EFAIL;
            return NULL;
        }
        nanosleep(&(struct timespec){0, 10000000}, NULL);
    }
    FILE *f = NULL;
    if (fd < 0 || fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK) != 0 || !(f = fdopen(fd, "wb"))) {
        fail(err, path, "cannot write", errno);
        if (fd >= 0) close(fd);
    }
    return f;
}

FILE *out_open(const char *path, hd_error_t *err) {
    if (n_staged == MAX_STAGED) {
        fail(err, path, "cannot write", EMFILE);
        return NULL;
    }
    staged_t *s = &S[n_staged];
    memset(s, 0, sizeof *s);
    if (strlen(path) >= sizeof s->name) {
        fail(err, path, "cannot write", ENAMETOOLONG);
        return NULL;
    }
    strcpy(s->name, path);
    struct stat st;
    char resolved[PATH_MAX];
    if (lstat(path, &st) == 0 && S_ISLNK(st.st_mode) && realpath(path, resolved)) strcpy(s->target, resolved);
    else strcpy(s->target, path);
    mode_t mode;
    if (stat(s->target, &st) == 0) {
        if (S_ISDIR(st.st_mode)) {
            fail(err, path, "cannot write", EISDIR);
            return NULL;
        }
        if (!S_ISREG(st.st_mode)) { /* a device or a FIFO: written in place */
            s->f = S_ISFIFO(st.st_mode) ? open_fifo(s->target, path, err) : fopen(s->target, "wb");
            if (!s->f) {
                if (!S_ISFIFO(st.st_mode)) fail(err, path, "cannot write", errno);
                return NULL;
            }
            s->direct = 1;
            n_staged++;
            return s->f;
        }
        mode = st.st_mode & 0777;
    } else {
        mode_t mask = umask(0);
        umask(mask);
        mode = 0666 & ~mask;
    }
    const char *slash = strrchr(s->target, '/');
    int dirlen = slash ? (int)(slash - s->target) + 1 : 0;
    /* DIR/.BASE.tmp.XXXXXX, BASE cut to 200 bytes to stay within NAME_MAX */
    size_t blen = strlen(s->target + dirlen);
    if (blen > 200) blen = 200;
    if ((size_t)dirlen + 1 + blen + sizeof ".tmp.XXXXXX" > sizeof s->tmp) {
        fail(err, path, "cannot write", ENAMETOOLONG);
        return NULL;
    }
    memcpy(s->tmp, s->target, (size_t)dirlen);
    s->tmp[dirlen] = '.';
    memcpy(s->tmp + dirlen + 1, s->target + dirlen, blen);
    memcpy(s->tmp + dirlen + 1 + blen, ".tmp.XXXXXX", sizeof ".tmp.XXXXXX");
    install();
    n_staged++; /* before the file exists, so that a signal finds it */
    int fd = mkstemp(s->tmp);
    if (fd < 0) { /* the file itself may be writable: say that its directory is not */
        int e = errno, shown = dirlen < 400 ? dirlen : 400;
        snprintf(err->message, sizeof err->message,
                 "%.400s: cannot write: no temporary file can be created in %.*s (the output is written there, "
                 "then renamed over its name): %s", path, dirlen ? shown : 2, dirlen ? s->target : "./", reason(e));
        err->code = OUT_EFAIL;
        n_staged--;
        return NULL;
    }
    s->live_tmp = 1;
    if (fchmod(fd, mode) != 0 || !(s->f = fdopen(fd, "wb"))) {
        fail(err, path, "cannot write", errno);
        close(fd);
        drop_tmp(s);
        n_staged--;
        return NULL;
    }
    return s->f;
}

const char *out_file_path(FILE *f) {
    for (int k = 0; k < n_staged; k++)
        if (S[k].f == f) return S[k].direct ? S[k].target : S[k].tmp;
    return NULL;
}

int out_is_direct(FILE *f) {
    for (int k = 0; k < n_staged; k++)
        if (S[k].f == f) return S[k].direct;
    return 0;
}

int out_close(FILE *f, int werr, hd_error_t *err) {
    staged_t *s = NULL;
    for (int k = 0; k < n_staged; k++)
        if (S[k].f == f) s = &S[k];
    if (!s) { /* not from out_open: a bug in the caller */
        snprintf(err->message, sizeof err->message, "internal error: a file not opened by out_open");
        return err->code = OUT_EFAIL;
    }
    int e = werr;
    errno = 0;
    if (fflush(f) != 0 && !e) e = errno ? errno : -1;
    if (ferror(f) && !e) e = -1;
    errno = 0;
    if (fclose(f) != 0 && !e) e = errno ? errno : -1;
    s->f = NULL;
    if (!e) return HD_OK;
    drop_tmp(s);
    return fail(err, s->name, "cannot write", e);
}

void out_discard(void) {
    for (int k = 0; k < n_staged; k++) {
        if (S[k].f) fclose(S[k].f);
        S[k].f = NULL;
        drop_tmp(&S[k]);
        if (S[k].live_old) {
            unlink(S[k].old);
            S[k].live_old = 0;
        }
    }
    n_staged = 0;
}

/* Rename every finished temporary over its target, all or none. */
static int commit(hd_error_t *err) {
    sigset_t block, prev;
    sigemptyset(&block);
    for (size_t k = 0; k < sizeof SIGNALS / sizeof SIGNALS[0]; k++) sigaddset(&block, SIGNALS[k]);
    sigprocmask(SIG_BLOCK, &block, &prev);
    int n = n_staged, rc = HD_OK, many = 0;
    for (int k = 0; k < n; k++) {
        staged_t *s = &S[k];
        if (s->f) { /* never closed: a bug in the caller, so not trusted */
            rc = fail(err, s->name, "cannot write", -1);
            goto out;
        }
        many += s->live_tmp;
    }
    for (int k = 0; k < n; k++) { /* each target still a place for a file */
        staged_t *s = &S[k];
        struct stat st;
        if (!s->live_tmp) continue;
        s->had = stat(s->target, &st) == 0;
        if (s->had && S_ISDIR(st.st_mode)) {
            rc = fail(err, s->name, "cannot replace", EISDIR);
            goto out;
        }
        if (many > 1 && s->had) {
            size_t len = strlen(s->tmp); /* < PATH_MAX, and old has 8 more */
            memcpy(s->old, s->tmp, len);
            memcpy(s->old + len, ".old", sizeof ".old");
            s->live_old = link(s->target, s->old) == 0;
        }
    }
    for (int k = 0; k < n; k++) {
        staged_t *s = &S[k];
        if (!s->live_tmp) continue;
        if (rename(s->tmp, s->target) != 0) {
            rc = fail(err, s->name, "cannot rename into place", errno);
            for (int j = 0; j < k; j++) { /* put back what the earlier renames replaced */
                staged_t *t = &S[j];
                if (!t->renamed) continue;
                if (t->live_old && rename(t->old, t->target) == 0) t->live_old = 0;
                else if (!t->had) unlink(t->target);
            }
            goto out;
        }
        s->live_tmp = 0;
        s->renamed = 1;
    }
out:
    out_discard(); /* the temporaries left, the links to old files */
    sigprocmask(SIG_SETMASK, &prev, NULL);
    return rc;
}

int out_finish(void) {
    int e = stdout_closed ? EBADF : 0;
    errno = 0;
    if (fflush(stdout) != 0 && !e) e = errno ? errno : -1;
    if (ferror(stdout) && !e) e = -1;
    errno = 0;
    if (fclose(stdout) != 0 && !e) e = errno ? errno : -1;
    if (e) {
        out_discard();
        fprintf(stderr, "%s: standard output: %s\n", cli_prog(), reason(e));
        return EXIT_FAILURE_;
    }
    hd_error_t err;
    if (commit(&err) != HD_OK) {
        fprintf(stderr, "%s: %s\n", cli_prog(), safe_text(err.message));
        return EXIT_FAILURE_;
    }
    return EXIT_OK;
}
