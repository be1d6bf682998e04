// All meshes that take part in collision handling (cloths and obstacles), flattened into one numbering of
// nodes, edges and faces so that contacts between different meshes and impact zones spanning several meshes
// need no special cases. Built from the meshes at one of two moments of the step (see ContactStage); cheap
// (linear in the mesh sizes) and rebuilt whenever it is needed.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "mesh/mesh.hpp"

namespace arcsim {

// One mesh handed to collision handling. Deformable meshes (cloths) have masses and move; the others
// (obstacles) are immovable: infinite mass, prescribed motion x0 -> x.
struct ContactBody {
  const Mesh* mesh = nullptr;
  bool deformable = true;
};

enum class ContactStage {
  // Before the velocity solve: cloth at its current x moving with v; obstacles at x0 moving to x.
  kBeforeStep,
  // After the position update: everything moves x0 -> x.
  kAfterStep,
};

struct ContactGeometry {
  struct Range {
    int node_begin = 0, node_end = 0;
    int edge_begin = 0, edge_end = 0;
    int face_begin = 0, face_end = 0;
    bool deformable = true;
    uint64_t topology = 0;  // hash of the mesh's connectivity (equal hash: same BVH structure)
  };
  std::vector<Range> meshes;

  // Nodes (global index = mesh range begin + mesh-local index).
  std::vector<Vec3> x0, x1;          // positions at the start and end of the step (m)
  std::vector<Vec3> v;               // velocity at the start of the step (m/s)
  std::vector<double> mass;          // kg; kInfinity for immovable nodes
  std::vector<double> area;          // m^2, a third of the incident faces' areas
  std::vector<int> node_mesh;
  // Rest-space (material) position of each deformable node (its first vert's u, m); unused for obstacles.
  // Proximity uses it to tell a collision from material neighbours (collision/proximity.hpp).
  std::vector<Vec3> rest;

  // Edges and faces by global node indices.
  std::vector<std::array<int, 2>> edges;
  std::vector<std::array<int, 2>> edge_faces;  // global face indices, kNone for a missing side
  std::vector<std::array<int, 3>> faces;
  std::vector<double> face_area;     // m^2: rest area for deformable meshes, world area for obstacles

  // Each node and edge is tested against other primitives from exactly one of its faces (its owner): its box
  // lies inside every incident face's box, so overlaps are never missed and pairs are never duplicated.
  // Compressed lists per face.
  std::vector<int> owned_node_begin, owned_nodes;  // face f owns owned_nodes[owned_node_begin[f] .. [f+1])
  std::vector<int> owned_edge_begin, owned_edges;

  int node_count() const { return static_cast<int>(x0.size()); }
  bool movable(int node) const { return mass[node] < kInfinity; }
  bool is_boundary_edge(int e) const { return edge_faces[e][0] == kNone || edge_faces[e][1] == kNone; }
};

// Builds the flattened geometry of `bodies` at `stage` (dt in s: obstacle velocities (x - x0)/dt, and in
// kBeforeStep the cloth end positions x + dt v).
void build_contact_geometry(const std::vector<ContactBody>& bodies, ContactStage stage, double dt,
                            ContactGeometry& geometry);

// The distance (m) in the rest shape between the two points of a pair (weights as in collision/distance.hpp:
// positive on one side, negative on the other, each side summing to 1), if all its nodes belong to one
// deformable mesh; infinity otherwise. Small for material neighbours, such as a crack's two lips, which are
// not a collision that needs a repulsion (collision/proximity.hpp).
double rest_distance(const ContactGeometry& g, const std::array<int, 4>& nodes, const std::array<double, 4>& weights);

// Unit normals of faces, and of nodes and edges (normalised sums of the incident face normals) at positions x.
std::vector<Vec3> face_normals(const ContactGeometry& g, const std::vector<Vec3>& x);
std::vector<Vec3> node_normals(const ContactGeometry& g, const std::vector<Vec3>& face_normal);
std::vector<Vec3> edge_normals(const ContactGeometry& g, const std::vector<Vec3>& face_normal);

}  // namespace arcsim
