#include "plasticity/plastic_embedding.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include "physics/bending.hpp"
#include "physics/face_element.hpp"
#include "physics/plate_bending.hpp"
#include "plasticity/bend_flow.hpp"
#include "plasticity/plastic_tensors.hpp"
#include "plasticity/stretch_flow.hpp"

namespace arcsim {

namespace {

// Rest angles within this of the rest dihedral (rad) carry no plastic offset (rounding of edits).
constexpr double kAngleTolerance = 1e-12;
// A rebuilt Fp this close to the identity (max entry deviation) is stored as exactly the identity.
constexpr double kIdentityTolerance = 1e-12;

std::vector<int> sorted_unique(std::vector<int> v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

bool live_face(const Mesh& m, int f) { return f != kNone && !m.faces[f].dead; }

// The faces and their flaps (faces across their edges), the faces first.
std::vector<int> faces_with_flaps(const Mesh& m, const std::vector<int>& faces) {
  std::vector<int> out;
  std::set<int> seen;
  for (int f : faces)
    if (live_face(m, f) && seen.insert(f).second) out.push_back(f);
  const size_t core = out.size();
  for (size_t k = 0; k < core; ++k)
    for (int e : m.faces[out[k]].e) {
      const int g = m.other_face(e, out[k]);
      if (live_face(m, g) && seen.insert(g).second) out.push_back(g);
    }
  return out;
}

// Corner positions of a face's plastic triangle in its 2D material frame: Fp2^-1 applied to the rest edge
// vectors (corner 0 at the origin).
std::array<Vec2, 3> plastic_triangle(const Mesh& m, int f) {
  const Face& face = m.faces[f];
  Mat2 P = Mat2::Identity();
  const Mat2 Fp2 = face_plastic_stretch_2d(face);
  if (std::abs(Fp2.determinant()) > 1e-12) P = Fp2.inverse();
  std::array<Vec2, 3> q;
  const Vec3& u0 = m.verts[face.v[0]].u;
  for (int i = 0; i < 3; ++i) q[i] = P * (face.rest_frame.transpose() * (m.verts[face.v[i]].u - u0));
  return q;
}

// Dihedral of edge e in the embedding, oriented like Mesh::rest_dihedral; false if a node is missing.
bool embedded_dihedral(const Mesh& m, const PlasticEmbedding& emb, int e, double& angle) {
  const Edge& ed = m.edges[e];
  if (ed.is_boundary()) return false;
  const int a = m.opposite_node(e, ed.f[0]), b = m.opposite_node(e, ed.f[1]);
  for (int n : {ed.n[0], ed.n[1], a, b})
    if (n == kNone || !emb.has(n)) return false;
  angle = dihedral_angle(emb.at(ed.n[0]), emb.at(ed.n[1]), emb.at(a), emb.at(b));
  return true;
}

// Places the one unplaced corner of face f across edge e from the placed face g, so that f keeps its plastic
// triangle and the hinge its plastic angle (Edge::rest_theta).
void place_across(const Mesh& m, PlasticEmbedding& emb, int f, int g, int e) {
  int r = kNone;
  for (int c = 0; c < 3; ++c)
    if (!emb.has(m.face_node(f, c))) r = c;
  if (r == kNone) return;
  const int ca = (r + 1) % 3, cb = (r + 2) % 3;  // f runs r -> a -> b counter-clockwise
  const std::array<Vec2, 3> q = plastic_triangle(m, f);
  const Vec2 ab = q[cb] - q[ca], ar = q[r] - q[ca];
  const double len2 = ab.squaredNorm();
  if (!(len2 > 0)) return;
  const double s = ar.dot(ab) / len2;                                // along the edge, fraction
  const double h = (ab.x() * ar.y() - ab.y() * ar.x()) / std::sqrt(len2);  // height, left of a -> b
  // Copies: placing the node appends to the embedding's storage.
  const Vec3 ya = emb.at(m.face_node(f, ca));
  const Vec3 yb = emb.at(m.face_node(f, cb));
  const Vec3 along = yb - ya;
  if (!(along.norm() > 0)) return;
  const Vec3 t = along.normalized();
  // Flat continuation points away from g's third corner; then the hinge turns by the plastic angle.
  const Vec3 to_g = emb.at(m.opposite_node(e, g)) - ya;
  Vec3 w0 = -(to_g - to_g.dot(t) * t);
  if (!(w0.norm() > 0)) w0 = t.unitOrthogonal();
  w0.normalize();
  const double theta = m.edges[e].rest_theta;
  const int node = m.face_node(f, r);
  Vec3 best = ya + s * along + h * w0;
  double best_error = kInfinity;
  for (double sign : {1.0, -1.0}) {
    const Vec3 w = std::cos(theta) * w0 + std::sin(sign * theta) * t.cross(w0);
    emb.set(node, ya + s * along + h * w);
    double angle = 0;
    if (!embedded_dihedral(m, emb, e, angle)) continue;
    const double error = std::abs(wrap_angle(angle - theta));
    if (error < best_error) {
      best_error = error;
      best = emb.at(node);
    }
  }
  emb.set(node, best);
}

// Places every corner of face f from its plastic triangle in the rest frame (a seed of the unfolding).
void place_seed(const Mesh& m, PlasticEmbedding& emb, int f) {
  const Face& face = m.faces[f];
  const std::array<Vec2, 3> q = plastic_triangle(m, f);
  const Vec3& u0 = m.verts[face.v[0]].u;
  for (int c = 0; c < 3; ++c)
    if (!emb.has(m.face_node(f, c))) emb.set(m.face_node(f, c), u0 + face.rest_frame * q[c]);
}

bool face_embedded(const Mesh& m, const PlasticEmbedding& emb, int f) {
  for (int c = 0; c < 3; ++c)
    if (!emb.has(m.face_node(f, c))) return false;
  return true;
}

// The rotation R of the polar decomposition A = S R (S symmetric positive), identity if A is degenerate.
Mat2 polar_rotation(const Mat2& A) {
  const Eigen::JacobiSVD<Mat2> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat2 R = svd.matrixU() * svd.matrixV().transpose();
  return R.allFinite() ? R : Mat2::Identity();
}

}  // namespace

// --- PlasticEmbedding ---------------------------------------------------------------------------------------

bool PlasticEmbedding::has(int node) const { return std::find(nodes.begin(), nodes.end(), node) != nodes.end(); }

const Vec3& PlasticEmbedding::at(int node) const {
  return y[std::find(nodes.begin(), nodes.end(), node) - nodes.begin()];
}

void PlasticEmbedding::set(int node, const Vec3& position) {
  const auto it = std::find(nodes.begin(), nodes.end(), node);
  if (it != nodes.end()) {
    y[it - nodes.begin()] = position;
    return;
  }
  nodes.push_back(node);
  y.push_back(position);
}

// --- queries ------------------------------------------------------------------------------------------------

bool is_plastic_material(const Material& material) {
  return has_bending_plasticity(material) || has_stretch_plasticity(material);
}

bool neighbourhood_has_plasticity(const Mesh& m, const std::vector<Material>& materials,
                                  const std::vector<int>& faces) {
  // Asked for every flip and collapse candidate: a sheet without plastic materials answers without looking.
  if (std::none_of(materials.begin(), materials.end(), is_plastic_material)) return false;
  for (int f : faces_with_flaps(m, faces)) {
    const Face& face = m.faces[f];
    if (!is_plastic_material(materials[face.material])) continue;
    if (!face.Fp.isIdentity(0) || !face.Sp.isZero(0)) return true;
    for (int e : face.e)
      if (std::abs(m.edges[e].rest_theta - m.rest_dihedral(e)) > kAngleTolerance) return true;
  }
  return false;
}

// --- unfolding ----------------------------------------------------------------------------------------------

PlasticEmbedding build_plastic_embedding(const Mesh& m, const std::vector<int>& faces) {
  PlasticEmbedding emb;
  const std::vector<int> all = faces_with_flaps(m, faces);
  std::vector<char> done(all.size(), 0);
  size_t remaining = all.size();
  while (remaining > 0) {
    bool progress = false;
    for (size_t k = 0; k < all.size(); ++k) {
      if (done[k]) continue;
      const int f = all[k];
      if (face_embedded(m, emb, f)) {
        done[k] = 1, --remaining, progress = true;
        continue;
      }
      // A placed neighbour across an edge whose two nodes are placed.
      for (int e : m.faces[f].e) {
        const int g = m.other_face(e, f);
        if (!live_face(m, g) || !face_embedded(m, emb, g)) continue;
        if (!emb.has(m.edges[e].n[0]) || !emb.has(m.edges[e].n[1])) continue;
        place_across(m, emb, f, g, e);
        break;
      }
      if (face_embedded(m, emb, f)) done[k] = 1, --remaining, progress = true;
    }
    if (progress) continue;
    // Nothing placed yet, or a piece not reachable through hinges (a seam): start it from its rest frame.
    for (size_t k = 0; k < all.size(); ++k)
      if (!done[k]) {
        place_seed(m, emb, all[k]);
        done[k] = 1, --remaining;
        break;
      }
  }
  return emb;
}

// --- Eq. 12 -------------------------------------------------------------------------------------------------

PlasticNodeEnergy plastic_node_energy(const Mesh& m, const std::vector<Material>& materials,
                                      const PlasticEmbedding& emb, int node, const Vec3& y, HessianKind kind) {
  PlasticNodeEnergy out;
  auto position = [&](int n) -> Vec3 { return n == node ? y : emb.at(n); };
  const std::vector<int> incident = m.node_faces(node);
  std::vector<int> bending = incident;
  for (int f : incident) {
    const Face& face = m.faces[f];
    if (!face_embedded(m, emb, f)) continue;
    const Material& mat = materials[face.material];
    // Rest metric: the plastic one where a stretching flow rule made it, else the reference (see header).
    const Mat2 Dm_inv = has_stretch_plasticity(mat) ? face_elastic_dm_inv(face) : face.Dm_inv;
    const MembraneTerms t =
        membrane_terms(position(m.face_node(f, 0)), position(m.face_node(f, 1)), position(m.face_node(f, 2)),
                       Dm_inv, face.rest_area, face_membrane_stiffness(face, mat, MembraneWeakening::kIgnored),
                       1.0, kind);
    out.energy += t.energy;
    const int c = m.corner_of_node(f, node);
    out.gradient += t.gradient.segment<3>(3 * c);
    if (kind != HessianKind::kNone) out.hessian += t.hessian.block<3, 3>(3 * c, 3 * c);
    const int across = m.other_face(face.e[(c + 1) % 3], f);
    if (live_face(m, across)) bending.push_back(across);
  }
  for (int f : sorted_unique(bending)) {
    if (!face_embedded(m, emb, f)) continue;
    const Face& face = m.faces[f];
    std::array<int, 6> nodes;
    std::array<bool, 3> has_wing;
    Vec3 rest = Vec3::Zero();
    for (int i = 0; i < 3; ++i) {
      nodes[i] = m.face_node(f, i);
      const int other = m.other_face(face.e[i], f);
      const int wing = live_face(m, other) ? m.opposite_node(face.e[i], other) : kNone;
      has_wing[i] = wing != kNone && emb.has(wing);
      nodes[3 + i] = has_wing[i] ? wing : nodes[0];
      // Against the edge's plastic angle theta^p (what the edit gave it: a split's halves keep the old hinge's,
      // its new edges inside the old faces are flat), not the paper's reference theta^R, which pulls every
      // placed node towards the flat reference (a split along a fold line of a uniformly curved plastic sheet
      // moved its node off the fold: 5e-3 rad of world / rest mismatch, tests/plasticity/
      // plastic_embedding_test.cpp's patch test).
      rest[i] = m.edges[face.e[i]].rest_theta;
    }
    const Mat3 Q = face_bending_matrix(m, materials[face.material], f, has_wing);
    std::array<Vec3, 6> xs;
    for (int i = 0; i < 6; ++i) xs[i] = position(nodes[i]);
    const PlateBendingTerms t = plate_bending_terms(xs, has_wing, rest, Q, kind);
    out.energy += t.energy;
    // A node may fill several slots (corner and wing on a tiny mesh): derivatives sum over them.
    auto is_node = [&](int slot) { return nodes[slot] == node && (slot < 3 || has_wing[slot - 3]); };
    for (int a = 0; a < 6; ++a) {
      if (!is_node(a)) continue;
      out.gradient += t.gradient.segment<3>(3 * a);
      if (kind == HessianKind::kNone) continue;
      for (int b = 0; b < 6; ++b)
        if (is_node(b)) out.hessian += t.hessian.block<3, 3>(3 * a, 3 * b);
    }
  }
  return out;
}

int place_node_in_embedding(const Mesh& m, const std::vector<Material>& materials, PlasticEmbedding& emb,
                            int node, int max_iterations) {
  if (!emb.has(node)) return 0;
  double length = 0;
  int count = 0;
  for (int e : m.nodes[node].edges) {
    const int other = m.edges[e].n[0] == node ? m.edges[e].n[1] : m.edges[e].n[0];
    if (!emb.has(other)) continue;
    length += (emb.at(other) - emb.at(node)).norm();
    ++count;
  }
  if (count == 0 || !(length > 0)) return 0;
  length /= count;
  Vec3 y = emb.at(node);
  PlasticNodeEnergy current = plastic_node_energy(m, materials, emb, node, y, HessianKind::kProjected);
  if (!std::isfinite(current.energy)) return 0;
  int accepted_steps = 0;
  for (int it = 0; it < max_iterations; ++it) {
    const Mat3& H = current.hessian;
    const double reg = 1e-10 * std::max(H.trace() / 3, 0.0) + 1e-300;
    Vec3 step = -(H + reg * Mat3::Identity()).ldlt().solve(current.gradient);
    if (!step.allFinite() || step.dot(current.gradient) >= 0) break;
    // The quadratic model is not trusted beyond the neighbourhood's size.
    if (step.norm() > 0.5 * length) step *= 0.5 * length / step.norm();
    if (step.norm() <= 1e-12 * length) break;
    bool accepted = false;
    double alpha = 1;
    for (int ls = 0; ls < 12 && !accepted; ++ls, alpha *= 0.5) {
      const PlasticNodeEnergy trial = plastic_node_energy(m, materials, emb, node, y + alpha * step, HessianKind::kNone);
      accepted = std::isfinite(trial.energy) && trial.energy < current.energy;
      if (accepted) y += alpha * step;
    }
    if (!accepted) break;
    ++accepted_steps;
    current = plastic_node_energy(m, materials, emb, node, y, HessianKind::kProjected);
  }
  emb.set(node, y);
  return accepted_steps;
}

// Gauss-Newton steps for a split node: it starts a sagitta away from the minimiser's height, so it needs more
// than a node nudged by an edit elsewhere (6 stopped short: a simulator-bent strip gained 1.3% rest curvature
// over 100 remesh cycles, 0.8% with 20).
constexpr int kSplitPlacementIterations = 20;

int place_split_node_in_embedding(const Mesh& m, const std::vector<Material>& materials, PlasticEmbedding& emb,
                                  int node, int end0, int end1) {
  if (!emb.has(end0) || !emb.has(end1)) return 0;
  const Vec3 ya = emb.at(end0), yb = emb.at(end1);
  const Vec3 middle = 0.5 * (ya + yb);
  emb.set(node, middle);
  Vec3 normal = Vec3::Zero();
  Mat3 S = Mat3::Zero();
  Vec3 e = Vec3::Zero();
  double area = 0;
  int halves = 0;
  std::vector<int> wings;
  for (int f : m.node_faces(node)) {
    if (!face_embedded(m, emb, f)) continue;
    const Face& face = m.faces[f];
    const Vec3 y0 = emb.at(m.face_node(f, 0)), y1 = emb.at(m.face_node(f, 1)), y2 = emb.at(m.face_node(f, 2));
    normal += (y1 - y0).cross(y2 - y0);
    area += face.rest_area;
    const int c = m.corner_of_node(f, node);
    for (int k = 1; k <= 2; ++k) {
      const int other = m.face_node(f, (c + k) % 3);
      if (other == end0) e -= m.verts[face.v[(c + k) % 3]].u - m.verts[face.v[c]].u, ++halves;
      if (other == end1) e += m.verts[face.v[(c + k) % 3]].u - m.verts[face.v[c]].u, ++halves;
    }
    // Wings across the face's edges that do not touch the new node: where the neighbourhood bends to.
    const int across = m.other_face(face.e[(c + 1) % 3], f);
    if (live_face(m, across)) wings.push_back(m.opposite_node(face.e[(c + 1) % 3], across));
  }
  if (!(area > 0) || !(normal.norm() > 0)) return 0;
  normal.normalize();
  // Plastic curvature S (1/m) around the split from the edges' plastic offsets (the rest angles are the truth; a
  // face's Sp is not uniform even on a uniformly bent sheet), over the split faces and their flaps (the split
  // faces alone see no hinge where they touch the sheet's boundary): sum of offset l n n^T, inner edges whole
  // and edges on the region's border half, over the region's area.
  std::vector<int> region;
  for (int f : faces_with_flaps(m, m.node_faces(node)))
    if (face_embedded(m, emb, f)) region.push_back(f);
  region = sorted_unique(region);
  double region_area = 0;
  for (int f : region) region_area += m.faces[f].rest_area;
  std::vector<int> edges;
  for (int f : region) edges.insert(edges.end(), m.faces[f].e.begin(), m.faces[f].e.end());
  for (int ed : sorted_unique(edges)) {
    const Edge& edge = m.edges[ed];
    if (edge.is_boundary()) continue;
    const double offset = edge.rest_theta - m.rest_dihedral(ed);
    if (offset == 0) continue;
    const bool inner = std::binary_search(region.begin(), region.end(), edge.f[0]) &&
                       std::binary_search(region.begin(), region.end(), edge.f[1]);
    const int f = std::binary_search(region.begin(), region.end(), edge.f[0]) ? edge.f[0] : edge.f[1];
    const Face& face = m.faces[f];
    const Vec3 d = m.verts[face.v[m.corner_of_node(f, edge.n[1])]].u -
                   m.verts[face.v[m.corner_of_node(f, edge.n[0])]].u;
    const double l = d.norm();
    if (!(l > 0)) continue;
    const Vec3 n = d.cross(face.rest_normal) / l;
    S += (inner ? 1.0 : 0.5) * offset * l * n * n.transpose();
  }
  S /= region_area;
  // e summed one half of the split edge per face: back to the whole edge's rest vector (m).
  e *= 2.0 / std::max(halves, 1);
  const double bulge = 0.125 * std::abs(e.dot(S * e));  // m
  // The neighbours across the faces' outer edges lie on the concave side: the node goes to the other.
  double side = 0;
  for (int w : wings)
    if (emb.has(w)) side += (emb.at(w) - middle).dot(normal);
  if (bulge > 0 && side != 0) emb.set(node, middle - (side > 0 ? 1 : -1) * bulge * normal);
  // Eq. 12 decides where the node settles, in every direction: the bulge only moves it off the saddle.
  return place_node_in_embedding(m, materials, emb, node, kSplitPlacementIterations);
}

Vec3 world_position_from_embedding(const Mesh& m, const PlasticEmbedding& emb, int node) {
  // Best rigid map of the embedded neighbours onto their world positions (Kabsch), applied to the node.
  std::vector<int> ring;
  for (int e : m.nodes[node].edges) {
    const int other = m.edges[e].n[0] == node ? m.edges[e].n[1] : m.edges[e].n[0];
    if (emb.has(other)) ring.push_back(other);
  }
  if (ring.size() < 3 || !emb.has(node)) return m.nodes[node].x;
  Vec3 cy = Vec3::Zero(), cx = Vec3::Zero();
  for (int n : ring) cy += emb.at(n), cx += m.nodes[n].x;
  cy /= static_cast<double>(ring.size());
  cx /= static_cast<double>(ring.size());
  Mat3 H = Mat3::Zero();
  for (int n : ring) H += (emb.at(n) - cy) * (m.nodes[n].x - cx).transpose();
  const Eigen::JacobiSVD<Mat3> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0) D(2, 2) = -1;
  const Mat3 R = svd.matrixV() * D * svd.matrixU().transpose();
  const Vec3 x = cx + R * (emb.at(node) - cy);
  return x.allFinite() ? x : m.nodes[node].x;
}

// --- Eq. 11 -------------------------------------------------------------------------------------------------

namespace {

// Eq. 11 for stretching: Fp2 of a face from its embedded triangle (plastic metric C = P^T P, P the map from the
// 2D material frame to the embedding; plastic stretch C^1/2), keeping the polar rotation of `current` (it
// orients anisotropic materials) and clamping the stretch to plastic_limit. Returns `current` when the
// embedded triangle is degenerate.
Mat2 plastic_stretch_from_embedding(const Mesh& m, const PlasticEmbedding& emb, int f, const Mat2& current,
                                    double plastic_limit) {
  const Face& face = m.faces[f];
  Mat32 D;
  D.col(0) = emb.at(m.face_node(f, 1)) - emb.at(m.face_node(f, 0));
  D.col(1) = emb.at(m.face_node(f, 2)) - emb.at(m.face_node(f, 0));
  const Mat32 P = D * face.Dm_inv;
  const Mat2 C = P.transpose() * P;
  if (!C.allFinite() || !(C.determinant() > 0)) return current;
  const Eigen::SelfAdjointEigenSolver<Mat2> eig(C);
  Vec2 inverse_stretch;
  for (int i = 0; i < 2; ++i) {
    double s = std::sqrt(std::max(eig.eigenvalues()[i], 0.0));
    if (std::isfinite(plastic_limit) && plastic_limit >= 1) s = std::clamp(s, 1 / plastic_limit, plastic_limit);
    inverse_stretch[i] = 1 / s;
  }
  Mat2 Fp2 = eig.eigenvectors() * inverse_stretch.asDiagonal() * eig.eigenvectors().transpose() *
             polar_rotation(current);
  if ((Fp2 - Mat2::Identity()).cwiseAbs().maxCoeff() <= kIdentityTolerance) Fp2 = Mat2::Identity();
  return Fp2.allFinite() && Fp2.determinant() > 0 ? Fp2 : current;
}

}  // namespace

void rebuild_plasticity_from_embedding(Mesh& m, const std::vector<Material>& materials,
                                       const PlasticEmbedding& emb, const std::vector<int>& new_faces) {
  // Fp of every plastic face is read back, also for bending-only materials: there it is the discrete metric
  // of a coarse flat triangle spanning a curved plastic region (its chords are shorter than its rest edges),
  // without which the rebuilt angles and lengths would not fit together. Sp only where bending plasticity is.
  std::vector<int> stretch, bend;
  for (int f : sorted_unique(new_faces)) {
    if (!live_face(m, f) || !face_embedded(m, emb, f)) continue;
    const Material& mat = materials[m.faces[f].material];
    if (is_plastic_material(mat)) stretch.push_back(f);
    if (has_bending_plasticity(mat)) bend.push_back(f);
  }
  auto is_bend = [&](int f) { return std::binary_search(bend.begin(), bend.end(), f); };

  // Target plastic offset of every edge of the rebuilt faces: the embedded dihedral where both wings are
  // embedded, the current offset otherwise (boundary edges, edges reaching outside the neighbourhood).
  std::vector<std::pair<int, double>> targets;
  auto target_of = [&](int e) {
    for (const auto& [edge, offset] : targets)
      if (edge == e) return offset;
    double angle = 0, offset = m.edges[e].rest_theta - m.rest_dihedral(e);
    if (embedded_dihedral(m, emb, e, angle)) offset = wrap_angle(angle - m.rest_dihedral(e));
    targets.emplace_back(e, offset);
    return offset;
  };
  std::vector<Mat3> new_Sp(bend.size());
  for (size_t k = 0; k < bend.size(); ++k) {
    const int f = bend[k];
    Vec3 d = Vec3::Zero();
    for (int i = 0; i < 3; ++i) {
      const int e = m.faces[f].e[i];
      const double t = target_of(e);
      const int g = m.other_face(e, f);
      if (!live_face(m, g) || is_bend(g)) {
        d[i] = t;
        continue;
      }
      // The unchanged neighbour keeps its Sp: this face takes the rest of the edge's mean.
      const Face& other = m.faces[g];
      double dg = 0;
      if (!other.Sp.isZero(0))
        for (int j = 0; j < 3; ++j)
          if (other.e[j] == e) dg = face_offsets_from_bending_strain(m, g, other.Sp)[j];
      d[i] = 2 * t - dg;
    }
    new_Sp[k] = d.isZero(0) ? Mat3::Zero() : face_bending_strain_from_offsets(m, f, d);
  }
  for (size_t k = 0; k < bend.size(); ++k) m.faces[bend[k]].Sp = new_Sp[k];
  for (const auto& [e, offset] : targets) m.edges[e].rest_theta = m.rest_dihedral(e) + offset;

  for (int f : stretch) {
    Face& face = m.faces[f];
    const Mat2 old_Fp2 = face_plastic_stretch_2d(face);
    const Mat2 Fp2 = plastic_stretch_from_embedding(m, emb, f, old_Fp2, materials[face.material].plastic_limit);
    // Volume kept as the stretching flow rule keeps it (plasticity/stretch_flow.hpp): h scales with det(Fp2).
    const double old_det = old_Fp2.determinant();
    if (old_det > 0) face.thickness *= Fp2.determinant() / old_det;
    face.Fp = face_plastic_stretch_3d(face, Fp2);
  }
}

void interpolate_plasticity(Mesh& m, const std::vector<Material>& materials, const std::vector<int>& new_faces) {
  std::vector<int> edges;
  for (int f : new_faces)
    if (live_face(m, f) && is_plastic_material(materials[m.faces[f].material]))
      edges.insert(edges.end(), m.faces[f].e.begin(), m.faces[f].e.end());
  if (!edges.empty()) update_edge_rest_angles_from_Sp(m, sorted_unique(edges));
}

}  // namespace arcsim
