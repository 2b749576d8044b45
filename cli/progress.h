/*
 * progress.h -- a progress line on stderr for the tool's long phases.
 *
 * The library never prints, and reading a file or computing a distance is
 * one call, so progress is reported by phase: the tool names each phase as
 * it starts ("reading A: scan.ply", "computing H(A,B)"), and a background
 * thread draws, once a phase has lasted about a second, a bar of the phases
 * done so far with the phase's name and elapsed time.  It draws only when
 * stderr is a terminal and the user did not ask for --quiet or --json; the
 * line is erased when the phase ends, so nothing remains in the scrollback.
 */
#ifndef HD_CLI_PROGRESS_H
#define HD_CLI_PROGRESS_H

/* Start reporting over `phases` phases (enabled: 0 turns every call into a
 * no-op).  Returns 0, or -1 when the thread cannot start (then silent). */
int progress_start(int enabled, int phases);
/* Begin the next phase, named by printf-style text. */
void progress_phase(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Stop the thread and erase the line. */
void progress_stop(void);

#endif
