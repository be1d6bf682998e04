// Paper §5.2 "Rest space position": repeated refinement to a fine size and coarsening back must not diffuse a
// curved rest shape. Rest verts stay on the reference surface, rest angles match the rest shape, and the rest
// area (and, for the closed sphere, the enclosed volume) does not drift: after every cycle it is within 0.1% of
// its value after the first cycle at the same size. (Against the input mesh itself the refined surface differs by
// its chord error, a few % at these sizes, which is resolution, not diffusion.)
#include <gtest/gtest.h>

#include "mesh/validate.hpp"
#include "remesh/remesh.hpp"
#include "remesh/remesh_fixtures.hpp"
#include "restshape/reference_surface.hpp"

namespace arcsim {
namespace {

using namespace remesh_test;

struct CycleResult {
  double max_off_reference = 0;     // m
  double max_rest_angle_error = 0;  // rad
  // Relative drift of the rest area and enclosed volume from the first coarse (fine) state, over all later
  // coarse (fine) states: what diffusion of the rest shape would show.
  double area_drift = 0, volume_drift = 0;
  double coarse_area = 0, fine_area = 0;  // first coarse / fine state (m^2)
  int coarse_faces = 0, fine_faces = 0;
};

double max_distance_to(const Mesh& m, const ReferenceSurface& ref) {
  double d = 0;
  for (const Vert& v : m.verts)
    if (!v.dead) d = std::max(d, (ref.closest_point(v.u) - v.u).norm());
  return d;
}

template <typename Outward>
CycleResult run_cycles(Mesh m, const ReferenceSurface& ref, double coarse, double fine, int cycles,
                       Outward outward) {
  const std::vector<Material> materials{glass()};
  set_thickness(m, materials[0]);
  CycleResult r;
  double first_volume[2] = {0, 0};
  for (int cycle = 0; cycle < cycles; ++cycle) {
    for (const int level : {1, 0}) {  // 1 fine, 0 coarse
      RemeshOptions o;
      o.extras.uniform_size = level == 1 ? fine : coarse;
      o.reference = &ref;
      remesh_mesh(m, materials, o);
      m.compact();
      const std::string where = "cycle " + std::to_string(cycle) + " level " + std::to_string(level);
      EXPECT_EQ(check_mesh(m), "") << where;
      EXPECT_EQ(inverted_face(m, outward), "") << where;
      r.max_off_reference = std::max(r.max_off_reference, max_distance_to(m, ref));
      // Rest angles follow the rest shape: every interior edge's rest angle is its rest dihedral.
      for (size_t e = 0; e < m.edges.size(); ++e)
        r.max_rest_angle_error = std::max(r.max_rest_angle_error,
                                          std::abs(m.edges[e].rest_theta - m.rest_dihedral(static_cast<int>(e))));
      double& first_area = level == 1 ? r.fine_area : r.coarse_area;
      if (cycle == 0) {
        first_area = rest_area(m);
        first_volume[level] = rest_volume(m);
        (level == 1 ? r.fine_faces : r.coarse_faces) = live_faces(m);
        continue;
      }
      r.area_drift = std::max(r.area_drift, std::abs(rest_area(m) / first_area - 1));
      r.volume_drift = std::max(r.volume_drift, std::abs(rest_volume(m) / first_volume[level] - 1));
    }
  }
  return r;
}

void check_sphere(int cycles) {
  const double R = 1;
  const Mesh sphere = make_icosphere(R, 2);  // edges ~0.3
  std::vector<Vec3> points;
  for (const Vert& v : sphere.verts) points.push_back(v.u);
  const auto ref = make_sphere_reference(points);
  const CycleResult r = run_cycles(sphere, *ref, 0.3, 0.12, cycles, [](const Vec3& c) { return c; });
  EXPECT_LT(r.max_off_reference, 1e-9);
  EXPECT_LT(r.max_rest_angle_error, 1e-9);
  EXPECT_LT(r.area_drift, 1e-3);
  EXPECT_LT(r.volume_drift, 1e-3);
  EXPECT_GT(r.fine_faces, 3 * r.coarse_faces);
  // Inscribed in the sphere, within the chord error of its edges (a few % of the area at 0.3 m edges).
  EXPECT_LT(r.coarse_area, 4 * kPi * R * R);
  EXPECT_GT(r.coarse_area, 0.95 * 4 * kPi * R * R);
}

void check_cylinder(int cycles) {
  // The reference is a fine tube (chord error 0.05%) containing every node of the coarse input tube.
  const Mesh tube = make_cylinder(1.0, 2.0, 24, 8);  // edges ~0.26
  const auto ref = make_mesh_reference(make_cylinder(1.0, 2.0, 96, 32));
  const CycleResult r =
      run_cycles(tube, *ref, 0.3, 0.12, cycles, [](const Vec3& c) { return Vec3(c.x(), c.y(), 0); });
  EXPECT_LT(r.max_off_reference, 1e-9);
  EXPECT_LT(r.max_rest_angle_error, 1e-9);
  EXPECT_LT(r.area_drift, 1e-3);
  EXPECT_GT(r.fine_faces, 3 * r.coarse_faces);
  // Inscribed in the cylinder, within the chord error of its edges.
  EXPECT_LT(r.coarse_area, 2 * kPi * 2.0);
  EXPECT_GT(r.coarse_area, 0.97 * 2 * kPi * 2.0);
}

TEST(ShapeCycles, SphereKeepsItsShape) { check_sphere(2); }
TEST(ShapeCycles, CylinderKeepsItsShape) { check_cylinder(2); }
TEST(ShapeCyclesSlow, SphereKeepsItsShapeOver100Cycles) { check_sphere(100); }
TEST(ShapeCyclesSlow, CylinderKeepsItsShapeOver100Cycles) { check_cylinder(100); }

}  // namespace
}  // namespace arcsim
