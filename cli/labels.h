/*
 * labels.h -- `--labels`: every label of two NIfTI label maps (labels.c).
 */
#ifndef HD_CLI_LABELS_H
#define HD_CLI_LABELS_H

#include "cli.h"

/* 1 when v is "all" or whole numbers separated by commas (--labels). */
int labels_list_ok(const char *v);

/* Run the whole command for parsed arguments with --labels: read both
 * maps, measure every label, print the table; returns the exit code (the
 * caller finishes standard output). */
int labels_run(const cli_args_t *a);

#endif
