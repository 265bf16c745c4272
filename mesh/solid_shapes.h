// Solid shapes for the contact verification cases (VERIFICATION.md cases 9 and 10),
// built with the gmsh OpenCASCADE kernel and registered in geometry_registry() as
// `hemisphere` and `solid_cylinder`.
//
// hemisphere: the lower half-ball z <= 0 of radius R centred at the origin; its pole
//   P = (0, 0, -R) is the contact point with a plane below it (Hertz contact).
//   Parameters [m]: radius, mesh_size (far from P), contact_size (element size within
//   refine_radius of P, default mesh_size), refine_radius (default radius / 4);
//   quarter (0/1, default 1): only x, y >= 0 (symmetry planes x = 0 and y = 0);
//   order (1 or 2). The size grows linearly from contact_size at distance
//   refine_radius from P to mesh_size at refine_radius + 2 (mesh_size - contact_size)
//   (gradient 1/2), through a gmsh background size field.
//   Surfaces: flat (z = 0), sphere (the curved face), and with quarter = 1 sym_x
//   (x = 0), sym_y (y = 0). Volume: body.
//
// solid_cylinder: a solid cylinder (or, with inner_radius > 0, a thick-walled tube)
//   of radius R about the y axis, y in [0, length]; it touches the plane
//   z = -R along the line x = 0 (rolling along x).
//   Parameters [m]: radius, length, inner_radius (default 0: solid), mesh_size,
//   order (1 or 2).
//   Surfaces: outer (r = R), ymin (y = 0), ymax (y = length), and inner (r =
//   inner_radius) for a tube. Volume: body.
#pragma once
#include "core/params.h"
#include "mesh/mesh.h"

namespace morphfem {

Mesh build_hemisphere(const ParamSet& params);
Mesh build_solid_cylinder(const ParamSet& params);

}  // namespace morphfem
