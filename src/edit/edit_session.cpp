#include "edit/edit_session.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "mesh/validate.hpp"
#include "physics/face_element.hpp"
#include "physics/membrane.hpp"

namespace arcsim {

namespace {

int vert_at(const Mesh& m, int f, int n) {
  const int c = m.corner_of_node(f, n);
  return c == kNone ? kNone : m.faces[f].v[c];
}

Vec3 rest_cross(const Mesh& m, const std::array<int, 3>& v) {
  return (m.verts[v[1]].u - m.verts[v[0]].u).cross(m.verts[v[2]].u - m.verts[v[0]].u);
}

// Linear part of the affine map taking a face's rest triangle to its world triangle, extended by mapping the
// rest normal to the world normal (identity when the world triangle is degenerate).
Mat3 rest_to_world_map(const Mesh& m, int f) {
  const Face& face = m.faces[f];
  const Vec3 &u0 = m.verts[face.v[0]].u, &u1 = m.verts[face.v[1]].u, &u2 = m.verts[face.v[2]].u;
  const Vec3 &x0 = m.nodes[m.face_node(f, 0)].x, &x1 = m.nodes[m.face_node(f, 1)].x,
             &x2 = m.nodes[m.face_node(f, 2)].x;
  const Vec3 nu = (u1 - u0).cross(u2 - u0), nx = (x1 - x0).cross(x2 - x0);
  if (!(nu.norm() > 0) || !(nx.norm() > 0)) return Mat3::Identity();
  Mat3 Du, Dx;
  Du << u1 - u0, u2 - u0, nu.normalized();
  Dx << x1 - x0, x2 - x0, nx.normalized();
  const Mat3 map = Dx * Du.inverse();
  return map.allFinite() ? map : Mat3::Identity();
}

// The face's total deformation gradient (world from its rest frame, 3x2; plasticity not included).
Mat32 face_deformation_gradient(const Mesh& m, int f) {
  return membrane_deformation_gradient(m.nodes[m.face_node(f, 0)].x, m.nodes[m.face_node(f, 1)].x,
                                       m.nodes[m.face_node(f, 2)].x, m.faces[f].Dm_inv);
}

// The rest-space move (m) that face f's deformation gradient F maps onto the world move `displacement`, in the
// face's plane (least squares: F a = displacement, a in the rest frame). Zero if F is degenerate.
Vec3 rest_move_of(const Mesh& m, int f, const Vec3& displacement) {
  const Mat32 F = face_deformation_gradient(m, f);
  const Mat2 normal_matrix = F.transpose() * F;
  if (!(normal_matrix.determinant() > 0)) return Vec3::Zero();
  const Vec2 a = normal_matrix.ldlt().solve(F.transpose() * displacement);
  const Vec3 move = m.faces[f].rest_frame * a;
  return move.allFinite() ? move : Vec3::Zero();
}

// The faces of `a` and `b`, sorted, each once (what the guard's fold test skips: the exempt faces and the moving
// node's own fan, which it checks as triangles).
std::vector<int> fan_and(const std::vector<int>& a, const std::vector<int>& b) {
  std::vector<int> out = a;
  out.insert(out.end(), b.begin(), b.end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void shift_node(Node& node, const Vec3& shift) {
  if (!shift.allFinite()) return;
  node.x += shift;
  node.x0 += shift;
}

}  // namespace

std::vector<int> edges_of_faces(const Mesh& m, const std::vector<int>& faces) {
  std::vector<int> edges;
  for (int f : faces)
    if (!m.faces[f].dead) edges.insert(edges.end(), m.faces[f].e.begin(), m.faces[f].e.end());
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

const char* edit_kind_name(EditKind kind) {
  switch (kind) {
    case EditKind::kSplitEdge: return "split_edge";
    case EditKind::kFlipEdge: return "flip_edge";
    case EditKind::kCollapseEdge: return "collapse_edge";
    case EditKind::kSplitNode: return "split_node";
  }
  return "?";
}

const char* edit_stage_name(EditStage stage) {
  switch (stage) {
    case EditStage::kGuardCheck: return "guard_check";
    case EditStage::kCapture: return "capture";
    case EditStage::kTopology: return "topology";
    case EditStage::kTrack: return "track";
    case EditStage::kRestPositions: return "rest_positions";
    case EditStage::kRestAngles: return "rest_angles";
    case EditStage::kPlastic: return "plastic";
    case EditStage::kGuardMoves: return "guard_moves";
    case EditStage::kReprojection: return "reprojection";
    case EditStage::kDone: return "done";
  }
  return "?";
}

EditSession::EditSession(Mesh& mesh, const std::vector<Material>& materials, EditSessionOptions options,
                         const std::vector<int>* zone)
    : m_(mesh), materials_(materials), o_(std::move(options)), whole_mesh_(zone == nullptr) {
  if (!whole_mesh_) {
    zone_.assign(m_.faces.size(), 0);
    for (int f : *zone)
      if (f >= 0 && f < static_cast<int>(m_.faces.size()) && !m_.faces[f].dead) zone_[f] = 1;
  }
  for (const Face& f : m_.faces)
    if (!f.dead) ++live_faces_;
  curved_reference_ = o_.reference != nullptr && o_.reference->kind() != "linear";
  if (o_.world_clearance > 0 && o_.shared_guard != nullptr) {
    guard_ = o_.shared_guard;
  } else if (o_.world_clearance > 0) {
    own_guard_ = std::make_unique<WorldGuard>(m_, o_.obstacles, o_.world_clearance);
    guard_ = own_guard_.get();
  }
}

EditSession::~EditSession() = default;

bool EditSession::in_zone(int f) const {
  return whole_mesh_ || (f < static_cast<int>(zone_.size()) && zone_[f]);
}

std::vector<int> EditSession::zone_faces() const {
  std::vector<int> faces;
  for (size_t f = 0; f < m_.faces.size(); ++f)
    if (!m_.faces[f].dead && in_zone(static_cast<int>(f))) faces.push_back(static_cast<int>(f));
  return faces;
}

void EditSession::report(EditKind kind, EditStage stage, const EditResult& result) {
  for (EditObserver* observer : observers_) observer->stage_done(kind, stage, result);
}

// --- the edits --------------------------------------------------------------------------------------------------

EditResult EditSession::split_edge(int e, double t) {
  const EditKind kind = EditKind::kSplitEdge;
  EditResult r;
  report(kind, EditStage::kGuardCheck, r);  // the new node lies on the old surface: nothing to check yet
  // The farthest a new rest vert may move onto the reference: the edge's rest length.
  double rest_length = 0;
  for (int s = 0; s < 2; ++s) {
    const int f = m_.edges[e].f[s];
    if (f == kNone) continue;
    const Vec3& u0 = m_.verts[vert_at(m_, f, m_.edges[e].n[0])].u;
    rest_length = std::max(rest_length, (m_.verts[vert_at(m_, f, m_.edges[e].n[1])].u - u0).norm());
  }
  // Children are told apart by the parent's corner opposite the edge.
  std::vector<std::pair<int, bool>> zone_by_corner;
  for (int s = 0; s < 2; ++s) {
    const int f = m_.edges[e].f[s];
    if (f != kNone) zone_by_corner.emplace_back(m_.opposite_node(e, f), in_zone(f));
  }
  const int end0 = m_.edges[e].n[0], end1 = m_.edges[e].n[1];
  PlasticEmbedding embedding;
  const bool plastic = capture_plastic({m_.edges[e].f[0], m_.edges[e].f[1]}, embedding);
  report(kind, EditStage::kCapture, r);

  r = arcsim::split_edge(m_, e, t);
  report(kind, EditStage::kTopology, r);
  if (!r.ok) return r;
  ++counts_.splits;

  std::vector<char> child_in_zone;
  for (int f : r.added_faces) {
    bool in = false;
    for (const auto& [node, parent_in] : zone_by_corner)
      if (m_.corner_of_node(f, node) != kNone) in = parent_in;
    child_in_zone.push_back(in);
  }
  track(r, &child_in_zone);
  report(kind, EditStage::kTrack, r);

  const int node = r.added_nodes[0];
  // The new node lies on the old surface; its moves below (onto the curved rest shape, into the plastic
  // embedding) are checked by the guard together.
  const Vec3 start_x = m_.nodes[node].x, start_x0 = m_.nodes[node].x0;
  std::vector<GuardTriangle> start_fan;
  if (guard_) start_fan = guard_->fan(node);
  // Initial world guess follows the rest displacement through the old faces' deformation.
  Mat3 map = Mat3::Zero();
  for (int f : r.added_faces) map += rest_to_world_map(m_, f) / static_cast<double>(r.added_faces.size());
  const std::vector<int> edges = edges_of_faces(m_, r.added_faces);
  const std::vector<double> offsets = plastic_offsets(edges);
  const bool project = o_.reference != nullptr && !r.added_verts.empty();
  if (project) {
    const Vec3 before = m_.verts[r.added_verts[0]].u;
    for (int v : r.added_verts) project_vert(v, rest_length);
    for (int f : r.added_faces) m_.update_rest_data(f);
    shift_node(m_.nodes[node], map * (m_.verts[r.added_verts[0]].u - before));
  }
  report(kind, EditStage::kRestPositions, r);
  if (project) apply_rest_angles(edges, offsets);
  report(kind, EditStage::kRestAngles, r);

  if (plastic && embedding.has(end0) && embedding.has(end1)) {
    // Paper §5.2: the new node goes onto the plastic surface in the embedding (place_split_node_in_embedding
    // says how); its world position follows the embedded neighbourhood's shape.
    const auto start = std::chrono::steady_clock::now();
    place_split_node_in_embedding(m_, materials_, embedding, node, end0, end1);
    Vec3 shift = world_position_from_embedding(m_, embedding, node) - m_.nodes[node].x;
    add_plastic_time(start);
    // The node moves no farther than the reprojection may move it across the sheet (max_displacement); the
    // reprojection that follows is free within the sheet. WHY: the world can be bent further than the plastic
    // shape (a sheet pressed around an obstacle), and moving a new node fully onto the plastic shape carried
    // it into the obstacle (measured on conf/metal-crumple-remesh.json: 18 cloth / sphere edge crossings after
    // the first refining frame without reprojection; a limit on the motion along the normal alone left them).
    const double limit = o_.reprojection.max_displacement;
    if (shift.norm() > limit) shift *= limit / shift.norm();
    shift_node(m_.nodes[node], shift);
  }
  transfer_plastic(r, plastic, embedding);
  report(kind, EditStage::kPlastic, r);
  keep_move(node, start_fan, start_x, start_x0);
  report(kind, EditStage::kGuardMoves, r);
  reproject(node);
  report(kind, EditStage::kReprojection, r);
  report(kind, EditStage::kDone, r);
  return r;
}

EditResult EditSession::flip_edge(int e) {
  const EditKind kind = EditKind::kFlipEdge;
  EditResult r;
  const bool allowed = guard_allows_flip(e);
  if (!allowed) ++counts_.guarded;
  report(kind, EditStage::kGuardCheck, r);
  if (!allowed) return r;
  PlasticEmbedding embedding;
  const bool plastic = capture_plastic({m_.edges[e].f[0], m_.edges[e].f[1]}, embedding);
  report(kind, EditStage::kCapture, r);
  r = arcsim::flip_edge(m_, e);
  report(kind, EditStage::kTopology, r);
  if (!r.ok) return r;
  ++counts_.flips;
  track(r, nullptr);
  report(kind, EditStage::kTrack, r);
  report(kind, EditStage::kRestPositions, r);  // no rest position moves
  refresh_rest_angles(r.added_faces);
  report(kind, EditStage::kRestAngles, r);
  transfer_plastic(r, plastic, embedding);
  report(kind, EditStage::kPlastic, r);
  report(kind, EditStage::kGuardMoves, r);     // no node moves
  report(kind, EditStage::kReprojection, r);   // no node changes
  report(kind, EditStage::kDone, r);
  return r;
}

EditResult EditSession::collapse_edge(int e, int remove_side) {
  const EditKind kind = EditKind::kCollapseEdge;
  EditResult r;
  // An edit the connectivity rules out is refused before the world guard (which costs ~100 times more): the
  // remesher asks for many such collapses (boundary nodes along interior edges, 1390 of 1408 attempts in
  // ARCSim's square.json), and the guard's answer could not change their outcome.
  if (!collapse_edge_precheck(m_, e, remove_side)) {
    report(kind, EditStage::kTopology, r);
    return r;
  }
  const int gone = m_.edges[e].n[remove_side], keep = m_.edges[e].n[1 - remove_side];
  const bool allowed = guard_allows_collapse(e, gone, keep);
  if (!allowed) ++counts_.guarded;
  report(kind, EditStage::kGuardCheck, r);
  if (!allowed) return r;
  PlasticEmbedding embedding;
  const bool plastic = capture_plastic(m_.node_faces(gone), embedding);
  report(kind, EditStage::kCapture, r);
  r = arcsim::collapse_edge(m_, e, remove_side);
  report(kind, EditStage::kTopology, r);
  if (!r.ok) return r;
  ++counts_.collapses;
  track(r, nullptr);
  report(kind, EditStage::kTrack, r);
  report(kind, EditStage::kRestPositions, r);  // the kept node keeps its rest positions
  refresh_rest_angles(r.added_faces);
  report(kind, EditStage::kRestAngles, r);
  transfer_plastic(r, plastic, embedding);
  report(kind, EditStage::kPlastic, r);
  report(kind, EditStage::kGuardMoves, r);     // no node moved yet
  reproject(keep);
  report(kind, EditStage::kReprojection, r);
  report(kind, EditStage::kDone, r);
  return r;
}

EditResult EditSession::split_node(int node, const std::vector<int>& cut_edges) {
  const EditKind kind = EditKind::kSplitNode;
  EditResult r;
  // A vertex split moves nothing: no guard check, and the faces keep their plastic state as they are.
  report(kind, EditStage::kGuardCheck, r);
  report(kind, EditStage::kCapture, r);
  // The nodes the edit may split (the node, far ends of cut edges) and whether they were preserved before it:
  // split_node marks all of them preserved, but only the ones held before (handles) stay out of reprojection.
  std::vector<std::pair<int, bool>> splittable{{node, node >= 0 && node < static_cast<int>(m_.nodes.size()) &&
                                                          m_.nodes[node].preserve}};
  for (int c : cut_edges) {
    if (c < 0 || c >= static_cast<int>(m_.edges.size())) continue;
    const int far = m_.edges[c].n[0] == node ? m_.edges[c].n[1] : m_.edges[c].n[0];
    splittable.emplace_back(far, m_.nodes[far].preserve);
  }
  r = arcsim::split_node(m_, node, cut_edges);
  report(kind, EditStage::kTopology, r);
  if (!r.ok) return r;
  ++counts_.node_splits;

  // added_faces[i] replaces removed_faces[i] (same face, a corner moved to a copy).
  std::vector<char> child_in_zone;
  for (size_t i = 0; i < r.added_faces.size(); ++i) child_in_zone.push_back(in_zone(r.removed_faces[i]));
  track(r, &child_in_zone);
  report(kind, EditStage::kTrack, r);
  report(kind, EditStage::kRestPositions, r);  // copies keep their rest positions
  report(kind, EditStage::kRestAngles, r);     // rest geometry unchanged: the edit's copied angles hold
  report(kind, EditStage::kPlastic, r);        // Fp, Sp copied with each face
  report(kind, EditStage::kGuardMoves, r);

  // The split nodes and their copies (a copy sits exactly where its original was when made): `node`, and a far
  // end only if it was split too.
  std::vector<int> changed;
  for (size_t k = 0; k < splittable.size(); ++k) {
    const auto& [original, was_preserved] = splittable[k];
    std::vector<int> copies;
    for (int copy : r.added_nodes)
      if (m_.nodes[copy].x == m_.nodes[original].x) copies.push_back(copy);
    if (was_preserved || (k > 0 && copies.empty())) continue;
    changed.push_back(original);
    changed.insert(changed.end(), copies.begin(), copies.end());
  }
  std::sort(changed.begin(), changed.end());
  changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
  if (o_.reproject)
    for (int n : changed) reproject_unchecked(n);
  report(kind, EditStage::kReprojection, r);
  report(kind, EditStage::kDone, r);
  return r;
}

// --- kTrack -----------------------------------------------------------------------------------------------------

void EditSession::track(const EditResult& r, const std::vector<char>* child_in_zone) {
  live_faces_ += static_cast<long>(r.added_faces.size()) - static_cast<long>(r.removed_faces.size());
  if (guard_)
    for (int f : r.added_faces) guard_->update_face(f);
  if (whole_mesh_) return;
  if (zone_.size() < m_.faces.size()) zone_.resize(m_.faces.size(), 0);
  for (size_t i = 0; i < r.added_faces.size(); ++i)
    zone_[r.added_faces[i]] = child_in_zone == nullptr || (*child_in_zone)[i];
}

// --- kRestPositions / kRestAngles ---------------------------------------------------------------------------------

// Moves the new vert's rest position onto the reference along its averaged rest normal, if the faces stay
// valid (not degenerate, normals turned by less than 60 degrees).
void EditSession::project_vert(int v, double max_distance) {
  Vert& vert = m_.verts[v];
  Vec3 normal = Vec3::Zero();
  for (int f : vert.faces) normal += m_.faces[f].rest_area * m_.faces[f].rest_normal;
  const Vec3 target = o_.reference->project(vert.u, normal, max_distance);
  if (!target.allFinite() || target == vert.u) return;
  const Vec3 old = vert.u;
  std::vector<Vec3> old_normals;
  for (int f : vert.faces) old_normals.push_back(rest_cross(m_, m_.faces[f].v));
  vert.u = target;
  for (size_t i = 0; i < vert.faces.size(); ++i) {
    const std::array<int, 3>& fv = m_.faces[vert.faces[i]].v;
    const Vec3 n = rest_cross(m_, fv);
    if (rest_triangle_degenerate(m_.verts[fv[0]].u, m_.verts[fv[1]].u, m_.verts[fv[2]].u) ||
        n.dot(old_normals[i]) <= 0.5 * n.norm() * old_normals[i].norm()) {
      vert.u = old;
      return;
    }
  }
}

bool EditSession::on_reference(int v) const {
  const Vec3& u = m_.verts[v].u;
  const double tolerance = 1e-9 * (1 + u.norm());
  return (o_.reference->closest_point(u) - u).norm() <= tolerance;
}

// The reference surface's rest dihedral of an interior, non-seam edge (0 otherwise, like Mesh::rest_dihedral).
// A vert left off the surface (its projection was refused) makes the actual rest triangles the stress-free
// shape, so the geometric rest dihedral is used there.
double EditSession::reference_dihedral(int e) const {
  const Edge& edge = m_.edges[e];
  if (edge.is_boundary()) return 0;
  const int f0 = edge.f[0], f1 = edge.f[1];
  const int a0 = vert_at(m_, f0, edge.n[0]), a1 = vert_at(m_, f0, edge.n[1]);
  if (a0 != vert_at(m_, f1, edge.n[0]) || a1 != vert_at(m_, f1, edge.n[1])) return 0;
  const int a2 = vert_at(m_, f0, m_.opposite_node(e, f0)), b3 = vert_at(m_, f1, m_.opposite_node(e, f1));
  for (int v : {a0, a1, a2, b3})
    if (!on_reference(v)) return m_.rest_dihedral(e);
  return o_.reference->rest_dihedral(m_.verts[a0].u, m_.verts[a1].u, m_.verts[a2].u, m_.verts[b3].u);
}

// Plastic offsets (rest angle minus geometric rest dihedral) of the edges, as the edits left them.
std::vector<double> EditSession::plastic_offsets(const std::vector<int>& edges) const {
  std::vector<double> offsets;
  for (int e : edges) offsets.push_back(m_.edges[e].rest_theta - m_.rest_dihedral(e));
  return offsets;
}

// Rest angle = plastic offset + the reference's dihedral of the current rest triangles. Without a curved
// reference the edits' geometric rest dihedral is already the right one.
void EditSession::apply_rest_angles(const std::vector<int>& edges, const std::vector<double>& offsets) {
  for (size_t i = 0; i < edges.size(); ++i) {
    const int e = edges[i];
    if (m_.edges[e].dead) continue;
    const double base = curved_reference_ ? reference_dihedral(e) : m_.rest_dihedral(e);
    m_.edges[e].rest_theta = offsets[i] + base;
  }
}

void EditSession::refresh_rest_angles(const std::vector<int>& faces) {
  if (!curved_reference_) return;
  const std::vector<int> edges = edges_of_faces(m_, faces);
  apply_rest_angles(edges, plastic_offsets(edges));
}

// --- kCapture / kPlastic (paper §5.2) ------------------------------------------------------------------------------

void EditSession::add_plastic_time(std::chrono::steady_clock::time_point start) {
  counts_.plastic_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Before an edit of `faces` (kNone entries ignored): true if they hold plastic state to transfer; with the
// embedding transfer, their plastic embedding is built into `embedding`.
bool EditSession::capture_plastic(const std::vector<int>& faces, PlasticEmbedding& embedding) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<int> live;
  for (int f : faces)
    if (f != kNone) live.push_back(f);
  const bool plastic = neighbourhood_has_plasticity(m_, materials_, live);
  if (plastic && o_.plastic_embedding) embedding = build_plastic_embedding(m_, live);
  add_plastic_time(start);
  return plastic;
}

// After the edit (and the rest-angle update): Fp, Sp and edge rest angles of the new faces, from the embedding
// or, with "plastic_transfer": "interpolate", from the edit's interpolated Sp.
void EditSession::transfer_plastic(const EditResult& r, bool plastic, const PlasticEmbedding& embedding) {
  if (!plastic) return;
  const auto start = std::chrono::steady_clock::now();
  if (o_.plastic_embedding) {
    rebuild_plasticity_from_embedding(m_, materials_, embedding, r.added_faces);
  } else {
    interpolate_plasticity(m_, materials_, r.added_faces);
  }
  add_plastic_time(start);
}

// --- kReprojection / kGuardMoves -------------------------------------------------------------------------------

bool EditSession::reproject(int node) {
  if (!o_.reproject || m_.nodes[node].preserve) return false;
  return reproject_unchecked(node);
}

bool EditSession::move_node(int node, const Vec3& displacement, const NodeMoveOptions& options) {
  Node& n = m_.nodes[node];
  const Vec3 x = n.x, x0 = n.x0;
  std::vector<GuardTriangle> before;
  if (guard_) before = guard_->fan(node);
  // Per vert of the node: the area-weighted rest-space image of the move over its elastic faces.
  std::vector<std::pair<int, Vec3>> rest_moves;
  if (options.stress_free) {
    for (int v : n.verts) {
      Vec3 sum = Vec3::Zero();
      double area = 0;
      for (int f : m_.verts[v].faces) {
        if (m_.faces[f].dead || is_plastic_material(materials_[m_.faces[f].material])) continue;
        sum += m_.faces[f].rest_area * rest_move_of(m_, f, displacement);
        area += m_.faces[f].rest_area;
      }
      if (area > 0) rest_moves.emplace_back(v, sum / area);
    }
  }
  // The hinges the node's position enters (the edges of its faces): world and rest angles before the move.
  std::vector<std::array<double, 3>> hinges;  // edge, world angle, rest angle
  if (options.stress_free)
    for (int e : edges_of_faces(m_, m_.node_faces(node)))
      if (!m_.edges[e].is_boundary()) hinges.push_back({double(e), m_.world_dihedral(e), m_.edges[e].rest_theta});
  n.x += displacement;
  n.x0 += displacement;
  if (!keep_move(node, before, x, x0, options)) return false;
  if (!rest_moves.empty()) cut_rest_shape(node, rest_moves);
  // Bending: each hinge's rest angle turns with its world angle. WHY: the lip gap is set apart along the
  // sheet's mean plane at the node, which is not the plane of each of its faces where the sheet is bent; over
  // faces a tenth of a millimetre across it kinked the hinges by tenths of a radian, and a bent steel sheet's
  // lip moves added 23 J of bending energy in one step (docs/repro/variety-steel-impact.json, step 25).
  for (const auto& [edge, world, rest] : hinges) {
    const int e = static_cast<int>(edge);
    m_.edges[e].rest_theta = rest + std::remainder(m_.world_dihedral(e) - world, 2 * M_PI);
  }
  return true;
}

bool EditSession::move_allowed(int node, const std::vector<int>& faces, const Vec3& displacement,
                               const NodeMoveOptions& options) const {
  if (!guard_) return true;
  const Vec3 from = m_.nodes[node].x, to = from + displacement;
  std::vector<GuardTriangle> before, after;
  std::vector<GuardSweep> sweeps;
  for (int f : faces) {
    const int c = m_.corner_of_node(f, node);
    if (c == kNone) continue;
    const int b0 = m_.face_node(f, (c + 1) % 3), b1 = m_.face_node(f, (c + 2) % 3);
    const Vec3 &x0 = m_.nodes[b0].x, &x1 = m_.nodes[b1].x;
    before.push_back({{from, x0, x1}, {node, b0, b1}});
    after.push_back({{to, x0, x1}, {node, b0, b1}});
    sweeps.push_back({{from, to, x0, x1}, {node, node, b0, b1}});
  }
  return guard_allows_move(node, before, after, sweeps, options);
}

bool EditSession::guard_allows_move(int node, const std::vector<GuardTriangle>& before,
                                    const std::vector<GuardTriangle>& after, const std::vector<GuardSweep>& sweeps,
                                    const NodeMoveOptions& options) const {
  // The moved fan is checked against itself and the faces it touches (the guard's other tests skip those).
  std::vector<int> exempt = options.exempt_faces;
  std::sort(exempt.begin(), exempt.end());
  const std::vector<int> fold_replaced = fan_and(exempt, m_.node_faces(node));
  if (!options.require_clearance)
    return !guard_->folds_through_neighbours(after, fold_replaced) && guard_->sweep_is_clear(sweeps, exempt);
  return guard_->allows_move(before, after, sweeps, &fold_replaced, exempt);
}

// The stress-free part of a node move: its elastic faces' rest shape moves with it (a cut, not a strain), and
// each such face keeps its mass (thickness times rest area). WHY not a plastic stretch Fp (what it was): the
// remesher averages the Fp of the faces an edit replaces, and averaged stretches are a strain an elastic sheet
// cannot relax. With ARCSim's default thicknesses the 0.2 mm lip gap over 2 mm faces made a notched strip's
// mode I path wander by up to 5.9 mm (straight with this), and glass shards held strains of 1-2%.
void EditSession::cut_rest_shape(int node, const std::vector<std::pair<int, Vec3>>& rest_moves) {
  for (const auto& [v, move] : rest_moves) m_.verts[v].u += move;
  const std::vector<int> faces = m_.node_faces(node);
  for (int f : faces) {
    Face& face = m_.faces[f];
    const double area = face.rest_area;
    m_.update_rest_data(f);
    if (!is_plastic_material(materials_[face.material]) && area > 0 && face.rest_area > 0)
      face.thickness *= area / face.rest_area;
  }
  refresh_rest_angles(faces);
}

bool EditSession::reproject_unchecked(int node) {
  const Vec3 x = m_.nodes[node].x, x0 = m_.nodes[node].x0;
  std::vector<GuardTriangle> before;
  if (guard_) before = guard_->fan(node);
  if (!reproject_node(m_, materials_, node, o_.reprojection).moved) return false;
  if (!keep_move(node, before, x, x0)) return false;
  ++counts_.reprojections;
  return true;
}

// After `node` moved from (x, x0), where its faces were `before`: keeps the move if the guard allows it (and
// indexes the moved faces), else puts the node back. True if the move stays.
bool EditSession::keep_move(int node, const std::vector<GuardTriangle>& before, const Vec3& x, const Vec3& x0,
                            const NodeMoveOptions& options) {
  if (!guard_) return true;
  if (m_.nodes[node].x != x &&
      !guard_allows_move(node, before, guard_->fan(node), guard_->fan_sweep(node, x), options)) {
    m_.nodes[node].x = x;
    m_.nodes[node].x0 = x0;
    ++counts_.guarded;
    return false;
  }
  guard_->update_node(node);
  return true;
}

// --- kGuardCheck ----------------------------------------------------------------------------------------------

GuardTriangle EditSession::world_triangle(std::array<int, 3> nodes) const {
  GuardTriangle t;
  t.nodes = nodes;
  for (int i = 0; i < 3; ++i) t.x[i] = m_.nodes[nodes[i]].x;
  return t;
}

GuardTriangle EditSession::face_triangle(int f) const {
  return world_triangle({m_.face_node(f, 0), m_.face_node(f, 1), m_.face_node(f, 2)});
}

// Whether flipping interior edge e keeps the world surface clear.
bool EditSession::guard_allows_flip(int e) const {
  if (!guard_) return true;
  const Edge& edge = m_.edges[e];
  if (edge.is_boundary()) return true;  // flip_edge refuses it
  const int a = m_.opposite_node(e, edge.f[0]), b = m_.opposite_node(e, edge.f[1]);
  const std::vector<GuardTriangle> before{face_triangle(edge.f[0]), face_triangle(edge.f[1])};
  const std::vector<GuardTriangle> after{world_triangle({edge.n[0], a, b}), world_triangle({edge.n[1], b, a})};
  const std::array<int, 4> quad{edge.n[0], edge.n[1], a, b};
  GuardSweep sweep{{}, quad};
  for (int i = 0; i < 4; ++i) sweep.x[i] = m_.nodes[quad[i]].x;
  return guard_->allows(before, after, {sweep}, {edge.f[0], edge.f[1]});
}

// Whether collapsing edge e by removing node `gone` into node `keep` keeps the world surface clear.
bool EditSession::guard_allows_collapse(int e, int gone, int keep) const {
  if (!guard_) return true;
  // The removed node slides to the kept one: each surviving face of its fan sweeps a tetrahedron.
  const std::vector<int> fan = m_.node_faces(gone);
  std::vector<GuardTriangle> before, after;
  std::vector<GuardSweep> sweeps;
  for (int f : fan) {
    before.push_back(face_triangle(f));
    if (f == m_.edges[e].f[0] || f == m_.edges[e].f[1]) continue;
    const int c = m_.corner_of_node(f, gone);
    const int b0 = m_.face_node(f, (c + 1) % 3), b1 = m_.face_node(f, (c + 2) % 3);
    std::array<int, 3> nodes{m_.face_node(f, 0), m_.face_node(f, 1), m_.face_node(f, 2)};
    nodes[c] = keep;
    after.push_back(world_triangle(nodes));
    sweeps.push_back({{m_.nodes[gone].x, m_.nodes[keep].x, m_.nodes[b0].x, m_.nodes[b1].x}, {gone, keep, b0, b1}});
  }
  return guard_->allows(before, after, sweeps, fan);
}

}  // namespace arcsim
