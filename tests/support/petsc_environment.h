// PETSc (and MPI) for the test binaries whose tests need Vec, Mat or an Assembler:
// initialised once before the first test, finalised after the last. Include it in
// exactly one source file of a test binary.
#pragma once
#include <gtest/gtest.h>
#include <petscsys.h>

namespace morphfem::testing {

class PetscEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    PetscBool up = PETSC_FALSE;
    PetscInitialized(&up);
    if (!up) {
      ASSERT_EQ(PetscInitializeNoArguments(), 0);
    }
  }
  void TearDown() override { PetscFinalize(); }
};

inline const auto* const petsc_environment = ::testing::AddGlobalTestEnvironment(new PetscEnvironment);

}  // namespace morphfem::testing
