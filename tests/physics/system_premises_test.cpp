// When the implicit system fails to factorise, the error names what broke the construction's premises (a node
// without mass, an element, a contact) or, if all hold, the element that is too stiff against its masses.
#include <gtest/gtest.h>

#include <string>

#include "io/errors.hpp"
#include "physics/cloth_physics.hpp"
#include "physics/system_premises.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

Material sheet_material(double youngs_modulus) {
  Material m;
  m.thickness = 1e-3;
  m.density = 800;
  m.youngs_modulus = youngs_modulus;
  m.poisson_ratio = 0.3;
  return m;
}

struct Sheet {
  Mesh mesh;
  std::vector<Material> materials;
  ElementCache cache;
  CholeskySolver solver;
  Sheet(Mesh m, double youngs_modulus) : mesh(std::move(m)), materials{sheet_material(youngs_modulus)} {
    for (Face& f : mesh.faces) f.thickness = materials[0].thickness;
    update_node_masses(mesh, materials);
  }
  void build() { build_element_cache(mesh, materials, cache); }
};

std::string step_error(Sheet& s, const ExternalLoads& loads, double dt) {
  try {
    implicit_euler_step(s.mesh, s.cache, s.solver, loads, dt);
  } catch (const NumericalError& e) {
    return e.what();
  }
  return "";
}

// A node that belongs to no face has no mass and no stiffness: its rows are zero, and the error names it.
TEST(SystemPremises, ANodeWithoutMassIsNamed) {
  Sheet s(testing::make_grid(3, 3, 0.1, 0.1), 1e6);
  Node lone;
  lone.x = Vec3(1, 1, 1);
  s.mesh.nodes.push_back(lone);
  s.build();
  const std::string error = step_error(s, ExternalLoads(), 1e-3);
  const std::string node = "node " + std::to_string(s.mesh.nodes.size());
  EXPECT_NE(error.find("not positive definite"), std::string::npos) << error;
  EXPECT_NE(error.find(node + " has mass 0 kg (it belongs to no face)"), std::string::npos) << error;
}

// Contacts with a negative stiffness break the premise; the explanation names the contact's nodes.
TEST(SystemPremises, AContactWithNegativeStiffnessIsNamed) {
  Sheet s(testing::make_grid(3, 3, 0.1, 0.1), 1e6);
  s.build();
  ExternalLoads loads;
  ContactTerm c;
  c.nodes = {4, kNone, kNone, kNone};
  c.weights = {1, 0, 0, 0};
  c.normal = Vec3::UnitZ();
  c.stiffness = -1e9;
  loads.contacts.push_back(c);
  update_contact_pattern(s.cache, loads.contacts);
  const std::string error = step_error(s, loads, 1e-2);
  EXPECT_NE(error.find("contact of nodes 5 0 0 0 has stiffness -1e+09 N/m"), std::string::npos) << error;
}

// Every premise holds, but a sheet so stiff that dt^2 K / m is ~1e21 cannot be factorised in double precision:
// the explanation says so and names the stiffest element against its masses.
TEST(SystemPremises, AnIllConditionedSystemNamesItsStiffestElement) {
  Sheet s(testing::make_grid(4, 4, 0.1, 0.1), 1e26);
  s.build();
  for (Node& n : s.mesh.nodes) n.x += Vec3(0.01 * n.x.y() * n.x.y(), 0.003 * n.x.x(), 0.02 * n.x.x() * n.x.y());
  const std::string error = step_error(s, ExternalLoads(), 1e-2);
  ASSERT_FALSE(error.empty()) << "the step did not fail";
  EXPECT_NE(error.find("every premise holds"), std::string::npos) << error;
  EXPECT_NE(error.find("the stiffest against its masses: membrane element of nodes"), std::string::npos) << error;
  EXPECT_NE(error.find("the factorisation stopped at node "), std::string::npos) << error;
  // And the same sheet at an ordinary stiffness passes the premises and factorises.
  Sheet ordinary(testing::make_grid(4, 4, 0.1, 0.1), 1e6);
  ordinary.build();
  EXPECT_EQ(step_error(ordinary, ExternalLoads(), 1e-2), "");
}

// Every term is positive semi-definite, but the assembly lost one: node 13's own stiffness block (as a scatter
// that dropped blocks did, commit ecd4ba2). The explanation does not blame ill-conditioning: it names the node
// where CHOLMOD stopped (node 13 or a neighbour) and says a term was assembled other than as computed.
TEST(SystemPremises, AnAssemblyThatLostABlockIsNamedWhereTheFactorisationStopped) {
  Sheet s(testing::make_grid(5, 5, 0.1, 0.1), 1e9);
  s.build();
  for (Node& n : s.mesh.nodes) n.x += Vec3(0.01 * n.x.y() * n.x.y(), 0.003 * n.x.x(), 0.02 * n.x.x() * n.x.y());
  const int n = static_cast<int>(s.mesh.nodes.size());
  const int lost = 12;  // an interior node (1-based 13)
  const double dt = 1e-2;
  BlockSystem system;
  system.reset(s.cache.pattern);
  const SystemDofs dofs = SystemDofs::all_nodes(n);
  assemble_implicit_euler(s.mesh, s.cache.faces, s.cache.bending, dofs, ExternalLoads(), dt, system);
  ASSERT_TRUE(s.solver.factorize(system)) << "the sheet as assembled must factorise";
  EXPECT_EQ(explain_indefinite_system(s.mesh, s.cache.faces, s.cache.bending, dofs, ExternalLoads(), dt, system,
                                      s.solver.failed_row())
                .find("assembled other than as computed"),
            std::string::npos);
  system.blocks[s.cache.pattern.diagonal_block(lost)] = s.mesh.nodes[lost].mass * Mat3::Identity();
  ASSERT_FALSE(s.solver.factorize(system));
  const int failed = s.solver.failed_row() / 3;
  ASSERT_GE(s.solver.failed_row(), 0);
  const bool near = failed == lost || s.cache.pattern.block_index(failed, lost) >= 0;
  EXPECT_TRUE(near) << "stopped at node " << failed + 1;
  const std::string error = explain_indefinite_system(s.mesh, s.cache.faces, s.cache.bending, dofs, ExternalLoads(),
                                                      dt, system, s.solver.failed_row());
  EXPECT_NE(error.find("the factorisation stopped at node " + std::to_string(failed + 1) + ", whose blocks"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("a term was assembled other than as computed"), std::string::npos) << error;
}

}  // namespace
}  // namespace arcsim
