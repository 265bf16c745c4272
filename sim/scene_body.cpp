// The body of a scene: its geometry (or mesh file), the material of each volume
// region, membranes on surfaces, and the boundary conditions.
#include <filesystem>

#include "sim/scene_reader.h"

namespace morphfem {

void read_geometry(const SceneReader& r, const YAML::Node& root, Scene& scene) {
  if (root["geometry"] && root["mesh"]) r.fail(root["mesh"], "mesh", "give either geometry or mesh, not both");
  if (const auto g = root["geometry"]) {
    scene.geometry = r.params(g, "geometry");
    if (!scene.geometry.has("type")) r.fail(g, "geometry", "missing key 'type'");
  } else if (const auto m = root["mesh"]) {
    r.allow(m, "mesh");
    if (!m["file"]) r.fail(m, "mesh", "missing key 'file'");
    std::filesystem::path file = r.text(m["file"], "mesh.file");
    if (file.is_relative()) file = std::filesystem::path(r.file).parent_path() / file;
    scene.mesh_file = file.string();
  } else {
    throw InputError(r.file, "missing 'geometry' or 'mesh'");
  }
}

void read_materials(const SceneReader& r, const YAML::Node& materials, Scene& scene) {
  if (!materials || !materials.IsMap() || materials.size() == 0)
    throw InputError(materials ? r.at(materials) : r.file, "'materials' must map each volume region to a material");
  for (const auto& kv : materials) {
    const std::string region = kv.first.as<std::string>();
    ParamSet p = r.params(kv.second, "materials." + region);
    if (!p.has("model")) r.fail(kv.second, "materials." + region, "missing key 'model'");
    scene.materials[region] = p;
  }
}

// Surface region -> sheet (fem/membrane.h).
void read_membranes(const SceneReader& r, const YAML::Node& membranes, Scene& scene) {
  if (!membranes) return;
  if (!membranes.IsMap())
    r.fail(membranes, "membranes", "expected a mapping: surface region -> {model, thickness, ...}");
  for (const auto& kv : membranes) {
    const std::string surface = kv.first.as<std::string>();
    const std::string key = "membranes." + surface;
    ParamSet p = r.params(kv.second, key);
    if (!p.has("model")) r.fail(kv.second, key, "missing key 'model'");
    if (!p.has("thickness")) r.fail(kv.second, key, "missing key 'thickness' [m]");
    MembraneSpec spec;
    spec.surface = surface;
    const KeyRange& thickness = *find_scene_key(key + ".thickness")->range;
    spec.thickness = p.number_in("thickness", thickness.lo, thickness.hi);
    spec.law = make_membrane_law(p.without("thickness"));
    spec.where = p.where("model");
    scene.membranes.push_back(spec);
  }
}

void read_boundary(const SceneReader& r, const YAML::Node& b, Scene& scene) {
  if (!b) return;
  if (!b.IsSequence()) r.fail(b, "boundary", "expected a list of {surface, fix | displacement}");
  for (const auto& item : b) {
    r.allow(item, "boundary");
    if (!item["surface"]) r.fail(item, "boundary", "missing key 'surface'");
    BoundarySpec spec;
    spec.surface = r.text(item["surface"], "boundary.surface");
    spec.where = r.at(item);
    if (item["fix"] && item["displacement"]) r.fail(item, "boundary", "give either 'fix' or 'displacement'");
    if (item["fix"])
      spec.components = r.axes(item["fix"], "boundary.fix");
    else if (item["displacement"]) {
      spec.components = {true, true, true};
      spec.displacement = r.vector3(item["displacement"], "boundary.displacement");
    } else {
      r.fail(item, "boundary", "missing 'fix: [x, y, z]' or 'displacement: [ux, uy, uz]'");
    }
    scene.boundary.push_back(spec);
  }
}

}  // namespace morphfem
