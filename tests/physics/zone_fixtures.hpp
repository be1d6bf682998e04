// A sheet for the zone-solve tests and benchmarks: curved rest shape (a cylinder), stretched and waved in world
// space, with stretching plasticity, plastic rest angles and damage on part of it, moving, with two handle
// springs, a pinned node, gravity, air drag and one contact term.
#pragma once

#include <cmath>
#include <vector>

#include "physics/cloth_physics.hpp"
#include "plasticity/plastic_tensors.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim::testing {

inline Material zone_test_material() {
  Material m;
  m.name = "zone-test";
  m.thickness = 5e-4;
  m.density = 1000;
  m.youngs_modulus = 2e8;
  m.poisson_ratio = 0.3;
  m.damping = 2e-4;
  m.weakening = 0.5;
  return m;
}

struct ZoneTestSheet {
  Mesh mesh;
  std::vector<Material> materials{zone_test_material()};
  ExternalLoads loads;
  int cells = 0;

  // cells x cells grid over 1 m x 1 m (2 cells^2 faces).
  explicit ZoneTestSheet(int grid_cells) : cells(grid_cells) {
    mesh = make_grid(cells, cells, 1.0, 1.0, Diagonal::kAlternating);
    // Curved rest shape: the unit square rolled onto a cylinder of radius 1.5 m about the y axis.
    const double radius = 1.5;
    for (Vert& v : mesh.verts) {
      const double s = v.u.x();
      v.u = Vec3(radius * std::sin(s / radius), v.u.y(), radius * (1 - std::cos(s / radius)));
    }
    mesh.update_rest_data();
    for (size_t e = 0; e < mesh.edges.size(); ++e) {
      Edge& edge = mesh.edges[e];
      edge.rest_theta = mesh.rest_dihedral(static_cast<int>(e));
      // Plastic rest angles and damage on part of the sheet.
      const Vec3 mid = 0.5 * (mesh.verts[mesh.nodes[edge.n[0]].verts[0]].u +
                              mesh.verts[mesh.nodes[edge.n[1]].verts[0]].u);
      if (mid.y() < 0.5) {
        edge.rest_theta += 0.05 * std::sin(9 * mid.x());
        edge.damage = 0.3;
      }
    }
    for (size_t f = 0; f < mesh.faces.size(); ++f) {
      Face& face = mesh.faces[f];
      face.thickness = materials[0].thickness;
      const Vec3 c = (mesh.verts[face.v[0]].u + mesh.verts[face.v[1]].u + mesh.verts[face.v[2]].u) / 3;
      if (c.x() > 0.4) {
        Mat2 Fp2;
        Fp2 << 1.0 / (1.03 + 0.02 * c.y()), 0.01, 0.01, 1.0 / 0.98;
        face.Fp = face_plastic_stretch_3d(face, Fp2);
        face.damage = 0.2 * c.y();
      }
    }
    // World: the rest shape stretched by 2% / 1%, waved, and moving.
    for (Node& n : mesh.nodes) {
      const Vec3& u = mesh.verts[n.verts[0]].u;
      n.x = Vec3(1.02 * u.x(), 1.01 * u.y(), u.z() + 0.01 * std::sin(6 * u.x()) * std::cos(4 * u.y()));
      n.x0 = n.x;
      n.v = Vec3(0.05 * std::cos(3 * u.y()), -0.02 * u.x(), 0.1 * std::sin(5 * u.x() + 2 * u.y()));
    }
    update_node_masses(mesh, materials);
    loads.gravity = Vec3(0, 0, -9.81);
    loads.wind.density = 1.2;
    loads.wind.velocity = Vec3(1, 0, 0.5);
    loads.wind.drag = 0.1;
    const int corner = cells;  // node (cells, 0)
    loads.springs.push_back({0, mesh.nodes[0].x + Vec3(0, 0, 0.01), 500});
    loads.springs.push_back({corner, mesh.nodes[corner].x, 500});
    loads.pinned.assign(mesh.nodes.size(), 0);
    loads.pinned[node_at(cells / 2, cells - 1)] = 1;
    ContactTerm contact;
    const int middle = cells / 2;
    contact.nodes = {node_at(middle, middle), node_at(middle + 1, middle), node_at(middle, middle + 1), kNone};
    contact.weights = {0.5, 0.3, 0.2, 0};
    contact.normal = Vec3(0.1, 0.2, 1).normalized();
    contact.force = 0.05;
    contact.stiffness = 200;
    contact.friction_damping = 0.3;
    contact.outside_velocity = Vec3(0.01, 0, -0.02);
    loads.contacts.push_back(contact);
  }

  // Node at grid column i, row j (make_grid numbers nodes row by row).
  int node_at(int i, int j) const { return j * (cells + 1) + i; }
};

}  // namespace arcsim::testing
