#include "fracture/separation_strength.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "mesh/edits.hpp"

namespace arcsim {

namespace {

// Integral from 0 to phi of the unit arc's outward normal (cos, sin) is M(phi) - M(0), M = (sin, -cos).
Vec2 arc_antiderivative(double phi) { return Vec2(std::sin(phi), -std::cos(phi)); }

// Sums over face pieces: of the arc normal integrals (geometry) and of sigma times them (the traction q across
// the arc, Eq. 5-6).
struct SectorSums {
  Vec2 arc = Vec2::Zero();
  Vec2 traction = Vec2::Zero();  // N/m
};

SectorSums operator-(const SectorSums& a, const SectorSums& b) { return {a.arc - b.arc, a.traction - b.traction}; }

// One face of the fan, unfolded: it covers angles [start, end] (rad) of the flat disc or wedge; a direction at
// angle beta in the face's material frame lies at angle beta + rotation in the unfolded frame.
struct FanPiece {
  int face = kNone;
  double start = 0, end = 0, rotation = 0;
  Mat2 stress = Mat2::Zero();  // sigma+ (N/m) in the unfolded frame
  double toughness = 0;        // area toughness (N/m)
  SectorSums before;           // the sums over [0, start): prefix sums make a sector two look-ups
  Vec2 start_antiderivative = Vec2::Zero();
};

struct UnfoldedFan {
  std::vector<FanPiece> pieces;
  double total = 0;  // total angle (rad): 2 pi for a flat interior node
  bool closed = false;
  SectorSums all;    // the sums over the whole fan
};

Mat2 rotation(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Mat2 R;
  R << c, -s, s, c;
  return R;
}

Vec2 in_face_frame(const Mesh& mesh, const Face& face, int from, int to) {
  return face.rest_frame.transpose() * (mesh.verts[face.v[to]].u - mesh.verts[face.v[from]].u);
}

void append_piece(UnfoldedFan& fan, FanPiece p) {
  p.before = fan.all;
  p.start_antiderivative = arc_antiderivative(p.start);
  const Vec2 arc = arc_antiderivative(p.end) - p.start_antiderivative;
  fan.all.arc += arc;
  fan.all.traction += p.stress * arc;
  fan.total = p.end;
  fan.pieces.push_back(p);
}

bool unfold_fan(const Mesh& mesh, const std::vector<Material>& materials, int node,
                const std::vector<FaceFractureStress>& stress, UnfoldedFan& fan) {
  NodeFan corners;
  if (!node_fan(mesh, node, corners)) return false;
  fan.closed = corners.closed;
  for (const FanCorner& c : corners.corners) {
    const Face& face = mesh.faces[c.face];
    const Vec2 out = in_face_frame(mesh, face, c.corner, (c.corner + 1) % 3);
    const Vec2 in = in_face_frame(mesh, face, c.corner, (c.corner + 2) % 3);
    const double angle = std::atan2(out.x() * in.y() - out.y() * in.x(), out.dot(in));
    if (!(angle > 0)) return false;  // degenerate or inverted rest corner
    FanPiece p;
    p.face = c.face;
    p.start = fan.total;
    p.end = fan.total + angle;
    p.rotation = p.start - std::atan2(out.y(), out.x());
    const Mat2 R = rotation(p.rotation);
    p.stress = R * stress[c.face].sigma * R.transpose();
    p.toughness = face_toughness(face, materials[face.material]);
    append_piece(fan, p);
  }
  return true;
}

// An unfolded angle brought into [0, total) (the second ray of an interior split may lie past the end).
double wrapped(const UnfoldedFan& fan, double phi) { return phi >= fan.total ? phi - fan.total : phi; }

// The piece containing angle phi in [0, total] (on an edge: the earlier one).
const FanPiece& piece_at(const UnfoldedFan& fan, double phi) {
  for (const FanPiece& p : fan.pieces)
    if (phi <= p.end) return p;
  return fan.pieces.back();
}

// The sums over [0, phi], phi in [0, total]; M = arc_antiderivative(phi).
SectorSums sums_up_to(const UnfoldedFan& fan, double phi, const Vec2& M) {
  const FanPiece& p = piece_at(fan, phi);
  const Vec2 arc = M - p.start_antiderivative;
  return {p.before.arc + arc, p.before.traction + p.stress * arc};
}

SectorSums sums_up_to(const UnfoldedFan& fan, double phi) { return sums_up_to(fan, phi, arc_antiderivative(phi)); }

int ray_count(const UnfoldedFan& fan) { return fan.closed ? 2 : 1; }

// The unfolded angle of ray k of the split at phi: phi, and at an interior node also phi + total / 2.
double ray_angle(const UnfoldedFan& fan, double phi, int k) { return k == 0 ? phi : phi + 0.5 * fan.total; }

// The two sectors of the split at angle phi (interior: phi in [0, total / 2]); the second is the rest of the fan.
// M = arc_antiderivative(phi), which the caller also needs (one sine and cosine for both).
std::array<SectorSums, 2> split_sectors(const UnfoldedFan& fan, double phi, const Vec2& M) {
  SectorSums first = sums_up_to(fan, phi, M);
  if (fan.closed) first = sums_up_to(fan, phi + 0.5 * fan.total) - first;
  return {first, fan.all - first};
}

// Eq. 7: the component common to q1 and -q2 along their difference (N/m); <= 0 when they do not pull apart.
double common_traction(const Vec2& q1, const Vec2& q2) {
  const Vec2 d = q1 - q2;
  const double len = d.norm();
  if (!(len > 0)) return 0;
  const Vec2 q_hat = d / len;
  return std::min(q1.dot(q_hat), -q2.dot(q_hat));
}

// Eq. 7 for the unit uniaxial stress n n^T across the split, n the normal of the (first) ray at angle phi:
// n = (-sin phi, cos phi) = -M, M = arc_antiderivative(phi).
double geometry_factor(const std::array<SectorSums, 2>& sectors, const Vec2& M) {
  const Vec2 n = -M;
  return common_traction(n * n.dot(sectors[0].arc), n * n.dot(sectors[1].arc));
}

double geometry_factor_at(const UnfoldedFan& fan, double phi) {
  if (fan.closed) {
    // The split at phi + total/2 is the same as at phi, sectors swapped.
    const double half = 0.5 * fan.total;
    phi = std::fmod(std::fmod(phi, half) + half, half);
  }
  phi = std::clamp(phi, 0.0, fan.total);
  const Vec2 M = arc_antiderivative(phi);
  return geometry_factor(split_sectors(fan, phi, M), M);
}

// Maximises the geometry factor near a sampled maximum (its peak can be a kink, e.g. 1 - |cos phi| at a
// straight border, which sampling alone would miss by a first-order amount).
double refined_geometry_factor(const UnfoldedFan& fan, double phi, double step, double sampled) {
  double lo = phi - step, hi = phi + step;
  for (int it = 0; it < 40; ++it) {
    const double a = lo + (hi - lo) / 3, b = hi - (hi - lo) / 3;
    if (geometry_factor_at(fan, a) < geometry_factor_at(fan, b)) lo = a;
    else hi = b;
  }
  return std::max(sampled, geometry_factor_at(fan, 0.5 * (lo + hi)));
}

bool rays_breakable(const UnfoldedFan& fan, double phi) {
  for (int k = 0; k < ray_count(fan); ++k)
    if (!(piece_at(fan, wrapped(fan, ray_angle(fan, phi, k))).toughness > 0)) return false;
  return true;
}

CutRay make_ray(const Mesh& mesh, const FanPiece& piece, double phi) {
  const double beta = phi - piece.rotation;  // phi already wrapped
  CutRay ray;
  ray.face = piece.face;
  ray.direction = mesh.faces[piece.face].rest_frame * Vec2(std::cos(beta), std::sin(beta));
  return ray;
}

// Whether even the strongest face of the fan can not break the weakest: the cheap skip (see header).
bool too_weak_to_break(const Mesh& mesh, const std::vector<Material>& materials, int node,
                       const std::vector<FaceFractureStress>& stress) {
  double lambda = 0, tau_min = kInfinity;
  for (int f : mesh.node_faces(node)) {
    const double tau = face_toughness(mesh.faces[f], materials[mesh.faces[f].material]);
    if (!(tau > 0)) continue;
    tau_min = std::min(tau_min, tau);
    lambda = std::max(lambda, stress[f].lambda_max);
  }
  return !(tau_min < kInfinity) || !(lambda > 0) || lambda < 0.5 * tau_min;
}

struct BestPlane {
  double phi = 0, raw = 0;  // raw > 0 once a candidate was found
  double factor_phi = 0, factor = 0;
};

BestPlane search_planes(const UnfoldedFan& fan, int samples, double step) {
  BestPlane best;
  const int count = fan.closed ? (samples + 1) / 2 : samples;
  for (int i = 0; i < count; ++i) {
    const double phi = i * step;
    const Vec2 M = arc_antiderivative(phi);
    const std::array<SectorSums, 2> sectors = split_sectors(fan, phi, M);
    const double c = geometry_factor(sectors, M);
    if (c > best.factor) best.factor = c, best.factor_phi = phi;
    if (c < kMinGeometryFactor || !rays_breakable(fan, phi)) continue;
    const double s = common_traction(sectors[0].traction, sectors[1].traction);
    if (s > best.raw) best.raw = s, best.phi = phi;
  }
  return best;
}

}  // namespace

NodeSeparation node_separation(const Mesh& mesh, const std::vector<Material>& materials, int node,
                               const std::vector<FaceFractureStress>& stress, const SeparationOptions& options) {
  NodeSeparation out;
  out.node = node;
  if (node < 0 || node >= static_cast<int>(mesh.nodes.size()) || mesh.nodes[node].dead) return out;
  if (too_weak_to_break(mesh, materials, node, stress)) return out;
  UnfoldedFan fan;
  if (!unfold_fan(mesh, materials, node, stress, fan)) return out;
  out.on_boundary = !fan.closed;
  const int samples = std::max(options.samples, 2);
  const double step = fan.total / samples;
  const BestPlane best = search_planes(fan, samples, step);
  if (!(best.raw > 0)) return out;
  double tau_sum = 0;
  for (int k = 0; k < ray_count(fan); ++k) {
    const double a = wrapped(fan, ray_angle(fan, best.phi, k));
    const FanPiece& piece = piece_at(fan, a);
    out.rays.push_back(make_ray(mesh, piece, a));
    tau_sum += piece.toughness;
  }
  out.toughness = tau_sum / out.rays.size();
  // The refined factor is at least the sampled one, so raw / sampled bounds the strength from above (in floating
  // point too: the refinement returns the larger of the two).
  if (options.breaking_only && !(out.toughness > 0 && best.raw / best.factor > out.toughness)) {
    out.rays.clear();
    out.toughness = 0;
    return out;
  }
  out.raw = best.raw;
  out.factor = refined_geometry_factor(fan, best.factor_phi, step, best.factor);
  out.strength = out.raw / out.factor;
  return out;
}

}  // namespace arcsim
