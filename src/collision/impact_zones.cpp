#include "collision/impact_zones.hpp"

#include <algorithm>
#include <optional>
#include <sstream>

namespace arcsim {

namespace {

// Below this sine of the angle between two edges, an edge-edge impact takes the second edge's surface normal.
constexpr double kNearParallelSine = 0.1;

// For an edge-edge pair of two borders (one face each) whose faces lie on opposite sides, a crack's two lips
// facing each other (or two shards edge to edge): the direction from the second edge's face toward the
// first's, across the edges (the normalised difference of the two faces' inward directions), if the edges
// started apart along it or overlapping by less than `reach`; zero otherwise (they are stacked: one lip slid
// over the other's face).
Vec3 facing_borders_normal(const ContactGeometry& g, const PrimitivePair& p, const std::array<int, 4>& nodes, double t,
                           const Vec3& start_gap, double reach) {
  if (!g.is_boundary_edge(p.a) || !g.is_boundary_edge(p.b)) return Vec3::Zero();
  auto at = [&](int n) { return Vec3(g.x0[n] + t * (g.x1[n] - g.x0[n])); };
  // The unit direction from edge (n0, n1) into its face, across the edge.
  auto inward = [&](int edge, int n0, int n1) {
    const int f = g.edge_faces[edge][0] != kNone ? g.edge_faces[edge][0] : g.edge_faces[edge][1];
    Vec3 centroid = Vec3::Zero();
    for (int n : g.faces[f]) centroid += at(n) / 3;
    const Vec3 along = (at(n1) - at(n0)).normalized();
    const Vec3 in = centroid - 0.5 * (at(n0) + at(n1));
    const Vec3 across = in - in.dot(along) * along;
    return across.norm() > 0 ? Vec3(across.normalized()) : Vec3(Vec3::Zero());
  };
  const Vec3 in_a = inward(p.a, nodes[0], nodes[1]), in_b = inward(p.b, nodes[2], nodes[3]);
  if (!(in_a.dot(in_b) < -0.5)) return Vec3::Zero();
  const Vec3 normal = (in_a - in_b).normalized();
  if (!(normal.dot(start_gap) > -reach)) return Vec3::Zero();
  return normal;
}

// For an edge-edge impact of nearly parallel edges (sine below kNearParallelSine), the normal of the surface
// at the second edge (the normalised sum of its faces' normals, at the impact's time), on the side the first
// edge came from; `normal` unchanged where that surface normal is undefined or leaves the side unclear. Two
// facing borders take facing_borders_normal instead.
// WHY: the two edges' cross product (the plane normal ccd.cpp uses) turns with the tiny angle between nearly
// parallel edges, so it can lie in the surface: a sheet pressed onto a sphere had its edge and a sphere edge
// side by side with normals pointing +x and -x at one node, and the impact zone met both only by moving the
// node 1 mm through the sheet's plane (26 J of collision work in one 1 ms step of
// conf/metal-crumple-remesh.json). The surface normal says which way is out.
// WHY facing borders: a crack's two lips, twisted against each other by micrometres, have one lip above the
// other's line at one end and below it at the other, so the side read off the start gap at the contact point
// flips along them. The impacts of one lip pair found at two points then asked for opposite normals, the zone
// of their 4 nodes was ill-conditioned (25-280x) at every substep, and pushing lips millimetres apart strained
// the glass to 1e3-1e8 times its toughness (conf/paper-metal-glass.json on an AMD EPYC guest). Facing lips
// are apart across their edges, within the sheet, whichever way they twist.
Vec3 near_parallel_edge_normal(const ContactGeometry& g, const PrimitivePair& p, const std::array<int, 4>& nodes,
                               const std::array<double, 4>& weights, double t, double reach, bool keep_stacked,
                               const Vec3& normal) {
  auto at = [&](int n) { return Vec3(g.x0[n] + t * (g.x1[n] - g.x0[n])); };
  const Vec3 a = at(nodes[1]) - at(nodes[0]), b = at(nodes[3]) - at(nodes[2]);
  const double lengths = a.norm() * b.norm();
  if (!(lengths > 0) || a.cross(b).norm() >= kNearParallelSine * lengths) return normal;
  Vec3 surface = Vec3::Zero();
  for (int f : g.edge_faces[p.b]) {
    if (f == kNone) continue;
    const std::array<int, 3>& c = g.faces[f];
    const Vec3 n = (at(c[1]) - at(c[0])).cross(at(c[2]) - at(c[0]));
    if (n.norm() > 0) surface += n.normalized();
  }
  if (!(surface.norm() > 1e-6)) return normal;
  surface.normalize();
  Vec3 start_gap = Vec3::Zero();
  for (int i = 0; i < 4; ++i) start_gap += weights[i] * g.x0[nodes[i]];
  const Vec3 facing = facing_borders_normal(g, p, nodes, t, start_gap, reach);
  const double start_side = surface.dot(start_gap), contact_side = surface.dot(normal);
  const bool side_clear = std::abs(start_side) > 0.1 * start_gap.norm() && start_side != 0;
  // Stacked lips (ImpactZoneParams::stacked_lips_keep_start_side): they start overlapped across their edges (one
  // lip's edge over the other's face) and apart out of the surface, so they stay on the side they start on. WHY:
  // across the edges, the facing normal is reached from such a start only by the edges passing each other; the
  // motion may already meet it at its end, so every detection round found the same crossing again and the zone
  // fell back at every substep (docs/repro/glass-plate-stacked-lips.json).
  const bool stacked = keep_stacked && facing.dot(start_gap) < 0 && side_clear;
  if (facing.norm() > 0 && !stacked) return facing;
  if (side_clear) return start_side > 0 ? surface : -surface;
  if (std::abs(contact_side) > 0.1) return contact_side > 0 ? surface : -surface;
  return normal;
}

// For an edge-edge impact whose closest points lie within `reach` of an end of each edge (the edges touch end
// to end, a vertex-vertex contact), the direction between those two ends at the start of the step; `normal`
// unchanged otherwise, or where the ends started in contact.
// WHY: the plane of two edges that meet end to end says nothing about which side each end is on, and its side
// cannot be read off a gap that runs nearly within that plane. A sheet node resting on a sphere vertex had its
// edge and a sphere edge meeting there take the normal out of the sphere's far side, so the impact zone had to
// lift the node up through the sphere's apex while the vertex-face pairs of the same two vertices held it
// below (conf/metal-crumple-remesh.json, rounding perturbation seed 2: a 47-node zone 110x ill-conditioned;
// held at its start positions, the sheet was run through by the sphere and later dragged up, 3.9e6 J of
// plastic work in one frame). The start direction holds at the start positions, as the vertex-face pairs of
// the same vertices do, so the zone's constraints agree.
Vec3 end_to_end_normal(const ContactGeometry& g, const std::array<int, 4>& nodes, const std::array<double, 4>& weights,
                       double t, double reach, const Vec3& normal) {
  auto at = [&](int n) { return Vec3(g.x0[n] + t * (g.x1[n] - g.x0[n])); };
  const double s = weights[1], u = -weights[3];
  const double to_end_a = std::min(s, 1 - s) * (at(nodes[1]) - at(nodes[0])).norm();
  const double to_end_b = std::min(u, 1 - u) * (at(nodes[3]) - at(nodes[2])).norm();
  if (!(to_end_a <= reach && to_end_b <= reach)) return normal;
  const Vec3 start_gap = g.x0[nodes[s < 0.5 ? 0 : 1]] - g.x0[nodes[u < 0.5 ? 2 : 3]];
  if (!(start_gap.norm() > 1e-3 * reach)) return normal;
  return start_gap.normalized();
}

}  // namespace

std::vector<ImpactRecord> detect_impacts(const ContactGeometry& g, BvhCache& cache, const ImpactZoneParams& params,
                                         const std::vector<char>* moved, double* work) {
  CandidateOptions options;
  options.margin = params.contact_distance;
  options.swept = true;
  options.moved = moved;
  const std::vector<PrimitivePair> pairs = find_candidates(g, cache, options);
  if (work) *work += kCcdPairWork * static_cast<double>(pairs.size());
  CcdOptions ccd;
  ccd.contact_distance = params.contact_distance;

  std::vector<std::optional<ImpactRecord>> found(pairs.size());
#pragma omp parallel for schedule(dynamic, 64) if (pairs.size() > 1024)
  for (int k = 0; k < static_cast<int>(pairs.size()); ++k) {
    const PrimitivePair& p = pairs[k];
    const std::array<int, 4> nodes = pair_nodes(g, p);
    std::array<Vec3, 4> x0, x1;
    for (int i = 0; i < 4; ++i) {
      x0[i] = g.x0[nodes[i]];
      x1[i] = g.x1[nodes[i]];
    }
    const std::optional<Impact> hit = p.kind == PairKind::kVertexFace ? vertex_face_impact(x0, x1, ccd)
                                                                      : edge_edge_impact(x0, x1, ccd);
    if (!hit) continue;
    ImpactRecord r;
    r.kind = static_cast<int>(p.kind);
    r.a = p.a;
    r.b = p.b;
    r.nodes = nodes;
    r.weights = hit->contact.weights;
    r.normal = hit->contact.normal;
    r.time = hit->time;
    if (p.kind == PairKind::kEdgeEdge) {
      r.normal = near_parallel_edge_normal(g, p, nodes, r.weights, r.time, params.thickness,
                                            params.stacked_lips_keep_start_side, r.normal);
      r.normal = end_to_end_normal(g, nodes, r.weights, r.time, params.thickness, r.normal);
    }
    found[k] = r;
  }
  std::vector<ImpactRecord> impacts;
  for (const auto& f : found)
    if (f) impacts.push_back(*f);

  if (params.floor) {
    // The floor proxy is a plane under everything: a node that was above it may not end below it.
    for (const auto& r : g.meshes) {
      if (!r.deformable) continue;
      for (int n = r.node_begin; n < r.node_end; ++n) {
        if (moved && !(*moved)[n]) continue;
        const double h0 = g.x0[n].y() - params.floor_height, h1 = g.x1[n].y() - params.floor_height;
        if (!(h0 >= -params.contact_distance) || !(h1 < params.contact_distance)) continue;
        ImpactRecord rec;
        rec.kind = kFloorImpact;
        rec.a = rec.b = n;
        rec.nodes = {n, kNone, kNone, kNone};
        rec.weights = {1, 0, 0, 0};
        rec.normal = Vec3::UnitY();
        rec.offset = -params.floor_height;
        rec.time = h0 > h1 ? std::clamp(h0 / (h0 - h1), 0.0, 1.0) : 0.0;
        impacts.push_back(rec);
      }
    }
  }
  return impacts;
}

namespace {

// The fallback ladder of a zone: projected, then moved rigidly with its own mean displacement, then carried
// with the obstacles it touches (if they moved), then held at its start positions.
enum class ZoneState { kProjected, kRigid, kCarried, kFrozen };

struct Zone {
  std::vector<int> nodes;  // global, movable
  std::vector<ImpactRecord> constraints;
  ZoneState state = ZoneState::kProjected;
  bool alive = true;
  bool dirty = false;
  bool warned = false;
};

class ZoneSet {
 public:
  explicit ZoneSet(const ContactGeometry& g) : g_(g), zone_of_(g.node_count(), kNone) {}

  // Adds the impacts' constraints, creating and merging zones over shared movable nodes: those with a weight in
  // the constraint, or with `whole_pairs` every movable node of the pair.
  // WHY whole_pairs (the fallback rounds): a pair of nearly collinear edges lying along each other is found
  // again by every detection while any of its four nodes moves, since its closest points slide along the
  // edges; a node of weight zero at the contact left out of the zone kept moving, so the zone held at its start
  // was hit again and the collisions stayed unresolved (conf/paper-window.json, step 68).
  void add(const std::vector<ImpactRecord>& impacts, bool whole_pairs = false) {
    for (const ImpactRecord& r : impacts) {
      std::vector<int> movable;
      for (int i = 0; i < 4; ++i)
        if (r.nodes[i] != kNone && (whole_pairs || r.weights[i] != 0) && g_.movable(r.nodes[i]))
          movable.push_back(r.nodes[i]);
      if (movable.empty()) continue;
      int target = kNone;
      for (int n : movable)
        if (zone_of_[n] != kNone && (target == kNone || zone_of_[n] < target)) target = zone_of_[n];
      if (target == kNone) {
        target = static_cast<int>(zones_.size());
        zones_.emplace_back();
      }
      for (int n : movable) {
        const int z = zone_of_[n];
        if (z == target) continue;
        if (z == kNone) {
          zone_of_[n] = target;
          zones_[target].nodes.push_back(n);
        } else {
          absorb(target, z);
        }
      }
      add_constraint(zones_[target], r);
      zones_[target].dirty = true;
    }
  }

  std::vector<Zone>& zones() { return zones_; }
  // Work units of the constraint bookkeeping so far (one per stored constraint compared with a new one).
  double work() const { return work_; }

 private:
  void absorb(int target, int source) {
    Zone& t = zones_[target];
    Zone& s = zones_[source];
    for (int n : s.nodes) zone_of_[n] = target;
    t.nodes.insert(t.nodes.end(), s.nodes.begin(), s.nodes.end());
    for (const ImpactRecord& r : s.constraints) add_constraint(t, r);
    t.state = std::max(t.state, s.state);
    s = Zone();
    s.alive = false;
  }

  void add_constraint(Zone& zone, const ImpactRecord& r) {
    work_ += static_cast<double>(zone.constraints.size());
    // A pair detected again with (almost) the same normal refreshes its constraint; a different normal is
    // kept as an additional constraint (the pair's relative orientation changed during the step).
    for (ImpactRecord& c : zone.constraints) {
      if (c.kind == r.kind && c.a == r.a && c.b == r.b && c.normal.dot(r.normal) > 0.999) {
        c = r;
        return;
      }
    }
    zone.constraints.push_back(r);
  }

  const ContactGeometry& g_;
  std::vector<int> zone_of_;
  std::vector<Zone> zones_;
  double work_ = 0;
};

ZoneResult project_zone(Zone& zone, const std::vector<Vec3>& target, ContactGeometry& g,
                        const ImpactZoneParams& params, double work_limit) {
  std::sort(zone.nodes.begin(), zone.nodes.end());
  auto local = [&](int node) {
    return static_cast<int>(std::lower_bound(zone.nodes.begin(), zone.nodes.end(), node) - zone.nodes.begin());
  };
  ZoneProblem problem;
  problem.thickness = params.thickness;
  std::vector<Vec3> x;
  for (int n : zone.nodes) {
    problem.target.push_back(target[n]);
    problem.mass.push_back(g.mass[n]);
    x.push_back(g.x1[n]);
  }
  for (const ImpactRecord& r : zone.constraints) {
    ZoneConstraint c;
    c.normal = r.normal;
    c.fixed_offset = r.offset;
    for (int i = 0; i < 4; ++i) {
      const int n = r.nodes[i];
      if (n == kNone || r.weights[i] == 0) continue;
      if (g.movable(n)) {
        c.vars[i] = local(n);
        c.weights[i] = r.weights[i];
      } else {
        c.fixed_offset += r.weights[i] * r.normal.dot(g.x1[n]);
      }
    }
    problem.constraints.push_back(c);
  }
  const ZoneResult result = solve_impact_zone(problem, x, params.method, work_limit);
  for (size_t i = 0; i < zone.nodes.size(); ++i) g.x1[zone.nodes[i]] = x[i];
  return result;
}

// The displacement over the step of the obstacle points the zone's impacts touch: the weighted mean, over its
// constraints, of their immovable nodes' displacements (zero if it touches none, or none of them moved).
Vec3 obstacle_displacement(const Zone& zone, const ContactGeometry& g) {
  Vec3 sum = Vec3::Zero();
  double weight = 0;
  for (const ImpactRecord& r : zone.constraints) {
    for (int i = 0; i < 4; ++i) {
      const int n = r.nodes[i];
      if (n == kNone || r.weights[i] == 0 || g.movable(n)) continue;
      sum += std::abs(r.weights[i]) * (g.x1[n] - g.x0[n]);
      weight += std::abs(r.weights[i]);
    }
  }
  return weight > 0 ? Vec3(sum / weight) : Vec3::Zero();
}

// Rigid fallback: the zone keeps its mean (mass-weighted) displacement of the step, or moves with the obstacles
// it touches, or stays at x0.
void move_rigidly(const Zone& zone, const std::vector<Vec3>& target, ContactGeometry& g) {
  Vec3 displacement = Vec3::Zero();
  if (zone.state == ZoneState::kCarried) displacement = obstacle_displacement(zone, g);
  if (zone.state == ZoneState::kRigid) {
    double mass = 0;
    for (int n : zone.nodes) {
      displacement += g.mass[n] * (target[n] - g.x0[n]);
      mass += g.mass[n];
    }
    displacement /= mass;
  }
  for (int n : zone.nodes) g.x1[n] = g.x0[n] + displacement;
}

// WHY: recorded, not printed: the library has no console; the application shows them unless told to be quiet.
void warn(const ImpactZoneParams& params, const std::string& what, ImpactZoneStats& stats) {
  stats.warnings.push_back("collision: step " + std::to_string(params.step) + ": " + what);
}

}  // namespace

ImpactZoneStats resolve_impacts(ContactGeometry& g, BvhCache& cache, const ImpactZoneParams& params) {
  ImpactZoneStats stats;
  const std::vector<Vec3> target = g.x1;
  ZoneSet zones(g);
  auto finish = [&](bool resolved) {
    stats.resolved = resolved;
    stats.work += zones.work();
    for (const Zone& z : zones.zones()) {
      if (!z.alive || z.nodes.empty()) continue;
      ++stats.zones;
      stats.largest_zone = std::max(stats.largest_zone, static_cast<int>(z.nodes.size()));
      if (z.state == ZoneState::kProjected) continue;
      ++stats.fallback_zones;
      stats.fallback_nodes.insert(stats.fallback_nodes.end(), z.nodes.begin(), z.nodes.end());
    }
    std::sort(stats.fallback_nodes.begin(), stats.fallback_nodes.end());
    stats.fallback_nodes.erase(std::unique(stats.fallback_nodes.begin(), stats.fallback_nodes.end()),
                               stats.fallback_nodes.end());
    return stats;
  };

  // Projection rounds. After the first, only pairs involving nodes of the zones just moved can have changed:
  // every other pair kept its motion and was collision free (or it would be in a zone).
  std::vector<char> moved;
  auto mark_moved = [&](const std::vector<Zone*>& changed) {
    moved.assign(g.node_count(), 0);
    for (const Zone* z : changed)
      for (int n : z->nodes) moved[n] = 1;
  };
  // The work budget is checked only between rounds and shared out before each round's (parallel) projections,
  // so where the response stops does not depend on the threads. A stop leaves the positions part-way: the
  // caller fails the step.
  auto spent = [&] { return stats.work + zones.work(); };
  auto out_of_budget = [&] {
    stats.out_of_budget = true;
    return finish(false);
  };
  for (int iteration = 0; iteration <= params.max_iterations; ++iteration) {
    const std::vector<ImpactRecord> impacts =
        detect_impacts(g, cache, params, iteration ? &moved : nullptr, &stats.work);
    stats.iterations = iteration + 1;
    if (iteration == 0) stats.impacts = static_cast<int>(impacts.size());
    if (impacts.empty()) return finish(true);
    if (iteration == params.max_iterations) {
      zones.add(impacts);
      break;
    }
    zones.add(impacts);
    if (!(spent() < params.work_budget)) return out_of_budget();
    std::vector<Zone*> dirty;
    size_t zone_nodes = 0;
    double zone_work = 0;
    for (Zone& z : zones.zones()) {
      if (!z.alive || !z.dirty) continue;
      dirty.push_back(&z);
      zone_nodes += z.nodes.size();
      zone_work += zone_evaluation_work(static_cast<int>(z.nodes.size()), z.constraints.size());
    }
    // Each zone may spend the budget left in proportion to its size, so that a round cannot overspend it.
    const double left = params.work_budget - spent();
    std::vector<double> work(dirty.size(), 0.0);
    std::vector<char> stopped(dirty.size(), 0);
    // An ill-conditioned projection (zone_solver.hpp) is not applied: the zone moves rigidly from then on,
    // and the fallback rounds below hold it at x0 if that collides too.
    std::vector<double> ill_ratio(dirty.size(), 0.0);
#pragma omp parallel for schedule(dynamic, 1) if (dirty.size() > 1 && zone_nodes > 64)
    for (int k = 0; k < static_cast<int>(dirty.size()); ++k) {
      Zone& z = *dirty[k];
      if (z.state == ZoneState::kProjected) {
        const double share =
            left * (zone_evaluation_work(static_cast<int>(z.nodes.size()), z.constraints.size()) / zone_work);
        const ZoneResult r = project_zone(z, target, g, params, share);
        work[k] = r.work;
        stopped[k] = r.out_of_budget;
        if (r.out_of_budget) continue;
        if (r.ill_conditioned) {
          z.state = ZoneState::kRigid;
          ill_ratio[k] = r.move_ratio;
        }
      }
      if (z.state != ZoneState::kProjected) move_rigidly(z, target, g);
      z.dirty = false;
    }
    for (size_t k = 0; k < dirty.size(); ++k) stats.work += work[k];
    if (std::find(stopped.begin(), stopped.end(), 1) != stopped.end()) return out_of_budget();
    for (size_t k = 0; k < dirty.size(); ++k) {
      if (ill_ratio[k] == 0) continue;
      ++stats.ill_conditioned_zones;
      std::ostringstream what;
      what << "impact zone of " << dirty[k]->nodes.size() << " nodes is ill-conditioned (meeting its constraints "
           << "would move a node " << ill_ratio[k] << "x farther than its deepest violation); moving it rigidly";
      warn(params, what.str(), stats);
    }
    mark_moved(dirty);
  }

  // Fallback rounds: zones still colliding move rigidly, then (if that collides too) stay at x0.
  for (int round = 0; round < params.max_fallback_iterations; ++round) {
    std::vector<Zone*> changed;
    for (Zone& z : zones.zones()) {
      if (!z.alive || !z.dirty) continue;
      changed.push_back(&z);
      z.dirty = false;
      if (z.state == ZoneState::kProjected) {
        z.state = ZoneState::kRigid;
        std::ostringstream what;
        what << "impact zone of " << z.nodes.size() << " nodes unresolved after " << params.max_iterations
             << " iterations; moving it rigidly";
        warn(params, what.str(), stats);
      } else if (z.state == ZoneState::kRigid && round > 0 && obstacle_displacement(z, g).norm() > 0) {
        // WHY: held at its start while an obstacle it touches moves on, the zone is run through: a sheet pressed
        // by a sphere was left behind inside it and later dragged up (conf/metal-crumple-remesh.json). Carried
        // along, it keeps its place against that obstacle.
        z.state = ZoneState::kCarried;
        std::ostringstream what;
        what << "rigid impact zone of " << z.nodes.size() << " nodes still collides; moving it with the "
             << "obstacle it touches";
        warn(params, what.str(), stats);
      } else if ((z.state == ZoneState::kRigid && round > 0) || z.state == ZoneState::kCarried) {
        const bool carried = z.state == ZoneState::kCarried;
        z.state = ZoneState::kFrozen;
        std::ostringstream what;
        what << (carried ? "carried" : "rigid") << " impact zone of " << z.nodes.size()
             << " nodes still collides; holding it at its start position";
        warn(params, what.str(), stats);
      }
      move_rigidly(z, target, g);
    }
    if (changed.empty()) break;
    mark_moved(changed);
    const std::vector<ImpactRecord> impacts = detect_impacts(g, cache, params, &moved, &stats.work);
    ++stats.iterations;
    if (impacts.empty()) return finish(true);
    zones.add(impacts, true);
    if (!(spent() < params.work_budget)) return out_of_budget();
  }
  std::ostringstream what;
  what << "collisions remain unresolved (zones held at their start positions are hit by moving obstacles "
       << "or other zones)";
  warn(params, what.str(), stats);
  return finish(false);
}

}  // namespace arcsim
