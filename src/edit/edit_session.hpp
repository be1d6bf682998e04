// The edit session: the one door through which every topology edit and node move of a sheet goes (remeshing's
// split / flip / collapse, fracture's vertex split along a crack, later defect lines). The raw edits of
// mesh/edits.hpp only change the connectivity; the session runs around each of them, in one place and in the
// paper's order, everything else the edit needs, as a fixed sequence of stages:
//
//   kGuardCheck      world-space guard (remesh/world_guard.hpp): a flip or collapse that would sweep through or
//                    come too close to another surface is refused before anything changes
//   kCapture         the plastic state of the faces the edit replaces: their local plastic embedding (Eq. 11-12)
//   kTopology        the edit itself (mesh/edits.hpp)
//   kTrack           bookkeeping: live face count, the zone (the faces a client works on, inherited by the
//                    children of zone faces), the guard's index of the new faces
//   kRestPositions   new rest verts onto the reference surface (restshape/), the new node's world position
//                    following the rest displacement
//   kRestAngles      edge rest angle = plastic offset + the reference surface's dihedral
//   kPlastic         a split's new node placed in the embedding (its world position follows the plastic shape),
//                    Fp and Sp of the new faces read back from the embedding, or interpolated (Eq. 11-12)
//   kGuardMoves      the world guard on the node moves of kRestPositions and kPlastic (undone if refused)
//   kReprojection    Eq. 13 for the changed nodes (remesh/reprojection.hpp), each move guarded
//   kDone            the edit is complete; observers may react (e.g. a client queueing flips around it)
//
// Which stages do work for which edit (the others are reported to observers but change nothing):
//   split_edge:    Capture, Topology, Track, RestPositions, RestAngles, Plastic, GuardMoves, Reprojection (new node)
//   flip_edge:     GuardCheck, Capture, Topology, Track, RestAngles, Plastic
//   collapse_edge: GuardCheck, Capture, Topology, Track, RestAngles, Plastic, Reprojection (kept node)
//   split_node:    Topology, Track, Reprojection (the node and its copies). A vertex split moves no rest
//                  position: faces keep Fp, Sp and the edges their rest angles exactly as the edit copies them
//                  (rebuilding them from an embedding would only add round-off), and the crack's lips stay where
//                  the plastic shape holds them unless the reprojection finds a lower energy.
// A refused edit stops at the stage that refused it (kGuardCheck or kTopology) and leaves the mesh untouched. A
// collapse that flags and boundaries alone rule out (collapse_edge_precheck) is refused at kTopology, reported
// alone, without a guard check.
//
// Follow-ups outside the mesh (node masses, the element cache and the solver's pattern, handle indices,
// compaction) belong to the simulation: after a session's edits its client calls
// Simulation::topology_changed(cloth, session.edited()) (sim/simulation.hpp).
//
// A new kind of edit: a raw edit in mesh/edits.hpp (valid mesh in, valid mesh out, tombstones), then a method
// here that runs it through the stages it needs.
#pragma once

#include <chrono>
#include <memory>
#include <vector>

#include "mesh/edits.hpp"
#include "mesh/mesh.hpp"
#include "physics/material.hpp"
#include "plasticity/plastic_embedding.hpp"
#include "remesh/reprojection.hpp"
#include "remesh/world_guard.hpp"
#include "restshape/reference_surface.hpp"

namespace arcsim {

enum class EditKind { kSplitEdge, kFlipEdge, kCollapseEdge, kSplitNode };

enum class EditStage {
  kGuardCheck,
  kCapture,
  kTopology,
  kTrack,
  kRestPositions,
  kRestAngles,
  kPlastic,
  kGuardMoves,
  kReprojection,
  kDone,
};

const char* edit_kind_name(EditKind kind);
const char* edit_stage_name(EditStage stage);

// The distinct edges of the live faces among `faces`, ascending: what an edit's new faces put up for rest angles
// or for a client's next edits (flips around a change).
std::vector<int> edges_of_faces(const Mesh& mesh, const std::vector<int>& faces);

// Told about every stage of every edit, after the session ran it. `result` is the edit's result so far (empty
// before kTopology; ok = false once refused, in which case the stage that refused is the last one reported).
class EditObserver {
 public:
  virtual ~EditObserver() = default;
  virtual void stage_done(EditKind kind, EditStage stage, const EditResult& result) = 0;
};

struct EditSessionOptions {
  const ReferenceSurface* reference = nullptr;  // where new rest positions go; nullptr: left on the chord
  bool plastic_embedding = true;                // false: "plastic_transfer": "interpolate"
  bool reproject = true;                        // world reprojection (Eq. 13) of the nodes an edit changes
  ReprojectionParams reprojection;
  // World-space guard: new triangles keep this clearance (m) from every surface they do not touch (the mesh
  // itself and `obstacles`), or come no closer than before. <= 0: off.
  double world_clearance = 0;
  std::vector<const Mesh*> obstacles;
  // A guard built once for several sessions in a row (fracture's substeps; building one indexes the whole mesh
  // and its obstacles). Valid while every edit and node move of the mesh goes through sessions sharing it (moves
  // that are undone exactly, like fracture's rewound prediction, need not). nullptr: each session builds its own.
  WorldGuard* shared_guard = nullptr;
};

// What the session did, summed over its edits.
struct EditCounts {
  int splits = 0, flips = 0, collapses = 0, node_splits = 0, reprojections = 0;
  int guarded = 0;              // edits and node moves refused (or undone) by the world-space guard
  double plastic_seconds = 0;   // wall time of the plastic transfer (capture, placement, rebuild), s
};

// How EditSession::move_node checks and books a move.
struct NodeMoveOptions {
  // Faces the guard does not check the move against (a crack's lips, which start coincident: any move of one
  // lip touches the other).
  std::vector<int> exempt_faces;
  // False: the guard only checks that the moving faces sweep through nothing, and the move may end closer to a
  // surface than the clearance (a lip set apart next to the lip of an earlier crack; collision handling keeps
  // the two apart from then on).
  bool require_clearance = true;
  // True: the move strains nothing. The node's rest position moves with it on its elastic faces (the rest-space
  // image of the move: a cut of the rest shape, not a strain), and each of those faces keeps its mass
  // (thickness times rest area; the thickness changes by the gap over the face's size). WHY: a crack's lips are
  // set apart by a gap the collision stage needs (twice the projection thickness, 2e-5 m in ARCSim's scenes),
  // and over glass's 1 mm faces that gap is a 1% strain, 25 times glass's critical strain: every opening of
  // sphere-break.json added elastic energy (72 J in one step) and its stress cracked the lips' neighbours.
  // Faces of plastic materials are left as they are: a ductile sheet yields to a strain of that size anyway,
  // and their rest shape belongs to the plastic embedding.
  // Bending, on every face: the rest angle of each hinge the node enters turns with its world angle, so the
  // move leaves the bending energy as it was.
  bool stress_free = false;
};

class EditSession {
 public:
  // `zone`: the faces the client works on (nullptr: the whole mesh). The mesh and materials must outlive the
  // session; the session is meant to live for one batch of edits (a remeshing pass, a fracture substep).
  EditSession(Mesh& mesh, const std::vector<Material>& materials, EditSessionOptions options,
              const std::vector<int>* zone = nullptr);
  ~EditSession();
  EditSession(const EditSession&) = delete;
  EditSession& operator=(const EditSession&) = delete;

  // The edits (see mesh/edits.hpp for what each does to the connectivity and when it is refused).
  EditResult split_edge(int edge, double t);
  EditResult flip_edge(int edge);
  EditResult collapse_edge(int edge, int remove_side);
  EditResult split_node(int node, const std::vector<int>& cut_edges);

  // Reprojects one node (Eq. 13) through the guard; true if it moved and the move was kept. Preserved nodes
  // (handles, crack tips) stay where they are.
  bool reproject(int node);

  // Moves a node (and its start-of-step position x0) by `displacement` (m) through the world guard; true if
  // the move was kept. For small moves an edit needs (fracture: the lips of a new crack set apart).
  bool move_node(int node, const Vec3& displacement, const NodeMoveOptions& options = {});
  // Whether the guard would keep a move of `node` by `displacement` that only `faces` (some of the node's faces)
  // follow, checked as move_node checks it; changes nothing. For an edit that must know before it splits a node
  // whether the moves it makes after the split will be kept (crack opening: a split whose lips cannot be set
  // apart leaves coincident lips, which collision handling cannot separate). The node's other faces are not
  // checked (they touch it). True without a guard.
  bool move_allowed(int node, const std::vector<int>& faces, const Vec3& displacement,
                    const NodeMoveOptions& options = {}) const;

  void add_observer(EditObserver* observer) { observers_.push_back(observer); }

  // Zone: a face is in it if it was given, or is a child of a zone face (split children inherit their parent's
  // membership, children of flips and collapses always join: those edits stay inside the client's region).
  bool in_zone(int face) const;
  std::vector<int> zone_faces() const;  // live faces in the zone, ascending
  long live_faces() const { return live_faces_; }

  const EditCounts& counts() const { return counts_; }
  // Whether any edit succeeded: the element cache, masses, the solver's pattern and the handles need the
  // simulation's follow-up (Simulation::topology_changed).
  bool edited() const { return counts_.splits + counts_.flips + counts_.collapses + counts_.node_splits > 0; }

  const Mesh& mesh() const { return m_; }

 private:
  void report(EditKind kind, EditStage stage, const EditResult& result);
  // kGuardCheck
  bool guard_allows_flip(int e) const;
  bool guard_allows_collapse(int e, int gone, int keep) const;
  // kCapture / kPlastic
  bool capture_plastic(const std::vector<int>& faces, PlasticEmbedding& embedding);
  void transfer_plastic(const EditResult& r, bool plastic, const PlasticEmbedding& embedding);
  void add_plastic_time(std::chrono::steady_clock::time_point start);
  // kTrack
  void track(const EditResult& r, const std::vector<char>* child_in_zone);
  // kRestPositions / kRestAngles
  void project_vert(int v, double max_distance);
  bool on_reference(int v) const;
  double reference_dihedral(int e) const;
  std::vector<double> plastic_offsets(const std::vector<int>& edges) const;
  void apply_rest_angles(const std::vector<int>& edges, const std::vector<double>& offsets);
  void refresh_rest_angles(const std::vector<int>& faces);
  void cut_rest_shape(int node, const std::vector<std::pair<int, Vec3>>& rest_moves);
  // kReprojection: `node` even if preserved (split_node marks every node it splits preserved).
  bool reproject_unchecked(int node);
  // kGuardMoves
  // Whether the guard keeps node's move from the triangles `before` to `after` through `sweeps` (its fan's
  // faces, as move_node and move_allowed check them).
  bool guard_allows_move(int node, const std::vector<GuardTriangle>& before, const std::vector<GuardTriangle>& after,
                         const std::vector<GuardSweep>& sweeps, const NodeMoveOptions& options) const;
  bool keep_move(int node, const std::vector<GuardTriangle>& before, const Vec3& x, const Vec3& x0,
                 const NodeMoveOptions& options = {});
  GuardTriangle world_triangle(std::array<int, 3> nodes) const;
  GuardTriangle face_triangle(int f) const;

  Mesh& m_;
  const std::vector<Material>& materials_;
  EditSessionOptions o_;
  bool curved_reference_ = false;
  bool whole_mesh_ = true;
  std::vector<char> zone_;
  long live_faces_ = 0;
  std::unique_ptr<WorldGuard> own_guard_;
  WorldGuard* guard_ = nullptr;  // own_guard_ or the options' shared guard
  std::vector<EditObserver*> observers_;
  EditCounts counts_;
};

}  // namespace arcsim
