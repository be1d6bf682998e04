// The separate pieces of a sheet after it has torn or shattered: faces joined through shared nodes (a crack's
// two lips have their own nodes once opened). Shard counts and size distributions for reports and tests.
#pragma once

#include <vector>

#include "mesh/mesh.hpp"

namespace arcsim {

struct Piece {
  int faces = 0;
  double rest_area = 0;   // m^2, sum of the faces' rest areas
  double world_area = 0;  // m^2, in the current positions
};

// Every piece of the mesh's live faces, largest (by face count, then rest area) first.
std::vector<Piece> mesh_pieces(const Mesh& mesh);

// The piece of each face (index into mesh_pieces' order; -1 for dead faces).
std::vector<int> face_pieces(const Mesh& mesh);

}  // namespace arcsim
