/*
 * analysis.h -- the command line's analysis features: per-point distances
 * and their statistics (analysis.c), the files they are written to
 * (writers.c), pictures (render.c, font.c), and NIfTI masks (nifti.c).
 * options.c parses their options (one table for every option of the tool)
 * and main.c runs them; everything else is here.
 */
#ifndef HD_CLI_ANALYSIS_H
#define HD_CLI_ANALYSIS_H

#include <hausdorff.h>
#include <stdint.h>
#include <stdio.h>

typedef enum { MASK_SURFACE = 0, MASK_ALL } mask_points_t;

/* What a mask file turned into (filled by cli_read_points). */
typedef struct mask_info {
    int is_mask;
    int nifti_version;         /* 1 or 2 */
    long long dim[3];          /* voxels per axis */
    double spacing[3];         /* pixdim, in the file's units */
    long long foreground;      /* foreground voxels */
    size_t points;             /* points produced (surface or all) */
    const char *transform;     /* "sform", "qform" or "pixdim" */
    double to_mm;              /* unit factor applied (1 for mm) */
    int unit_known;            /* the header names mm, um or m (now mm) */
    int surface_dims;          /* axes of the surface's neighbourhood (0: --mask-points all) */
    int connectivity;          /* its connectivity (1..surface_dims) */
} mask_info_t;

enum { ANALYSIS_MAX_TAUS = 64 };

typedef struct analysis_args {
    int percentile_on;
    double percentile;
    int mean, chamfer, histogram;
    size_t bins;
    const char *distances_out;
    double max_distance;       /* colour and histogram scale; 0 = automatic */
    const char *render_out;
    const char *histogram_png;
    mask_points_t mask_points;
    int connectivity;          /* --connectivity 1|2|3 (default 1: faces) */
    int mask_dims;             /* --mask-dims: 0 auto, 2 slice by slice, 3 */
    const char *units;         /* --units TEXT, or NULL */
    hd_empty_policy_t empty;   /* --empty: error (default), inf, nan, zero, monai */
    mask_info_t mask[2];       /* for A and B */
    size_t n_taus;             /* --tau T[,T...]: scores at these tolerances */
    double taus[ANALYSIS_MAX_TAUS];
    hd_tolerance_rule_t tau_rule; /* --tau-rule le|lt (default le: d <= tau) */
    double dtu_cap;            /* --dtu-cap D: DTU accuracy/completeness (0: off) */
    const char *labels;        /* --labels all|L[,L...]: label maps (labels.c); NULL: off */
    int components;            /* --components 6|18|26|4|8 (0: off) */
    int csv;                   /* --csv: the label table as CSV */
    /* --farther-than D OUT, --nearer-than D OUT (writeback.c): the points
     * whose distance is > D / <= D, in their file's own format */
    struct { int on; double d; const char *out; } subset[2];
    /* how the sides were read, for the files written back into their
     * format: the read options, each side's FORMAT: (or NULL) */
    hd_read_options_t read;
    const char *format[2];
} analysis_args_t;

enum { SUBSET_FARTHER = 0, SUBSET_NEARER = 1 };

/* ---- options (analysis.c) ---------------------------------------------- */
void analysis_args_init(analysis_args_t *an);

/* ---- reading (nifti.c) --------------------------------------------------- */
/* Read a point set: NIfTI masks (.nii, .nii.gz) become the world
 * coordinates of their surface or foreground voxels; every other file goes
 * to hd_read_file.  An empty set is an error (HD_EEMPTY) unless --empty
 * chose a policy; then it is returned as a cloud of 0 points.  `which` is 0
 * for A and 1 for B. */
int cli_read_points(const char *path, const hd_read_options_t *ro,
                    analysis_args_t *an, int which, hd_cloud_t **out,
                    hd_error_t *err);
/* A cloud of `count` points the tool fills itself (uninitialised; 0 points
 * allowed), freed by hd_cloud_free like the library's; NULL when out of
 * memory or count * 3 elements overflows. */
hd_cloud_t *cli_cloud_new(size_t count, hd_dtype_t dtype, const char *format);
/* 1 when the name ends in .nii or .nii.gz. */
int nifti_is_mask_path(const char *path);
/* 1 when the tool was built with the NIfTI library. */
int nifti_available(void);
/* A NIfTI label map (--labels): its values in their own integer type (a
 * float image's whole numbers as int64), placed as a mask's voxels are
 * (the same map and unit); info as for a mask (foreground 0). */
typedef struct nifti_labels {
    hd_label_image_t img;
    mask_info_t info;
    void *image;       /* the nifti_image holding the values */
    int64_t *converted; /* a float image's labels */
} nifti_labels_t;
int nifti_read_labels(const char *path, nifti_labels_t *out, hd_error_t *err);
void nifti_labels_free(nifti_labels_t *l);

/* ---- the run (analysis.c) ---------------------------------------------- */
/* Where a witness point was drawn in a picture. */
typedef struct render_marker {
    int view;                  /* 0 front, 1 side, 2 top */
    char set;                  /* 'A' or 'B' */
    size_t index;              /* the point's index in its set */
    int x, y;                  /* pixel of the marker's centre */
} render_marker_t;

/* What the picture says besides the points: the unit (NULL: none) and,
 * when percentile_on, the percentile figures of the run. */
typedef struct render_notes {
    const char *unit;
    int percentile_on;
    hd_percentile_t pct;
    int surface;               /* the witness's partner is the closest point
                                  on triangle j of B (--surface) */
} render_notes_t;
/* What render_distances drew as text and where it marked the percentile
 * on the colour bar (pct_y < 0: not marked), for the JSON and the tests. */
typedef struct render_info {
    char bar_title[64];
    char caption[3][512];
    int pct_y, pct_x0, pct_x1;
} render_info_t;
/* Where a mean or percentile line was drawn on the histogram picture. */
typedef struct hist_marker {
    char kind;                 /* 'm' mean (solid), 'p' percentile (dashed) */
    int dir;                   /* 0 A->B, 1 B->A */
    int x, y0, y1;             /* its centre column, rows [y0, y1) */
    unsigned char rgb[3];      /* its colour (the direction's bars') */
} hist_marker_t;

typedef struct analysis_result {
    int active;                /* some analysis option was given */
    int empty;                 /* A or B is empty: every figure is the
                                  --empty policy's value (analysis_empty) */
    int directed;
    size_t n_a, n_b;
    double *d_ab, *d_ba;       /* per-point distances (d_ba NULL: directed) */
    size_t *j_ab, *j_ba;       /* nearest indices */
    double seconds;            /* per-point distances */
    hd_percentile_t pct;
    hd_summary_t sum;
    double hist_lo, hist_hi;
    uint64_t *hist_ab, *hist_ba;
    size_t above_ab, above_ba; /* values beyond the histogram range */
    const char *dist_path_a;   /* --distances */
    char *dist_path_b;         /* its _b file (malloc: analysis_free) */
    int render_w, render_h, n_markers;
    render_marker_t markers[6];
    render_info_t render;
    int n_hist_markers;
    hist_marker_t hist_markers[4];
    hd_tolerance_t tol[ANALYSIS_MAX_TAUS]; /* --tau, in the order given */
    hd_capped_mean_t dtu;      /* --dtu-cap */
    /* the files written back into the sides' formats (writeback.c): [0]
     * --distances, [1] --farther-than, [2] --nearer-than; per side the
     * path (A's is the option's, B's malloc'd) and the points written */
    char *wb_path_b[3];
    size_t wb_points[3][2];
    int wb_sides[3];           /* bit 0: A's written, bit 1: B's */
    int surface;               /* d_ab: distances to B's triangles, j_ab
                                  the nearest triangles (--surface) */
} analysis_result_t;

/* The unit of the distances: --units, else "mm" when a mask's header
 * names its unit (converted to mm), else NULL (unknown: no label). */
const char *analysis_units(const analysis_args_t *an);
/* Does anything need the per-point distances? */
int analysis_active(const analysis_args_t *an);
/* Only the percentile asked for: no figure needs every distance. */
int analysis_percentile_only(const analysis_args_t *an);
/* When A or B is empty (the counts n_a, n_b), under the --empty policy:
 * every figure asked for is the policy's value (the scores of --tau and
 * --dtu-cap: none within, NaN for no points) into r, and s the distances
 * (H, h(A,B), h(B,A)) as the report prints them; says on stderr that no
 * picture is drawn when one was asked for.  The per-point files are the
 * caller's (analysis_empty_files for hausdorff).  Returns HD_OK or
 * HD_ENOMEM with err filled. */
int analysis_empty(const analysis_args_t *an, size_t n_a, size_t n_b, int directed, hd_symmetric_t *s,
                   analysis_result_t *r, hd_error_t *err);
/* The per-point files of a run with an empty set (--distances, and the
 * files written back): the other set's rows at the policy's value v with
 * nearest index -1; an empty set gets a file with no rows, so that scripts
 * find the files they asked for. */
int analysis_empty_files(const analysis_args_t *an, const hd_points_t *A, const hd_points_t *B, int directed,
                         double v, const char *path_a, const char *path_b, analysis_result_t *r, hd_error_t *err);
/* Compute per-point distances and every figure asked for, write the files
 * asked for.  Returns HD_OK or a library code with err filled. */
struct surface_columns; /* below, with the writers */
/* The figures, files and pictures asked for from per-point distances
 * already in r (d_ab and j_ab; d_ba and j_ba unless r->directed; n_a,
 * n_b, seconds), whatever computed them.  s holds the witness; wq (NULL:
 * B's point s->ab.j or s->ba.j) is its partner's position in the picture;
 * surf (NULL: point sets) gives the --distances files the surface's
 * columns. */
int analysis_finish(const analysis_args_t *an, const hd_points_t *A, const hd_points_t *B,
                    const hd_symmetric_t *s, const double *wq, const char *path_a, const char *path_b,
                    const struct surface_columns *surf, analysis_result_t *r, hd_error_t *err);
int analysis_run(const analysis_args_t *an, const hd_options_t *opt,
                 const hd_points_t *A, const hd_points_t *B,
                 const hd_symmetric_t *s, int directed, const char *path_a,
                 const char *path_b, analysis_result_t *r, hd_error_t *err);
/* The figures of the per-point distances d_ab (n_a values) and d_ba (n_b;
 * ignored when r->directed) into r->sum, r->pct (--percentile) and the
 * histograms (--histogram, --histogram-png; r->n_a and r->n_b, the
 * distances of all of A and B, give the values above the range), by ops:
 * the library's functions here, hausdorff-mpi's over the ranks (each rank
 * passing its own distances).  r->directed is set by the caller; r's
 * histograms may be allocated by it (`bins` counts each), else they are
 * allocated here. */
typedef struct analysis_ops {
    int (*summarize)(const double *d_ab, size_t n_a, const double *d_ba, size_t n_b, hd_summary_t *out,
                     hd_error_t *err);
    int (*percentile_of)(const double *d_ab, size_t n_a, const double *d_ba, size_t n_b, double p,
                         hd_percentile_t *out, hd_error_t *err);
    int (*histogram)(const double *values, size_t n, double lo, double hi, size_t bins, uint64_t *counts,
                     hd_error_t *err);
} analysis_ops_t;
int analysis_figures(const analysis_args_t *an, const analysis_ops_t *ops, const double *d_ab, size_t n_a,
                     const double *d_ba, size_t n_b, analysis_result_t *r, hd_error_t *err);
/* The picture's title line: "A's name (N points) coloured by distance to
 * B's name". */
void analysis_render_title(const char *path_a, size_t n_a, const char *path_b, char *title, size_t size);
/* What the pictures say besides the points: the unit and the percentile
 * figures asked for. */
render_notes_t analysis_notes(const analysis_args_t *an, const analysis_result_t *r);
/* The colour and histogram scale: --max-distance, else the largest
 * distance (r->sum). */
double analysis_scale(const analysis_args_t *an, const analysis_result_t *r);
/* The JSON members (each preceded by ", ") and the lines for a person. */
void analysis_json(FILE *out, const analysis_args_t *an,
                   const analysis_result_t *r);
void analysis_print(FILE *out, const analysis_args_t *an,
                    const analysis_result_t *r);
void analysis_free(analysis_result_t *r);

/* ---- files (writers.c) ------------------------------------------------- */
/* The colour of a distance: viridis at d / dmax (clipped to [0, 1]). */
void colormap_viridis(double t, unsigned char rgb[3]);
/* Write points with their distance, the index of their nearest point (-1
 * for every row when nearest is NULL) and, in PLY, the distance's colour
 * at d / dmax: CSV, PLY or NPY by the path's extension (writers.c). */
int write_distances(const char *path, const hd_points_t *P, const double *d,
                    const size_t *nearest, double dmax, hd_error_t *err);
/* What a point's distance to a surface adds to its row (--surface): the
 * nearest face, the closest point on it, its barycentric weights u v w of
 * the face's corners, and the sign (NULL: no sign column). */
typedef struct surface_columns {
    const size_t *face;
    const double *closest, *bary; /* 3 a point */
    const int8_t *sign;
} surface_columns_t;
/* Write points with their distance to a surface: the columns x y z
 * distance face closest_x closest_y closest_z u v w [sign], in CSV, PLY
 * (with the distance's colour) or NPY (float64) by the path's extension. */
int write_surface_distances(const char *path, const hd_points_t *P, const double *d,
                            const surface_columns_t *c, double dmax, hd_error_t *err);
/* 1 when the path names a format write_distances knows. */
int distances_format_known(const char *path);

/* ---- files in the inputs' own formats (writeback.c) -------------------- */
/* Whether --distances writes side w (read from in_path) back into its own
 * format as `out` (A's: OUT, B's: OUT_b.EXT): .las, .laz, .xyz, .txt,
 * .pts, .asc always; .ply when the side is one regular PLY file read as
 * its own points; .csv and .npy never (they, and .ply otherwise, are
 * write_distances' tables).  A FIFO or device as out gets the bytes of
 * the file written back. */
int analysis_writes_back(const analysis_args_t *an, int w, const char *out, const char *in_path);
/* 1 when OUT can name a file written back (--farther-than, --nearer-than:
 * .ply .las .laz .xyz .txt .csv .pts .asc .obj). */
int analysis_writeback_format_known(const char *out);
/* Before reading: every file written back names its side's format, and
 * the sides are files read as their points (not sampled, not a mask or a
 * directory of tiles).  HD_OK, or HD_EINVAL with the reason in err. */
int analysis_check_outputs(const analysis_args_t *an, const char *path_a, const char *path_b, int directed,
                           hd_error_t *err);
/* A side's per-point values for the files written back: n distances,
 * the nearest point's (or with --surface face's) index (NULL: -1 for
 * every point) and the sign (--signed; NULL: none). */
typedef struct writeback_side {
    const double *d;
    size_t n;
    const size_t *index;
    const int8_t *sign;
} writeback_side_t;
/* After the distances: the files written back (--distances into the
 * inputs' formats, --farther-than, --nearer-than), A's from side[0] and,
 * when not directed, B's from side[1] into OUT_b.EXT; surface: the index
 * is a face's; what was written into r. */
int analysis_write_back(const analysis_args_t *an, const char *path_a, const char *path_b,
                        const writeback_side_t side[2], int directed, int surface, analysis_result_t *r,
                        hd_error_t *err);
/* Their lines in the report and their JSON members. */
void analysis_write_back_print(FILE *out, const analysis_args_t *an, const analysis_result_t *r);
void analysis_write_back_json(FILE *out, const analysis_args_t *an, const analysis_result_t *r);
/* The pieces of a distances file, for a writer that places the rows
 * itself (hausdorff-mpi: each rank writes its rows at its offset): the
 * header, then one row a point, each row's bytes depending on that row
 * alone (PLY: given the colour scale dmax and `wide`, nearest indices as
 * doubles because one exceeds 2^31 - 1 somewhere in the file). */
enum { DIST_CSV, DIST_PLY, DIST_NPY, DIST_UNKNOWN };
enum { DIST_HEAD_MAX = 1024, DIST_ROW_MAX = 160 }; /* a CSV row: 4 numbers of NUM_TEXT and an index */
typedef struct dist_layout {
    int format;                /* DIST_* */
    size_t count;              /* rows in the file */
    double dmax;
    int wide;
} dist_layout_t;
/* The layout of a file of `count` rows by the path's extension; an unknown
 * one is HD_EUNSUPPORTED with err filled. */
int distances_layout(const char *path, size_t count, double dmax, int wide, dist_layout_t *f, hd_error_t *err);
/* 1 when an index of nearest[0..n) needs the wide PLY column. */
int distances_wide(const size_t *nearest, size_t n);
/* The header's bytes, and one row's (nearest NULL: -1). */
size_t distances_header(const dist_layout_t *f, char buf[DIST_HEAD_MAX]);
size_t distances_row(const dist_layout_t *f, const double q[3], double d, const size_t *nearest,
                     unsigned char buf[DIST_ROW_MAX]);

/* ---- pictures (render.c) ------------------------------------------------- */
int render_available(void);
/* 1 when the path may name a PNG: it ends in .png (any case) or has no
 * extension (/dev/stdout); another extension (.jpg) would be a lie. */
int render_path_ok(const char *path);
/* The picture of A coloured by its distances to B, three views, colour
 * bar, the witness pair of the Hausdorff distance marked and labelled. */
int render_distances(const char *path, const hd_points_t *A,
                     const hd_points_t *B, const double *d_a, double dmax,
                     const hd_symmetric_t *s, const double *wq, int directed,
                     const render_notes_t *notes, const char *title,
                     render_marker_t markers[6], int *n_markers,
                     render_info_t *info, int *width, int *height,
                     hd_error_t *err);
/* render_distances in two halves, for hausdorff-mpi, whose ranks each
 * hold some of the points: render_splat draws points into per-pixel
 * layers (3 views of RENDER_PANEL x RENDER_PANEL), which merge pixel by
 * pixel in any order (render_near_merge, render_far_merge, and the OR of
 * b), and render_compose draws the picture from the merged layers.  The
 * scene is what every rank must agree on first: the bounds of all of A and
 * B, A's count (the splat size), the colour scale and whether a distance
 * lies beyond it. */
enum { RENDER_PANEL = 460 };
typedef struct render_scene {
    double lo[3], hi[3];
    size_t n_a;
    double dmax;
    int clipped;
} render_scene_t;
/* A pixel's nearest splat of A (the largest float depth, then the smallest
 * index; none: k = UINT64_MAX, depth -inf) and its colour (0xRRGGBB). */
typedef struct render_px {
    uint64_t k;
    float depth;
    uint32_t rgb;
} render_px_t;
/* The splat drawn over the surface there: of the points at a quarter of
 * the scale or more, the smallest (distance, index) (none: k = UINT64_MAX). */
typedef struct render_far {
    double d;
    uint64_t k;
    uint32_t rgb, pad;
} render_far_t;
typedef struct render_layers {
    size_t n;                  /* 3 * RENDER_PANEL^2 pixels */
    render_px_t *near;
    render_far_t *far;
    unsigned char *b;          /* 1 where a point of B is */
} render_layers_t;
void render_scene_bounds(render_scene_t *sc, const hd_points_t *A, const hd_points_t *B);
int render_layers_init(render_layers_t *L); /* -1: out of memory */
void render_layers_free(render_layers_t *L);
void render_near_merge(render_px_t *dst, const render_px_t *src, size_t n);
void render_far_merge(render_far_t *dst, const render_far_t *src, size_t n);
/* A's points (their indices first, first + 1, ...) with their distances,
 * and B's, into L. */
void render_splat(const render_scene_t *sc, const hd_points_t *A, size_t first, const double *d_a,
                  const hd_points_t *B, render_layers_t *L);
/* The picture from the layers; wp and wq are the witness pair's points. */
int render_compose(const char *path, const render_scene_t *sc, const render_layers_t *L, const double wp[3],
                   const double wq[3], const hd_symmetric_t *s, int directed, const render_notes_t *notes,
                   const char *title, render_marker_t markers[6], int *n_markers, render_info_t *info, int *width,
                   int *height, hd_error_t *err);
/* A bar chart of the histogram(s) with the percentile and mean marked;
 * where those lines were drawn goes into marks (at most 4). */
int render_histogram(const char *path, const analysis_result_t *r,
                     const render_notes_t *notes, size_t bins,
                     hist_marker_t marks[4], int *n_marks, hd_error_t *err);

/* ---- text (font.c) --------------------------------------------------------- */
/* Width in font pixels of s at scale 1; the glyphs are 9 pixels high with
 * the baseline after row 7. */
int font_width(const char *s);
/* Draw s with its top-left corner at (x, y), each font pixel scale x scale,
 * into an RGB image of w x h; pixels outside are clipped. */
void font_draw(unsigned char *rgb, int w, int h, int x, int y, int scale,
               const char *s, const unsigned char color[3]);

#endif
