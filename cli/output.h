/*
 * output.h -- how the tool writes: standard output and every file
 * (--distances, --render, --histogram-png) go through here, so that no
 * output is lost without an exit status that says so (output.c).
 */
#ifndef HD_CLI_OUTPUT_H
#define HD_CLI_OUTPUT_H

#include <hausdorff.h>
#include <stdio.h>

/* The code of an output failure (not a library code): exit status 3. */
#define OUT_EFAIL (-100)

/* Before anything else: give descriptors 0, 1 and 2 a file (/dev/null)
 * when they are closed, so that no file the tool opens takes their number,
 * and remember that standard output was closed (out_finish reports it). */
void out_guard_std(void);

/* Refuse an output that names an input, or another output: the same
 * literal path, or the same file (st_dev and st_ino).  outs[k] is a path
 * (NULL: that output is not asked for), what[k] the option that named it;
 * inputs[k] is an input file (every tile of a side, and a list of tiles)
 * and side[k] its side, 'A' or 'B'.  Returns 0, or 1 (the usage exit
 * status) after a message naming both. */
int out_check_paths(const char *const *outs, const char *const *what, int n,
                    const char *const *inputs, const char *side,
                    size_t n_inputs);

/* The tool's outputs (--distances and its _b file, --render,
 * --histogram-png) checked with out_check_paths against every input (each
 * tile of either side, and a list of them) and each other: 0, or the exit
 * status after a message.  hausdorff and hausdorff-mpi (rank 0) run it
 * before reading. */
struct cli_args;
struct tiles;
int out_check_outputs(const struct cli_args *a, const struct tiles *side);

/* Begin writing `path`: a new temporary file beside it (or the file itself
 * when it is a device or a FIFO).  NULL with err filled (OUT_EFAIL). */
FILE *out_open(const char *path, hd_error_t *err);
/* The file an open FILE from out_open writes: its temporary (or the target
 * itself when written in place), for a writer that writes it by name
 * after out_close (hausdorff-mpi's ranks, through MPI-IO); it is renamed
 * by out_finish or removed by out_discard as any other.  NULL when f is
 * not open. */
const char *out_file_path(FILE *f);
/* 1 when f from out_open writes its target in place (a device or a FIFO:
 * no temporary, no offsets to seek to), else 0. */
int out_is_direct(FILE *f);
/* Finish a file from out_open: flush, check, close.  werr is the errno of
 * the first write that failed (0 if none, -1 for an unknown reason).
 * Returns HD_OK, or OUT_EFAIL
 * with err filled after removing the temporary. */
int out_close(FILE *f, int werr, hd_error_t *err);

/* The end of a run that succeeded: flush and close standard output, then
 * rename every finished file into place, all of them or none.  Returns
 * the exit status: 0, or 3 after a message ("hausdorff: what: reason"). */
int out_finish(void);
/* The end of a run that failed: remove every temporary. */
void out_discard(void);

#endif
