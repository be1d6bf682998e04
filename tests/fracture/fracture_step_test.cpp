// Fracture substepping's inputs from the rest of the step (fracture/fracture_step.hpp): nodes that the collision
// response moved by a fallback (FractureContext::untrusted_nodes) neither break nor seed a zone, and nodes away
// from them still do.
#include <gtest/gtest.h>

#include <vector>

#include "fracture/fracture_step.hpp"
#include "fracture/fracture_stress.hpp"
#include "fracture/separation_strength.hpp"
#include "mesh/validate.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

constexpr double kLength = 0.08, kWidth = 0.04;  // m

// An 8 x 4 cell sheet stretched along x by 3% (Green strain 3.0%, three times tau / E = 1%), its end columns
// pinned, so that the stretch survives the virtual update.
struct StretchedSheet {
  Mesh mesh;
  std::vector<Material> materials;
  FractureContext context;
  StretchedSheet() {
    Material m;
    m.thickness = 1e-3;
    m.density = 1000;
    m.youngs_modulus = 1e9;
    m.poisson_ratio = 0;
    m.toughness = 1e7;
    materials = {m};
    mesh = testing::make_grid(8, 4, kLength, kWidth, testing::Diagonal::kAlternating);
    for (Face& f : mesh.faces) f.thickness = m.thickness;
    context.dt = 1e-3;
    context.loads.pinned.assign(mesh.nodes.size(), 0);
    for (size_t n = 0; n < mesh.nodes.size(); ++n) {
      Node& node = mesh.nodes[n];
      const double u = node.x.x();
      node.x.x() *= 1.03;
      node.x0 = node.x;
      if (u < 1e-9 || u > kLength - 1e-9) context.loads.pinned[n] = 1;
    }
    update_node_masses(mesh, materials);
  }
  FractureStats fracture(const std::vector<int>& untrusted) {
    context.untrusted_nodes = untrusted;
    CholeskySolver solver;
    return fracture_step(mesh, materials, FractureParams(), context, solver);
  }
  std::vector<int> nodes_where(bool (*keep)(const Vec3&)) const {
    std::vector<int> out;
    for (size_t n = 0; n < mesh.nodes.size(); ++n)
      if (keep(mesh.nodes[n].x / 1.03)) out.push_back(static_cast<int>(n));
    return out;
  }
};

// The nodes of a fresh stretched sheet, at rest positions u where keep(u), whose separation strength exceeds tau.
int breaking_nodes_where(bool (*keep)(const Vec3&)) {
  StretchedSheet s;
  const std::vector<FaceFractureStress> stress = fracture_stresses(s.mesh, s.materials);
  int count = 0;
  for (int n : s.nodes_where(keep)) count += node_separation(s.mesh, s.materials, n, stress).breaks() ? 1 : 0;
  return count;
}

TEST(FractureStep, AStretchedSheetCracks) {
  StretchedSheet s;
  const FractureStats stats = s.fracture({});
  EXPECT_EQ(stats.candidates, breaking_nodes_where([](const Vec3&) { return true; }));
  EXPECT_GT(stats.cracks, 0);
  EXPECT_EQ(check_mesh(s.mesh), "");
}

TEST(FractureStep, NodesMovedByACollisionFallbackNeitherBreakNorSeedAZone) {
  StretchedSheet s;
  const int nodes = static_cast<int>(s.mesh.nodes.size());
  const FractureStats stats = s.fracture(s.nodes_where([](const Vec3&) { return true; }));
  EXPECT_EQ(stats.candidates, 0);
  EXPECT_EQ(stats.cracks, 0);
  EXPECT_EQ(static_cast<int>(s.mesh.nodes.size()), nodes);  // untouched
}

TEST(FractureStep, NodesAwayFromTheFallbackStillBreak) {
  StretchedSheet s;
  // The left half and, through the 1-ring, one more column are excluded; the right three columns are not.
  const std::vector<int> left = s.nodes_where([](const Vec3& u) { return u.x() < 0.5 * kLength - 1e-9; });
  const FractureStats stats = s.fracture(left);
  // Columns 0-3 and their 1-ring, column 4, are out; the breaking nodes of columns 5-8 (x >= 0.05 m) remain.
  EXPECT_EQ(stats.candidates, breaking_nodes_where([](const Vec3& u) { return u.x() > 0.05 - 1e-9; }));
  EXPECT_GT(stats.cracks, 0);
  EXPECT_EQ(check_mesh(s.mesh), "");
  // Every node of the left half keeps the faces it had: none of them was split.
  StretchedSheet fresh;
  for (int n : left) {
    const double u = fresh.mesh.nodes[n].x.x() / 1.03;
    if (u > 0.5 * kLength - 0.02) continue;  // the cut may cross faces of nodes within a cell of the border
    EXPECT_EQ(s.mesh.node_faces(n).size(), fresh.mesh.node_faces(n).size()) << "node " << n;
  }
}

}  // namespace
}  // namespace arcsim
