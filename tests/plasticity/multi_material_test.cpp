// Multi-material remeshing (issue 6 acceptance 3, paper Fig. 2): a rigid-ish elastic glass pane inside an
// aluminium frame that is bent and stretched plastically. Through refinement, coarsening and flips, with either
// plastic transfer, every pane face keeps Fp = I and Sp = 0 exactly, while the frame keeps its plasticity.
// (One refine / coarsen cycle: flips run inside both passes.)
#include <gtest/gtest.h>

#include "plasticity/plastic_embedding.hpp"
#include "plasticity/plastic_tensors.hpp"
#include "remesh/remesh.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

constexpr int kFrame = 0, kPane = 1;

std::vector<Material> frame_and_pane() {
  Material aluminium;
  aluminium.name = "aluminium";
  aluminium.thickness = 1e-3;
  aluminium.density = 2700;
  aluminium.youngs_modulus = 70e9;
  aluminium.poisson_ratio = 0.33;
  aluminium.yield_curv = 5;      // bending plasticity
  aluminium.yield_stress = 1e8;  // and stretching plasticity
  aluminium.flow_rate = 1e-7;
  Material glass;
  glass.name = "glass";
  glass.thickness = 4e-3;
  glass.density = 2500;
  glass.youngs_modulus = 70e9;
  glass.poisson_ratio = 0.22;
  return {aluminium, glass};
}

// 0.6 m square of 0.15 m cells; the middle 2 x 2 cells are glass.
Mesh framed_pane(const std::vector<Material>& materials) {
  Mesh m = testing::make_grid(4, 4, 0.6, 0.6, testing::Diagonal::kAlternating);
  for (size_t f = 0; f < m.faces.size(); ++f) {
    Face& face = m.faces[f];
    Vec3 c = Vec3::Zero();
    for (int v : face.v) c += m.verts[v].u / 3;
    const bool pane = c.x() > 0.15 && c.x() < 0.45 && c.y() > 0.15 && c.y() < 0.45;
    face.material = pane ? kPane : kFrame;
    face.thickness = materials[face.material].thickness;
    if (pane) continue;
    // Plastic frame: bent about y (2 1/m) and stretched 5% along x, the world folded to match the bend.
    face.Sp = 2.0 * Vec3::UnitX() * Vec3::UnitX().transpose();
    face.Fp = face_plastic_stretch_3d(face, Mat2(Vec2(1 / 1.05, 1.0).asDiagonal()));
  }
  update_edge_rest_angles_from_Sp(m, {});
  for (Node& n : m.nodes) {
    const double x = n.x.x() - 0.3, radius = 0.5;
    n.x = Vec3(0.3 + radius * std::sin(x / radius), n.x.y(), radius * (1 - std::cos(x / radius)));
    n.x0 = n.x;
  }
  return m;
}

struct Census {
  int pane = 0, frame = 0, plastic_frame = 0, pane_not_exact = 0;
};

Census census(const Mesh& m) {
  Census c;
  for (const Face& f : m.faces) {
    if (f.dead) continue;
    if (f.material == kPane) {
      ++c.pane;
      if (!f.Fp.isIdentity(0) || !f.Sp.isZero(0)) ++c.pane_not_exact;
    } else {
      ++c.frame;
      if (!f.Fp.isIdentity(0) && !f.Sp.isZero(0)) ++c.plastic_frame;
    }
  }
  return c;
}

TEST(MultiMaterial, PaneStaysExactlyElasticThroughRemeshing) {
  const std::vector<Material> materials = frame_and_pane();
  for (bool embedding : {true, false}) {
    SCOPED_TRACE(embedding ? "embedding" : "interpolate");
    Mesh m = framed_pane(materials);
    const Census before = census(m);
    ASSERT_EQ(before.pane, 8);
    ASSERT_EQ(before.plastic_frame, before.frame);
    RemeshOptions o;
    o.sizing.remeshing.size_min = 0.08;
    o.sizing.remeshing.size_max = 0.2;
    o.sizing.remeshing.plastic_embedding = embedding;
    o.max_surface_change = 0;
    int max_pane = 0, passes = 0;
    for (int cycle = 0; cycle < 1; ++cycle) {
      for (double size : {0.08, 0.2}) {
        o.extras.uniform_size = size;
        const RemeshStats stats = remesh_mesh(m, materials, o);
        m.compact();
        ++passes;
        EXPECT_GT(stats.splits + stats.collapses, 0);
        const Census c = census(m);
        max_pane = std::max(max_pane, c.pane);
        EXPECT_EQ(c.pane_not_exact, 0) << "pass " << passes << ": pane faces with Fp != I or Sp != 0";
        EXPECT_GT(c.pane, 0);
        // The frame keeps its plasticity (no face of it loses both tensors to the pane).
        EXPECT_GT(c.plastic_frame, c.frame * 9 / 10) << "pass " << passes;
      }
    }
    EXPECT_GT(max_pane, 2 * before.pane);  // the pane itself was refined
  }
}

}  // namespace
}  // namespace arcsim
