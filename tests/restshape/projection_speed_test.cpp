// Throughput of the mesh reference (reported, not asserted: machines differ). The results are still checked.
#include <gtest/gtest.h>

#include <chrono>
#include <iostream>
#include <random>

#include "restshape/reference_surface.hpp"
#include "restshape/surface_fixtures.hpp"

namespace arcsim {
namespace {

TEST(MeshReferenceSpeed, HundredThousandProjectionsOnTwentyThousandFaces) {
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> tris;
  const double R = 0.5;
  test::icosphere(5, R, Vec3::Zero(), points, tris);
  ASSERT_EQ(tris.size(), 20480u);
  const auto t_build = std::chrono::steady_clock::now();
  const auto ref = make_mesh_reference(test::mesh_from_soup(points, tris));
  const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_build).count();

  // Points within 2 % of the surface, projected along a slightly tilted normal (as a split's averaged normal is).
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> U(-1, 1);
#ifdef __SANITIZE_ADDRESS__
  const int count = 10000;  // sanitizer runs check correctness only; the figure is meaningless there
#else
  const int count = 100000;
#endif
  std::vector<Vec3> u(count), d(count);
  for (int i = 0; i < count; ++i) {
    const Vec3 n = test::random_unit(rng);
    u[i] = R * (1 + 0.02 * U(rng)) * n;
    d[i] = n + 0.1 * test::random_unit(rng);
  }
  // The chords of a level-5 icosphere of radius R are at most ~R * 3e-3 / 2 inside the sphere.
  const double chord_depth = 2e-3 * R;
  auto t0 = std::chrono::steady_clock::now();
  int off_surface = 0;
  for (int i = 0; i < count; ++i) {
    const double r = ref->project(u[i], d[i], kInfinity).norm();
    off_surface += r > R * (1 + 1e-12) || r < R - chord_depth;
  }
  const double project_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < count; ++i) {
    const double r = ref->closest_point(u[i]).norm();
    off_surface += r > R * (1 + 1e-12) || r < R - chord_depth;
  }
  const double closest_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(off_surface, 0);
  std::cout << "[ speed    ] mesh reference, 20480 faces: build " << build_s * 1e3 << " ms; " << count
            << " line projections " << project_s << " s; " << count << " closest points " << closest_s << " s\n";
  RecordProperty("project_seconds", std::to_string(project_s));
  RecordProperty("closest_seconds", std::to_string(closest_s));
}

}  // namespace
}  // namespace arcsim
