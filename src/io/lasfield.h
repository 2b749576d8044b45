/*
 * lasfield.h -- what the LAS and LAZ writers of hd_write_field share
 * (write_las.c): the plan of the output's header and VLRs, and the
 * header, VLRs and bytes before the points written from it.
 */
#ifndef HD_LASFIELD_H
#define HD_LASFIELD_H

#include "io.h"

typedef struct hd__las_plan {
    unsigned minor, fmt;
    size_t header, offset, rec, out_rec; /* out_rec: rec + 8 a field */
    uint32_t n_vlr;
    uint64_t count;
    size_t vlr_end;   /* the end of the last VLR */
    size_t eb_at;     /* the extra-bytes VLR's header, 0: none */
    size_t end;       /* the end of the point data (uncompressed LAS) */
    int add;          /* fields are added */
    size_t gap;       /* extra bytes no descriptor described */
    size_t n_desc;    /* descriptors added */
    size_t vlr_added; /* bytes added before the points */
    /* COPC (write_copc.c): the info VLR's header (0: none) and length, the
     * hierarchy EVLR's header (0: none) and data length; the info VLR's and
     * the hierarchy's new data (NULL: copied), or both dropped */
    size_t copc_at, copc_len;
    uint64_t hier_at, hier_len;
    const unsigned char *copc_info, *copc_hier;
    int copc_drop;
} hd__las_plan_t;

/* The plan for w's LAS input (header checked by the reader before):
 * HD_OK, or a field name the extra-bytes VLR already has (HD_EINVAL), no
 * room in the record or the VLR (HD_EUNSUPPORTED). */
int hd__las_plan(hd__writer_t *w, hd__las_plan_t *pl);
/* The header (counts, by_return[1..15], bounds: max/min x, y, z, of `kept`
 * points in a subset), the VLRs (the extra-bytes one with the fields'
 * descriptors, each with its kept values' range; laz_vlr: the LASzip VLR's new data, whose
 * data started at laz_vlr_at in the input) and the bytes up to the
 * points; points_bytes is what the points will take. */
void hd__las_write_head(hd__writer_t *w, const hd__las_plan_t *pl, uint64_t kept, const uint64_t by_return[16],
                        const double bounds[6], uint64_t points_bytes, const unsigned char *laz_vlr,
                        size_t laz_vlr_at, size_t laz_vlr_len);
unsigned hd__las_return(const unsigned char *rec, unsigned fmt);
/* Widen the bounds by record rec's coordinates (first: start them). */
void hd__las_bound(double bounds[6], const unsigned char *rec, const double scale[3], const double shift[3], int first);
void hd__las_scale(const unsigned char *d, double scale[3], double shift[3]);
void hd__w_range(const hd__writer_t *w, const double *v, double *lo, double *hi);
void hd__st_u64(unsigned char *p, uint64_t v);
/* The input's bytes from `from` (after the points: the extended VLRs) to
 * its end, the COPC hierarchy EVLR's data replaced by pl->copc_hier or the
 * EVLR dropped (pl->copc_drop); returns the bytes written. */
uint64_t hd__las_put_tail(hd__writer_t *w, const hd__las_plan_t *pl, size_t from);

/* For the LAZ writers (write_laz.c, write_lazpw.c). */
typedef struct hd__enc hd__enc_t;
/* The header las.c builds from the input's (already accepted). */
void hd__las_header_of(const hd__writer_t *w, const hd__las_plan_t *pl, hd__las_header_t *h);
/* The chunk table's entries (counts only when variable) into e. */
int hd__laz_table_encode(int variable, size_t nc, const uint32_t *counts, const uint64_t *bytes, hd__enc_t *e);
/* Pointwise LAZ (point formats 0-3, items of version 2): write_lazpw.c.
 * hd__laz_encode_pointwise: the stream of a chunk of n records (rec bytes
 * each; the items' types and sizes) after its raw first record, into e:
 * HD_OK or HD_ENOMEM. */
int hd__laz_encode_pointwise(const unsigned char *recs, size_t n, size_t rec, const unsigned *type, const unsigned *sz,
                             unsigned n_items, hd__enc_t *e);
/* hd__write_laz_pointwise: every chunk decoded to whole records and the
 * kept ones (with the fields' values) compressed again: pointwise LAZ, and
 * subsets of layered LAZ (laz14.c encodes their chunks). */
int hd__write_laz_pointwise(hd__writer_t *w, hd__las_plan_t *pl, const hd__las_header_t *h, const hd__laz_chunks_t *c,
                            hd__read_t *r);

/* COPC (write_copc.c).  hd__copc_plan: for a file whose info VLR
 * hd__las_plan found, its hierarchy EVLR (which must follow the chunk
 * table) and every entry checked: a node with points is exactly one chunk
 * of c (offset, byte size, point count), a page pointer and the root page
 * lie inside the hierarchy EVLR; HD_OK, or HD_EFORMAT naming the entry. */
int hd__copc_plan(hd__writer_t *w, hd__las_plan_t *pl, const hd__laz_chunks_t *c);
/* hd__copc_drop: neither the info VLR nor the hierarchy is written (the
 * output is plain LAZ). */
void hd__copc_drop(hd__las_plan_t *pl);
/* hd__copc_move: input chunk k now starts at new_start[k], is bytes[k]
 * long and holds count[k] points (0: a node emptied, its entry offset 0,
 * byte size 0, point count 0; count NULL: every point kept), and every byte after the chunk table moved
 * by shift: the info VLR's root page offset and every entry moved with
 * what it points at, into *info and *hier (malloc'd; set into pl).  HD_OK,
 * or HD_EUNSUPPORTED for a chunk too large for an entry. */
int hd__copc_move(hd__writer_t *w, hd__las_plan_t *pl, const hd__laz_chunks_t *c, const uint64_t *new_start,
                  const uint64_t *bytes, const uint64_t *count, uint64_t shift, unsigned char **info, unsigned char **hier);

#endif
