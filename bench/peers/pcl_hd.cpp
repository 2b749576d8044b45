// pcl_hd.cpp -- PCL's KD-tree (pcl::KdTreeFLANN over pcl::PointXYZ, as in
// PCL's own tools): tree on B, nearestKSearch(1) for each point of A, max;
// then the other direction.  PCL points are float32, so the distance agrees
// with the exact one only to float precision.  With threads > 1 the searches
// run in an OpenMP loop.
//
// usage: pcl_hd A.bin B.bin THREADS RUNS BUDGET_SECONDS
#include "peer_io.hpp"

#include <cmath>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

static pcl::PointCloud<pcl::PointXYZ>::Ptr to_cloud(const std::vector<double> &p) {
    pcl::PointCloud<pcl::PointXYZ>::Ptr c(new pcl::PointCloud<pcl::PointXYZ>);
    c->resize(p.size() / 3);
    for (size_t i = 0; i < p.size() / 3; i++)
        (*c)[i] = pcl::PointXYZ((float)p[3 * i], (float)p[3 * i + 1], (float)p[3 * i + 2]);
    return c;
}

static double directed2(const pcl::PointCloud<pcl::PointXYZ>::Ptr &a,
                        const pcl::PointCloud<pcl::PointXYZ>::Ptr &b, int threads) {
    pcl::KdTreeFLANN<pcl::PointXYZ> tree;
    tree.setInputCloud(b);
    long na = (long)a->size();
    double best = 0;
#pragma omp parallel for num_threads(threads) reduction(max : best) schedule(dynamic, 1024)
    for (long i = 0; i < na; i++) {
        std::vector<int> idx(1);
        std::vector<float> d2(1);
        tree.nearestKSearch((*a)[(size_t)i], 1, idx, d2);
        best = std::max(best, (double)d2[0]);
    }
    return best;
}

int main(int argc, char **argv) {
    if (argc < 6) {
        std::fprintf(stderr, "usage: %s A.bin B.bin THREADS RUNS BUDGET\n", argv[0]);
        return 2;
    }
    std::vector<double> pa = read_points(argv[1]), pb = read_points(argv[2]);
    int threads = std::atoi(argv[3]);
    run_repeated(std::atoi(argv[4]), std::atof(argv[5]), [&] {
        // Converting to PCL's cloud type is part of using PCL.
        auto a = to_cloud(pa), b = to_cloud(pb);
        return std::sqrt(std::max(directed2(a, b, threads), directed2(b, a, threads)));
    });
    return 0;
}
