// PETSC_CHECK(call): turns a PETSc error code into a C++ exception that names the
// call, so failures surface as clear messages instead of aborts.
#pragma once
#include <petscsys.h>

#include <stdexcept>
#include <string>

#define PETSC_CHECK(call)                                                            \
  do {                                                                               \
    PetscErrorCode petsc_check_ierr_ = (call);                                       \
    if (petsc_check_ierr_) {                                                         \
      const char* petsc_check_text_ = nullptr;                                       \
      PetscErrorMessage(petsc_check_ierr_, &petsc_check_text_, nullptr);             \
      throw std::runtime_error(std::string("PETSc error in ") + #call + ": " +       \
                               (petsc_check_text_ ? petsc_check_text_ : "unknown")); \
    }                                                                                \
  } while (0)
