// Reference surfaces for curved rest shapes (paper §5.2 "Rest space position"). The rest-space (material)
// positions u of vertices that remeshing creates or moves are put back onto a fixed copy of the initial rest
// surface, so that a curved rest shape survives any number of refinements and coarsenings without the
// resampling error of placing new vertices on chords.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "math/types.hpp"
#include "mesh/mesh.hpp"
#include "scene/transform.hpp"

namespace arcsim {

// Where rest-space (material) positions of new or moved vertices are put so that a curved rest shape is kept
// exactly through any number of refinements and coarsenings: a high-resolution copy of the initial rest surface.
class ReferenceSurface {
 public:
  virtual ~ReferenceSurface() = default;
  // Projects rest point u onto the surface along the line u + s * direction (s of either sign, the hit nearest
  // to u; paper Fig. 6a), falling back to the closest surface point when the line misses or the hit is farther
  // than max_distance. direction need not be unit; a zero direction means closest point.
  virtual Vec3 project(const Vec3& u, const Vec3& direction, double max_distance) const = 0;
  virtual Vec3 closest_point(const Vec3& u) const = 0;
  // Signed dihedral angle (rad) the reference surface has across a rest-space edge from a to b whose two faces
  // have wing points c (face a,b,c) and d (face b,a,d): the rest angle a new edge must get so that a curved
  // rest shape stays curved. For a flat (linear) reference it is 0. Sphere and mesh: the chord dihedral
  // dihedral_angle(P(a), P(b), P(c), P(d)) (mesh.hpp, same sign convention) of the four points moved to their
  // closest surface points P. Points already on the surface are kept, so a remeshed edge gets exactly the
  // rest-space dihedral of its two faces, the bending model's stress-free angle.
  virtual double rest_dihedral(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) const = 0;
  virtual std::string kind() const = 0;  // "linear", "sphere", "mesh"
};

// Identity: project and closest_point return u unchanged; rest_dihedral is 0.
std::unique_ptr<ReferenceSurface> make_linear_reference();
// Least-squares sphere through the points (ARCSim: centre from all point pairs, radius = RMS distance).
// Throws InputError if fewer than 4 points or they are (nearly) coplanar.
std::unique_ptr<ReferenceSurface> make_sphere_reference(const std::vector<Vec3>& points);
// Copies the rest triangles (live faces' verts' u) and builds an AABB tree for ray casts and closest points.
// Throws InputError if the mesh has no live face.
std::unique_ptr<ReferenceSurface> make_mesh_reference(const Mesh& rest_mesh);

// True if the rest shape is curved: some rest face normal differs from the first face's by more than ~1e-6 rad,
// or some rest vert lies off the plane of the faces by more than 1e-9 of the mesh size.
bool rest_shape_is_curved(const Mesh& mesh);

// Chooses a cloth's reference from the scene's `reference` string:
//  - "sphere": least-squares sphere fitted to the live rest verts;
//  - "linear" (the scene default) or "": linear for a flat rest shape, but the mesh reference (the cloth's own
//    rest triangles) for a curved one, since an identity projection would let remeshing flatten it;
//  - anything else: path of an OBJ file whose node positions, placed with `placement` (the cloth's scene
//    transform, as the cloth's own rest shape is), are the reference triangles.
// `context` names the scene and cloth in error messages (e.g. "scene.json: cloths[0].reference"). Throws
// InputError for an unreadable reference mesh or a degenerate sphere fit.
std::unique_ptr<ReferenceSurface> choose_reference(const std::string& reference, const Mesh& cloth_mesh,
                                                   const Transform& placement, const std::string& context);

// Load-time reprojection (ARCSim): for a "sphere" reference every live vert's u is replaced by its closest point
// on the sphere and every node's world position x (and x0) is set to its first vert's u. Other kinds: no change.
void reproject_rest_positions(Mesh& mesh, const ReferenceSurface& reference);

}  // namespace arcsim
