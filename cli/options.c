/*
 * options.c -- command-line parsing: every option, its argument, and the
 * usage text.  A bad option or argument is a usage error (exit 1) with one
 * line on stderr saying what was wrong.
 */
#include "cli.h"
#include "tiles.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

/* hausdorff-mpi (cli_set_mpi): its own usage line, description and examples. */
static int mpi_tool;

void cli_set_mpi(void) { mpi_tool = 1; }

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

static void usage_examples(FILE *out) {
    if (mpi_tool) {
        fprintf(out,
"\n"
"hausdorff-mpi computes with its own distributed algorithm: --algorithm,\n"
"--depth, --lambda, --theta, --no-early-break and --no-culling are checked\n"
"and have no effect; --threads is per process.\n"
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
"  hausdorff --json tiles2019/ @tiles2024.txt\n");
    }
    fprintf(out, "\nExit status: 0 success, 1 usage error, 2 bad input, 3 other failure.\n");
}

void cli_usage(FILE *out) {
    usage_head(out);
    fprintf(out,
"\n"
"Options:\n"
"  --algorithm NAME   auto (default), naive, earlybreak, inc, nohd, ohd,\n"
"                     framework, kdtree\n"
"  --directed         compute only h(A,B)\n"
"  --threads N        threads to use (default: every core; 1 = serial)\n"
"  --seed N           seed for randomised steps (default 0)\n"
"  --depth N          NOHD octree depth (default 6)\n"
"  --lambda X         OHD sample fraction of |A| (default 0.01)\n"
"  --theta X          framework overlap threshold (default 0.33)\n"
"  --no-early-break   NOHD without early breaking (the paper's nNOHD)\n"
"  --no-culling       OHD without point culling (the paper's nOHD)\n"
"  --format NAME      read both files as NAME instead of by extension\n"
"                     (a file named - is standard input: its format is\n"
"                     --format's, else told from its content); one file's\n"
"                     format: FORMAT:PATH, e.g. xyz:- or ply:scan.dat\n"
"                     (./ply:x for a file whose name holds a colon)\n"
"  --formats          list the file formats and exit\n"
"  A or B as tiles:   a directory (its point files by extension, sorted by\n"
"                     name in byte order, not recursed) or @LIST (a file of\n"
"                     paths, one a line, relative to the list's folder; '#'\n"
"                     comments; a line may be FORMAT:PATH): their points in\n"
"                     that order; the witness is named by file and index\n"
"                     (./@x for a file whose name starts with @)\n"
"  --vertices         read a mesh (ply, obj, off, stl) as its vertices (default)\n"
"  --surface          measure B, a mesh, as its surface: each point of A to its\n"
"                     nearest triangle, correctly rounded (A must be points)\n"
"  --sample N         read a mesh as N points drawn uniformly by area on its\n"
"                     faces, reproducibly for a given --seed; a point format\n"
"                     (las, laz, xyz, pcd, npy) is read as its points\n"
"  --float32          store coordinates as float (half the memory)\n"
"  --decimal-comma    text files write 1,5 for 1.5: commas are decimal points\n"
"                     and fields are separated by ';' or blanks (without it\n"
"                     a decimal comma is refused with its line)\n"
"  --max-stream-size SIZE  most bytes read from an input that is not a\n"
"                     regular file (standard input, a pipe, a FIFO), with an\n"
"                     optional K, M or G suffix (default 2G)\n"
"  --fifo-wait SECONDS  how long a FIFO's writer (input) or reader (output)\n"
"                     is awaited (default 30)\n"
"  --laz-points-per-byte N  the most points a LAZ chunk may hold per byte,\n"
"                     bounding a small file's memory (default 256, up to 4096)\n"
"  --json             print one JSON object\n"
"  --quiet            no progress bar on stderr (there is none when stderr\n"
"                     is not a terminal, nor with --json)\n"
"  --help, --version\n");
    analysis_usage(out);
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
    if (*s == '-') return -1;
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

static int parse_double(const char *s, double *out) {
    char *e;
    errno = 0;
    double v = strtod(s, &e);
    if (e == s || *e || errno) return -1;
    *out = v;
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
        if (strcmp(s, "--help") == 0 || strcmp(s, "-h") == 0) { cli_usage(stdout); return EXIT_OK; }
        if (strcmp(s, "--version") == 0) { printf("%s %s\n", cli_prog(), hd_version()); return EXIT_OK; }
        if (strcmp(s, "--directed") == 0) { a->directed = 1; continue; }
        if (strcmp(s, "--json") == 0) { a->json = 1; continue; }
        if (strcmp(s, "--quiet") == 0 || strcmp(s, "-q") == 0) { a->quiet = 1; continue; }
        if (strcmp(s, "--no-early-break") == 0) { a->opt.early_break = 0; continue; }
        if (strcmp(s, "--no-culling") == 0) { a->opt.culling = 0; continue; }
        if (strcmp(s, "--float32") == 0) { a->read.dtype = HD_FLOAT32; continue; }
        if (strcmp(s, "--decimal-comma") == 0) { a->read.decimal_comma = 1; continue; }
        if (strcmp(s, "--vertices") == 0) { a->read.mesh = HD_MESH_VERTICES; continue; }
        if (strcmp(s, "--surface") == 0) { a->surface = 1; continue; }
        if (strcmp(s, "--formats") == 0) { cli_formats(stdout); return EXIT_OK; }
        int an = analysis_parse_option(argc, argv, &k, &a->an);
        if (an < 0) return EXIT_USAGE;
        if (an > 0) continue;
        /* options with an argument, as "--opt VALUE" or "--opt=VALUE" */
        const char *eq = strchr(s, '=');
        char name[64];
        size_t nl = eq ? (size_t)(eq - s) : strlen(s);
        if (nl >= sizeof name) return bad("unknown option '%s'", s);
        memcpy(name, s, nl);
        name[nl] = '\0';
        static const char *const with_arg[] = {"--algorithm", "--threads", "--seed", "--depth",
                                               "--lambda", "--theta", "--format", "--sample",
                                               "--max-stream-size", "--fifo-wait", "--laz-points-per-byte", NULL};
        int known = 0;
        for (int w = 0; with_arg[w]; w++) known |= strcmp(name, with_arg[w]) == 0;
        if (!known) return bad("unknown option '%s'", s);
        const char *v = eq ? eq + 1 : (k + 1 < argc ? argv[++k] : NULL);
        if (!v) return bad("option '%s' needs a value", name);
        long l;
        if (strcmp(name, "--algorithm") == 0) {
            if (hd_algorithm_from_name(v, &a->opt.algorithm) != HD_OK)
                return bad("unknown algorithm '%s'", v);
        } else if (strcmp(name, "--threads") == 0) {
            if (parse_long(v, 0, 1024, &l)) return bad("--threads needs a whole number 0..1024, not '%s'", v);
            a->opt.threads = (int)l;
        } else if (strcmp(name, "--seed") == 0) {
            if (parse_u64(v, &a->opt.seed)) return bad("--seed needs a non-negative whole number, not '%s'", v);
        } else if (strcmp(name, "--depth") == 0) {
            if (parse_long(v, 1, 21, &l)) return bad("--depth needs a whole number 1..21, not '%s'", v);
            a->opt.depth = (int)l;
        } else if (strcmp(name, "--lambda") == 0) {
            if (parse_double(v, &a->opt.lambda) || !(a->opt.lambda > 0 && a->opt.lambda <= 1))
                return bad("--lambda needs a number in (0, 1], not '%s'", v);
        } else if (strcmp(name, "--theta") == 0) {
            if (parse_double(v, &a->opt.theta) || !(a->opt.theta >= 0 && a->opt.theta <= 1))
                return bad("--theta needs a number in [0, 1], not '%s'", v);
        } else if (strcmp(name, "--format") == 0) {
            if (!(a->read.format = tiles_format_named(v, strlen(v))))
                return bad("unknown format '%s' (see --formats)", v);
        } else if (strcmp(name, "--sample") == 0) {
            uint64_t n;
            if (parse_u64(v, &n) || n == 0 || n > (uint64_t)1 << 40)
                return bad("--sample needs a whole number of points 1..2^40, not '%s'", v);
            a->read.mesh = HD_MESH_SAMPLE;
            a->read.sample = (size_t)n;
        } else if (strcmp(name, "--max-stream-size") == 0) {
            if (parse_size(v, &a->read.stream_limit))
                return bad("--max-stream-size needs a positive size in bytes (K, M or G may follow), not '%s'", v);
        } else if (strcmp(name, "--fifo-wait") == 0) {
            if (parse_long(v, 1, 86400, &l)) return bad("--fifo-wait needs a whole number of seconds 1..86400, not '%s'", v);
            a->read.fifo_wait_ms = (int)l * 1000;
        } else if (strcmp(name, "--laz-points-per-byte") == 0) {
            if (parse_long(v, 1, HD_LAZ_POINTS_PER_BYTE_MAX, &l))
                return bad("--laz-points-per-byte needs a whole number 1..4096, not '%s'", v);
            a->read.laz_points_per_byte = (unsigned)l;
        }
    }
    a->read.seed = a->opt.seed; /* --seed also seeds --sample */
    if (nfiles != 2) {
        /* one line and a pointer, not the whole help */
        fprintf(stderr, "%s: expected two files, A and B, not %d\n"
                        "usage: %s [options] A B   (%s --help lists the options)\n", cli_prog(),
                nfiles, cli_prog(), cli_prog());
        return EXIT_USAGE;
    }
    a->path_a = tiles_split_format(files[0], &a->format_a);
    a->path_b = tiles_split_format(files[1], &a->format_b);
    return -1;
}
