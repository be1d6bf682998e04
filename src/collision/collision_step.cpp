#include "collision/collision_step.hpp"

#include <algorithm>

namespace arcsim {

namespace {

std::vector<ContactBody> bodies_of(const std::vector<const Mesh*>& cloths, const std::vector<const Mesh*>& obstacles) {
  std::vector<ContactBody> bodies;
  for (const Mesh* m : cloths) bodies.push_back({m, true});
  for (const Mesh* m : obstacles) bodies.push_back({m, false});
  return bodies;
}

// CCD contact distance (m): well below the gap the projection enforces.
double contact_distance(const CollisionSettings& s) { return std::min(1e-6, 0.1 * s.projection_thickness); }

}  // namespace

void ImpactZoneTotals::add(const ImpactZoneStats& s) {
  ++steps;
  impacts += s.impacts;
  zones += s.zones;
  iterations += s.iterations;
  largest_zone = std::max(largest_zone, s.largest_zone);
  fallback_zones += s.fallback_zones;
  ill_conditioned_zones += s.ill_conditioned_zones;
  unresolved_steps += !s.resolved;
  work += s.work;
  largest_work = std::max(largest_work, s.work);
  for (const std::string& w : s.warnings)
    if (static_cast<int>(first_warnings.size()) < kMaxWarnings) first_warnings.push_back(w);
  warnings += static_cast<long long>(s.warnings.size());
}

std::vector<std::vector<ContactTerm>> CollisionHandler::proximity_terms(const std::vector<const Mesh*>& cloths,
                                                                        const std::vector<const Mesh*>& obstacles,
                                                                        const CollisionSettings& settings,
                                                                        double dt) {
  std::vector<std::vector<ContactTerm>> terms(cloths.size());
  if (cloths.empty()) return terms;
  build_contact_geometry(bodies_of(cloths, obstacles), ContactStage::kBeforeStep, dt, geometry_);
  ProximityParams params;
  params.thickness = settings.repulsion_thickness;
  params.stiffness = settings.stiffness;
  params.friction = settings.friction;
  params.obstacle_friction = settings.obstacle_friction;
  params.floor = settings.floor;
  params.floor_height = settings.floor_height;
  params.neighbour_thickness = std::min(settings.repulsion_thickness, settings.neighbour_thickness);
  const std::vector<ProximityContact> contacts = find_proximities(geometry_, cache_, params);
  totals_.proximities += static_cast<long long>(contacts.size());
  for (size_t c = 0; c < cloths.size(); ++c)
    terms[c] = contact_terms(geometry_, contacts, static_cast<int>(c), dt);
  return terms;
}

ImpactZoneStats CollisionHandler::resolve_collisions(const std::vector<Mesh*>& cloths,
                                                     const std::vector<const Mesh*>& obstacles,
                                                     const CollisionSettings& settings, double dt) {
  fallback_nodes_.assign(cloths.size(), {});
  if (cloths.empty()) return {};
  const std::vector<const Mesh*> cloth_view(cloths.begin(), cloths.end());
  build_contact_geometry(bodies_of(cloth_view, obstacles), ContactStage::kAfterStep, dt, geometry_);
  ImpactZoneParams params;
  params.thickness = settings.projection_thickness;
  params.contact_distance = contact_distance(settings);
  params.floor = settings.floor;
  params.floor_height = settings.floor_height;
  params.step = settings.step;
  params.stacked_lips_keep_start_side = settings.stacked_lips_keep_start_side;
  params.work_budget = settings.work_budget;
  const ImpactZoneStats stats = resolve_impacts(geometry_, cache_, params);
  totals_.add(stats);
  if (stats.out_of_budget) return stats;

  for (size_t c = 0; c < cloths.size(); ++c) {
    Mesh& mesh = *cloths[c];
    const int begin = geometry_.meshes[c].node_begin, end = geometry_.meshes[c].node_end;
    for (int n : stats.fallback_nodes)
      if (n >= begin && n < end) fallback_nodes_[c].push_back(n - begin);
    for (size_t i = 0; i < mesh.nodes.size(); ++i) {
      Node& n = mesh.nodes[i];
      const Vec3 moved = geometry_.x1[begin + i] - n.x;
      if (moved.isZero(0)) continue;
      n.x += moved;
      if (dt > 0) n.v += moved / dt;
    }
  }
  return stats;
}

}  // namespace arcsim
