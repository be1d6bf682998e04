// Fracture substepping (paper §4.1, Algorithm 1): per physics step and cloth, after plasticity and before the
// frame-end remesh, every node whose separation strength exceeds its toughness may open a crack; one crack at a
// time, each decided on a local prediction of the stress after the previous one.
//
//   1. sigma+ of every face, s of every node (fracture/fracture_stress.hpp, separation_strength.hpp);
//      Z = the nodes with s > tau. None: done (the usual case; it costs one stress evaluation).
//   2. While Z is not empty and fewer than max_cracks openings were made:
//      a. Z' = Z and its n-ring (n = zone_rings);
//      b. local remesh of Z''s faces down to size_min (remesh/remesh.hpp with a face subset, uniform metric),
//         so the crack opens at the finest resolution;
//      c. virtual physics update of Z' (physics/zone_solve.hpp; a 1-ring support held fixed): one implicit
//         step of the step's size with the step's gravity, handle springs and contacts, started from
//         rest (v = 0 in the zone and its support); the nodes move by x + dt dv: that is the stress
//         relaxation the opened cracks cause, not the step's motion, which the next full step makes (with the
//         velocities in, dv would also carry -v in the stiff limit: measured on paper-tearing.json, predicted
//         principal stresses at the notch turned by 60 degrees and tripled); the step is solved by Newton
//         iterations (virtual_iterations), because one linearised step of a bent stiff sheet stretches it
//         along tangents by order theta^2 / 2, more than glass's critical strain. The contacts are the
//         step's repulsions moved to its end positions (contact_term_at_gap_change): without them a crack tip
//         in a fold of the sheet relaxed through the layer pressed against it (paper-tearing.json, t = 1.33 s:
//         s / tau 4.2 at the tip, predicted 0 every step, so the ligament never tore while its stress grew
//         to 7.6 tau; with them the prediction moves the tip 0.09 mm instead of 0.56 and it opens);
//      d. s for Z''s nodes at the predicted positions, then positions rewound;
//      e. the node with the largest s / tau opens (fracture/crack_opening.hpp, through one edit session):
//         Z = the nodes of Z' with s > tau, minus the opened node, plus the new crack tips. A refused opening
//         is logged and that node is not tried again in this step.
//         Independent openings (FractureParams::independent_openings, the default; "substep_openings" in the
//         scene's "fracture" object): the further breaking nodes of the same prediction open too, strongest
//         first, each if it lies more than 2 (zone_rings + 1) rings (mesh graph, measured after the openings
//         before it) from every node opened or refused in this substep. Their zones (n rings) can then not
//         touch, so one opening cannot change the other's neighbourhood; a substep costs one prediction for
//         many openings where the breaking region is large (an impact). false: the strict Algorithm 1.
//   Work per substep follows the zone, not the mesh: sigma+ and normals only for the zone's faces, masses only
//   for the nodes an edit touched, sizing only for the zone's verts, one world guard for the whole pass.
//   At the end the node positions are the step's positions (up to the edit session's local reprojection of
//   the split nodes, Eq. 13): only the topology changed.
//
// Ablations (paper §7, Fig. 5): substepping = false opens every node with s > tau of one evaluation, largest
// first, with neither local remesh nor virtual update (nodes next to an earlier opening are skipped);
// reproject = false turns off the crack opening's local reprojection.
#pragma once

#include <vector>

#include "fracture/crack_opening.hpp"
#include "fracture/separation_strength.hpp"
#include "mesh/mesh.hpp"
#include "physics/block_system.hpp"
#include "physics/cloth_physics.hpp"
#include "physics/material.hpp"
#include "remesh/remesh.hpp"

namespace arcsim {

struct FractureParams {
  int zone_rings = 3;        // n of Algorithm 1 (at least 2 relieve bending stress, paper §4.1)
  // The zone then grows ring by ring, up to max_zone_rings in all, while its support (the ring the virtual
  // update holds fixed) touches a face whose sigma+ exceeds support_stress times its toughness: a support held
  // in material that is itself past breaking imposes that state on the prediction, which then cannot relax
  // it (a collision response's projection at a large time step strains a stiff sheet over many rings).
  int max_zone_rings = 3;
  double support_stress = 1.0;
  int max_cracks = 100;      // openings per step and cloth (magic.max_cracks)
  bool substepping = true;   // Algorithm 1; false: the ablation described above
  bool local_remesh = true;  // step 2b (needs the remeshing module and a finite size_min)
  bool reproject = true;     // Eq. 13 after each opening
  // false: one opening per substep (the strict Algorithm 1). true: step 2e also opens the further candidates of
  // the same prediction, strongest first, that lie more than 2 (zone_rings + 1) rings from every node opened
  // in this substep (see above).
  bool independent_openings = true;
  // Newton iterations of the virtual update (at least 1; 1 is the single linearised step), stopped early once
  // a correction moves no node by more than virtual_tolerance times its displacement so far.
  int virtual_iterations = 4;
  double virtual_tolerance = 1e-2;
  SeparationOptions separation;
  CrackOpeningOptions opening;  // opening.size_min: remeshing size_min, else the median rest edge length
};

// What the simulation hands to one fracture pass of a cloth.
struct FractureContext {
  RemeshOptions remesh;  // the cloth's remeshing options (sizes, reference, reprojection, world guard)
  // Gravity and handle springs at the step's time, and the step's contacts as its implicit step had them (gaps
  // measured at the step's start; the virtual update re-evaluates them at the step's end positions).
  ExternalLoads loads;
  double dt = 0;         // s
  // Nodes the step's collision response moved by a fallback (rigid or held impact zones): the strain between
  // them and their neighbours is an artefact of the fallback, not the material's, so they and their 1-ring
  // (the nodes whose fans hold such faces) neither break nor seed a zone in this step. Measured on
  // paper-tearing.json after the tear ran through: nodes of a zone held at x0 reached s / tau 28 in the next
  // step, broke, and the shards they cut jammed further zones: 200 pieces within 15 steps.
  std::vector<int> untrusted_nodes;
};

struct FractureStats {
  int cracks = 0;         // openings made
  int refused = 0;        // openings refused (mesh left valid)
  int substeps = 0;       // iterations of Algorithm 1's loop
  int candidates = 0;     // nodes with s > tau in the first evaluation
  int largest_zone = 0;   // nodes of the largest Z'
  int remesh_edits = 0;   // local remeshing edits
  double max_ratio = 0;   // largest s / tau seen in the first evaluation
  bool edited = false;    // some topology edit happened (the caller's topology_changed)
  double seconds = 0;     // wall time
  FractureStats& operator+=(const FractureStats& o);
};

// One fracture pass (Algorithm 1) over `mesh`. Leaves tombstones (the caller compacts) and node masses current.
// `zone_solver` is a solver kept for zone solves (its pattern changes every solve).
FractureStats fracture_step(Mesh& mesh, const std::vector<Material>& materials, const FractureParams& params,
                            const FractureContext& context, CholeskySolver& zone_solver);

// Whether any material can break (toughness > 0).
bool has_fracture(const std::vector<Material>& materials);

}  // namespace arcsim
