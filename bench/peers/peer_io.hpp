// peer_io.hpp -- what the C++ peer programs share: reading the benchmark's
// point files (raw little-endian float64 x, y, z triples, as bench.c writes
// them), a clock, and the one-line JSON report bench.c parses.
#ifndef HD_BENCH_PEER_IO_HPP
#define HD_BENCH_PEER_IO_HPP

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

static std::vector<double> read_points(const char *path) {
    std::vector<double> v;
    FILE *f = std::fopen(path, "rb");
    if (!f) {
        std::perror(path);
        std::exit(2);
    }
    std::fseek(f, 0, SEEK_END);
    long bytes = std::ftell(f);
    std::fseek(f, 0, SEEK_SET);
    v.resize((size_t)bytes / sizeof(double));
    if (std::fread(v.data(), sizeof(double), v.size(), f) != v.size()) {
        std::perror(path);
        std::exit(2);
    }
    std::fclose(f);
    v.resize(v.size() / 3 * 3);
    return v;
}

static double now_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// {"distance": D, "times": [t1, t2, ...]}: the symmetric distance of the
// last run and the wall time of each run (building included, reading not).
static void report(double distance, const std::vector<double> &times) {
    std::printf("{\"distance\": %.17g, \"times\": [", distance);
    for (size_t k = 0; k < times.size(); k++) std::printf("%s%.9g", k ? ", " : "", times[k]);
    std::printf("]}\n");
}

// Runs: at most `runs`, and no more once `budget` seconds have been spent.
template <class F> static void run_repeated(int runs, double budget, F once) {
    std::vector<double> times;
    double spent = 0, d = 0;
    for (int r = 0; r < runs && (r == 0 || spent < budget); r++) {
        double t0 = now_seconds();
        d = once();
        double t = now_seconds() - t0;
        times.push_back(t);
        spent += t;
    }
    report(d, times);
}

#endif
