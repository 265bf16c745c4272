// Parametric meshes of the shape-changing pneumatic soft robot (ROBOT.md), flat
// configuration, built with the gmsh OpenCASCADE kernel from axis-aligned boxes joined
// by boolean fragments (conforming: bladders and skin share their interface nodes).
// Registered in geometry_registry() as `robot_voxel` and `robot_physical`.
//
// Frame (both builders): x across the body, y along it (the rolling / tube axis),
// z up; the body occupies [0, width] x [0, length] x [0, height], so z = 0 is the
// lowest plane (the bottom faces of the lower bladders, i.e. flat ground).
// Stacking in z: lower bladders, bottom skin layer, core gap (sealed by solid bonded
// strips along the long edges x ~ 0 and x ~ width and end seals at y ~ 0 and
// y ~ length), top skin layer, upper bladders. Bladders 1..4 are on top with
// increasing x, 5..8 below with decreasing x, so 1..8 runs around the cross-section.
// The feet are the bottom faces of the bottom skin layer at y in [0, foot_length]
// (foot_a) and [length - foot_length, length] (foot_b); in robot_voxel also that
// layer's end and side faces in those bands (the lattice's feet are whole voxels, and
// an arched body stands on its feet's outer edges).
//
// Common parameters: mesh_size [m] (required), order (1 or 2, default 1).
//
// robot_voxel (the voxel study's model; defaults in m):
//   width 0.15, length 0.22, layer_thickness 0.01, core_gap 0.002,
//   edge_width 0.01 (bonded long-edge strips), end_seal 0.01 (strips closing the gap at
//   the two ends), bladder_thickness 0.02, bladder_width 0.03 (four columns per face,
//   evenly spaced from x = 0 to x = width), bladder_start 0.03, bladder_end 0.19 (y),
//   foot_length 0.03. end_seal 0 (either preset) leaves the core open at both ends,
//   like the lattice's layers (bonded only along the long edges) and the physical
//   sleeve around its inner balloon; its pressure then needs volume_axes [x, z].
//   Volumes: skin (both layers and the bonding strips), bladder_1 .. bladder_8 (solid).
//   Surfaces: core_wall (closed inner boundary of the core gap), bottom (every
//   downward-facing outer face: lower-bladder bottoms at z = 0 and uncovered skin
//   bottom, feet included), foot_a, foot_b (bottom faces in bottom, end and side faces
//   in outer), outer (the rest of the
//   outer boundary). core_wall, bottom and outer together hold every boundary face once.
//   end_a, end_b (also in outer): the end faces at y = 0 and y = length (a short slice
//   with u_y = 0 on both is the mid-length cross-section in plane strain).
//
// robot_physical (the physical laminate; defaults in m):
//   width 0.10 (flat width = half of the 0.20 circumference), length 0.15 (tube axis),
//   skin_thickness 0.003 per layer, fabric_thickness 0.0005 (fabric sheet at the
//   mid-thickness of each skin layer), core_gap 0.001, edge_width 0.005, end_seal 0.005,
//   bladder_thickness 0.003, bladder_wall 0.0008 (DS30 wall around each chamber),
//   bladder_width 0.02, foot_length 0.02 (bladders span y in [foot_length,
//   length - foot_length]), bladder_end_walls 1 (0: chambers open at both ends, as
//   sleeves along y, e.g. through a whole plane-strain slice with foot_length 0),
//   foot_pad 0 (> 0: a solid pad that thick under the skin in each foot band, volume
//   `foot`, standing in for the foot balloon in its lamina; its bottom face is the foot.
//   A pad thicker than bladder_thickness lifts the body: the robot stands on its feet
//   with the pads' bottoms at z = 0, as in a pull test).
//   bladder_bond_width (default bladder_width: each chamber bonded to the skin over its
//   full width; less: bonded along a central DS30 strip that wide, the chamber standing
//   bladder_gap (default bladder_wall) off the skin, so that its floor is free on
//   either side of the strip and the chamber unfolds like a flattened tube; surfaces
//   bladder_1_gap .. bladder_8_gap name the outside faces in each gap, for self-contact),
//   bladder_mesh_size (default mesh_size; smaller: the mesh size at the chambers'
//   corners, graded to mesh_size away from them),
//   fabric: solid (default: the volume `fabric`) or membrane (no fabric volume: each skin
//   layer is DS10 throughout, split at its mid-thickness by an internal surface
//   `fabric_sheet` for a membrane term, fem/membrane.h; fabric_thickness is then unused).
//   Volumes: skin (DS10: both layers without the fabric, the bonding strips), fabric,
//   bladder_1 .. bladder_8 (DS30 chamber walls), foot (with foot_pad > 0).
//   Surfaces: core_wall, bladder_1_wall .. bladder_8_wall (closed chamber cavities),
//   bottom, foot_a, foot_b, outer (as for robot_voxel), fabric_sheet (membrane fabric).
#pragma once
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "core/params.h"
#include "mesh/mesh.h"

namespace morphfem {

Mesh build_robot_voxel(const ParamSet& params);
Mesh build_robot_physical(const ParamSet& params);

// The voxel study's lattice over a robot_voxel body of these parameters: one box of
// reference space per lattice voxel (ROBOT.md), for the lattice's floor contact
// (contact/lattice_floor.h). Skin layers are split into voxel x voxel columns (one
// voxel through a layer), each bladder block into voxel-wide columns and
// round(bladder_thickness / (bladder_min_scale voxel)) voxels through its
// thickness (the lattice's deflated bladder voxels, 0.2 voxel thick: two). Along y a
// body shorter than a voxel (a slice) is one voxel. The bonding strips in the core
// gap belong to no box (the lattice's layers touch there). base_scale is the box's
// lattice scale when nothing grows: (1, 1, box thickness / voxel).
struct LatticeVoxelBox {
  std::string region;  // volume region of the box's cells
  Eigen::Vector3d lo, hi, base_scale;
};
std::vector<LatticeVoxelBox> robot_voxel_lattice(const ParamSet& params, double voxel, double bladder_min_scale);

}  // namespace morphfem
