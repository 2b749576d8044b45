/*
 * tiles.h -- a side of the comparison given as many files (tiles.c).
 *
 * A side argument is one file, a directory (every file in it whose
 * extension names a point format, sorted by name in byte order, not
 * recursed) or "@LIST" (one path per line, relative to the list's folder).
 * Its points are its files' points concatenated in that order, so global
 * index g names point g - first of the one tile with first <= g < first +
 * count.  Expanding (tiles_expand) touches only directory entries and file
 * metadata; reading (tiles_read) reads any contiguous range of the tiles,
 * so a program that spreads the tiles over processes (hausdorff-mpi) reads
 * its share with the same code and numbers its points by adding the counts
 * of the tiles before its range.
 *
 * Uses the public API only, like the rest of cli/.
 */
#ifndef HD_CLI_TILES_H
#define HD_CLI_TILES_H

#include <hausdorff.h>
#include <stdint.h>

#include "analysis.h"

typedef enum { TILES_FILE = 0, TILES_DIR, TILES_LIST } tiles_kind_t;

/* What a regular file was when its side was expanded (stat): a tile whose
 * stat differs later changed during the run, and reading refuses it. */
typedef struct tile_stamp {
    uint64_t dev, ino, size;
    int64_t mtime_s, mtime_ns, ctime_s, ctime_ns;
} tile_stamp_t;

typedef struct tile {
    char *path;           /* as it is opened and named in messages */
    const char *format;   /* FORMAT: of its list line, else the side's
                             FORMAT:, else NULL (--format, extension) */
    long line;            /* its line in the list (TILES_LIST), else 0 */
    uint64_t bytes;       /* its size when expanded (0: not a regular file,
                             or the one file of a TILES_FILE side) */
    size_t first, count;  /* filled by tiles_read: its first point's index
                             counted from the range read, its points */
    int stamped;          /* a regular file when expanded: stamp holds */
    tile_stamp_t stamp;
} tile_t;

typedef struct tile_skip {
    char *name;           /* the directory entry */
    const char *reason;   /* "hidden", "not a point format", ... */
} tile_skip_t;

typedef struct tiles {
    tiles_kind_t kind;
    const char *arg;      /* the side as given, FORMAT: removed */
    size_t n;             /* tiles (0 only for an empty directory or list) */
    tile_t *t;
    size_t n_skipped;     /* directory entries that are not tiles */
    tile_skip_t *skipped;
} tiles_t;

/* The reader named by the n bytes at s, in any case: a reader's name, or
 * one of the text extensions the xyz reader has (csv, txt, pts, asc: a user
 * who names a file .csv types csv:- or --format csv); NULL for neither. */
const char *tiles_format_named(const char *s, size_t n);

/* The FORMAT of a path written FORMAT:PATH (FORMAT a reader's name or
 * alias in any case: "xyz:-", "csv:-", "PLY:scan.dat") into *format and the path after the
 * colon; anything else is a path as it stands, *format NULL ("./ply:x"
 * names a file whose name holds a colon).  Used for the command line's two
 * sides and for each line of a list. */
const char *tiles_split_format(const char *s, const char **format);

/* Expand one side: `arg` (FORMAT: already split off by tiles_split_format)
 * with the side's `format` (or NULL).  A regular file, "-" or anything that
 * is neither a directory nor "@LIST" is one tile, not opened here (reading
 * reports what is wrong with it).  A directory's tiles are its entries
 * whose extension names a format (hd_format_of_path) and that are regular
 * files (through symbolic links), in strcmp order, except a .txt or .csv
 * that has no line starting with a number (a README, a table of words:
 * tiles_text_has_numbers); the other entries are listed in skipped with
 * the reason.  A list's tiles are its lines: blank
 * lines and lines whose first non-blank character is '#' are skipped,
 * blanks around a path are dropped, a line may be FORMAT:PATH, and a
 * relative path is taken relative to the list's folder; each must be a
 * regular file (through links): a stream (a FIFO, a device, standard
 * input) cannot be read twice, nor by another process, as hausdorff-mpi
 * reads tiles.  Every regular file's stat is kept (tile_t.stamp).
 * Errors (err names the list and line, or the directory): HD_EIO (list or
 * directory unreadable; a listed file missing or unreadable), HD_EFORMAT
 * (a listed "-", directory, stream or NIfTI mask; a NUL byte or a line
 * longer than 4096 bytes in the list),
 * HD_ENOMEM.  An empty directory or list is not an error here: n is 0.
 * On failure *out is left empty (tiles_free is still safe). */
int tiles_expand(const char *arg, const char *format, tiles_t *out,
                 hd_error_t *err);

/* Read tiles [first, first + n) into one cloud, in order: each tile by
 * cli_read_points with ro (its format as tile_t.format says; with
 * --sample, tile k drawn with seed ro->seed + k, so a side of one mesh is
 * sampled as that mesh alone), appended to a cloud that grows by half
 * again when full and is trimmed at the end: the peak is the points read
 * so far (plus the growth's slack) and one tile's own cloud, never two
 * copies of the whole.  Fills each tile's first and count.  The cloud's
 * format is the tiles' common format or "mixed"; n_faces is their sum.
 * Errors: those of cli_read_points (the message names the tile, and its
 * list line), HD_EIO "changed during the run" (a tile whose stat differs,
 * before or after its read, from its stamp), HD_EOVERFLOW (more points than memory can index),
 * HD_ENOMEM.  An empty tile is an error unless --empty chose a policy
 * (an->empty), as for one file; so is a side of no tiles (an empty
 * directory or list), which with a policy is a cloud of 0 points.  A range
 * of no tiles of a side that has some (a process's empty share) is a cloud
 * of 0 points.  `which` is 0 for A and 1 for B (where cli_read_points
 * describes a mask).  A range beyond the tiles is HD_EINVAL.
 * *out is the caller's (hd_cloud_free); on failure it is NULL. */
int tiles_read(tiles_t *s, size_t first, size_t n, const hd_read_options_t *ro,
               analysis_args_t *an, int which, hd_cloud_t **out,
               hd_error_t *err);

/* Split by points, for processes that share a side of few big files.
 * tiles_count: for the tiles k with k % parts == rank, counts[k] = the
 * tile's point count + 1 from its header (hd_read_count), 0 when the header
 * does not say (text, sampled meshes, ...), the tile is not a regular file
 * stamped at expansion, its stat no longer matches the stamp, or it cannot
 * be opened (reading it reports all of these); the other entries are 0, so
 * a sum over the processes gives every tile's.  counts has s->n entries.
 * Never fails.
 * tiles_read_points: the side's points [g, g + m), once every tile's count
 * and first are set (tiles_number): the tiles that meet the range, each
 * read in part (hd_read_options_t.range_first/range_count) and appended.
 * Errors as tiles_read, and "changed during the run" when a part holds
 * other than the count the header gave; m = 0 is a cloud of 0 points. */
int tiles_count(const tiles_t *s, int rank, int parts,
                const hd_read_options_t *ro, uint64_t *counts);
int tiles_read_points(tiles_t *s, uint64_t g, uint64_t m,
                      const hd_read_options_t *ro, analysis_args_t *an,
                      int which, hd_cloud_t **out, hd_error_t *err);

/* A digest of what expanding a side found: its kind, every tile's path,
 * format and stamp (but its device number, which differs between machines
 * that mount one file system), every skipped entry.  Processes that expanded the same
 * side each on its own compare digests: a side that changed between their
 * listings is refused rather than read as two different sides. */
uint64_t tiles_digest(const tiles_t *s);

/* What path is when it is a stream rather than a file: "standard input"
 * ("-"), "a FIFO or pipe", "a character device", ...; NULL for a regular
 * file, a directory, or a path that cannot be stat'ed. */
const char *tiles_stream(const char *path);

/* Whether the text file at path has a line that starts with a number:
 * after blanks, commas and semicolons (a byte-order mark and NUL bytes
 * aside, so UTF-16 text is judged by its characters), a digit, '+', '-' or '.' before a digit, or the word nan, inf or
 * infinity in any case; blank and comment lines hold none.  1, 0, or -1
 * when the file cannot be read.  A directory's .txt and .csv entries
 * without one are not tiles (a README, a table of words); a file with one
 * is a tile even when a later line is not a point (reading refuses it). */
int tiles_text_has_numbers(const char *path);

/* Number the whole side from the tiles' counts: first = the counts of the
 * tiles before, summed.  For processes that each read a share: once every
 * tile's count is known everywhere (gathered), tiles_locate works as after
 * reading the whole side.  HD_EOVERFLOW (err filled) when the sum does not
 * fit a size_t; else HD_OK. */
int tiles_number(tiles_t *s, hd_error_t *err);

/* What was skipped, for a person: "skipped 2: notes.md (no point format
 * has this extension), sub (a directory, not recursed)", the first three
 * and how many more; "" when nothing was.  Truncated to size. */
void tiles_skipped_text(const tiles_t *s, char *buf, size_t size);

/* The tile that holds point g of a side read whole (tiles_read over every
 * tile) and g's index within it.  g must be below the side's count. */
size_t tiles_locate(const tiles_t *s, size_t g, size_t *local);

/* The contiguous range [*first, *first + *n) of tiles that part `rank` of
 * `parts` reads, balanced by file size: part r takes the tiles whose
 * starting byte (the sizes of the tiles before, summed) falls in
 * [r * total / parts, (r + 1) * total / parts).  Every tile goes to one
 * part, in order, so the parts' points concatenated in rank order are the
 * side's points in order.  Some parts may get none.  parts >= 1 and
 * 0 <= rank < parts (asserted). */
/* floor(r * total / parts) without overflow (0 <= r <= parts): where part r
 * of `parts` equal shares of `total` starts. */
uint64_t tiles_bound(uint64_t total, int r, int parts);

void tiles_share(const tiles_t *s, int rank, int parts, size_t *first,
                 size_t *n);

void tiles_free(tiles_t *s);

#endif
