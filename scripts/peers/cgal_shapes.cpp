// Plane detection peers for aniso-alpha's benchmarks: CGAL 5.5's Efficient
// RANSAC and region growing on a point set, timed in-process.
//
//   cgal_shapes ransac|region POINTS.xyz LABELS.txt [--k K] [--epsilon E]
//       [--cluster-epsilon C] [--min-points M] [--normal-threshold T]
//       [--max-angle DEG] [--probability P]
//
// POINTS.xyz: `x y z` per line, or `x y z nx ny nz`. Normals are
// estimated with CGAL::pca_estimate_normals over K neighbours (timed
// apart as "normals"); with `--k 0`, the file's own normals (columns 4-6)
// are used instead, as CGAL's examples do with a scan that has them. LABELS.txt: one integer per input point, the plane
// id or -1. Prints one JSON line: n, planes, seconds of the normals and
// of the detection, unassigned points.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Shape_detection/Efficient_RANSAC.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing_on_point_set.h>
#include <CGAL/pca_estimate_normals.h>
#include <CGAL/Real_timer.h>
#include <boost/iterator/function_output_iterator.hpp>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef K::Point_3 Point;
typedef K::Vector_3 Vector;
// Efficient RANSAC reorders its input: each point carries its input index.
typedef std::tuple<Point, Vector, std::size_t> Pwn;
typedef std::vector<Pwn> Pwns;
typedef CGAL::Nth_of_tuple_property_map<0, Pwn> Point_map;
typedef CGAL::Nth_of_tuple_property_map<1, Pwn> Normal_map;
typedef CGAL::Shape_detection::Efficient_RANSAC_traits<K, Pwns, Point_map, Normal_map> Traits;
typedef CGAL::Shape_detection::Efficient_RANSAC<Traits> Ransac;
typedef CGAL::Shape_detection::Plane<Traits> Plane;
typedef CGAL::Shape_detection::Point_set::K_neighbor_query<K, Pwns, Point_map> Neighbors;
typedef CGAL::Shape_detection::Point_set::Least_squares_plane_fit_region<K, Pwns, Point_map, Normal_map> Region;
typedef CGAL::Shape_detection::Region_growing<Pwns, Neighbors, Region> Growing;

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: cgal_shapes ransac|region POINTS.xyz LABELS.txt [options]\n";
    return 2;
  }
  std::string mode = argv[1];
  unsigned k = 12;
  double eps = -1, ceps = -1, thr = 0.9, max_angle = 20, prob = 0.05;
  long min_points = -1;
  for (int i = 4; i + 1 < argc; i += 2) {
    std::string o = argv[i];
    double v = std::atof(argv[i + 1]);
    if (o == "--k") k = unsigned(v);
    else if (o == "--epsilon") eps = v;
    else if (o == "--cluster-epsilon") ceps = v;
    else if (o == "--min-points") min_points = long(v);
    else if (o == "--normal-threshold") thr = v;
    else if (o == "--max-angle") max_angle = v;
    else if (o == "--probability") prob = v;
    else { std::cerr << "unknown option " << o << "\n"; return 2; }
  }
  Pwns pts;
  {
    std::ifstream in(argv[2]);
    std::string line;
    while (std::getline(in, line)) {
      std::istringstream s(line);
      double x, y, z, nx = 0, ny = 0, nz = 0;
      if (s >> x >> y >> z) {
        if (k == 0 && !(s >> nx >> ny >> nz)) {
          std::cerr << "--k 0 needs x y z nx ny nz per line\n";
          return 2;
        }
        pts.push_back(Pwn(Point(x, y, z), Vector(nx, ny, nz), pts.size()));
      }
    }
  }
  std::vector<long> labels(pts.size(), -1);
  CGAL::Real_timer tn, td;
  tn.start();
  if (k > 0)
    CGAL::pca_estimate_normals<CGAL::Sequential_tag>(
        pts, k, CGAL::parameters::point_map(Point_map()).normal_map(Normal_map()));
  tn.stop();
  long planes = 0;
  if (mode == "ransac") {
    td.start();
    Ransac ransac;
    ransac.set_input(pts);
    ransac.add_shape_factory<Plane>();
    ransac.preprocess();
    Ransac::Parameters p;
    p.probability = prob;
    if (min_points > 0) p.min_points = std::size_t(min_points);
    if (eps > 0) p.epsilon = eps;
    if (ceps > 0) p.cluster_epsilon = ceps;
    p.normal_threshold = thr;
    ransac.detect(p);
    td.stop();
    for (auto it = ransac.shapes().begin(); it != ransac.shapes().end(); ++it, ++planes)
      for (std::size_t i : (*it)->indices_of_assigned_points()) labels[std::get<2>(pts[i])] = planes;
  } else if (mode == "region") {
    td.start();
    Neighbors nq(pts, k > 0 ? k : 12, Point_map());
    Region region(pts, eps > 0 ? eps : 1.0, max_angle,
                  std::size_t(min_points > 0 ? min_points : 50), Point_map(), Normal_map());
    Growing growing(pts, nq, region);
    std::vector<std::vector<std::size_t>> regions;
    growing.detect(std::back_inserter(regions));
    td.stop();
    for (auto& r : regions) {
      for (std::size_t i : r) labels[std::get<2>(pts[i])] = planes;
      ++planes;
    }
  } else {
    std::cerr << "mode must be ransac or region\n";
    return 2;
  }
  std::ofstream out(argv[3]);
  long unassigned = 0;
  for (long l : labels) {
    out << l << "\n";
    unassigned += l < 0;
  }
  std::cout << "{\"peer\":\"cgal_" << mode << "\",\"n\":" << pts.size() << ",\"planes\":" << planes
            << ",\"normals_seconds\":" << tn.time() << ",\"detect_seconds\":" << td.time()
            << ",\"unassigned\":" << unassigned << "}" << std::endl;
  return 0;
}
