// Proximity (repulsion) contacts, ARCSim style: at the start of the step every vertex-face and edge-edge pair
// closer than the repulsion thickness T is a candidate (material neighbours, closer than T in the rest shape
// too, only within ProximityParams::neighbour_thickness); each node keeps its nearest face on each side of its
// normal, each edge its nearest edge per side, each face its nearest node per side, and (crack lips) each
// boundary node / boundary edge its nearest in-plane partner on the outward side of the edge. Each kept pair
// becomes a one-sided penalty on its gap g = n . sum_i w_i x_i with energy k max(T - g, 0)^3 / (6 T) (J),
// k = collision_stiffness * (smaller area of the two elements) (N/m), plus Coulomb friction.
// The `floor` proxy adds such a penalty between every cloth node and the plane y = floor.
#pragma once

#include <array>
#include <vector>

#include "collision/candidates.hpp"
#include "collision/contact_geometry.hpp"
#include "physics/cloth_physics.hpp"

namespace arcsim {

struct ProximityParams {
  double thickness = 1e-3;           // repulsion thickness T (m)
  double stiffness = 1e9;            // collision_stiffness (N/m^3): k = stiffness * area
  double friction = 0.6;             // Coulomb coefficient between deformable meshes
  double obstacle_friction = 0.3;    // ... when an immovable node takes part (obstacles, floor)
  bool floor = false;                // floor proxy on
  double floor_height = 0;           // m (plane y = floor_height, normal +y)
  // Thickness (m) between material neighbours: pairs whose closest points are within `thickness` of each other
  // in the rest shape as well (a crack's two lips). The simulation sets it to the lip gap new cracks open with,
  // so that lips repel only once they come closer than they started. 0: such pairs never repel.
  double neighbour_thickness = 0;
};

struct ProximityContact {
  std::array<int, 4> nodes{kNone, kNone, kNone, kNone};  // global node indices (kNone: unused slot)
  std::array<double, 4> weights{0, 0, 0, 0};
  Vec3 normal = Vec3::UnitY();
  double gap = 0;        // n . sum_i w_i x0_i (m); the floor proxy: height above the plane
  double stiffness = 0;  // k (N/m)
  double friction = 0;   // Coulomb coefficient
  double thickness = 0;  // T of its penalty (m): ProximityParams::thickness, or neighbour_thickness
};

// The contacts at the geometry's start positions x0, in a deterministic order.
std::vector<ProximityContact> find_proximities(const ContactGeometry& g, BvhCache& cache,
                                               const ProximityParams& params);

// The penalty's force magnitude (N, along +n) and stiffness d^2E/dg^2 (N/m) at gap g (m).
struct Penalty {
  double force = 0, stiffness = 0;
};
Penalty repulsion_penalty(double gap, double k, double thickness);

// The implicit-step terms of the contacts that involve nodes of mesh `mesh` (local node numbering of that
// mesh), with the lagged Coulomb friction turned into a tangential damper (see friction_damping).
std::vector<ContactTerm> contact_terms(const ContactGeometry& g, const std::vector<ProximityContact>& contacts,
                                       int mesh, double dt);

// A contact term moved to a gap larger by `gap_change` (m) under the same penalty law (repulsion_penalty: the
// depth is 2 force / stiffness), the other side at rest (outside_velocity 0). Returns false when the contact
// has come apart (no depth left). Fracture's virtual update re-evaluates the step's contacts this way at the
// step's end positions: the gaps were measured at its start.
bool contact_term_at_gap_change(ContactTerm& term, double gap_change);

// Damping coefficient c (kg/s) of the implicit friction force -c P u on the relative tangential velocity u_t
// (m/s): c = mu f_n / |u_t|, so that a sliding contact feels exactly the Coulomb force, capped at
// kStickFactor m_eff / dt (m_eff = 1 / sum_i w_i^2 / m_i) so that a sticking contact (u_t -> 0) stays
// well conditioned while losing all but 1/kStickFactor of its tangential velocity each step.
constexpr double kStickFactor = 1e3;
double friction_damping(double mu, double normal_force, double tangential_speed, double effective_mass,
                        double dt);

}  // namespace arcsim
