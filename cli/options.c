/*
 * options.c -- command-line parsing: every option, its argument, and the
 * usage text.  A bad option or argument is a usage error (exit 1) with one
 * line on stderr saying what was wrong.
 */
#include "cli.h"
#include "labels.h"
#include "tiles.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* hausdorff-mpi (cli_set_mpi): its own usage line, description, examples
 * and --version line. */
static int mpi_tool;
static void (*mpi_version)(FILE *out);

void cli_set_mpi(void (*version)(FILE *out)) {
    mpi_tool = 1;
    mpi_version = version;
}

static void print_version(FILE *out) {
    if (mpi_version) mpi_version(out);
    else fprintf(out, "%s %s\n", cli_prog(), hd_version());
}

static void usage_head(FILE *out) {
    if (mpi_tool) {
        fprintf(out, "usage: mpirun -n K %s [options] A B\n", cli_prog());
        fprintf(out,
"\n"
"Exact Hausdorff distance between the point sets in files A and B on K MPI\n"
"processes, each reading a share of each side: the same distances, witnesses\n"
"and per-point outputs as hausdorff, to the bit, plus the exchange's figures\n"
"(the \"mpi:\" lines; \"mpi\" in the JSON).\n");
    } else {
        fprintf(out, "usage: %s [options] A B\n", cli_prog());
        fprintf(out, "\nExact Hausdorff distance between the point sets in files A and B:\n");
    }
    fprintf(out,
"H(A,B) = max(h(A,B), h(B,A)),\n"
"h(A,B) = max over a in A of min over b in B of |a-b|.\n"
"Distances are bit-identical to a brute force in double precision.\n");
}

static void usage_one_process(FILE *out); /* from the option table, below */

static void usage_examples(FILE *out) {
    if (mpi_tool) {
        fprintf(out,
"\n"
"hausdorff-mpi computes with its own distributed algorithm: --algorithm,\n"
"--depth, --lambda, --theta, --no-early-break and --no-culling are checked\n"
"and have no effect; --threads is per process.\n");
        usage_one_process(out);
        fprintf(out,
"\n"
"Examples:\n"
"  mpirun -n 64 hausdorff-mpi --json tiles2019/ @tiles2024.txt\n"
"  mpirun -n 64 hausdorff-mpi --distances dev.ply tiles2019/ @tiles2024.txt\n"
"  mpirun -n 64 hausdorff-mpi --percentile 95 --mean --chamfer --render dev.png \\\n"
"      tiles2019/ @tiles2024.txt\n"
"Open MPI refuses to run as root without --allow-run-as-root, and more\n"
"processes than the machine has slots without --oversubscribe (or a hostfile):\n"
"  mpirun --allow-run-as-root --oversubscribe -n 4 hausdorff-mpi scan.las model.ply\n");
    } else {
        fprintf(out,
"\n"
"Examples:\n"
"  hausdorff scan.ply model.ply\n"
"  hausdorff --json --algorithm framework a.xyz b.xyz\n"
"  hausdorff --directed --threads 1 part.ply reference.ply\n"
"  hausdorff --sample 100000 --seed 7 part.stl scan.las\n"
"  cat cloud.csv | hausdorff xyz:- model.ply\n"
"  hausdorff --percentile 95 --mean --render dev.png scan.ply model.ply\n"
"  hausdorff --json --percentile 95 seg.nii.gz truth.nii.gz\n"
"  hausdorff --labels all --components 26 --csv seg.nii.gz truth.nii.gz\n"
"  hausdorff --json tiles2019/ @tiles2024.txt\n");
    }
    fprintf(out, "\nExit status: 0 success, 1 usage error, 2 bad input, 3 other failure.\n");
}

static void usage_options(FILE *out); /* from the option table, below */

void cli_usage(FILE *out) {
    usage_head(out);
    usage_options(out);
    usage_examples(out);
}

void cli_formats(FILE *out) {
    fprintf(out, "Formats (chosen by extension, confirmed by content; --format NAME overrides):\n");
    for (const char *const *f = hd_formats(); *f; f++) fprintf(out, "  %-5s %s\n", *f, hd_format_description(*f));
    fprintf(out, "  nifti NIfTI-1/2 segmentation masks (.nii, .nii.gz): the surface or every foreground voxel,\n"
                 "        in millimetres (read by the tool, %s)\n",
            nifti_available() ? "available" : "unavailable: built without libnifti2");
    fprintf(out, "Extensions: .ply .obj .off .stl; .xyz .txt .csv .pts .asc; .pcd .las .laz .npy; .nii .nii.gz.\n"
                 "csv, txt, pts and asc name the xyz reader too (--format csv, csv:-).\n"
                 "One file's format: FORMAT:PATH (xyz:-, ply:scan.dat).\n");
}

static int bad(const char *fmt, const char *arg) {
    fprintf(stderr, "%s: ", cli_prog());
    fprintf(stderr, fmt, safe_text(arg));
    fprintf(stderr, "\nTry '%s --help'.\n", cli_prog());
    return EXIT_USAGE;
}

static int parse_long(const char *s, long lo, long hi, long *out) {
    char *e;
    errno = 0;
    long v = strtol(s, &e, 10);
    if (e == s || *e || errno || v < lo || v > hi) return -1;
    *out = v;
    return 0;
}

static int parse_u64(const char *s, uint64_t *out) {
    char *e;
    errno = 0;
    if (strchr(s, '-')) return -1; /* strtoull negates " -1" to 2^64 - 1 */
    unsigned long long v = strtoull(s, &e, 10);
    if (e == s || *e || errno) return -1;
    *out = v;
    return 0;
}

/* A size in bytes with an optional K, M or G suffix (powers of 1024). */
static int parse_size(const char *s, uint64_t *out) {
    char *e;
    errno = 0;
    if (*s < '0' || *s > '9') return -1;
    unsigned long long v = strtoull(s, &e, 10);
    if (e == s || errno) return -1;
    int shift = 0;
    if (*e == 'K' || *e == 'k') shift = 10, e++;
    else if (*e == 'M' || *e == 'm') shift = 20, e++;
    else if (*e == 'G' || *e == 'g') shift = 30, e++;
    if (*e || v == 0 || v > (UINT64_MAX >> shift)) return -1;
    *out = (uint64_t)v << shift;
    return 0;
}

/* A finite number filling s up to end; a subnormal (1e-320), or one below
 * the smallest subnormal (read as 0), is the value strtod returns. */
static int parse_double_upto(const char *s, const char *end, double *out) {
    char *e;
    errno = 0;
    double v = strtod(s, &e);
    if (e == s || e != end || (errno && !(errno == ERANGE && fabs(v) <= DBL_MIN)) || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

static int parse_double(const char *s, double *out) { return parse_double_upto(s, s + strlen(s), out); }

/* Every option: first those that take a value, as "--opt VALUE" or
 * "--opt=VALUE" (the run's before OPT_PERCENTILE, then the analysis's:
 * analysis.h), then the flags, which take none. */
typedef enum {
    OPT_NONE = -1, /* a heading or note of the help, not an option */
    OPT_ALGORITHM, OPT_THREADS, OPT_SEED, OPT_DEPTH, OPT_LAMBDA, OPT_THETA, OPT_FORMAT, OPT_SAMPLE,
    OPT_MAX_STREAM_SIZE, OPT_FIFO_WAIT, OPT_LAZ_POINTS_PER_BYTE, OPT_TOLERANCE, OPT_WITHIN,
    OPT_PERCENTILE, OPT_BINS, OPT_DISTANCES, OPT_MAX_DISTANCE, OPT_RENDER, OPT_HISTOGRAM_PNG,
    OPT_MASK_POINTS, OPT_EMPTY, OPT_CONNECTIVITY, OPT_MASK_DIMS, OPT_UNITS, OPT_TAU, OPT_TAU_RULE,
    OPT_DTU_CAP, OPT_LABELS, OPT_COMPONENTS,
    OPT_FARTHER_THAN, OPT_NEARER_THAN, /* these two take D and OUT */
    OPT_FLAGS, /* the first flag */
    OPT_HELP = OPT_FLAGS, OPT_VERSION, OPT_FORMATS, OPT_DIRECTED, OPT_JSON, OPT_QUIET, OPT_NO_EARLY_BREAK,
    OPT_NO_CULLING, OPT_FLOAT32, OPT_DECIMAL_COMMA, OPT_VERTICES, OPT_SURFACE, OPT_SIGNED, OPT_MEAN,
    OPT_CHAMFER, OPT_HISTOGRAM, OPT_CSV,
    OPT_COUNT
} option_t;

/* The one table of options, in the order --help lists them: the name, a
 * short alias, the argument's name (NULL for a flag), what it needs ('p'
 * libpng, 'n' libnifti2: the %s in the help says when it is unavailable),
 * 1 for what only one process computes (surfaces, scores, label maps:
 * hausdorff-mpi refuses those when parsing, before reading anything, never
 * answering another question) and the help text (continuation lines are
 * indented to the help column; options without help share one line).
 * OPT_NONE entries are the help's headings and notes.  An option missing
 * here is unknown to the parser: every one has its entry and its help. */
typedef struct {
    int id;
    const char *name, *alias, *arg;
    char needs;
    char one_process; /* 1: computed by hausdorff only; hausdorff-mpi refuses it when parsing */
    const char *help;
} option_entry_t;

static const option_entry_t options[] = {
    {OPT_NONE, NULL, NULL, NULL, 0, 0,
     "\n"
     "Options:\n"},
    {OPT_ALGORITHM, "--algorithm", NULL, "NAME", 0, 0,
     "auto (default), naive, earlybreak, inc, nohd, ohd,\n"
     "framework, kdtree"},
    {OPT_DIRECTED, "--directed", NULL, NULL, 0, 0,
     "compute only h(A,B)"},
    {OPT_THREADS, "--threads", NULL, "N", 0, 0,
     "threads to use (default: every core; 1 = serial)"},
    {OPT_SEED, "--seed", NULL, "N", 0, 0,
     "seed for randomised steps (default 0)"},
    {OPT_DEPTH, "--depth", NULL, "N", 0, 0,
     "NOHD octree depth (default 6)"},
    {OPT_LAMBDA, "--lambda", NULL, "X", 0, 0,
     "OHD sample fraction of |A| (default 0.01)"},
    {OPT_THETA, "--theta", NULL, "X", 0, 0,
     "framework overlap threshold (default 0.33)"},
    {OPT_NO_EARLY_BREAK, "--no-early-break", NULL, NULL, 0, 0,
     "NOHD without early breaking (the paper's nNOHD)"},
    {OPT_NO_CULLING, "--no-culling", NULL, NULL, 0, 0,
     "OHD without point culling (the paper's nOHD)"},
    {OPT_FORMAT, "--format", NULL, "NAME", 0, 0,
     "read both files as NAME instead of by extension\n"
     "(a file named - is standard input: its format is\n"
     "--format's, else told from its content); one file's\n"
     "format: FORMAT:PATH, e.g. xyz:- or ply:scan.dat\n"
     "(./ply:x for a file whose name holds a colon)"},
    {OPT_FORMATS, "--formats", NULL, NULL, 0, 0,
     "list the file formats and exit"},
    {OPT_NONE, "A or B as tiles:", NULL, NULL, 0, 0,
     "a directory (its point files by extension, sorted by\n"
     "name in byte order, not recursed) or @LIST (a file of\n"
     "paths, one a line, relative to the list's folder; '#'\n"
     "comments; a line may be FORMAT:PATH): their points in\n"
     "that order; the witness is named by file and index\n"
     "(./@x for a file whose name starts with @)"},
    {OPT_VERTICES, "--vertices", NULL, NULL, 0, 0,
     "read a mesh (ply, obj, off, stl) as its vertices (default)"},
    {OPT_SURFACE, "--surface", NULL, NULL, 0, 1,
     "measure meshes as surfaces: each point of A to B's\n"
     "nearest triangle, correctly rounded (the analysis\n"
     "options below work on these distances); with a mesh\n"
     "as A, every point of A's surface against B (a mesh or\n"
     "points): the distance enclosed in [lower, upper] with\n"
     "a witness"},
    {OPT_SIGNED, "--signed", NULL, NULL, 0, 1,
     "with --surface: each distance's sign, -1 inside B, +1\n"
     "outside, 0 on it, from B's winding number (exact); B must\n"
     "be closed and consistently oriented, else it is refused\n"
     "naming an edge"},
    {OPT_TOLERANCE, "--tolerance", NULL, "T", 0, 1,
     "with --surface and a mesh as A: upper - lower <= T,\n"
     "absolute, or with a d suffix a fraction of the\n"
     "bounding-box diagonal (default 1e-9d; 0: as tight\n"
     "as doubles allow)"},
    {OPT_WITHIN, "--within", NULL, "D", 0, 1,
     "with --surface and two meshes: only answer whether\n"
     "H(A,B) <= D (h(A,B) with --directed), stopping early"},
    {OPT_SAMPLE, "--sample", NULL, "N", 0, 0,
     "read a mesh as N points drawn uniformly by area on its\n"
     "faces, reproducibly for a given --seed; a point format\n"
     "(las, laz, xyz, pcd, npy) is read as its points"},
    {OPT_FLOAT32, "--float32", NULL, NULL, 0, 0,
     "store coordinates as float (half the memory)"},
    {OPT_DECIMAL_COMMA, "--decimal-comma", NULL, NULL, 0, 0,
     "text files write 1,5 for 1.5: commas are decimal points\n"
     "and fields are separated by ';' or blanks (without it\n"
     "a decimal comma is refused with its line)"},
    {OPT_MAX_STREAM_SIZE, "--max-stream-size", NULL, "SIZE", 0, 0,
     "most bytes read from an input that is not a\n"
     "regular file (standard input, a pipe, a FIFO), with an\n"
     "optional K, M or G suffix (default 2G)"},
    {OPT_FIFO_WAIT, "--fifo-wait", NULL, "SECONDS", 0, 0,
     "how long a FIFO's writer (input) or reader (output)\n"
     "is awaited (default 30)"},
    {OPT_LAZ_POINTS_PER_BYTE, "--laz-points-per-byte", NULL, "N", 0, 0,
     "the most points a LAZ chunk may hold per byte,\n"
     "bounding a small file's memory (default 256, up to 4096)"},
    {OPT_JSON, "--json", NULL, NULL, 0, 0,
     "print one JSON object"},
    {OPT_QUIET, "--quiet", "-q", NULL, 0, 0,
     "no progress bar on stderr (there is none when stderr\n"
     "is not a terminal, nor with --json)"},
    {OPT_HELP, "--help", "-h", NULL, 0, 0, NULL},
    {OPT_VERSION, "--version", NULL, NULL, 0, 0, NULL},
    {OPT_NONE, NULL, NULL, NULL, 0, 0,
     "\n"
     "Where the deviation is (per-point nearest-neighbour distances):\n"},
    {OPT_PERCENTILE, "--percentile", NULL, "P", 0, 0,
     "percentile Hausdorff, e.g. 95 for HD95: the P-th\n"
     "percentile (numpy's linear interpolation) of the\n"
     "distances of A's points to B (ab), of B's to A (ba),\n"
     "symmetric = max(ab, ba) as MONAI, pooled = both\n"
     "directions together as medpy; P = 100 is H(A,B)"},
    {OPT_MEAN, "--mean", NULL, NULL, 0, 0,
     "mean distances: A->B, B->A, their max (the average\n"
     "Hausdorff distance), their average, and pooled"},
    {OPT_CHAMFER, "--chamfer", NULL, NULL, 0, 0,
     "Chamfer distance = mean squared distance A->B + mean\n"
     "squared distance B->A (as PyTorch3D); the JSON also\n"
     "has the summed and the unsquared variants"},
    {OPT_HISTOGRAM, "--histogram", NULL, NULL, 0, 0,
     "histogram of the distances (--bins N, default 20) on\n"
     "[0, largest distance] or [0, --max-distance]"},
    {OPT_BINS, "--bins", NULL, "N", 0, 0,
     "the histogram's number of bins, 1 to 100000 (default 20)"},
    {OPT_DISTANCES, "--distances", NULL, "OUT", 0, 0,
     "write A's points with distance and nearest index in B\n"
     "(.csv: x,y,z,distance,nearest; .ply: also a viridis\n"
     "colour; .npy: (N, 5) float64); B's go to OUT_b.EXT.\n"
     "OUT of A's own format (.las, .laz, .xyz/.txt/.pts/.asc,\n"
     ".ply when A is a PLY file): A's file with a field\n"
     "`distance` added to every point, everything else kept (a\n"
     "PLY property, with `nearest` too; a LAS/LAZ extra-bytes\n"
     "dimension; a column)"},
    {OPT_FARTHER_THAN, "--farther-than", NULL, "D OUT", 0, 0,
     "write the points of A farther than D from B (d > D),\n"
     "with their distance, as a file of A's own format (PLY,\n"
     "LAS, LAZ, text, OBJ); B's farther than D from A to\n"
     "OUT_b.EXT"},
    {OPT_NEARER_THAN, "--nearer-than", NULL, "D OUT", 0, 0,
     "the same for the points within D (d <= D)"},
    {OPT_MAX_DISTANCE, "--max-distance", NULL, "D", 0, 0,
     "top of the colour and histogram scale (default: the\n"
     "Hausdorff distance)"},
    {OPT_RENDER, "--render", NULL, "OUT.png", 'p', 0,
     "picture of A coloured by distance to B: front, side\n"
     "and top views, colour bar, the Hausdorff witness pair\n"
     "marked, the --percentile figure on the bar%s"},
    {OPT_HISTOGRAM_PNG, "--histogram-png", NULL, "OUT.png", 'p', 0,
     "the histogram as a picture%s\n"
     "(pictures are PNG: OUT must end in .png)"},
    {OPT_UNITS, "--units", NULL, "TEXT", 0, 0,
     "the distances' unit, shown in the report, the JSON and\n"
     "the pictures (a label: nothing is scaled); masks whose\n"
     "header names mm, um or m are in mm without it"},
    {OPT_NONE, NULL, NULL, NULL, 0, 0,
     "\n"
     "Scores at a tolerance (A: the prediction or reconstruction, B: the reference):\n"},
    {OPT_TAU, "--tau", NULL, "T[,T...]", 0, 1,
     "at each tolerance T (up to 64): precision (share of A\n"
     "within T of B), recall (of B within T of A), F-score,\n"
     "and NSD, the normalized surface Dice counted per point\n"
     "(MONAI's compute_surface_dice on masks' surfaces)"},
    {OPT_TAU_RULE, "--tau-rule", NULL, "le|lt", 0, 1,
     "within means d <= T (le, default: MONAI, DeepMind) or\n"
     "d < T (lt: the Tanks and Temples evaluation)"},
    {OPT_DTU_CAP, "--dtu-cap", NULL, "D", 0, 1,
     "DTU accuracy (mean A->B distance) and completeness\n"
     "(mean B->A) over the distances below D, and overall =\n"
     "their average, as the DTU MVS evaluation (D = 20 there)"},
    {OPT_NONE, NULL, NULL, NULL, 'n', 0,
     "\n"
     "Medical masks: A or B may be a NIfTI-1/2 mask (.nii, .nii.gz)%s.\n"
     "  Voxels with a nonzero value are foreground; each becomes the world\n"
     "  coordinate of its centre (sform when sform_code > 0, else qform, else\n"
     "  pixdim), in millimetres (m and um are converted).  Distances are in mm.\n"},
    {OPT_MASK_POINTS, "--mask-points", NULL, "surface|all", 0, 0,
     "surface (default): the foreground voxels that\n"
     "binary erosion removes, outside the image counting as\n"
     "background (as medpy and MONAI); all: every foreground\n"
     "voxel"},
    {OPT_CONNECTIVITY, "--connectivity", NULL, "1|2|3", 0, 0,
     "the surface's neighbourhood, as medpy's connectivity:\n"
     "1 (default) 6-neighbour in 3-D, 4 in 2-D; 2: 18 (8 in\n"
     "2-D); 3: 26"},
    {OPT_MASK_DIMS, "--mask-dims", NULL, "auto|2|3", 0, 0,
     "the axes of that neighbourhood: auto (default) those\n"
     "of more than one voxel (a single slice is a 2-D mask);\n"
     "2: each slice (constant k) on its own, a stack of\n"
     "in-plane contours; 3: all three, a one-voxel axis too"},
    {OPT_EMPTY, "--empty", NULL, "inf|nan|zero|monai", 0, 0,
     "an empty mask or file is an error by default;\n"
     "with this option every distance is reported as inf, NaN\n"
     "or 0 instead; monai: inf when one set is empty, NaN when\n"
     "both are, as MONAI (JSON: null for inf and NaN, and an\n"
     "\"empty\" member)"},
    {OPT_NONE, NULL, NULL, NULL, 'n', 0,
     "\n"
     "Label maps: A (the prediction) and B (the reference) are NIfTI label maps%s\n"
     "  of one size, one integer label a voxel (0: background).\n"},
    {OPT_LABELS, "--labels", NULL, "all|L[,L...]", 0, 1,
     "every nonzero label in A or B (all), or these: per\n"
     "label Dice, HD, HD_P (--percentile, default 95: max of\n"
     "the directed ones as MONAI, and pooled as medpy), ASSD,\n"
     "NSD at --tau (default 1) counted per surface voxel\n"
     "(MONAI) and weighted by surfel area (DeepMind), and\n"
     "DeepMind's HD_P; a table, --csv or --json; a label\n"
     "absent from a side follows --empty (else an error)"},
    {OPT_COMPONENTS, "--components", NULL, "CONN", 0, 1,
     "with --labels, also each connected component (CONN\n"
     "6, 18 or 26; 4 or 8 in 2-D) of each side: its directed\n"
     "HD, HD_P and nearest distance to the other side, and\n"
     "whether it overlaps or comes within --tau (detected)"},
    {OPT_CSV, "--csv", NULL, NULL, 0, 1,
     "with --labels, print the table as CSV"},
};
enum { N_OPTIONS = sizeof options / sizeof options[0], HELP_COLUMN = 21 };

/* The help's note for an option that needs what this build lacks. */
static const char *missing(char needs) {
    if (needs == 'p' && !render_available()) return " (unavailable: built without libpng)";
    if (needs == 'n' && !nifti_available()) return " (unavailable: built without libnifti2)";
    return "";
}

/* t with its "%s" (at most one) as note, each line after a newline
 * indented by indent. */
static void put_text(FILE *out, const char *t, const char *note, int indent) {
    for (; *t; t++) {
        if (t[0] == '%' && t[1] == 's') {
            fputs(note, out);
            t++;
            continue;
        }
        fputc(*t, out);
        if (*t == '\n' && indent && t[1]) fprintf(out, "%*s", indent, "");
    }
}

/* The options' part of --help, from the table. */
static void usage_options(FILE *out) {
    for (size_t k = 0; k < N_OPTIONS; k++) {
        const option_entry_t *o = &options[k];
        if (!o->name) {
            put_text(out, o->help, missing(o->needs), 0);
        } else if (!o->help) { /* "  --help, --version" */
            fprintf(out, "%s%s", k && !options[k - 1].help ? ", " : "  ", o->name);
            if (k + 1 == N_OPTIONS || options[k + 1].help) fputc('\n', out);
        } else {
            int n = fprintf(out, "  %s%s%s", o->name, o->arg ? " " : "", o->arg ? o->arg : "");
            fprintf(out, "%*s", n < HELP_COLUMN ? HELP_COLUMN - n : 2, "");
            put_text(out, o->help, missing(o->needs), HELP_COLUMN);
            fputc('\n', out);
        }
    }
}

/* hausdorff-mpi's help: the options it refuses, from the table. */
static void usage_one_process(FILE *out) {
    int n = fprintf(out, "Computed by hausdorff only, and refused here:");
    for (size_t k = 0; k < N_OPTIONS; k++) {
        if (!options[k].one_process) continue;
        int w = (int)strlen(options[k].name) + 1;
        if (n + w > 78) n = fprintf(out, "\n ") - 1;
        n += fprintf(out, " %s", options[k].name);
    }
    fprintf(out, ".\n");
}

/* The option that s names: "--name", its alias, or "--name=VALUE" for an
 * option that takes a value; -1 for none. */
static int option_named(const char *s) {
    const char *eq = strchr(s, '=');
    size_t nl = eq ? (size_t)(eq - s) : strlen(s);
    for (size_t k = 0; k < N_OPTIONS; k++) {
        const option_entry_t *o = &options[k];
        if (o->id == OPT_NONE || (eq && !o->arg)) continue;
        if ((strlen(o->name) == nl && strncmp(s, o->name, nl) == 0) || (!eq && o->alias && strcmp(s, o->alias) == 0))
            return o->id;
    }
    return -1;
}

/* The table's entry of option id (not OPT_NONE). */
static const option_entry_t *option_entry(int id) {
    size_t k = 0;
    while (k + 1 < N_OPTIONS && options[k].id != id) k++;
    return &options[k];
}

/* An option's name ("--tau") for messages. */
static const char *option_name(int id) { return option_entry(id)->name; }

/* A flag: 1 when the run ends here (--help, --version, --formats: printed), else 0. */
static int set_flag(cli_args_t *a, int which) {
    switch (which) {
    case OPT_HELP: cli_usage(stdout); return 1;
    case OPT_VERSION: print_version(stdout); return 1;
    case OPT_FORMATS: cli_formats(stdout); return 1;
    case OPT_DIRECTED: a->directed = 1; break;
    case OPT_JSON: a->json = 1; break;
    case OPT_QUIET: a->quiet = 1; break;
    case OPT_NO_EARLY_BREAK: a->opt.early_break = 0; break;
    case OPT_NO_CULLING: a->opt.culling = 0; break;
    case OPT_FLOAT32: a->read.dtype = HD_FLOAT32; break;
    case OPT_DECIMAL_COMMA: a->read.decimal_comma = 1; break;
    case OPT_VERTICES: a->read.mesh = HD_MESH_VERTICES; break;
    case OPT_SURFACE: a->surface = 1; break;
    case OPT_SIGNED: a->signed_distance = 1; break;
    case OPT_MEAN: a->an.mean = 1; break;
    case OPT_CHAMFER: a->an.chamfer = 1; break;
    case OPT_HISTOGRAM: a->an.histogram = 1; break;
    case OPT_CSV: a->an.csv = 1; break;
    }
    return 0;
}

/* A run option's value (hd_options_t, hd_read_options_t): 0, or
 * EXIT_USAGE after a message. */
static int set_run(cli_args_t *a, int which, const char *v) {
    long l;
    if (which == OPT_ALGORITHM) {
        if (hd_algorithm_from_name(v, &a->opt.algorithm) != HD_OK)
            return bad("unknown algorithm '%s'", v);
    } else if (which == OPT_THREADS) {
        if (parse_long(v, 0, 1024, &l)) return bad("--threads needs a whole number 0..1024, not '%s'", v);
        a->opt.threads = (int)l;
    } else if (which == OPT_SEED) {
        if (parse_u64(v, &a->opt.seed)) return bad("--seed needs a non-negative whole number, not '%s'", v);
    } else if (which == OPT_DEPTH) {
        if (parse_long(v, 1, 21, &l)) return bad("--depth needs a whole number 1..21, not '%s'", v);
        a->opt.depth = (int)l;
    } else if (which == OPT_LAMBDA) {
        if (parse_double(v, &a->opt.lambda) || !(a->opt.lambda > 0 && a->opt.lambda <= 1))
            return bad("--lambda needs a number in (0, 1], not '%s'", v);
    } else if (which == OPT_THETA) {
        if (parse_double(v, &a->opt.theta) || !(a->opt.theta >= 0 && a->opt.theta <= 1))
            return bad("--theta needs a number in [0, 1], not '%s'", v);
    } else if (which == OPT_FORMAT) {
        if (!(a->read.format = tiles_format_named(v, strlen(v))))
            return bad("unknown format '%s' (see --formats)", v);
    } else if (which == OPT_SAMPLE) {
        uint64_t n;
        if (parse_u64(v, &n) || n == 0 || n > (uint64_t)1 << 40)
            return bad("--sample needs a whole number of points 1..2^40, not '%s'", v);
        a->read.mesh = HD_MESH_SAMPLE;
        a->read.sample = (size_t)n;
    } else if (which == OPT_MAX_STREAM_SIZE) {
        if (parse_size(v, &a->read.stream_limit))
            return bad("--max-stream-size needs a positive size in bytes (K, M or G may follow), not '%s'", v);
    } else if (which == OPT_FIFO_WAIT) {
        if (parse_long(v, 1, 86400, &l)) return bad("--fifo-wait needs a whole number of seconds 1..86400, not '%s'", v);
        a->read.fifo_wait_ms = (int)l * 1000;
    } else if (which == OPT_TOLERANCE) {
        size_t n = strlen(v);
        a->tolerance_relative = n > 1 && v[n - 1] == 'd';
        if (parse_double_upto(v, v + n - (size_t)a->tolerance_relative, &a->tolerance) ||
            !(a->tolerance >= 0) || isinf(a->tolerance))
            return bad("--tolerance needs a number >= 0, optionally with the suffix d (of the diagonal), not '%s'", v);
        a->tolerance_set = 1;
    } else if (which == OPT_WITHIN) {
        if (parse_double(v, &a->within) || !(a->within >= 0) || isinf(a->within))
            return bad("--within needs a distance >= 0, not '%s'", v);
        a->within_set = 1;
    } else if (which == OPT_LAZ_POINTS_PER_BYTE) {
        if (parse_long(v, 1, HD_LAZ_POINTS_PER_BYTE_MAX, &l))
            return bad("--laz-points-per-byte needs a whole number 1..4096, not '%s'", v);
        a->read.laz_points_per_byte = (unsigned)l;
    }
    return 0;
}

/* --tau T[,T...]: each a number >= 0, at most ANALYSIS_MAX_TAUS of them;
 * 0, or EXIT_USAGE after a message.  Each field is read in place, its end
 * the next comma, so a list of any length needs no copy. */
static int set_taus(analysis_args_t *an, const char *v) {
    an->n_taus = 0;
    for (const char *t = v;; t++) {
        const char *comma = strchr(t, ',');
        size_t len = comma ? (size_t)(comma - t) : strlen(t);
        double d;
        if (len) {
            if (parse_double_upto(t, t + len, &d) || d < 0)
                return bad("--tau needs numbers >= 0 separated by commas, not '%s'", v);
            if (an->n_taus == ANALYSIS_MAX_TAUS) return bad("--tau takes at most 64 tolerances ('%s')", v);
            an->taus[an->n_taus++] = d;
        }
        if (!comma) break;
        t = comma;
    }
    if (!an->n_taus) return bad("--tau needs numbers >= 0 separated by commas, not '%s'", v);
    return 0;
}

/* --farther-than D OUT, --nearer-than D OUT: 0, or EXIT_USAGE after a
 * message. */
static int set_subset(analysis_args_t *an, int which, const char *name, const char *v, const char *out) {
    double d;
    char msg[600];
    if (parse_double(v, &d) || !(d >= 0)) {
        snprintf(msg, sizeof msg, "%s needs a distance >= 0 and a file (%s D OUT), not '%s'", name, name, v);
        return bad("%s", msg);
    }
    if (!analysis_writeback_format_known(out)) {
        snprintf(msg, sizeof msg,
                 "%s %s: cannot tell the format of '%s'; the points are written in their file's format: name it "
                 "with its extension (.ply, .las, .laz, .xyz, .csv, .obj)",
                 name, v, out);
        return bad("%s", msg);
    }
    an->subset[which].on = 1;
    an->subset[which].d = d;
    an->subset[which].out = out;
    return 0;
}

/* An analysis option's value (analysis.h): 0, or EXIT_USAGE after a message. */
static int set_analysis(analysis_args_t *an, int which, const char *name, const char *v) {
    double d;
    switch (which) {
    case OPT_PERCENTILE:
        if (parse_double(v, &d) || d < 0 || d > 100)
            return bad("--percentile needs a number in [0, 100], not '%s'", v);
        an->percentile_on = 1;
        an->percentile = d;
        break;
    case OPT_BINS:
        if (parse_double(v, &d) || d < 1 || d > 100000 || d != floor(d))
            return bad("--bins needs a whole number 1..100000, not '%s'", v);
        an->bins = (size_t)d;
        break;
    case OPT_DISTANCES:
        if (!distances_format_known(v) && !analysis_writeback_format_known(v))
            return bad("--distances: cannot tell the format of '%s'; name it .csv, .ply or .npy (or the extension "
                       "of A's format: .las, .laz, .xyz)",
                       v);
        an->distances_out = v;
        break;
    case OPT_MAX_DISTANCE:
        if (parse_double(v, &d) || !(d > 0)) {
            errno = 0;
            double u = strtod(v, NULL); /* 1e-400: positive, but no double */
            if (u == 0 && errno == ERANGE && !signbit(u))
                return bad("--max-distance %s is below the smallest positive double, 4.9e-324", v);
            return bad("--max-distance needs a positive number, not '%s'", v);
        }
        an->max_distance = d;
        break;
    case OPT_RENDER:
    case OPT_HISTOGRAM_PNG:
        if (!render_available())
            return bad("%s is unavailable: this hausdorff was built without libpng "
                               "(Debian: libpng-dev)", name);
        if (!render_path_ok(v)) {
            fprintf(stderr, "%s: %s %s: pictures are written as PNG only; name the file .png\nTry '%s --help'.\n",
                    cli_prog(), name, safe_text(v), cli_prog());
            return EXIT_USAGE;
        }
        if (which == OPT_RENDER) an->render_out = v;
        else an->histogram_png = v;
        break;
    case OPT_MASK_POINTS:
        if (strcmp(v, "surface") == 0) an->mask_points = MASK_SURFACE;
        else if (strcmp(v, "all") == 0) an->mask_points = MASK_ALL;
        else return bad("--mask-points is surface or all, not '%s'", v);
        break;
    case OPT_EMPTY:
        if (hd_empty_policy_from_name(v, &an->empty) != HD_OK || an->empty < HD_EMPTY_INF ||
            an->empty > HD_EMPTY_MONAI)
            return bad("--empty is inf, nan, zero or monai, not '%s'", v);
        break;
    case OPT_CONNECTIVITY:
        if (strcmp(v, "1") && strcmp(v, "2") && strcmp(v, "3"))
            return bad("--connectivity is 1, 2 or 3 (faces, and edges, and corners), not '%s'", v);
        an->connectivity = v[0] - '0';
        break;
    case OPT_MASK_DIMS:
        if (strcmp(v, "auto") == 0) an->mask_dims = 0;
        else if (strcmp(v, "2") == 0 || strcmp(v, "3") == 0) an->mask_dims = v[0] - '0';
        else return bad("--mask-dims is auto, 2 or 3, not '%s'", v);
        break;
    case OPT_UNITS:
        if (!v[0] || strlen(v) > 16 || strpbrk(v, "\"\\") || strspn(v, " ") == strlen(v))
            return bad("--units needs a short label (1 to 16 characters, no quotes), not '%s'", v);
        for (const char *c = v; *c; c++)
            if ((unsigned char)*c < ' ' || (unsigned char)*c > '~')
                return bad("--units needs printable ASCII (the pictures' font has no other), not '%s'", v);
        an->units = v;
        break;
    case OPT_TAU:
        return set_taus(an, v);
    case OPT_TAU_RULE:
        if (strcmp(v, "le") == 0) an->tau_rule = HD_AT_MOST;
        else if (strcmp(v, "lt") == 0) an->tau_rule = HD_BELOW;
        else return bad("--tau-rule is le (d <= tau) or lt (d < tau), not '%s'", v);
        break;
    case OPT_DTU_CAP:
        if (strcmp(v, "inf") == 0) d = INFINITY;
        else if (parse_double(v, &d) || !(d > 0))
            return bad("--dtu-cap needs a positive number or inf, not '%s'", v);
        an->dtu_cap = d;
        break;
    case OPT_LABELS:
        if (!labels_list_ok(v)) return bad("--labels is all or whole numbers separated by commas, not '%s'", v);
        an->labels = v;
        break;
    case OPT_COMPONENTS:
        if (strcmp(v, "6") && strcmp(v, "18") && strcmp(v, "26") && strcmp(v, "4") && strcmp(v, "8"))
            return bad("--components is 6, 18 or 26 (4 or 8 in 2-D), not '%s'", v);
        an->components = atoi(v);
        break;
    }
    return 0;
}

int cli_parse(int argc, char **argv, cli_args_t *a) {
    memset(a, 0, sizeof *a);
    if (argc > 0) cli_set_prog(argv[0]);
    hd_options_init(&a->opt);
    hd_read_options_init(&a->read);
    analysis_args_init(&a->an);
    const char *files[2];
    int nfiles = 0, only_files = 0;
    for (int k = 1; k < argc; k++) {
        const char *s = argv[k];
        if (only_files || s[0] != '-' || strcmp(s, "-") == 0) {
            if (nfiles == 2) return bad("too many files: '%s' (give two)", s);
            files[nfiles++] = s;
            continue;
        }
        if (strcmp(s, "--") == 0) { only_files = 1; continue; }
        int which = option_named(s);
        if (which < 0) return bad("unknown option '%s'", s);
        if (mpi_tool && option_entry(which)->one_process)
            return bad("%s is computed by hausdorff only; hausdorff-mpi measures point sets", option_name(which));
        if (which >= OPT_FLAGS) {
            if (set_flag(a, which)) return EXIT_OK;
            continue;
        }
        const char *eq = strchr(s, '='), *name = option_name(which);
        const char *v = eq ? eq + 1 : (k + 1 < argc ? argv[++k] : NULL);
        if (!v) return bad("option '%s' needs a value", name);
        if (which == OPT_FARTHER_THAN || which == OPT_NEARER_THAN) {
            const char *out = k + 1 < argc ? argv[++k] : NULL;
            if (!out) return bad("%s needs a distance and a file: --farther-than D OUT (or --nearer-than D OUT)", name);
            if (set_subset(&a->an, which == OPT_FARTHER_THAN ? SUBSET_FARTHER : SUBSET_NEARER, name, v, out))
                return EXIT_USAGE;
            continue;
        }
        int rc = which < OPT_PERCENTILE ? set_run(a, which, v) : set_analysis(&a->an, which, name, v);
        if (rc) return rc;
    }
    a->read.seed = a->opt.seed; /* --seed also seeds --sample */
    if ((a->tolerance_set || a->within_set) && !a->surface)
        return bad("%s measures a surface: it needs --surface (and a mesh as A)",
                   a->within_set ? "--within" : "--tolerance");
    if (a->signed_distance && !a->surface)
        return bad("--signed needs --surface: a sign is taken from the surface of the mesh B%s", "");
    if (nfiles != 2) {
        /* one line and a pointer, not the whole help */
        fprintf(stderr, "%s: expected two files, A and B, not %d\n"
                        "usage: %s [options] A B   (%s --help lists the options)\n", cli_prog(),
                nfiles, cli_prog(), cli_prog());
        return EXIT_USAGE;
    }
    a->path_a = tiles_split_format(files[0], &a->format_a);
    a->path_b = tiles_split_format(files[1], &a->format_b);
    a->an.read = a->read; /* for the files written back (writeback.c) */
    a->an.format[0] = a->format_a;
    a->an.format[1] = a->format_b;
    return -1;
}
