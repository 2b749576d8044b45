/*
 * surface.h -- `--surface`: points of A against the surface of the mesh B
 * (surface.c).
 */
#ifndef HD_CLI_SURFACE_H
#define HD_CLI_SURFACE_H

#include "cli.h"

/* Run the whole command for parsed arguments with --surface: read, measure,
 * print; returns the exit code (the caller finishes standard output). */
int surface_run(const cli_args_t *a);

/* The same with a mesh as A: its surface against B, a mesh or a point
 * set, as an enclosure (m2m.c). */
int m2m_run(const cli_args_t *a);

#endif
