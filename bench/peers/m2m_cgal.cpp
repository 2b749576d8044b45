// m2m_cgal -- CGAL peer of the surface-to-surface benchmark (Debian 12's
// CGAL 5.5, header-only; bench/m2m_bench.py runs it).  Sequential_tag
// everywhere: CGAL 5.5's bounded-error Hausdorff distance has no parallel
// version (its parallel branch compiles only with TBB, METIS and
// USE_PARALLEL_BEHD defined, and the manual says it is not implemented),
// and the sampled one is compared at one thread too.
//
//   m2m_cgal bounded A.off B.off TOLERANCE ab|ba|sym
//       bounded_error_Hausdorff_distance(A, B) (ab), (B, A) (ba), or
//       bounded_error_symmetric_Hausdorff_distance (sym) at the absolute
//       tolerance, on Exact_predicates_inexact_constructions_kernel (as in
//       CGAL's own example), match_faces left on (its default).
//   m2m_cgal larger A.off B.off D TOLERANCE ab|sym
//       is_Hausdorff_distance_larger(A, B, D, TOLERANCE), one-sided (ab) or
//       symmetric (sym): prints its answer as "within" (1 when it says the
//       distance is not larger than D).
//   m2m_cgal sampled A.off B.off SAMPLES SEED
//       approximate_Hausdorff_distance both ways: SAMPLES points drawn
//       uniformly on the faces, plus the vertices and one point per vertex
//       on the edges (CGAL's defaults for those two), seeded; and a
//       Metro-style estimate: both meshes rounded to float32, their
//       vertices plus SAMPLES points uniform by area drawn in float32, the
//       distance to the other mesh rounded to float32 (MeshLab's stock
//       builds store coordinates and distances as float).
//
// Prints one JSON line.  Times are wall and processor seconds of the call
// (CGAL's trees are built inside it; reading the files is not timed).
//
// Meshes: OFF with triangles.  Each face goes into a CGAL::Surface_mesh
// over shared vertices; a face that Surface_mesh refuses (a repeated index,
// a non-manifold edge or vertex) is added over three new vertices at its
// corners' coordinates instead, so the geometry is the same triangle soup
// (the count is reported as "detached").
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Surface_mesh.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <random>
#include <string>
#include <vector>

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef K::Point_3 Point;
typedef CGAL::Surface_mesh<Point> Mesh;
namespace PMP = CGAL::Polygon_mesh_processing;

struct Soup {
    std::vector<double> v;
    std::vector<size_t> t;
};

static Soup read_off(const char *path) {
    std::ifstream in(path);
    std::string magic;
    size_t nv, nf, ne;
    if (!(in >> magic >> nv >> nf >> ne) || magic != "OFF") {
        std::fprintf(stderr, "m2m_cgal: %s: not an OFF file\n", path);
        std::exit(2);
    }
    Soup s;
    s.v.resize(3 * nv);
    for (size_t i = 0; i < 3 * nv; i++)
        if (!(in >> s.v[i])) {
            std::fprintf(stderr, "m2m_cgal: %s: short vertex list\n", path);
            std::exit(2);
        }
    for (size_t k = 0; k < nf; k++) {
        size_t n, a, b, c;
        if (!(in >> n >> a >> b >> c) || n != 3 || a >= nv || b >= nv || c >= nv) {
            std::fprintf(stderr, "m2m_cgal: %s: face %zu is not a triangle over the vertices\n", path, k);
            std::exit(2);
        }
        s.t.insert(s.t.end(), {a, b, c});
    }
    return s;
}

static Mesh to_mesh(const Soup &s, size_t *detached) {
    Mesh m;
    std::vector<Mesh::Vertex_index> vi;
    for (size_t i = 0; i < s.v.size() / 3; i++) vi.push_back(m.add_vertex(Point(s.v[3 * i], s.v[3 * i + 1], s.v[3 * i + 2])));
    *detached = 0;
    for (size_t k = 0; k < s.t.size() / 3; k++) {
        const size_t *f = &s.t[3 * k];
        if (f[0] != f[1] && f[1] != f[2] && f[0] != f[2] &&
            m.add_face(vi[f[0]], vi[f[1]], vi[f[2]]) != Mesh::null_face())
            continue;
        Mesh::Vertex_index c[3];
        for (int j = 0; j < 3; j++) c[j] = m.add_vertex(m.point(vi[f[j]]));
        m.add_face(c[0], c[1], c[2]);
        (*detached)++;
    }
    return m;
}

struct Clock {
    std::chrono::steady_clock::time_point w;
    std::clock_t c;
    Clock() : w(std::chrono::steady_clock::now()), c(std::clock()) {}
    double wall() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - w).count(); }
    double cpu() const { return double(std::clock() - c) / CLOCKS_PER_SEC; }
};

static int bounded(const Mesh &a, const Mesh &b, double tol, const char *which) {
    Clock t;
    double d;
    if (!std::strcmp(which, "ab"))
        d = PMP::bounded_error_Hausdorff_distance<CGAL::Sequential_tag>(a, b, tol);
    else if (!std::strcmp(which, "ba"))
        d = PMP::bounded_error_Hausdorff_distance<CGAL::Sequential_tag>(b, a, tol);
    else if (!std::strcmp(which, "sym"))
        d = PMP::bounded_error_symmetric_Hausdorff_distance<CGAL::Sequential_tag>(a, b, tol);
    else
        return 2;
    double wall = t.wall(), cpu = t.cpu();
    std::printf("{\"which\": \"%s\", \"tolerance\": %.17g, \"distance\": %.17g, \"seconds\": %.6g, \"cpu\": %.6g}\n",
                which, tol, d, wall, cpu);
    return 0;
}

static int larger(const Mesh &a, const Mesh &b, double d, double tol, const char *which) {
    if (std::strcmp(which, "ab") && std::strcmp(which, "sym")) return 2;
    Clock t;
    bool beyond = PMP::is_Hausdorff_distance_larger<CGAL::Sequential_tag>(
        a, b, d, tol, PMP::parameters::use_one_sided_hausdorff(!std::strcmp(which, "ab")));
    double wall = t.wall(), cpu = t.cpu();
    std::printf("{\"which\": \"%s\", \"d\": %.17g, \"tolerance\": %.17g, \"within\": %d, \"seconds\": %.6g, "
                "\"cpu\": %.6g}\n",
                which, d, tol, beyond ? 0 : 1, wall, cpu);
    return 0;
}

// Metro-style: float32 everywhere a stock MeshLab build has it.
static double metro(const Soup &a, const Soup &b, size_t samples, unsigned seed) {
    typedef CGAL::Simple_cartesian<double> KD;
    std::vector<KD::Triangle_3> tris;
    auto fl = [](double x) { return (double)(float)x; };
    for (size_t k = 0; k < b.t.size() / 3; k++) {
        KD::Point_3 p[3];
        for (int j = 0; j < 3; j++) {
            const double *q = &b.v[3 * b.t[3 * k + j]];
            p[j] = KD::Point_3(fl(q[0]), fl(q[1]), fl(q[2]));
        }
        tris.emplace_back(p[0], p[1], p[2]);
    }
    typedef CGAL::AABB_triangle_primitive<KD, std::vector<KD::Triangle_3>::iterator> Prim;
    CGAL::AABB_tree<CGAL::AABB_traits<KD, Prim>> tree(tris.begin(), tris.end());
    tree.accelerate_distance_queries();
    float worst = 0;
    auto visit = [&](float x, float y, float z) {
        float d = (float)std::sqrt(tree.squared_distance(KD::Point_3(x, y, z)));
        if (d > worst) worst = d;
    };
    for (size_t i = 0; i < a.v.size() / 3; i++) visit((float)a.v[3 * i], (float)a.v[3 * i + 1], (float)a.v[3 * i + 2]);
    // Faces chosen with probability proportional to area (float32 areas).
    size_t nf = a.t.size() / 3;
    std::vector<double> cum(nf);
    double total = 0;
    for (size_t k = 0; k < nf; k++) {
        float p[3][3];
        for (int j = 0; j < 3; j++)
            for (int c = 0; c < 3; c++) p[j][c] = (float)a.v[3 * a.t[3 * k + j] + c];
        float u[3], w[3];
        for (int c = 0; c < 3; c++) u[c] = p[1][c] - p[0][c], w[c] = p[2][c] - p[0][c];
        float n0 = u[1] * w[2] - u[2] * w[1], n1 = u[2] * w[0] - u[0] * w[2], n2 = u[0] * w[1] - u[1] * w[0];
        total += std::sqrt(n0 * n0 + n1 * n1 + n2 * n2);
        cum[k] = total;
    }
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> U(0, 1);
    for (size_t s = 0; s < samples && total > 0; s++) {
        size_t k = std::lower_bound(cum.begin(), cum.end(), U(rng) * total) - cum.begin();
        if (k >= nf) k = nf - 1;
        float r1 = (float)std::sqrt(U(rng)), r2 = (float)U(rng);
        float w0 = 1 - r1, w1 = r1 * (1 - r2), w2 = r1 * r2, q[3];
        for (int c = 0; c < 3; c++)
            q[c] = w0 * (float)a.v[3 * a.t[3 * k] + c] + w1 * (float)a.v[3 * a.t[3 * k + 1] + c] +
                   w2 * (float)a.v[3 * a.t[3 * k + 2] + c];
        visit(q[0], q[1], q[2]);
    }
    return worst;
}

static int sampled(const Soup &sa, const Soup &sb, const Mesh &a, const Mesh &b, size_t samples, unsigned seed) {
    auto np = [&](size_t n) {
        return PMP::parameters::use_random_uniform_sampling(true).number_of_points_on_faces(n).random_seed(seed);
    };
    Clock t;
    double ab = PMP::approximate_Hausdorff_distance<CGAL::Sequential_tag>(a, b, np(samples));
    double ba = PMP::approximate_Hausdorff_distance<CGAL::Sequential_tag>(b, a, np(samples));
    double wall = t.wall(), cpu = t.cpu();
    Clock tm;
    double mab = metro(sa, sb, samples, seed), mba = metro(sb, sa, samples, seed + 1);
    double mwall = tm.wall(), mcpu = tm.cpu();
    std::printf("{\"samples\": %zu, \"approximate\": {\"ab\": %.17g, \"ba\": %.17g, \"seconds\": %.6g, \"cpu\": %.6g}, "
                "\"metro\": {\"ab\": %.9g, \"ba\": %.9g, \"seconds\": %.6g, \"cpu\": %.6g}}\n",
                samples, ab, ba, wall, cpu, mab, mba, mwall, mcpu);
    return 0;
}

int main(int argc, char **argv) {
    int is_larger = argc == 7 && !std::strcmp(argv[1], "larger");
    if (!is_larger && (argc != 6 || (std::strcmp(argv[1], "bounded") && std::strcmp(argv[1], "sampled")))) {
        std::fprintf(stderr, "usage: m2m_cgal bounded A.off B.off TOLERANCE ab|ba|sym\n"
                             "       m2m_cgal larger A.off B.off D TOLERANCE ab|sym\n"
                             "       m2m_cgal sampled A.off B.off SAMPLES SEED\n");
        return 2;
    }
    Soup sa = read_off(argv[2]), sb = read_off(argv[3]);
    size_t da, db;
    Mesh a = to_mesh(sa, &da), b = to_mesh(sb, &db);
    std::fprintf(stderr, "m2m_cgal: %zu and %zu faces detached\n", da, db);
    if (is_larger) return larger(a, b, std::atof(argv[4]), std::atof(argv[5]), argv[6]);
    if (!std::strcmp(argv[1], "bounded")) return bounded(a, b, std::atof(argv[4]), argv[5]);
    return sampled(sa, sb, a, b, (size_t)std::atof(argv[4]), (unsigned)std::atoi(argv[5]));
}
