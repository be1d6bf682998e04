// The reference-mesh surface: a frozen copy of the initial rest triangles (paper §5.2 "Rest space position").
#include <cmath>
#include <sstream>

#include "math/errors.hpp"
#include "restshape/reference_surface.hpp"
#include "restshape/triangle_tree.hpp"

namespace arcsim {

namespace {

class MeshReference : public ReferenceSurface {
 public:
  explicit MeshReference(std::vector<std::array<Vec3, 3>> triangles) : tree_(std::move(triangles)) {}

  Vec3 closest_point(const Vec3& u) const override { return u.allFinite() ? tree_.closest_point(u) : u; }

  // Nearest hit of the line through u, on either side (a concave region puts the surface behind u, paper
  // Fig. 6a); the watertight triangle test cannot slip between neighbours, and grazing or missing lines fall
  // back to the closest point, as do points beyond a boundary of an open reference.
  Vec3 project(const Vec3& u, const Vec3& direction, double max_distance) const override {
    if (!u.allFinite()) return u;
    const double length = direction.norm();
    if (!(length > 0) || !std::isfinite(length) || !(max_distance >= 0)) return closest_point(u);
    Vec3 hit;
    if (tree_.nearest_line_hit(u, direction / length, max_distance, hit)) return hit;
    return closest_point(u);
  }

  // Chord dihedral of the four points moved to their closest reference points. Verts of the remeshed rest mesh
  // already lie on the reference, so this is the rest-space dihedral of the new edge's two faces, which is the
  // bending model's stress-free angle; projecting first guards against points left off the surface.
  double rest_dihedral(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) const override {
    const double theta = dihedral_angle(closest_point(a), closest_point(b), closest_point(c), closest_point(d));
    return std::isfinite(theta) ? theta : 0;
  }

  std::string kind() const override { return "mesh"; }

 private:
  TriangleTree tree_;
};

}  // namespace

std::unique_ptr<ReferenceSurface> make_mesh_reference(const Mesh& rest_mesh) {
  std::vector<std::array<Vec3, 3>> triangles;
  for (size_t f = 0; f < rest_mesh.faces.size(); ++f) {
    const Face& face = rest_mesh.faces[f];
    if (face.dead) continue;
    std::array<Vec3, 3> tri;
    for (int i = 0; i < 3; ++i) {
      tri[i] = rest_mesh.verts[face.v[i]].u;
      if (!tri[i].allFinite()) {
        std::ostringstream msg;
        msg << "mesh reference: face " << f + 1 << " has a rest position that is not finite";
        throw InputError(msg.str());
      }
    }
    triangles.push_back(tri);
  }
  if (triangles.empty()) throw InputError("mesh reference: the rest mesh has no faces");
  return std::make_unique<MeshReference>(std::move(triangles));
}

}  // namespace arcsim
