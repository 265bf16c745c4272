// Scene -> model: the term builders' table and the order of the terms it gives
// the assembler (the order of the energy table's columns and of every sum over
// terms), and the handles the observers read.
#include <gtest/gtest.h>
#include <petscsys.h>

#include <string>
#include <vector>

#include "sim/model.h"
#include "sim/scene.h"
#include "sim/terms.h"

using namespace morphfem;

TEST(Model, TermBuildersInTheirOrder) {
  std::vector<std::string> names;
  for (const NamedTermBuilder& b : term_builders()) names.push_back(b.name);
  EXPECT_EQ(names, (std::vector<std::string>{"elastic", "membranes", "gravity", "body_force", "cavities",
                                             "volume_cavities", "tractions", "pulls", "inertia", "damping", "ground",
                                             "friction", "self_contact", "lattice_floor"}));
}

TEST(Model, BlockOnSlopeHasTheTermsItDeclares) {
  const Scene scene = read_scene(MORPHFEM_SOURCE_DIR "/examples/block_on_slope.yaml");
  Mesh mesh = build_scene_mesh(scene, PETSC_COMM_WORLD);
  const auto model = build_model(scene, mesh, PETSC_COMM_WORLD);
  std::vector<std::string> names;
  for (const auto& term : model->assembler->terms()) names.push_back(term->name());
  ASSERT_EQ(names.size(), 5u);
  EXPECT_EQ(names[0], "elastic");
  EXPECT_EQ(names[1], "body_force");  // gravity, one term per region with a density
  EXPECT_EQ(names[2], "inertia");
  EXPECT_EQ(names[3].rfind("ground:", 0), 0u) << names[3];
  EXPECT_EQ(names[4].rfind("friction", 0), 0u) << names[4];
  EXPECT_TRUE(model->elastic && model->inertia && model->ground && model->friction);
  EXPECT_FALSE(model->damping || model->self_contact);
  EXPECT_TRUE(model->cavities.empty() && model->volume_driven.empty() && model->pulls.empty());
  EXPECT_NEAR(model->mass_kg, 1000 * 0.02 * 0.02 * 0.02, 1e-12);
  EXPECT_EQ(&model->mesh, &mesh);
  ASSERT_TRUE(model->solver);
  EXPECT_EQ(model->solver->time(), 0.0);
}
