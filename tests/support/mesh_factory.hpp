// Procedural meshes for tests: rectangular grids with either diagonal direction, and strips of (nearly)
// equilateral triangles in two orientations.
#pragma once

#include "mesh/mesh.hpp"

namespace arcsim::testing {

enum class Diagonal { kForward, kBackward, kAlternating };

// nx x ny cells over [x0, x0 + width] x [y0, y0 + height] in the z = 0 plane; rest = world.
Mesh make_grid(int nx, int ny, double width, double height, Diagonal diagonal = Diagonal::kForward,
               double x0 = 0, double y0 = 0);

// A strip over [x0, x0 + length] x [0, width] made of rows of nearly equilateral triangles. With
// rows_along_length the triangle rows run along x (edges parallel to the strip axis); otherwise they run
// along y (edges perpendicular to the axis). `target_edge` is the approximate edge length (m). With rows along
// the length, odd rows get an extra point at x = `straight_line_x` (if inside), so that a clamp along that line
// is straight.
Mesh make_equilateral_strip(double length, double width, double target_edge, bool rows_along_length,
                            double x0 = 0, double straight_line_x = -1e300);

}  // namespace arcsim::testing
