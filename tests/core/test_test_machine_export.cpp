// Test-machine export reader: every dialect (separators, decimal commas, quotes,
// units row or units in names, several specimen blocks), the real tensile exports
// in shared/data/materials, and each kind of malformed file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "core/paths.h"
#include "core/test_machine_export.h"

namespace morphfem {
namespace {

const std::string kDataDir = shared_data_dir() + "/materials";

// Every dialect below writes the same two rows: t = 0.5, 1.0 s, extension 0.8,
// 1.6 mm and load 1.25, 2.5 N.
void expect_pull_rows(const SpecimenExport& s) {
  ASSERT_EQ(s.columns.size(), 3u);
  ASSERT_EQ(s.rows(), 2u);
  const ExportColumn* t = s.find(ExportQuantity::time);
  const ExportColumn* x = s.find(ExportQuantity::displacement);
  const ExportColumn* f = s.find(ExportQuantity::force);
  ASSERT_TRUE(t && x && f);
  EXPECT_DOUBLE_EQ(t->values[1], 1.0);
  EXPECT_DOUBLE_EQ(x->values[0], 0.8e-3);
  EXPECT_DOUBLE_EQ(x->values[1], 1.6e-3);
  EXPECT_DOUBLE_EQ(f->values[0], 1.25);
  EXPECT_DOUBLE_EQ(f->values[1], 2.5);
}

TEST(TestMachineExport, SemicolonDecimalCommaUnitsInNames) {
  const auto blocks = parse_test_machine_export(
      "Surface;wood;;\nFoot state;inflated;;\n;;;\nTime (s);Extension (mm);Load (N)\n0,5;0,8;1,25\n1;1,6;2,5\n",
      "a.csv");
  ASSERT_EQ(blocks.size(), 1u);
  expect_pull_rows(blocks[0]);
  EXPECT_EQ(blocks[0].header_value("surface"), "wood");
  EXPECT_EQ(blocks[0].header_value("foot"), "inflated");
  EXPECT_EQ(blocks[0].label, "a");
  EXPECT_EQ(blocks[0].find(ExportQuantity::force)->name, "Load");
}

TEST(TestMachineExport, CommaQuotedBluehillUnitsRow) {
  // Bluehill 2 raw data: header, blank line, names row, units row, quoted values.
  const auto blocks = parse_test_machine_export(
      "\"Specimen "
      "label\",\"S3\"\r\n\"Sample\",\"feet\"\r\n\r\n\"Time\",\"Extension\",\"Load\"\r\n\"(s)\",\"(mm)\",\"(N)\"\r\n"
      "\"0.50000\",\"0.80000\",\"1.25000\"\r\n\"1.00000\",\"1,6\",\"2.50000\"\r\n",
      "Specimen_RawData_3.csv");
  ASSERT_EQ(blocks.size(), 1u);
  expect_pull_rows(blocks[0]);
  EXPECT_EQ(blocks[0].label, "S3");
  EXPECT_EQ(blocks[0].find(ExportQuantity::displacement)->unit, "mm");
}

TEST(TestMachineExport, TabSeparatedUnitsInBracketsAndOtherUnits) {
  const auto blocks = parse_test_machine_export(
      "Time [ms]\tExtension [cm]\tLoad [kN]\n500\t0,08\t0,00125\n1000\t0.16\t0.0025\n", "t.txt");
  ASSERT_EQ(blocks.size(), 1u);
  expect_pull_rows(blocks[0]);
}

TEST(TestMachineExport, SeveralSpecimenBlocksInOneFile) {
  const std::string block1 =
      "Specimen;1\nSurface;acrylic\n\nTime (s);Extension (mm);Load (N)\n0.5;0.8;1.25\n1;1.6;2.5\n";
  const std::string block2 =
      "\nSpecimen;2\nSurface;wood\n\nTime (s);Extension (mm);Load (N)\n0.5;0.8;1.25\n\n1;1.6;2.5\n";
  const auto blocks = parse_test_machine_export(block1 + block2, "two.csv");
  ASSERT_EQ(blocks.size(), 2u);
  expect_pull_rows(blocks[0]);
  expect_pull_rows(blocks[1]);  // a blank line inside the data does not end the block
  EXPECT_EQ(blocks[0].label, "1");
  EXPECT_EQ(blocks[1].label, "2");
  EXPECT_EQ(blocks[1].header_value("surface"), "wood");
  EXPECT_EQ(blocks[1].first_line, 8);
}

TEST(TestMachineExport, StrainAndStressColumnsAndHeaderNumbers) {
  const auto blocks = parse_test_machine_export(
      "Specimen Length (mm);33\nSpeed (mm/min);100\nTime (s);Strain (%);Engineering Strain;Stress (MPa)\n"
      "0.1;10;0.1;0.05\n0.2;20;0.2;0.1\n",
      "s.csv");
  const SpecimenExport& s = blocks.at(0);
  EXPECT_DOUBLE_EQ(s.find(ExportQuantity::strain, "", {"engineering"})->values[1], 0.2);
  EXPECT_DOUBLE_EQ(s.find(ExportQuantity::strain, "engineering")->values[1], 0.2);
  EXPECT_DOUBLE_EQ(s.find(ExportQuantity::stress)->values[0], 0.05e6);
  double length = 0, speed = 0;
  EXPECT_TRUE(s.header_si("length", length));
  EXPECT_DOUBLE_EQ(length, 0.033);
  EXPECT_TRUE(s.header_si("speed", speed));
  EXPECT_DOUBLE_EQ(speed, 0.1 / 60.0);
  EXPECT_FALSE(s.header_si("width", length));
}

TEST(TestMachineExport, ReadsTheRealTensileExports) {
  const auto blocks = read_test_machine_exports({kDataDir});
  ASSERT_EQ(blocks.size(), 2u);
  for (const auto& s : blocks) {
    SCOPED_TRACE(s.file);
    EXPECT_EQ(s.columns.size(), 5u);
    EXPECT_GT(s.rows(), 300u);
    EXPECT_EQ(s.header_value("standard"), "ASTM D412");
    ASSERT_NE(s.find(ExportQuantity::strain, "engineering"), nullptr);
    ASSERT_NE(s.find(ExportQuantity::stress, "engineering"), nullptr);
    ASSERT_NE(s.find(ExportQuantity::strain, "true"), nullptr);
  }
  const SpecimenExport& ds10 = blocks[0];
  EXPECT_EQ(ds10.header_value("material"), "DragonSkin10");
  EXPECT_NEAR(ds10.find(ExportQuantity::stress, "engineering")->values[0], 1988.01196097173, 1e-9);
  EXPECT_NEAR(ds10.find(ExportQuantity::strain, "engineering")->values[0], 0.0445783731527225, 1e-16);
  EXPECT_EQ(ds10.rows(), 475u - 18u);
}

void expect_error(const std::string& text, const std::string& where, const std::string& needle) {
  try {
    parse_test_machine_export(text, "bad.csv");
    ADD_FAILURE() << "no InputError; expected '" << needle << "'";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), where) << e.what();
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(TestMachineExport, MalformedFilesSayFileLineAndReason) {
  const std::string head = "Surface;wood\n\n";
  // Missing units row: names without units and no row of units under them.
  expect_error(head + "Time;Extension;Load\n0.5;0.8;1.25\n1;1.6;2.5\n", "bad.csv:3", "missing units row");
  // Unrecognised unit.
  expect_error(head + "Time (s);Extension (furlong);Load (N)\n0.5;0.8;1.25\n", "bad.csv:3", "unrecognised unit");
  expect_error(head + "Time;Extension;Load\n(s);(mm);(bar)\n0.5;0.8;1.25\n", "bad.csv:4", "unrecognised unit 'bar'");
  // Truncated line (the last row cut short).
  expect_error(head + "Time (s);Extension (mm);Load (N)\n0.5;0.8;1.25\n1;1.6\n", "bad.csv:5", "truncated line");
  expect_error(head + "Time (s);Extension (mm);Load (N)\n0.5;0.8;1.25\n1;;2.5\n", "bad.csv:5", "empty field");
  // Wrong separator: one row written with commas in a ';' file.
  expect_error(head + "Time (s);Extension (mm);Load (N)\n0.5;0.8;1.25\n1;1.6;2.5\n1.5,2.4,3.75\n", "bad.csv:6",
               "wrong separator");
  // Names row split by another separator than the data.
  expect_error("Time (s),Extension (mm),Load (N)\n0.5;0.8;1.25\n1;1.6;2.5\n", "bad.csv:1", "wrong separator");
  // Text in a numeric column.
  expect_error(head + "Time (s);Extension (mm);Load (N)\n0.5;0.8;1.25\n1;1.6;overload\n", "bad.csv:5",
               "text 'overload' in numeric column 'Load (N)'");
  // No data at all, and a block with no names row.
  expect_error("Surface;wood\nTime (s);Load (N)\n", "bad.csv", "no data rows");
  expect_error("0.5;0.8;1.25\n1;1.6;2.5\n", "bad.csv:1", "no column names row");
  EXPECT_THROW(read_test_machine_export("/nonexistent/x.csv"), InputError);
}

}  // namespace
}  // namespace morphfem
