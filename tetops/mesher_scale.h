// The scale the meshers work at. TetGen and CGAL Mesh_3 decide with some tolerances in absolute
// units: on a surface 1e-15 across CGAL's exact circumradius computation divides by zero (SIGFPE), and
// on one 1e12 across its exuder leaves 1.9-degree tets (0 degrees at 1e20). So a surface far from
// unit size is meshed as a copy scaled by a power of two to a bounding-box diagonal in [1, 2), and
// the mesh is scaled back. Multiplying by 2^k is exact in binary floating point (short of overflow
// and subnormals), so the surface's vertices keep their coordinates bit for bit. Surfaces of ordinary
// size are meshed as they are, which keeps every mesh made at those sizes what it was.
#pragma once

#include "tetops/size_field.h"
#include "tetops/tet_mesh.h"
#include "tetops/triangle_surface.h"

namespace waxwork {

// The power of two k by which to scale `surface` before meshing: 0 when its bounding-box diagonal
// lies in [2^-10, 2^20] (about 1e-3 to 1e6), otherwise the k that brings it into [1, 2). Throws
// InvalidArgumentError when the diagonal is zero or not finite.
int mesher_scale_exponent(const TriangleSurface& surface);

// The surface with every coordinate multiplied by 2^exponent.
TriangleSurface scaled_surface(const TriangleSurface& surface, int exponent);

// The size field with its lengths multiplied by 2^exponent (grading is a ratio; infinity stays).
SizeField scaled_size_field(const SizeField& size, int exponent);

// Multiplies the rest positions of every vertex by 2^exponent (piece transforms are untouched: a
// freshly meshed volume has none).
void scale_positions(TetMesh& mesh, int exponent);

}  // namespace waxwork
