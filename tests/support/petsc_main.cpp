// GoogleTest main with PETSc (and MPI) initialised around the tests.
#include <gtest/gtest.h>
#include <petscsys.h>

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  if (PetscInitialize(&argc, &argv, nullptr, nullptr)) return 1;
  const int status = RUN_ALL_TESTS();
  PetscFinalize();
  return status;
}
