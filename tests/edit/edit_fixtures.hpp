// A plastically bent, curved-rest sheet for the edit session's tests: rest shape a cylinder patch of radius 1,
// world shape the same sheet rolled (arc length kept) onto a cylinder of radius 0.6 and stretched 1% along the
// axis, with Fp, Sp and the edges' rest angles set so that the world is exactly the plastic shape: every face's
// elastic strain F Fp is a rotation and every interior edge's rest angle is its world dihedral.
#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>

#include "mesh/mesh_fixtures.hpp"
#include "physics/material.hpp"
#include "plasticity/plastic_fixtures.hpp"
#include "plasticity/plastic_tensors.hpp"

namespace arcsim::test {

struct BentSheet {
  Mesh mesh;
  std::vector<Material> materials;
  double world_radius = 0;  // m, axis along y through the origin
};

inline BentSheet make_plastically_bent_sheet(int nx, int ny) {
  const double rest_radius = 1.0, angle = 1.2, height = 0.8, world_radius = 0.6, stretch = 1.01;
  BentSheet s;
  s.world_radius = world_radius;
  s.materials = {testing::aluminium_sheet(1.0)};
  s.mesh = make_cylinder_patch(nx, ny, rest_radius, angle, height);
  Mesh& m = s.mesh;
  for (Face& f : m.faces) f.thickness = s.materials[0].thickness;
  for (Node& n : m.nodes) {
    const double phi = std::atan2(n.x.x(), n.x.z()) * rest_radius / world_radius;
    n.x = Vec3(world_radius * std::sin(phi), stretch * n.x.y(), world_radius * std::cos(phi));
    n.x0 = n.x;
    n.v.setZero();
    n.a.setZero();
  }
  for (size_t e = 0; e < m.edges.size(); ++e) {
    const int ei = static_cast<int>(e);
    m.edges[e].rest_theta = m.edges[e].is_boundary() ? m.rest_dihedral(ei) : m.world_dihedral(ei);
  }
  for (size_t fi = 0; fi < m.faces.size(); ++fi) {
    Face& f = m.faces[fi];
    const int fidx = static_cast<int>(fi);
    const Vec3 x0 = m.nodes[m.face_node(fidx, 0)].x;
    Mat32 Dx;
    Dx << m.nodes[m.face_node(fidx, 1)].x - x0, m.nodes[m.face_node(fidx, 2)].x - x0;
    const Mat32 F = Dx * f.Dm_inv;
    const Eigen::SelfAdjointEigenSolver<Mat2> eig(F.transpose() * F);
    const Mat2 Fp2 = eig.operatorInverseSqrt();
    f.Fp = face_plastic_stretch_3d(f, Fp2);
    Vec3 offsets;
    for (int i = 0; i < 3; ++i) offsets[i] = m.edges[f.e[i]].rest_theta - m.rest_dihedral(f.e[i]);
    f.Sp = face_bending_strain_from_offsets(m, fidx, offsets);
  }
  return s;
}

// Distance (m) of a world point from the world cylinder's axis.
inline double distance_from_axis(const Vec3& x) { return std::hypot(x.x(), x.z()); }

}  // namespace arcsim::test
