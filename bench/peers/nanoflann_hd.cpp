// nanoflann_hd.cpp -- the peer the engine is measured against: what PDAL
// and point-cloud-utils do with nanoflann.  Build a KD-tree on B, run one
// exact nearest-neighbour search for each point of A, keep the maximum;
// then the other direction.  With threads > 1 the searches run in an
// OpenMP parallel loop.  Squared distances are nanoflann's L2_Simple sums
// ((dx*dx + dy*dy) + dz*dz), the same doubles as the library's.
//
// usage: nanoflann_hd A.bin B.bin THREADS RUNS BUDGET_SECONDS
#include "peer_io.hpp"

#include <cmath>
#include <nanoflann.hpp>
#ifdef _OPENMP
#include <omp.h>
#endif

struct Cloud {
    const std::vector<double> &p;
    size_t kdtree_get_point_count() const { return p.size() / 3; }
    double kdtree_get_pt(size_t i, size_t d) const { return p[3 * i + d]; }
    template <class BBOX> bool kdtree_get_bbox(BBOX &) const { return false; }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>,
                                                 Cloud, 3, size_t>;

static double directed2(const std::vector<double> &a, const std::vector<double> &b, int threads) {
    Cloud cb{b};
    Tree tree(3, cb, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    long na = (long)(a.size() / 3);
    double best = 0;
#pragma omp parallel for num_threads(threads) reduction(max : best) schedule(dynamic, 1024)
    for (long i = 0; i < na; i++) {
        size_t j;
        double d2;
        tree.knnSearch(&a[3 * (size_t)i], 1, &j, &d2);
        best = std::max(best, d2);
    }
    return best;
}

int main(int argc, char **argv) {
    if (argc < 6) {
        std::fprintf(stderr, "usage: %s A.bin B.bin THREADS RUNS BUDGET\n", argv[0]);
        return 2;
    }
    std::vector<double> a = read_points(argv[1]), b = read_points(argv[2]);
    int threads = std::atoi(argv[3]);
    run_repeated(std::atoi(argv[4]), std::atof(argv[5]), [&] {
        return std::sqrt(std::max(directed2(a, b, threads), directed2(b, a, threads)));
    });
    return 0;
}
