// The energy terms of a scene: one builder per scene section, registered by name
// in one table. build_model runs the builders in the table's order, which is the
// order of the terms in the Assembler and of the columns of the energy table;
// sums over the terms, hence the results to the last bit, follow that order.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "contact/lattice_floor.h"
#include "fem/material.h"
#include "mesh/mesh.h"
#include "sim/model.h"
#include "sim/scene.h"

namespace morphfem {

// Adds the terms of one scene section (none if the scene has no such section) to
// model.assembler and keeps the handles the observers read. Throws InputError
// naming the scene key on bad input.
using TermBuilder = void (*)(const Scene& scene, Model& model);

struct NamedTermBuilder {
  const char* name;
  TermBuilder build;
};

// elastic (with growth), membranes, gravity, body_force, cavities, volume_cavities
// (gas, then volume-controlled), tractions, pulls, inertia, damping, ground,
// friction, self_contact, lattice_floor: in this order.
const std::vector<NamedTermBuilder>& term_builders();

// Shear modulus [Pa] of the material under most of the surfaces' area (each
// boundary face takes the material of the cell it bounds; 0 if none). The
// default contact barrier stiffness is E ~ 3 mu of the material a contact presses
// into, not of the stiffest material in the body: with kappa 2,300x the skin's E
// (the 100 MPa fabric sheet, whose 0.5 mm edges reach the outer surface, inside a
// 43 kPa skin) a node entering the barrier rests within sqrt(p / 3 kappa) dhat of
// its edge, where the barrier is nearly cubic, and Newton converges linearly
// (residual / 4 per iteration) until it gets there.
double contact_shear_modulus(const Mesh& mesh, const std::vector<std::shared_ptr<const Material>>& materials,
                             const std::vector<std::string>& surfaces);

// The lattice voxels of a robot_voxel scene with contact.lattice_floor as floor
// contact points (contact/lattice_floor.h): the material point at each voxel box's
// centre, its footprint, its sphere radius L (s_x + s_y + s_z)/6 growing with the
// region's actuation.growth, and its friction coefficient: the region's, or for skin
// voxels over a foot's y range (both layers, as the lattice's foot voxels) the
// foot's mu(t) from actuation.feet. Throws InputError naming the scene key.
std::vector<LatticePoint> lattice_points(const Scene& scene, const Mesh& mesh);

}  // namespace morphfem
