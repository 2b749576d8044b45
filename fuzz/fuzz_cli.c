/*
 * fuzz_cli.c -- a libFuzzer target for the command line's argument parser,
 * cli_parse() (cli/options.c: one table and one parser for every option of
 * both programs).
 *
 * The input is split at NUL bytes into arguments (at most 64) after
 * argv[0] = "hausdorff"; a seed file is a command line written as
 * `printf -- '--sample\0100\0a.ply\0b.ply'`.  What cli_parse prints
 * (usage, --formats, --version, error lines) goes to /dev/null: stdout and
 * stderr are pointed at it around the call.
 *
 * The contract: cli_parse returns -1 (go on), 0 (after --help, --version,
 * --formats) or 1 (a usage error).  On -1 the arguments are walked again
 * here, independently of the parser (the options that take one value, the
 * two that take D and OUT, the flags), and every field of cli_args_t must
 * hold what its option's last occurrence says, read here with the C
 * library, or its default when the option was not given: --threads,
 * --seed (also the sampling seed), --depth, --lambda, --theta,
 * --algorithm, --format, --sample / --vertices (the last one wins),
 * --max-stream-size with its K/M/G suffix, --fifo-wait, --laz-points-per-byte,
 * --tolerance with its relative `d` suffix, --within, --percentile, --bins,
 * --distances, --max-distance, --render, --histogram-png, --mask-points,
 * --empty, --connectivity, --mask-dims, --units, --tau (a list), --tau-rule,
 * --dtu-cap, --labels, --components, --farther-than / --nearer-than (the
 * distance and the path), and each flag; the two files are the arguments
 * left, each with its FORMAT: prefix split off.  The combinations the
 * parser refuses (--tolerance, --within or --signed without --surface)
 * never come back as -1.
 *
 * The contract covers every option: LLVMFuzzerInitialize reads each
 * "--name" that --help prints and aborts when one is unknown here, so an
 * option added to the table without its check here fails at once.  It also
 * parses command lines at the edges of what the options accept (--tolerance
 * 1d, 64 --tau values, the largest --seed, --fifo-wait, --sample ...): each
 * must be accepted and meet the contract, since a fuzzer cannot tell a
 * valid input wrongly refused from one rightly refused.
 */
#include "cli.h"
#include "labels.h"
#include "tiles.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define MAX_ARGS 64

/* Every option, as the contract knows it: its name, its alias, and how many
 * values follow it (0 for a flag). */
typedef enum {
    ALGORITHM, THREADS, SEED, DEPTH, LAMBDA, THETA, FORMAT, SAMPLE, MAX_STREAM_SIZE, FIFO_WAIT,
    LAZ_POINTS_PER_BYTE, TOLERANCE, WITHIN, PERCENTILE, BINS, DISTANCES, MAX_DISTANCE, RENDER,
    HISTOGRAM_PNG, MASK_POINTS, EMPTY, CONNECTIVITY, MASK_DIMS, UNITS, TAU, TAU_RULE, DTU_CAP, LABELS,
    COMPONENTS, FARTHER_THAN, NEARER_THAN, HELP, VERSION, FORMATS, DIRECTED, JSON, QUIET,
    NO_EARLY_BREAK, NO_CULLING, FLOAT32, DECIMAL_COMMA, VERTICES, SURFACE, SIGNED, MEAN, CHAMFER,
    HISTOGRAM, CSV, N_OPTIONS
} opt_t;

static const struct {
    const char *name, *alias;
    int values;
} known[N_OPTIONS] = {
    [ALGORITHM] = {"--algorithm", NULL, 1}, [THREADS] = {"--threads", NULL, 1}, [SEED] = {"--seed", NULL, 1},
    [DEPTH] = {"--depth", NULL, 1}, [LAMBDA] = {"--lambda", NULL, 1}, [THETA] = {"--theta", NULL, 1},
    [FORMAT] = {"--format", NULL, 1}, [SAMPLE] = {"--sample", NULL, 1},
    [MAX_STREAM_SIZE] = {"--max-stream-size", NULL, 1}, [FIFO_WAIT] = {"--fifo-wait", NULL, 1},
    [LAZ_POINTS_PER_BYTE] = {"--laz-points-per-byte", NULL, 1}, [TOLERANCE] = {"--tolerance", NULL, 1},
    [WITHIN] = {"--within", NULL, 1}, [PERCENTILE] = {"--percentile", NULL, 1}, [BINS] = {"--bins", NULL, 1},
    [DISTANCES] = {"--distances", NULL, 1}, [MAX_DISTANCE] = {"--max-distance", NULL, 1},
    [RENDER] = {"--render", NULL, 1}, [HISTOGRAM_PNG] = {"--histogram-png", NULL, 1},
    [MASK_POINTS] = {"--mask-points", NULL, 1}, [EMPTY] = {"--empty", NULL, 1},
    [CONNECTIVITY] = {"--connectivity", NULL, 1}, [MASK_DIMS] = {"--mask-dims", NULL, 1},
    [UNITS] = {"--units", NULL, 1}, [TAU] = {"--tau", NULL, 1}, [TAU_RULE] = {"--tau-rule", NULL, 1},
    [DTU_CAP] = {"--dtu-cap", NULL, 1}, [LABELS] = {"--labels", NULL, 1},
    [COMPONENTS] = {"--components", NULL, 1}, [FARTHER_THAN] = {"--farther-than", NULL, 2},
    [NEARER_THAN] = {"--nearer-than", NULL, 2}, [HELP] = {"--help", "-h", 0}, [VERSION] = {"--version", NULL, 0},
    [FORMATS] = {"--formats", NULL, 0}, [DIRECTED] = {"--directed", NULL, 0}, [JSON] = {"--json", NULL, 0},
    [QUIET] = {"--quiet", "-q", 0}, [NO_EARLY_BREAK] = {"--no-early-break", NULL, 0},
    [NO_CULLING] = {"--no-culling", NULL, 0}, [FLOAT32] = {"--float32", NULL, 0},
    [DECIMAL_COMMA] = {"--decimal-comma", NULL, 0}, [VERTICES] = {"--vertices", NULL, 0},
    [SURFACE] = {"--surface", NULL, 0}, [SIGNED] = {"--signed", NULL, 0}, [MEAN] = {"--mean", NULL, 0},
    [CHAMFER] = {"--chamfer", NULL, 0}, [HISTOGRAM] = {"--histogram", NULL, 0}, [CSV] = {"--csv", NULL, 0},
};

static FILE *devnull;

/* The option named by the n bytes at s (a name or an alias), or -1. */
static int known_option(const char *s, size_t n) {
    for (int k = 0; k < N_OPTIONS; k++)
        if ((strlen(known[k].name) == n && strncmp(s, known[k].name, n) == 0) ||
            (known[k].alias && strlen(known[k].alias) == n && strncmp(s, known[k].alias, n) == 0))
            return k;
    return -1;
}

/* Every "--name" in the help must be an option the contract knows. */
static void check_help_names(void) {
    char *help = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&help, &len);
    if (!f) abort();
    cli_usage(f);
    fclose(f);
    for (const char *p = strstr(help, "--"); p; p = strstr(p + 2, "--")) {
        size_t n = 2 + strspn(p + 2, "abcdefghijklmnopqrstuvwxyz0123456789-");
        while (n > 2 && p[n - 1] == '-') n--;
        if (n > 2 && known_option(p, n) < 0) {
            fprintf(stderr, "fuzz_cli: the help lists %.*s, which the contract does not check\n", (int)n, p);
            abort();
        }
    }
    free(help);
}

static void check_contract(int argc, char **argv, const cli_args_t *a);

/* cli_parse with its messages sent to /dev/null. */
static int parse_quietly(int argc, char **argv, cli_args_t *a) {
    FILE *out = stdout, *err = stderr;
    stdout = devnull;
    stderr = devnull;
    int rc = cli_parse(argc, argv, a);
    stdout = out;
    stderr = err;
    return rc;
}

/* Command lines at the edges of what each option accepts: each must be
 * accepted (-1) and meet the contract, so a parser that starts refusing a
 * valid value fails here, as one that stores a wrong one fails below. */
static void check_accepted_edges(void) {
    static char taus64[64 * 2];
    for (int k = 0; k < 64; k++) memcpy(taus64 + 2 * k, k < 63 ? "1," : "1", 2);
    const char *lines[][12] = {
        {"--surface", "--tolerance", "1d", "a.obj", "b.off"},
        {"--surface", "--tolerance=0d", "--within", "0", "--signed", "a.obj", "b.off"},
        {"--surface", "--tolerance", "1e-320", "--within=1e308", "a.obj", "b.off"},
        {"--tau", taus64, "--tau-rule", "lt", "--dtu-cap", "inf", "a", "b"},
        {"--tau", ",0,", "--dtu-cap=1e-320", "--max-distance", "1e-320", "a", "b"},
        {"--labels", "all", "--components", "4", "--csv", "a.nii", "b.nii"},
        {"--labels=0,1,2", "--components=26", "--connectivity=3", "--mask-dims", "3", "a.nii", "b.nii"},
        {"--farther-than", "0", "x.ply", "--nearer-than=1e300", "y.laz", "a.ply", "b"},
        {"--distances", "x.LAS", "--histogram", "--units", "0123456789abcdef", "a", "b"},
        {"--seed", "18446744073709551615", "--sample", "1099511627776", "--threads", "1024", "a", "b"},
        {"--max-stream-size", "16G", "--fifo-wait", "86400", "--laz-points-per-byte", "4096", "a", "b"},
        {"--percentile", "0", "--bins", "100000", "--empty", "monai", "--depth", "21", "-q", "a", "b"},
    };
    static char name[] = "hausdorff";
    for (size_t k = 0; k < sizeof lines / sizeof lines[0]; k++) {
        char *argv[14] = {name};
        int argc = 1;
        for (int j = 0; j < 12 && lines[k][j]; j++) argv[argc++] = (char *)lines[k][j];
        cli_args_t a;
        if (parse_quietly(argc, argv, &a) != -1) {
            fprintf(stderr, "fuzz_cli: cli_parse refuses valid line %zu (%s %s ...)\n", k, argv[1], argv[2]);
            abort();
        }
        check_contract(argc, argv, &a);
    }
}

int LLVMFuzzerInitialize(int *argc, char ***argv) {
    (void)argc, (void)argv;
    devnull = fopen("/dev/null", "w");
    if (!devnull) abort();
    check_help_names();
    check_accepted_edges();
    return 0;
}

/* The arguments walked: each option's last value(s) (NULL when not given),
 * whether each flag was given, which of --sample and --vertices came last,
 * and the two files. */
typedef struct {
    const char *value[N_OPTIONS], *out[N_OPTIONS];
    int given[N_OPTIONS];
    int last_mesh;
    const char *files[2];
    int nfiles;
} walk_t;

static void fail(const char *what) {
    fprintf(stderr, "fuzz_cli: contract broken: %s\n", what);
    abort();
}
#define CHECK(cond)                                                                                                    \
    do {                                                                                                               \
        if (!(cond)) fail(#cond);                                                                                      \
    } while (0)

/* The walk of a command line cli_parse accepted (-1). */
static void walk(int argc, char **argv, walk_t *w) {
    memset(w, 0, sizeof *w);
    w->last_mesh = -1;
    int only_files = 0;
    for (int k = 1; k < argc; k++) {
        const char *s = argv[k];
        if (only_files || s[0] != '-' || strcmp(s, "-") == 0) {
            CHECK(w->nfiles < 2);
            w->files[w->nfiles++] = s;
            continue;
        }
        if (strcmp(s, "--") == 0) {
            only_files = 1;
            continue;
        }
        const char *eq = strchr(s, '=');
        int o = known_option(s, eq ? (size_t)(eq - s) : strlen(s));
        CHECK(o >= 0 && !(eq && (!known[o].values || s[1] != '-')));
        w->given[o] = 1;
        if (o == SAMPLE || o == VERTICES) w->last_mesh = o;
        if (known[o].values) {
            CHECK(eq || k + known[o].values < argc);
            w->value[o] = eq ? eq + 1 : argv[++k];
            if (known[o].values == 2) w->out[o] = argv[++k];
        }
    }
}

/* strtod's reading of s (the parser's numbers are C numbers). */
static double num(const char *s) { return strtod(s, NULL); }

static int same(double x, double y) { return memcmp(&x, &y, sizeof x) == 0; }

/* A file argument and the path and format cli_parse split from it. */
static void check_file(const char *arg, const char *path, const char *format) {
    const char *colon = strchr(arg, ':');
    if (!format) {
        CHECK(path == arg);
        return;
    }
    CHECK(colon && path == colon + 1 && hd_format_description(format));
    size_t n = (size_t)(colon - arg);
    static const char *const text_aliases[] = {"csv", "txt", "pts", "asc", NULL};
    int named = strlen(format) == n && strncasecmp(arg, format, n) == 0;
    for (const char *const *f = text_aliases; !named && *f && strcmp(format, "xyz") == 0; f++)
        named = strlen(*f) == n && strncasecmp(arg, *f, n) == 0;
    CHECK(named);
}

/* --max-stream-size's value: digits, then K, M or G (powers of 1024). */
static uint64_t size_value(const char *s) {
    char *e;
    uint64_t v = strtoull(s, &e, 10);
    switch (*e) {
    case 'K': case 'k': return v << 10;
    case 'M': case 'm': return v << 20;
    case 'G': case 'g': return v << 30;
    default: return v;
    }
}

/* The run's options (hd_options_t, hd_read_options_t) against the walk. */
static void check_run(const walk_t *w, const cli_args_t *a, const cli_args_t *d) {
    const hd_options_t *o = &a->opt;
    const hd_read_options_t *r = &a->read;
    const char *const *v = w->value;
    hd_algorithm_t alg = d->opt.algorithm;
    if (v[ALGORITHM]) CHECK(hd_algorithm_from_name(v[ALGORITHM], &alg) == HD_OK);
    CHECK(o->algorithm == alg);
    CHECK(o->threads == (v[THREADS] ? strtol(v[THREADS], NULL, 10) : d->opt.threads));
    CHECK(o->seed == (v[SEED] ? strtoull(v[SEED], NULL, 10) : d->opt.seed) && r->seed == o->seed);
    CHECK(!v[SEED] || !strchr(v[SEED], '-')); /* no negative number, not even after a blank */
    CHECK(o->depth == (v[DEPTH] ? strtol(v[DEPTH], NULL, 10) : d->opt.depth) && o->depth >= 1 && o->depth <= 21);
    CHECK(same(o->lambda, v[LAMBDA] ? num(v[LAMBDA]) : d->opt.lambda) && o->lambda > 0 && o->lambda <= 1);
    CHECK(same(o->theta, v[THETA] ? num(v[THETA]) : d->opt.theta) && o->theta >= 0 && o->theta <= 1);
    CHECK(o->early_break == (w->given[NO_EARLY_BREAK] ? 0 : d->opt.early_break));
    CHECK(o->culling == (w->given[NO_CULLING] ? 0 : d->opt.culling));
    CHECK(v[FORMAT] ? r->format && hd_format_description(r->format) && r->format == tiles_format_named(v[FORMAT], strlen(v[FORMAT]))
                    : r->format == d->read.format);
    CHECK(r->dtype == (w->given[FLOAT32] ? HD_FLOAT32 : d->read.dtype));
    CHECK(r->decimal_comma == (w->given[DECIMAL_COMMA] ? 1 : d->read.decimal_comma));
    if (w->last_mesh == SAMPLE)
        CHECK(r->mesh == HD_MESH_SAMPLE && r->sample == strtoull(v[SAMPLE], NULL, 10) && r->sample >= 1 &&
              r->sample <= (size_t)1 << 40);
    else
        CHECK(r->mesh == (w->last_mesh == VERTICES ? HD_MESH_VERTICES : d->read.mesh) &&
              r->sample == (v[SAMPLE] ? strtoull(v[SAMPLE], NULL, 10) : d->read.sample));
    CHECK(r->threads == d->read.threads && r->range_first == d->read.range_first && r->range_count == d->read.range_count);
    /* 0: the library's default (hausdorff.h); a value given is positive */
    CHECK(r->stream_limit == (v[MAX_STREAM_SIZE] ? size_value(v[MAX_STREAM_SIZE]) : d->read.stream_limit));
    CHECK(!v[MAX_STREAM_SIZE] || r->stream_limit > 0);
    CHECK(r->fifo_wait_ms == (v[FIFO_WAIT] ? 1000 * strtol(v[FIFO_WAIT], NULL, 10) : d->read.fifo_wait_ms));
    CHECK(!v[FIFO_WAIT] || (r->fifo_wait_ms >= 1000 && r->fifo_wait_ms <= 86400000));
    CHECK(r->laz_points_per_byte == (v[LAZ_POINTS_PER_BYTE] ? (unsigned)strtol(v[LAZ_POINTS_PER_BYTE], NULL, 10)
                                                             : d->read.laz_points_per_byte));
    CHECK(!v[LAZ_POINTS_PER_BYTE] || (r->laz_points_per_byte >= 1 && r->laz_points_per_byte <= HD_LAZ_POINTS_PER_BYTE_MAX));
}

/* The surface options and the flags of cli_args_t against the walk. */
static void check_surface_and_flags(const walk_t *w, const cli_args_t *a) {
    const char *t = w->value[TOLERANCE];
    CHECK(a->tolerance_set == !!t && a->within_set == !!w->value[WITHIN]);
    if (t) {
        size_t n = strlen(t);
        CHECK(a->tolerance_relative == (n > 1 && t[n - 1] == 'd'));
        CHECK(same(a->tolerance, num(t)) && a->tolerance >= 0 && isfinite(a->tolerance));
    }
    if (w->value[WITHIN]) CHECK(same(a->within, num(w->value[WITHIN])) && a->within >= 0 && isfinite(a->within));
    CHECK(a->surface == w->given[SURFACE] && a->signed_distance == w->given[SIGNED]);
    CHECK(a->directed == w->given[DIRECTED] && a->json == w->given[JSON] && a->quiet == w->given[QUIET]);
    /* what the parser refuses: these need --surface */
    CHECK(a->surface || (!t && !w->value[WITHIN] && !w->given[SIGNED]));
}

/* --tau's list: each non-empty field between commas, as strtod reads it. */
static void check_taus(const char *v, const analysis_args_t *an) {
    size_t n = 0;
    for (const char *p = v;; p++) {
        const char *comma = strchr(p, ',');
        if (comma != p && *p) {
            CHECK(n < an->n_taus && n < ANALYSIS_MAX_TAUS && same(an->taus[n], num(p)));
            CHECK(an->taus[n] >= 0 && isfinite(an->taus[n]));
            n++;
        }
        if (!comma) break;
        p = comma;
    }
    CHECK(n == an->n_taus && n >= 1);
}

/* The analysis's value options against the walk (d: the defaults). */
static void check_analysis_values(const walk_t *w, const analysis_args_t *an, const analysis_args_t *d) {
    const char *const *v = w->value;
    CHECK(an->percentile_on == !!v[PERCENTILE]);
    CHECK(same(an->percentile, v[PERCENTILE] ? num(v[PERCENTILE]) : d->percentile) && an->percentile >= 0 &&
          an->percentile <= 100);
    CHECK(an->bins == (v[BINS] ? (size_t)num(v[BINS]) : d->bins) && an->bins >= 1 && an->bins <= 100000);
    CHECK(an->distances_out == v[DISTANCES]);
    if (v[DISTANCES])
        CHECK(distances_format_known(v[DISTANCES]) || analysis_writeback_format_known(v[DISTANCES]));
    CHECK(same(an->max_distance, v[MAX_DISTANCE] ? num(v[MAX_DISTANCE]) : d->max_distance));
    CHECK(an->max_distance >= 0 && isfinite(an->max_distance));
    CHECK(an->render_out == v[RENDER] && an->histogram_png == v[HISTOGRAM_PNG]);
    CHECK((!v[RENDER] || render_path_ok(v[RENDER])) && (!v[HISTOGRAM_PNG] || render_path_ok(v[HISTOGRAM_PNG])));
    CHECK(an->mask_points == (!v[MASK_POINTS] ? d->mask_points
                              : strcmp(v[MASK_POINTS], "all") == 0 ? MASK_ALL
                                                                   : MASK_SURFACE));
    CHECK(!v[MASK_POINTS] || strcmp(v[MASK_POINTS], "all") == 0 || strcmp(v[MASK_POINTS], "surface") == 0);
    hd_empty_policy_t empty = d->empty;
    if (v[EMPTY]) CHECK(hd_empty_policy_from_name(v[EMPTY], &empty) == HD_OK);
    CHECK(an->empty == empty && (!v[EMPTY] || (empty >= HD_EMPTY_INF && empty <= HD_EMPTY_MONAI)));
    CHECK(an->connectivity == (v[CONNECTIVITY] ? atoi(v[CONNECTIVITY]) : d->connectivity));
    CHECK(an->connectivity >= 1 && an->connectivity <= 3);
    CHECK(an->mask_dims == (!v[MASK_DIMS] || strcmp(v[MASK_DIMS], "auto") == 0 ? 0 : atoi(v[MASK_DIMS])));
    CHECK(an->mask_dims == 0 || an->mask_dims == 2 || an->mask_dims == 3);
    CHECK(an->units == v[UNITS] && (!an->units || (an->units[0] && strlen(an->units) <= 16)));
    if (v[TAU]) check_taus(v[TAU], an);
    else CHECK(an->n_taus == 0);
    CHECK(an->tau_rule == (!v[TAU_RULE] ? d->tau_rule : strcmp(v[TAU_RULE], "lt") == 0 ? HD_BELOW : HD_AT_MOST));
    CHECK(!v[TAU_RULE] || strcmp(v[TAU_RULE], "lt") == 0 || strcmp(v[TAU_RULE], "le") == 0);
    CHECK(same(an->dtu_cap, !v[DTU_CAP] ? d->dtu_cap : strcmp(v[DTU_CAP], "inf") == 0 ? INFINITY : num(v[DTU_CAP])));
    CHECK(!v[DTU_CAP] || an->dtu_cap > 0);
    CHECK(an->labels == v[LABELS] && (!an->labels || labels_list_ok(an->labels)));
    CHECK(an->components == (v[COMPONENTS] ? atoi(v[COMPONENTS]) : d->components));
    CHECK(an->components == 0 || an->components == 4 || an->components == 6 || an->components == 8 ||
          an->components == 18 || an->components == 26);
}

/* The analysis's flags and --farther-than / --nearer-than D OUT. */
static void check_analysis_rest(const walk_t *w, const cli_args_t *a) {
    const analysis_args_t *an = &a->an;
    CHECK(an->mean == w->given[MEAN] && an->chamfer == w->given[CHAMFER] && an->histogram == w->given[HISTOGRAM]);
    CHECK(an->csv == w->given[CSV]);
    static const opt_t subset_option[2] = {[SUBSET_FARTHER] = FARTHER_THAN, [SUBSET_NEARER] = NEARER_THAN};
    for (int s = 0; s < 2; s++) {
        const char *v = w->value[subset_option[s]], *out = w->out[subset_option[s]];
        CHECK(an->subset[s].on == !!v && an->subset[s].out == out);
        if (v) CHECK(same(an->subset[s].d, num(v)) && an->subset[s].d >= 0 && analysis_writeback_format_known(out));
    }
    CHECK(an->format[0] == a->format_a && an->format[1] == a->format_b);
    /* the files written back are read as the inputs were */
    CHECK(an->read.format == a->read.format && an->read.dtype == a->read.dtype && an->read.mesh == a->read.mesh);
    CHECK(an->read.decimal_comma == a->read.decimal_comma && an->read.sample == a->read.sample);
}

static void check_contract(int argc, char **argv, const cli_args_t *a) {
    walk_t w;
    walk(argc, argv, &w);
    CHECK(w.nfiles == 2 && !w.given[HELP] && !w.given[VERSION] && !w.given[FORMATS]);
    check_file(w.files[0], a->path_a, a->format_a);
    check_file(w.files[1], a->path_b, a->format_b);
    cli_args_t d; /* the defaults */
    memset(&d, 0, sizeof d);
    hd_options_init(&d.opt);
    hd_read_options_init(&d.read);
    analysis_args_init(&d.an);
    check_run(&w, a, &d);
    check_surface_and_flags(&w, a);
    check_analysis_values(&w, &a->an, &d.an);
    check_analysis_rest(&w, a);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *buf = malloc(size + 1);
    if (!buf) return 0;
    if (size) memcpy(buf, data, size);
    buf[size] = '\0';
    static char name[] = "hausdorff";
    char *argv[MAX_ARGS + 2];
    int argc = 0;
    argv[argc++] = name;
    for (size_t k = 0; k <= size && argc <= MAX_ARGS;) {
        argv[argc++] = buf + k;
        k += strlen(buf + k) + 1;
    }
    if (size == 0) argc = 1; /* no input: no arguments */
    argv[argc] = NULL;

    cli_args_t a;
    int rc = parse_quietly(argc, argv, &a);
    if (rc != -1 && rc != EXIT_OK && rc != EXIT_USAGE) fail("cli_parse returned an unknown code");
    if (rc == -1) check_contract(argc, argv, &a);
    free(buf);
    return 0;
}
