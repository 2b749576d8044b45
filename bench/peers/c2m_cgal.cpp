// c2m_cgal -- CGAL peer of the cloud-to-mesh benchmark (Debian 12's CGAL
// 5.5): an AABB tree of the triangles (Simple_cartesian<double>) with
// accelerate_distance_queries(), squared_distance per point, 1 thread.
//
//   c2m_cgal CASE.bin RUNS
//
// Prints the median seconds of RUNS (tree build included; wall and
// processor time), the largest
// difference from the correctly rounded distances (sqrt of CGAL's squared
// distance) and the number of points that differ.
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <vector>

typedef CGAL::Simple_cartesian<double> K;
typedef K::Point_3 Point;
typedef K::Triangle_3 Triangle;
typedef std::vector<Triangle>::iterator Iterator;
typedef CGAL::AABB_triangle_primitive<K, Iterator> Primitive;
typedef CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>> Tree;

static std::vector<double> get(FILE *f, size_t n) {
    std::vector<double> v(n);
    if (fread(v.data(), sizeof(double), n, f) != n) { fprintf(stderr, "short file\n"); std::exit(1); }
    return v;
}

int main(int argc, char **argv) {
    if (argc < 3) { fprintf(stderr, "usage: c2m_cgal CASE.bin RUNS\n"); return 2; }
    FILE *f = fopen(argv[1], "rb");
    uint64_t n, nv, nt;
    if (!f || fread(&n, 8, 1, f) != 1) return 1;
    std::vector<double> p = get(f, 3 * n), exact = get(f, n);
    if (fread(&nv, 8, 1, f) != 1) return 1;
    std::vector<double> v = get(f, 3 * nv);
    if (fread(&nt, 8, 1, f) != 1) return 1;
    std::vector<uint64_t> t(3 * nt);
    if (fread(t.data(), 8, 3 * nt, f) != 3 * nt) return 1;
    fclose(f);
    int runs = atoi(argv[2]);
    std::vector<double> times, cpu, d(n);
    for (int r = 0; r < runs; r++) {
        auto t0 = std::chrono::steady_clock::now();
        std::clock_t c0 = std::clock();
        std::vector<Triangle> tris;
        tris.reserve(nt);
        for (uint64_t k = 0; k < nt; k++) {
            const double *a = &v[3 * t[3 * k]], *b = &v[3 * t[3 * k + 1]], *c = &v[3 * t[3 * k + 2]];
            tris.emplace_back(Point(a[0], a[1], a[2]), Point(b[0], b[1], b[2]), Point(c[0], c[1], c[2]));
        }
        Tree tree(tris.begin(), tris.end());
        tree.accelerate_distance_queries();
        for (uint64_t i = 0; i < n; i++) d[i] = std::sqrt(tree.squared_distance(Point(p[3 * i], p[3 * i + 1], p[3 * i + 2])));
        times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        cpu.push_back(double(std::clock() - c0) / CLOCKS_PER_SEC);
    }
    std::sort(times.begin(), times.end());
    std::sort(cpu.begin(), cpu.end());
    double worst = 0;
    size_t differ = 0;
    for (uint64_t i = 0; i < n; i++) {
        double e = std::fabs(d[i] - exact[i]);
        worst = std::max(worst, e);
        differ += e > 0;
    }
    printf("cgal 1 thread: median %.3f s of %d (cpu %.3f s); max error %.3g, %zu of %llu points differ\n",
           times[runs / 2], runs, cpu[runs / 2],
           worst, differ, (unsigned long long)n);
    return 0;
}
