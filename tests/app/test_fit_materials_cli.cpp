// `morphfem fit-materials`: its options reach fem/material_fit.h's fit_materials (the
// shared Dragon Skin exports), bad ones are refused with an InputError.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "app/commands.h"
#include "core/errors.h"
#include "core/paths.h"

namespace morphfem {
namespace {

TEST(FitMaterialsCommand, PassesItsOptionsAndRefusesBadOnes) {
  const std::string data = shared_data_dir() + "/materials";
  std::ostringstream json;
  EXPECT_EQ(fit_materials_main({"--json", "--max-strain", "1.5", "--data-dir", data}, data + "/nowhere", json), 0);
  EXPECT_NE(json.str().find("\"max_strain\": 1.5"), std::string::npos) << json.str();
  EXPECT_NE(json.str().find("\"model\": \"yeoh\""), std::string::npos) << json.str();

  std::ostringstream ignored;
  EXPECT_THROW(fit_materials_main({"--max-strian", "2"}, data, ignored), InputError);
  EXPECT_THROW(fit_materials_main({"--max-strain"}, data, ignored), InputError);
  EXPECT_THROW(fit_materials_main({"--max-strain", "x"}, data, ignored), InputError);
  EXPECT_THROW(fit_materials_main({"--max-strain", "0.05"}, data, ignored), InputError);
  EXPECT_THROW(fit_materials_main({}, data + "/nowhere", ignored), InputError);
}

}  // namespace
}  // namespace morphfem
