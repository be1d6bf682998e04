// Linear and sphere references, the choice of a cloth's reference, and load-time reprojection. The mesh
// reference is in mesh_reference.cpp.
#include "restshape/reference_surface.hpp"

#include <cmath>
#include <sstream>

#include "io/obj.hpp"
#include "math/errors.hpp"
#include "restshape/sphere_fit.hpp"

namespace arcsim {

namespace {

// Rest shapes whose face normals all agree within this angle (rad) count as flat.
constexpr double kFlatAngle = 1e-6;
// ... and whose verts are off the common plane by at most this fraction of the mesh size.
constexpr double kFlatOffset = 1e-9;

class LinearReference : public ReferenceSurface {
 public:
  Vec3 project(const Vec3& u, const Vec3& direction, double max_distance) const override { return u; }
  Vec3 closest_point(const Vec3& u) const override { return u; }
  // A flat reference has no curvature for a new edge to keep.
  double rest_dihedral(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) const override { return 0; }
  std::string kind() const override { return "linear"; }
};

class SphereReference : public ReferenceSurface {
 public:
  explicit SphereReference(const Sphere& sphere) : sphere_(sphere) {}

  Vec3 closest_point(const Vec3& u) const override {
    if (!u.allFinite()) return u;
    const Vec3 w = u - sphere_.center;
    const double r = w.norm();
    // The centre is equally far from every surface point: any one will do.
    if (!(r > 0)) return sphere_.center + sphere_.radius * Vec3::UnitZ();
    return sphere_.center + (sphere_.radius / r) * w;
  }

  // Roots of |u + s D - c|^2 = R^2 for unit D: s^2 + 2 b s + k = 0 with b = (u - c).D, k = |u - c|^2 - R^2.
  Vec3 project(const Vec3& u, const Vec3& direction, double max_distance) const override {
    const double length = direction.norm();
    if (!(length > 0) || !std::isfinite(length) || !u.allFinite()) return closest_point(u);
    const Vec3 D = direction / length;
    const Vec3 w = u - sphere_.center;
    const double r = w.norm();
    const double b = w.dot(D);
    const double k = (r - sphere_.radius) * (r + sphere_.radius);  // factored: exact sign near the surface
    const double discriminant = b * b - k;
    if (discriminant < 0) return closest_point(u);
    // Cancellation-free pair of roots; the one of smaller magnitude is the hit nearest to u.
    const double q = -(b + std::copysign(std::sqrt(discriminant), b));
    double s = q;
    if (q != 0 && std::abs(k / q) < std::abs(s)) s = k / q;
    if (!(std::abs(s) <= max_distance)) return closest_point(u);
    // Radial clean-up removes the rounding of u + s D, leaving the point on the sphere to machine precision.
    return closest_point(u + s * D);
  }

  // Chord dihedral of the four points moved radially onto the sphere: the rest angle the bending model
  // measures between two flat triangles inscribed in the sphere.
  double rest_dihedral(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) const override {
    const double theta = dihedral_angle(closest_point(a), closest_point(b), closest_point(c), closest_point(d));
    return std::isfinite(theta) ? theta : 0;
  }

  std::string kind() const override { return "sphere"; }

 private:
  Sphere sphere_;
};

std::vector<Vec3> live_rest_positions(const Mesh& mesh) {
  std::vector<Vec3> points;
  for (const Vert& v : mesh.verts)
    if (!v.dead && !v.faces.empty()) points.push_back(v.u);
  return points;
}

// Triangles of an OBJ file's node positions after the placement transform.
std::unique_ptr<ReferenceSurface> load_reference_mesh(const std::string& path, const Transform& placement,
                                                      const std::string& context) {
  const ObjData obj = read_obj(path);
  if (obj.tris.empty()) throw InputError(context + ": reference mesh " + path + " has no faces");
  std::vector<Vec3> node_u(obj.node_x.size());
  for (size_t n = 0; n < obj.node_x.size(); ++n) node_u[n] = placement.apply(obj.node_x[n]);
  // Only rest positions and faces are read by make_mesh_reference; one vert per corner avoids any topology
  // requirement (a reference surface may be non-manifold).
  std::vector<Vec3> corner_u;
  std::vector<int> corner_node;
  std::vector<std::array<int, 3>> tris;
  for (const auto& tri : obj.tris) {
    std::array<int, 3> t;
    for (int i = 0; i < 3; ++i) {
      t[i] = static_cast<int>(corner_u.size());
      corner_u.push_back(node_u[obj.vert_node[tri[i]]]);
      corner_node.push_back(static_cast<int>(corner_node.size()));
    }
    tris.push_back(t);
  }
  std::vector<Vec3> corner_x = corner_u;
  try {
    return make_mesh_reference(Mesh::from_triangles(corner_x, corner_u, corner_node, tris));
  } catch (const InputError& e) {
    throw InputError(context + ": reference mesh " + path + ": " + e.what());
  }
}

}  // namespace

std::unique_ptr<ReferenceSurface> make_linear_reference() { return std::make_unique<LinearReference>(); }

std::unique_ptr<ReferenceSurface> make_sphere_reference(const std::vector<Vec3>& points) {
  Sphere sphere;
  if (!fit_sphere(points, sphere)) {
    std::ostringstream msg;
    msg << "sphere reference: cannot fit a sphere to " << points.size()
        << " rest positions (need at least 4 finite points not all in one plane)";
    throw InputError(msg.str());
  }
  return std::make_unique<SphereReference>(sphere);
}

bool rest_shape_is_curved(const Mesh& mesh) {
  bool have_plane = false;
  Vec3 normal = Vec3::Zero(), origin = Vec3::Zero();
  for (const Face& f : mesh.faces) {
    if (f.dead) continue;
    const Vec3& u0 = mesh.verts[f.v[0]].u;
    const Vec3 c = (mesh.verts[f.v[1]].u - u0).cross(mesh.verts[f.v[2]].u - u0);
    if (!(c.norm() > 0)) continue;  // a degenerate face has no normal to compare
    const Vec3 n = c.normalized();
    if (!have_plane) {
      have_plane = true;
      normal = n;
      origin = u0;
      continue;
    }
    if (std::atan2(normal.cross(n).norm(), normal.dot(n)) > kFlatAngle) return true;
  }
  if (!have_plane) return false;
  Vec3 lo = Vec3::Constant(kInfinity), hi = Vec3::Constant(-kInfinity);
  for (const Vert& v : mesh.verts)
    if (!v.dead) {
      lo = lo.cwiseMin(v.u);
      hi = hi.cwiseMax(v.u);
    }
  const double size = (hi - lo).norm();
  for (const Vert& v : mesh.verts)
    if (!v.dead && std::abs(normal.dot(v.u - origin)) > kFlatOffset * size) return true;
  return false;
}

std::unique_ptr<ReferenceSurface> choose_reference(const std::string& reference, const Mesh& cloth_mesh,
                                                   const Transform& placement, const std::string& context) {
  if (reference == "linear" || reference.empty())
    return rest_shape_is_curved(cloth_mesh) ? make_mesh_reference(cloth_mesh) : make_linear_reference();
  if (reference == "sphere") {
    try {
      return make_sphere_reference(live_rest_positions(cloth_mesh));
    } catch (const InputError& e) {
      throw InputError(context + ": " + e.what());
    }
  }
  return load_reference_mesh(reference, placement, context);
}

void reproject_rest_positions(Mesh& mesh, const ReferenceSurface& reference) {
  if (reference.kind() != "sphere") return;
  // Plastic offsets (rest angle minus rest dihedral, e.g. from OBJ edge records) survive the move.
  std::vector<double> offset(mesh.edges.size(), 0);
  for (size_t e = 0; e < mesh.edges.size(); ++e)
    if (!mesh.edges[e].dead) offset[e] = mesh.edges[e].rest_theta - mesh.rest_dihedral(static_cast<int>(e));
  for (Vert& v : mesh.verts)
    if (!v.dead) v.u = reference.closest_point(v.u);
  for (Node& n : mesh.nodes) {
    if (n.dead) continue;
    for (int v : n.verts)
      if (!mesh.verts[v].dead) {
        n.x = n.x0 = mesh.verts[v].u;
        break;
      }
  }
  mesh.update_rest_data();
  for (size_t e = 0; e < mesh.edges.size(); ++e)
    if (!mesh.edges[e].dead) mesh.edges[e].rest_theta = offset[e] + mesh.rest_dihedral(static_cast<int>(e));
}

}  // namespace arcsim
