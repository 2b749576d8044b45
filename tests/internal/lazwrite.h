/*
 * lazwrite.h -- a LAZ writer for the tests: the LASzip range encoder and
 * integer compressor over the models of src/io/lazcoder.c, POINT10 v2
 * pointwise chunks (point formats 0-3, with GPSTIME11, RGB12 and BYTE
 * items; or their version 1 in LASzip 1.x's single stream) and POINT14 v3 layered chunks (format 6, with a BYTE14 item),
 * fixed or variable chunk sizes, and the compressed chunk table.
 *
 * Only x, y, z, the return number and count, and (layered) the scanner
 * channel vary; every other field keeps its first value (so their changed
 * bits stay 0 and their layers are empty), which is what the reader must
 * walk past.  Its files are checked against laz-perf
 * (tests/laz_lazperf.py), so it is an independent witness of the format
 * only for what it shares with the reader: the models, which laz-perf
 * checks.
 */
#ifndef HD_TEST_LAZWRITE_H
#define HD_TEST_LAZWRITE_H

#include "files.h"
#include "gen.h"

#include <hausdorff.h>

#include <stddef.h>
#include <stdint.h>

typedef struct lazw_point {
    int32_t x, y, z;
    unsigned char r, n;   /* return number and count: 0-7 (format 0-3), 0-15 (6) */
    unsigned char channel; /* scanner channel 0-3 (format 6) */
} lazw_point_t;

typedef struct lazw_opts {
    int format;           /* 0, 1, 2, 3 (pointwise) or 6 (layered) */
    unsigned extra;       /* extra bytes per point (0-8; pointwise version 2: up to
                           * 65515, the most a record of 65535 bytes holds) */
    uint32_t chunk_size;  /* points per chunk; 0: variable, sizes in chunks[] */
    const size_t *chunks; /* variable chunk sizes (n_chunks of them, sum n) */
    size_t n_chunks;
    double scale[3], offset[3];
    int v1; /* formats 0-3: LASzip 1.x, items version 1 in one unchunked
             * stream (compressor 1); chunk sizes are then ignored */
} lazw_opts_t;

/* The LAZ file of n points into *out (appended). */
void lazw_encode(tf_buf_t *out, const lazw_opts_t *o, const lazw_point_t *p, size_t n);

/* A chunk table (version, count, the compressed entries) appended to out:
 * per chunk its point count (counts NULL: fixed chunk size) and bytes. */
void lazw_table(tf_buf_t *out, const uint32_t *counts, const uint32_t *bytes, size_t nc);

/* n random points for `format`: random walks with small steps, repeats
 * and arbitrary 32-bit jumps; returns of 1..n mostly, any 0..7 (0..15)
 * sometimes; scanner channels switching now and then (format 6). */
void lazw_random(gen_rng_t *g, lazw_point_t *p, size_t n, int format);

/* Byte offsets of the parts of the last file lazw_encode, lazw_pointwise
 * or lazw_layered wrote (for hostile tests that damage one of them). */
typedef struct lazw_layout {
    size_t vlr, points, table; /* the LASzip VLR's data, the point data, the chunk table */
    size_t chunk[64];          /* the first 64 chunks' starts */
} lazw_layout_t;
extern lazw_layout_t lazw_last;

/* n random whole records of point format fmt (0-3) with `extra` extra
 * bytes, every field varying (returns, flags, classification, scan angle,
 * user data, point source, intensity, GPS times repeated, stepping and
 * jumping, colours grey and not, extra bytes); malloc'd, *rec bytes each. */
unsigned char *lazw_rich_records(gen_rng_t *g, int fmt, unsigned extra, size_t n, size_t *rec);
/* The pointwise LAZ file (LAS 1.2, LASzip items of version 2, chunks of
 * `chunk` points) of those records, compressed by the library's pointwise
 * encoder (hd__laz_encode_pointwise, src/io/write_lazpw.c), appended to b. */
void lazw_pointwise(tf_buf_t *b, int fmt, unsigned extra, const unsigned char *recs, size_t rec, size_t n,
                    size_t chunk);

/* n random whole records of LAS 1.4 point format fmt (6-10) with
 * `extra` extra bytes, every field varying; scanner channels switching
 * when `channels`, else all 0; malloc'd, *rec bytes each. */
unsigned char *lazw_rich_records14(gen_rng_t *g, int fmt, unsigned extra, size_t n, size_t *rec, int channels);
/* The layered LAZ file (LAS 1.4, items of `version` 3 or 4, chunks of
 * `chunk` points) of those records, compressed by the library's layered
 * encoder (hd__laz14_encode, src/io/laz14.c), appended to b. */
void lazw_layered(tf_buf_t *b, int fmt, unsigned extra, const unsigned char *recs, size_t rec, size_t n, size_t chunk,
                  unsigned version);

/* Every whole record of the LAZ file d[0..size) (named path), decoded by
 * the library (hd__laz_chunk_records: pointwise items of version 2, or
 * every layer); malloc'd, *n records of *rec bytes; NULL with err set when
 * the file is refused. */
unsigned char *lazw_decode_records(const char *path, const unsigned char *d, size_t size, size_t *n, size_t *rec,
                                   hd_error_t *err);

/* ---- COPC ------------------------------------------------------------------ */
/* The COPC file of the layered LAZ file laz[0..size) (LAS 1.4, no EVLRs;
 * its nc chunks start at chunk[k] and hold counts[k] points, the last
 * ending at the chunk table) appended to out: the COPC info VLR first,
 * then the LAZ VLR; after the chunk table the hierarchy EVLR (user
 * "copc", record 1000) of two pages, the child page first: the root page
 * holds chunk 0 (level 0), chunk 1 (level 1), an empty node and a pointer
 * to the child page, which holds every other chunk (level 2); then an EVLR
 * of another user ("someone", record 9, the 4 bytes "EVLR"). */
void lazw_copc(tf_buf_t *out, const unsigned char *laz, size_t size, const size_t *chunk, const size_t *counts, size_t nc);

/* A COPC node as lazw_copc_nodes found it: its key, and its points: the
 * first's number in file order and how many. */
typedef struct lazw_node {
    int32_t key[4];
    uint64_t first, count;
} lazw_node_t;
/* The nodes (at most max) of COPC file d[0..size), checked independently
 * of the library's writer: the info VLR is the first VLR; its root page
 * lies inside the EVLR of user "copc", record 1000; every page reached
 * from it (pointers: point count -1) does too; every node with points is
 * exactly one chunk of the chunk table (offset, byte size, point count),
 * a node without points has offset 0 and byte size 0,
 * no chunk twice, every chunk once, and the counts add up to the header's.
 * Returns 0, or -1 with why (a sentence) filled. */
int lazw_copc_nodes(const unsigned char *d, size_t size, lazw_node_t *nodes, size_t max, size_t *n, char *why,
                    size_t why_len);

#endif
