// Remeshing operators on flat and bent sheets: refinement and coarsening to a target size, flips, preserved
// nodes, subsets, adaptivity to bending, and mesh validity after randomised passes.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "mesh/edits.hpp"
#include "mesh/mesh_fixtures.hpp"
#include "mesh/validate.hpp"
#include "remesh/remesh.hpp"
#include "remesh/remesh_fixtures.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

using remesh_test::cotton;
using remesh_test::live_faces;
using remesh_test::rest_area;
using remesh_test::set_thickness;

RemeshOptions uniform_options(double size) {
  RemeshOptions o;
  o.extras.uniform_size = size;
  return o;
}

double max_rest_edge(const Mesh& m) {
  double l = 0;
  for (const Face& f : m.faces)
    if (!f.dead)
      for (int i = 0; i < 3; ++i) l = std::max(l, (m.verts[f.v[(i + 1) % 3]].u - m.verts[f.v[i]].u).norm());
  return l;
}

// Flat sheets in the z = 0 plane keep every rest normal on +z (no face inverted) and every node at its rest
// position in world space (world = rest, so reprojection must not move anything).
void expect_flat_and_valid(const Mesh& m, const std::string& when) {
  EXPECT_EQ(check_mesh(m), "") << when;
  for (const Face& f : m.faces) {
    if (f.dead) continue;
    EXPECT_GT(f.rest_normal.z(), 0.99) << when;
    EXPECT_GT(f.rest_area, 0) << when;
  }
}

TEST(Remesh, RefinesAFlatSheetToTheUniformSize) {
  Mesh m = testing::make_grid(4, 4, 1.0, 1.0);
  const std::vector<Material> materials{cotton()};
  set_thickness(m, materials[0]);
  const RemeshStats s = remesh_mesh(m, materials, uniform_options(0.1));
  expect_flat_and_valid(m, "after refinement");
  EXPECT_GT(s.splits, 100);
  EXPECT_LE(max_rest_edge(m), 0.1 * (1 + 1e-9));
  EXPECT_NEAR(rest_area(m), 1.0, 1e-12);
  for (const Node& n : m.nodes) {
    if (n.dead) continue;
    EXPECT_LT((n.x - m.verts[n.verts[0]].u).norm(), 1e-12);  // world stays at rest
    EXPECT_TRUE(n.x.allFinite() && n.v.allFinite());
  }
  for (const Vert& v : m.verts) {
    if (v.dead) continue;
    EXPECT_TRUE(v.sizing.allFinite());
  }
}

TEST(Remesh, CoarsensBackKeepingTheOutline) {
  Mesh m = testing::make_grid(20, 20, 1.0, 1.0, testing::Diagonal::kAlternating);
  const std::vector<Material> materials{cotton()};
  set_thickness(m, materials[0]);
  const int before = live_faces(m);
  const RemeshStats s = remesh_mesh(m, materials, uniform_options(0.3));
  expect_flat_and_valid(m, "after coarsening");
  EXPECT_GT(s.collapses, 200);
  EXPECT_LT(live_faces(m), before / 8);
  EXPECT_NEAR(rest_area(m), 1.0, 1e-12);
  // The corners are not on a straight piece of the boundary: they stay.
  for (const Vec3& corner : {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)}) {
    bool found = false;
    for (const Node& n : m.nodes) found = found || (!n.dead && (n.x - corner).norm() < 1e-12);
    EXPECT_TRUE(found) << corner.transpose();
  }
}

TEST(Remesh, PreservedAndLabelledNodesSurvive) {
  Mesh m = testing::make_grid(12, 12, 1.0, 1.0);
  const std::vector<Material> materials{cotton()};
  set_thickness(m, materials[0]);
  const int preserved = 6 * 13 + 6, labelled = 3 * 13 + 3;
  m.nodes[preserved].preserve = true;
  m.nodes[labelled].label = 4;
  const Vec3 xp = m.nodes[preserved].x, xl = m.nodes[labelled].x;
  remesh_mesh(m, materials, uniform_options(0.5));
  EXPECT_FALSE(m.nodes[preserved].dead);
  EXPECT_FALSE(m.nodes[labelled].dead);
  EXPECT_EQ(m.nodes[preserved].x, xp);  // preserved nodes are not reprojected either
  EXPECT_LT((m.nodes[labelled].x - xl).norm(), 1e-12);
  EXPECT_EQ(check_mesh(m), "");
}

TEST(Remesh, SubsetLeavesFarFacesAlone) {
  Mesh m = testing::make_grid(8, 8, 1.0, 1.0);
  const std::vector<Material> materials{cotton()};
  set_thickness(m, materials[0]);
  std::vector<int> left;
  for (size_t f = 0; f < m.faces.size(); ++f) {
    const Face& face = m.faces[f];
    const double cx = (m.verts[face.v[0]].u.x() + m.verts[face.v[1]].u.x() + m.verts[face.v[2]].u.x()) / 3;
    if (cx < 0.3) left.push_back(static_cast<int>(f));
  }
  const Mesh before = m;
  const RemeshStats s = remesh_mesh(m, materials, uniform_options(0.04), &left);
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_GT(s.splits, 50);
  // Faces entirely right of x = 0.5 are untouched (same index, alive, same corners).
  for (size_t f = 0; f < before.faces.size(); ++f) {
    const Face& face = before.faces[f];
    bool right = true;
    for (int i = 0; i < 3; ++i) right = right && before.verts[face.v[i]].u.x() > 0.5 - 1e-12;
    if (!right) continue;
    EXPECT_FALSE(m.faces[f].dead) << f;
    EXPECT_EQ(m.faces[f].v, face.v) << f;
  }
  // The active faces reported are live and on the left.
  for (int f : s.active_faces) {
    ASSERT_FALSE(m.faces[f].dead);
    EXPECT_LT(m.verts[m.faces[f].v[0]].u.x(), 0.5);
  }
}

TEST(Remesh, FlipTestFollowsTheMetric) {
  // A rhombus with the long diagonal as its edge violates the isotropic Delaunay criterion; in a metric that
  // shrinks that direction 10-fold it does not.
  std::vector<Vec3> p{{0, 0, 0}, {2, 0, 0}, {1, 0.4, 0}, {1, -0.4, 0}};
  Mesh m = Mesh::from_triangles(p, p, {0, 1, 2, 3}, {{0, 1, 2}, {1, 0, 3}});
  const int diagonal = m.find_edge(0, 1);
  for (Vert& v : m.verts) v.sizing = Mat3::Identity();
  EXPECT_TRUE(should_flip(m, diagonal, 1e-2));
  for (Vert& v : m.verts) v.sizing = Vec3(0.01, 1, 1).asDiagonal();
  EXPECT_FALSE(should_flip(m, diagonal, 1e-2));
  // After the flip the new edge is Delaunay (no flip back).
  for (Vert& v : m.verts) v.sizing = Mat3::Identity();
  ASSERT_TRUE(flip_edge(m, diagonal).ok);
  EXPECT_FALSE(should_flip(m, m.find_edge(2, 3), 1e-2));
  // A sharply folded quad is not flipped: lift the wings 60 degrees up.
  Mesh folded = Mesh::from_triangles(p, p, {0, 1, 2, 3}, {{0, 1, 2}, {1, 0, 3}});
  folded.nodes[2].x = Vec3(1, 0.2, 0.35);
  folded.nodes[3].x = Vec3(1, -0.2, 0.35);
  for (Vert& v : folded.verts) v.sizing = Mat3::Identity();
  EXPECT_FALSE(should_flip(folded, folded.find_edge(0, 1), 1e-2));
}

TEST(Remesh, RefinesWhereTheSheetBends) {
  // Flat rest sheet; in world space flat for x < 0.4 and x > 0.6 with a 90 degree bend of radius 0.2/(pi/2)
  // between. With refine_angle 0.1 only the bend asks for small edges.
  Mesh m = testing::make_grid(10, 5, 1.0, 0.5);
  const std::vector<Material> materials{cotton()};
  set_thickness(m, materials[0]);
  const double R = 0.2 / (M_PI / 2);
  auto bend = [&](const Vec3& u) -> Vec3 {
    if (u.x() <= 0.4) return Vec3(u.x(), u.y(), 0);
    if (u.x() >= 0.6) return Vec3(0.4 + R, u.y(), R + (u.x() - 0.6));
    const double phi = (u.x() - 0.4) / R;
    return Vec3(0.4 + R * std::sin(phi), u.y(), R * (1 - std::cos(phi)));
  };
  for (Node& n : m.nodes) n.x = n.x0 = bend(m.verts[n.verts[0]].u);
  RemeshOptions o;
  o.sizing.remeshing.refine_angle = 0.1;
  o.sizing.remeshing.size_min = 0.005;
  o.sizing.remeshing.size_max = 0.5;
  o.sizing.remeshing.aspect_min = 0.2;
  o.reproject = false;  // the bent sheet is not in equilibrium; keep the geometry exact for the measurement
  // Between passes the world shape is put back on the smooth bend, as the physics would keep it (new nodes
  // start on the chords of the coarser mesh).
  for (int pass = 0; pass < 4; ++pass) {
    remesh_mesh(m, materials, o);
    ASSERT_EQ(check_mesh(m), "");
    m.compact();
    for (Node& n : m.nodes) n.x = n.x0 = bend(m.verts[n.verts[0]].u);
  }
  double bend_sum = 0, flat_sum = 0;
  int bend_count = 0, flat_count = 0;
  for (const Edge& e : m.edges) {
    const Vec3 mid = 0.5 * (m.verts[m.nodes[e.n[0]].verts[0]].u + m.verts[m.nodes[e.n[1]].verts[0]].u);
    const double l = (m.nodes[e.n[1]].x - m.nodes[e.n[0]].x).norm();
    if (mid.x() > 0.45 && mid.x() < 0.55) {
      bend_sum += l;
      ++bend_count;
    } else if (mid.x() < 0.3 || mid.x() > 0.7) {
      flat_sum += l;
      ++flat_count;
    }
  }
  ASSERT_GT(bend_count, 0);
  ASSERT_GT(flat_count, 0);
  // Flat parts stay coarse, the bend is refined until the bending angle per edge is about refine_angle (the
  // initial 10 cm grid bends up to 0.5 rad per edge there).
  EXPECT_GT(flat_sum / flat_count, 0.1);
  EXPECT_LT(bend_sum / bend_count, 0.05);
  double max_angle = 0;
  for (size_t e = 0; e < m.edges.size(); ++e)
    max_angle = std::max(max_angle, std::abs(m.world_dihedral(static_cast<int>(e))));
  EXPECT_LT(max_angle, 0.12);
}

TEST(Remesh, SeamedTubeStaysValid) {
  Mesh m = test::make_seamed_tube(8, 3, 0.2, 0.5);
  const std::vector<Material> materials{cotton()};
  set_thickness(m, materials[0]);
  remesh_mesh(m, materials, uniform_options(0.06));
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_LE(max_rest_edge(m), 0.06 * (1 + 1e-9));
  remesh_mesh(m, materials, uniform_options(0.3));
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_NEAR(rest_area(m), 2 * M_PI * 0.2 * 0.5, 1e-12);  // the unrolled rectangle
}

// Randomised: flat sheets with random world deformation, velocities and per-face metrics, several passes with
// compaction in between. After every pass the mesh is valid (check_mesh: topology, positive rest areas,
// current rest data, finite state), no face is inverted in rest space, and every vert has a finite metric.
TEST(Remesh, RandomisedPassesKeepTheMeshValid) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> unit(0, 1), sym(-1, 1);
  const std::vector<Material> materials{cotton()};
  for (int trial = 0; trial < 4; ++trial) {
    Mesh m = testing::make_grid(4 + trial % 3, 5, 1.0, 0.8, testing::Diagonal::kAlternating);
    set_thickness(m, materials[0]);
    for (Node& n : m.nodes) {
      n.x += 0.02 * Vec3(sym(rng), sym(rng), sym(rng));
      n.x0 = n.x;
      n.v = Vec3(sym(rng), sym(rng), sym(rng));
      n.a = Vec3(sym(rng), sym(rng), sym(rng));
    }
    for (int pass = 0; pass < 5; ++pass) {
      RemeshOptions o;
      o.sizing.remeshing.size_min = 0.04;
      o.sizing.remeshing.size_max = 0.05 + 0.4 * unit(rng);
      o.sizing.remeshing.aspect_min = 0.2;
      o.sizing.remeshing.refine_angle = 0.3;
      o.sizing.remeshing.refine_velocity = 2 + 10 * unit(rng);
      o.sizing.remeshing.refine_compression = 0.01;
      std::vector<Mat3> extra(m.faces.size());
      const Vec3 dir(std::cos(7.0 * pass), std::sin(7.0 * pass), 0);
      for (Mat3& e : extra) e = (unit(rng) < 0.3 ? 400.0 * unit(rng) : 0.0) * dir * dir.transpose();
      o.extras.face_terms = &extra;
      const RemeshStats st = remesh_mesh(m, materials, o);
      EXPECT_GT(st.splits + st.collapses, 0);
      const std::string where = "trial " + std::to_string(trial) + " pass " + std::to_string(pass);
      ASSERT_EQ(check_mesh(m), "") << where;
      for (const Face& f : m.faces) {
        if (f.dead) continue;
        ASSERT_GT(f.rest_normal.z(), 0.99) << where;
      }
      for (const Vert& v : m.verts) {
        if (v.dead) continue;
        ASSERT_TRUE(v.sizing.allFinite()) << where;
      }
      m.compact();
      ASSERT_EQ(check_mesh(m), "") << where << " after compact";
      EXPECT_NEAR(rest_area(m), 0.8, 1e-12) << where;
    }
  }
}

// Collapse rounds ask again only edges whose neighbourhood changed since they were turned down; the mesh must
// come out exactly as when every round asks every edge. Bumpy, moving sheets coarsened and refined in turns
// (the world shape and the velocities feed the collapse tests), with and without a subset.
TEST(Remesh, RememberedRefusedCollapsesGiveTheSameMesh) {
  std::mt19937 rng(777);
  std::uniform_real_distribution<double> unit(0, 1), sym(-1, 1);
  const std::vector<Material> materials{cotton()};
  int collapses = 0;
  for (int trial = 0; trial < 3; ++trial) {
    Mesh m = testing::make_grid(16 + 4 * trial, 14, 1.0, 0.8, testing::Diagonal::kAlternating);
    set_thickness(m, materials[0]);
    for (Node& n : m.nodes) {
      n.x += Vec3(0, 0, 0.05 * std::sin(9 * n.x.x()) * std::cos(7 * n.x.y())) + 0.004 * Vec3(sym(rng), sym(rng), sym(rng));
      n.x0 = n.x;
      n.v = Vec3(sym(rng), sym(rng), sym(rng));
    }
    Mesh reference = m;
    for (int pass = 0; pass < 4; ++pass) {
      RemeshOptions o;
      o.sizing.remeshing.size_min = 0.02;
      o.sizing.remeshing.size_max = pass % 2 == 0 ? 0.3 + 0.2 * unit(rng) : 0.06;
      o.sizing.remeshing.aspect_min = 0.2;
      o.sizing.remeshing.refine_angle = 0.3;
      o.sizing.remeshing.refine_velocity = 1 + 4 * unit(rng);
      o.sizing.remeshing.refine_compression = 0.01;
      std::vector<int> subset;
      for (size_t f = 0; f < m.faces.size(); ++f)
        if (!m.faces[f].dead && unit(rng) < 0.7) subset.push_back(static_cast<int>(f));
      const std::vector<int>* region = trial == 2 ? &subset : nullptr;
      const RemeshStats remembered = remesh_mesh(m, materials, o, region);
      o.remember_refused_collapses = false;
      const RemeshStats asked = remesh_mesh(reference, materials, o, region);
      const std::string where = "trial " + std::to_string(trial) + " pass " + std::to_string(pass);
      ASSERT_EQ(remembered.collapses, asked.collapses) << where;
      ASSERT_EQ(remembered.splits, asked.splits) << where;
      ASSERT_EQ(remembered.flips, asked.flips) << where;
      ASSERT_EQ(m.faces.size(), reference.faces.size()) << where;
      for (size_t f = 0; f < m.faces.size(); ++f) {
        ASSERT_EQ(m.faces[f].dead, reference.faces[f].dead) << where << " face " << f;
        ASSERT_EQ(m.faces[f].v, reference.faces[f].v) << where << " face " << f;
      }
      ASSERT_EQ(m.nodes.size(), reference.nodes.size()) << where;
      for (size_t n = 0; n < m.nodes.size(); ++n) ASSERT_EQ(m.nodes[n].x, reference.nodes[n].x) << where << " node " << n;
      ASSERT_EQ(check_mesh(m), "") << where;
      collapses += remembered.collapses;
      m.compact();
      reference.compact();
    }
  }
  EXPECT_GT(collapses, 150);  // the comparison covered many collapse rounds
}

}  // namespace
}  // namespace arcsim
