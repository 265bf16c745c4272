// Calibration files: SHA-256 against the FIPS 180-4 examples, write/read round trip,
// data checksums, and malformed files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "core/calibration_file.h"
#include "core/errors.h"

namespace morphfem {
namespace {

TEST(CalibrationFile, Sha256MatchesTheStandardExamples) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000, 'a')).size(), 64u);
}

class CalibrationFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(::testing::TempDir()) / ("morphfem_calib_file_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  std::filesystem::path dir_;
};

TEST_F(CalibrationFileTest, RoundTripAndChecksums) {
  const std::string data = write("wood_inflated_01.csv", "Time (s);Load (N)\n0;0\n1;0.5\n");
  Calibration c;
  c.kind = "friction";
  c.command = "morphfem calibrate friction --weight-N 1.2 \"dir with space\"";
  c.created = "2026-11-22T08:00:00Z";
  c.group = {{"surface", "wood"}, {"foot_state", "inflated"}};
  c.parameters = {{"mu_static", {0.7012345678, 0.0012, 0.6988, 0.7036, "-"}},
                  {"stiffness_N_per_m", {250.5, 0.8, 248.9, 252.1, "N/m"}}};
  c.fit = {{"method", "PETSc TAO POUNDERS"}, {"residual_rms_N", "0.003"}};
  c.data = {{data, sha256_file(data), "wood_inflated_01"}};
  const std::string path = (dir_ / "calibration.yaml").string();
  write_calibration_file(path, c);
  const Calibration back = read_calibration_file(path);
  EXPECT_EQ(back.kind, "friction");
  EXPECT_EQ(back.command, c.command);
  EXPECT_EQ(back.group.at("foot_state"), "inflated");
  ASSERT_EQ(back.parameters.size(), 2u);
  EXPECT_EQ(back.parameters[0].first, "mu_static");  // file order kept
  EXPECT_DOUBLE_EQ(back.parameter("mu_static").value, 0.7012345678);
  EXPECT_DOUBLE_EQ(back.parameter("mu_static").ci_high, 0.7036);
  EXPECT_EQ(back.parameter("stiffness_N_per_m").unit, "N/m");
  EXPECT_EQ(back.fit.at("method"), "PETSc TAO POUNDERS");
  ASSERT_EQ(back.data.size(), 1u);
  EXPECT_EQ(back.data[0].sha256, sha256_file(data));
  EXPECT_TRUE(verify_calibration_data(back).empty());
  write("wood_inflated_01.csv", "Time (s);Load (N)\n0;0\n1;0.6\n");
  ASSERT_EQ(verify_calibration_data(back).size(), 1u);
  EXPECT_NE(verify_calibration_data(back)[0].find("checksum differs"), std::string::npos);
  EXPECT_THROW(back.parameter("mu_kinetic"), InputError);
}

TEST_F(CalibrationFileTest, MalformedFilesAreInputErrors) {
  const auto expect_error = [&](const std::string& text, const std::string& needle) {
    const std::string path = write("bad.yaml", text);
    try {
      read_calibration_file(path);
      ADD_FAILURE() << "no InputError for: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  expect_error("kind: friction\nparameters: {mu: {value: 0.5}}\nextra: 1\n", "unknown key 'extra'");
  expect_error("kind: friction\nparameters: {mu: {value: abc}}\n", "must be a number");
  expect_error("kind: friction\nparameters: {mu: {value: 0.5, sd: 1}}\n", "unknown key 'sd'");
  expect_error("kind: friction\n", "'parameters'");
  expect_error("kind: friction\nparameters: {mu: {value: 0.5, ci95: [1]}}\n", "ci95");
  expect_error("kind: [friction\n", "YAML syntax error");
  EXPECT_THROW(read_calibration_file((dir_ / "absent.yaml").string()), InputError);
}

}  // namespace
}  // namespace morphfem
