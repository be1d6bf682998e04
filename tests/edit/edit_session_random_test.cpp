// Randomised sequences of thousands of edits through the edit session on a plastically bent, curved-rest sheet:
// remeshing edits (split, flip, collapse) mixed with vertex splits at interior and boundary nodes, cracks
// meeting cracks and the border, with check_mesh() after every edit and a fresh session after each
// compaction. Deterministic: fixed seeds.
#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "edit/edit_fixtures.hpp"
#include "edit/edit_session.hpp"
#include "mesh/validate.hpp"
#include "restshape/reference_surface.hpp"

namespace arcsim {
namespace {

struct Counts {
  int split = 0, flip = 0, collapse = 0, refused = 0;
  int interior_node_split = 0, boundary_node_split = 0, meets_boundary = 0;
};

int random_live_node(const Mesh& m, std::mt19937& rng) {
  std::uniform_int_distribution<int> pick(0, static_cast<int>(m.nodes.size()) - 1);
  for (int tries = 0; tries < 1000; ++tries) {
    const int i = pick(rng);
    if (!m.nodes[i].dead) return i;
  }
  return kNone;
}

int random_live_edge(const Mesh& m, std::mt19937& rng) {
  std::uniform_int_distribution<int> pick(0, static_cast<int>(m.edges.size()) - 1);
  for (int tries = 0; tries < 1000; ++tries) {
    const int i = pick(rng);
    if (!m.edges[i].dead) return i;
  }
  return kNone;
}

int live_faces(const Mesh& m) {
  int n = 0;
  for (const Face& f : m.faces) n += !f.dead;
  return n;
}

Counts run(unsigned seed, int steps, double node_split_rate) {
  std::mt19937 rng(seed);
  test::BentSheet sheet = test::make_plastically_bent_sheet(8, 6);
  Mesh& m = sheet.mesh;
  const std::unique_ptr<ReferenceSurface> reference = make_mesh_reference(m);
  EditSessionOptions options;
  options.reference = reference.get();
  std::unique_ptr<EditSession> session = std::make_unique<EditSession>(m, sheet.materials, options);
  EXPECT_EQ(check_mesh(m), "");
  std::uniform_real_distribution<double> unit(0, 1);
  Counts c;
  for (int step = 0; step < steps; ++step) {
    const uint64_t before = test::fingerprint(m);
    const int faces = live_faces(m);
    const double dice = unit(rng);
    std::string op;
    EditResult r;
    if (dice < node_split_rate) {
      const int node = random_live_node(m, rng);
      std::vector<int> cuts;
      for (int e : m.nodes[node].edges)
        if (!m.edges[e].is_boundary()) cuts.push_back(e);
      std::shuffle(cuts.begin(), cuts.end(), rng);
      const bool interior = !m.is_boundary_node(node);
      const size_t wanted = interior ? 2 : (cuts.size() >= 2 && unit(rng) < 0.3 ? 2 : 1);
      if (cuts.size() < wanted) continue;
      cuts.resize(wanted);
      bool meets = false;
      for (int e : cuts) meets |= m.is_boundary_node(m.edges[e].n[0] == node ? m.edges[e].n[1] : m.edges[e].n[0]);
      op = "split_node";
      r = session->split_node(node, cuts);
      if (!r.ok) {
        ADD_FAILURE() << "split_node refused a valid request at step " << step << " (seed " << seed << ")";
        return c;
      }
      (interior ? c.interior_node_split : c.boundary_node_split) += 1;
      c.meets_boundary += meets;
    } else if (dice < node_split_rate + 0.3 && faces < 200) {
      op = "split_edge";
      r = session->split_edge(random_live_edge(m, rng), 0.2 + 0.6 * unit(rng));
      c.split += r.ok;
    } else if (dice < node_split_rate + 0.6) {
      op = "flip_edge";
      r = session->flip_edge(random_live_edge(m, rng));
      c.flip += r.ok;
    } else if (faces > 40) {
      op = "collapse_edge";
      r = session->collapse_edge(random_live_edge(m, rng), unit(rng) < 0.5 ? 0 : 1);
      c.collapse += r.ok;
    } else {
      continue;
    }
    std::ostringstream where;
    where << op << " at step " << step << " (seed " << seed << ")";
    if (!r.ok) {
      ++c.refused;
      if (test::fingerprint(m) != before) {
        ADD_FAILURE() << "refused " << where.str() << " changed the mesh";
        return c;
      }
      continue;
    }
    const std::string problem = check_mesh(m);
    if (!problem.empty()) {
      ADD_FAILURE() << where.str() << ": " << problem;
      return c;
    }
    if (session->live_faces() != live_faces(m)) {
      ADD_FAILURE() << where.str() << ": the session counts " << session->live_faces() << " live faces, the mesh has "
                    << live_faces(m);
      return c;
    }
    if (step % 97 == 96) {
      // Compaction renumbers everything a session holds: the next batch of edits gets a new one.
      session.reset();
      m.compact();
      const std::string after = check_mesh(m);
      if (!after.empty()) {
        ADD_FAILURE() << "compact after step " << step << ": " << after;
        return c;
      }
      session = std::make_unique<EditSession>(m, sheet.materials, options);
    }
  }
  return c;
}

TEST(EditSessionRandom, RemeshingEditsMixedWithCracks) {
  for (unsigned seed : {1u, 2u}) {
    const Counts c = run(seed, 2000, 0.04);
    EXPECT_GE(c.split, 100) << "seed " << seed;
    EXPECT_GE(c.flip, 100) << "seed " << seed;
    EXPECT_GE(c.collapse, 100) << "seed " << seed;
    EXPECT_GT(c.refused, 0) << "seed " << seed;
    EXPECT_GE(c.interior_node_split, 5) << "seed " << seed;
    EXPECT_GE(c.boundary_node_split, 5) << "seed " << seed;
    EXPECT_GE(c.meets_boundary, 5) << "seed " << seed;
  }
}

}  // namespace
}  // namespace arcsim
