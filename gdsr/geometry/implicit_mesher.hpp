// A closed, manifold, outward-oriented triangle mesh of the zero set of an implicit
// function (negative inside), deterministically: marching tetrahedra on a regular grid,
// then CGAL isotropic remeshing to a target edge length, then vertices projected back onto
// the zero set by Newton steps. Units are the caller's (metres in gdsr).
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <functional>

namespace gdsr {

// field(p) < 0 inside; its zero set must lie strictly inside the box [lo, hi]. grid_step:
// marching-tetrahedra cell size (the box is padded by two cells); edge: target edge length
// of the remeshing. Throws when no surface or a non-manifold one is found.
TriMesh mesh_implicit(const std::function<double(const Vec3&)>& field, Vec3 lo, Vec3 hi, double grid_step, double edge);

}  // namespace gdsr
