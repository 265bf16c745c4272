// Schedule format, genome row construction and the time query (actuation/schedule.h).
// Lives in test_hardware because the schedule library does not need the solver.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "actuation/schedule.h"
#include "core/errors.h"

using namespace morphfem;

namespace {

const std::string kExamples = std::string(MORPHFEM_SOURCE_DIR) + "/examples/schedules/";

ScheduleMatrix rolling_matrix() {
  ScheduleMatrix m(10, std::vector<int>(8, 0));
  for (int b = 1; b <= 8; ++b) m[b - 1][8 - b] = 1;  // bladder 8 in column 1, ..., bladder 1 in column 8
  return m;
}

ScheduleMatrix inching_matrix() {
  ScheduleMatrix m(10, std::vector<int>(8, 0));
  for (int c = 0; c < 8; c += 2) {
    for (int b = 0; b < 4; ++b) m[b][c] = 1;  // bladders 1-4 on odd (1-based) columns
    m[9][c] = 1;                              // foot B on odd columns
    m[8][c + 1] = 1;                          // foot A on even columns
  }
  return m;
}

std::string expect_error(const std::string& text) {
  try {
    parse_schedule(text, "bad.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return "";
}

}  // namespace

TEST(GenomeRow, ZeroFrequencyIsAllOnes) {
  for (int phi = 0; phi <= 8; ++phi) EXPECT_EQ(genome_row(0, phi), std::vector<int>(8, 1));
}

TEST(GenomeRow, PeriodicFromPhi) {
  // f = 1, phi = 0: columns 1, 3, 5, 7.
  EXPECT_EQ(genome_row(1, 0), (std::vector<int>{1, 0, 1, 0, 1, 0, 1, 0}));
  // f = 1, phi = 1: columns 2, 4, 6, 8.
  EXPECT_EQ(genome_row(1, 1), (std::vector<int>{0, 1, 0, 1, 0, 1, 0, 1}));
  // f = 2, phi = 4: anchor 5, then 5 +/- 3 -> 2, 8.
  EXPECT_EQ(genome_row(2, 4), (std::vector<int>{0, 1, 0, 0, 1, 0, 0, 1}));
  // f = 3, phi = 5: anchor 6, 6 - 4 = 2.
  EXPECT_EQ(genome_row(3, 5), (std::vector<int>{0, 1, 0, 0, 0, 1, 0, 0}));
}

TEST(GenomeRow, PhiBeyondTheRow) {
  // phi = 8 with T = 8: the anchor column 9 is outside the row; its neighbours count.
  EXPECT_EQ(genome_row(1, 8), (std::vector<int>{1, 0, 1, 0, 1, 0, 1, 0}));  // 9-2, 9-4, ...
  EXPECT_EQ(genome_row(3, 8), (std::vector<int>{1, 0, 0, 0, 1, 0, 0, 0}));  // 9-4 = 5, 9-8 = 1
  EXPECT_EQ(genome_row(7, 8), (std::vector<int>{1, 0, 0, 0, 0, 0, 0, 0}));  // 9-8 = 1
  EXPECT_EQ(genome_row(8, 8), std::vector<int>(8, 0));                      // 9 +/- 9 = 0, 18
}

TEST(GenomeRow, LargestFrequencyGivesOneColumn) {
  for (int phi = 0; phi < 8; ++phi) {
    std::vector<int> expect(8, 0);
    expect[phi] = 1;  // period 9 > T: only the anchor
    EXPECT_EQ(genome_row(8, phi), expect) << "phi " << phi;
  }
}

TEST(GenomeRow, BruteForceDefinition) {
  // Compare with the literal definition for every (f, phi) and several T.
  for (int T : {1, 3, 8, 16})
    for (int f = 1; f <= 8; ++f)
      for (int phi = 0; phi <= 8; ++phi) {
        std::vector<int> expect(T, 0);
        for (int k = -40; k <= 40; ++k) {
          int c = phi + 1 + k * (f + 1);
          if (c >= 1 && c <= T) expect[c - 1] = 1;
        }
        EXPECT_EQ(genome_row(f, phi, T), expect) << "f " << f << " phi " << phi << " T " << T;
      }
}

TEST(GenomeRow, RejectsOutOfRange) {
  EXPECT_THROW(genome_row(9, 0), std::invalid_argument);
  EXPECT_THROW(genome_row(-1, 0), std::invalid_argument);
  EXPECT_THROW(genome_row(1, 9), std::invalid_argument);
}

TEST(GenomeMatrix, ReproducesRolling) {
  Genome g;
  for (int b = 1; b <= 8; ++b) g.rows[b - 1] = {7, 8 - b};
  g.rows[8] = g.rows[9] = {8, 8};
  EXPECT_EQ(genome_matrix(g), rolling_matrix());
}

TEST(GenomeMatrix, ReproducesInching) {
  Genome g;
  for (int b = 0; b < 4; ++b) g.rows[b] = {1, 0};
  for (int b = 4; b < 8; ++b) g.rows[b] = {8, 8};
  g.rows[8] = {1, 1};  // foot A: even columns
  g.rows[9] = {1, 0};  // foot B: odd columns
  EXPECT_EQ(genome_matrix(g), inching_matrix());
}

TEST(ScheduleFile, ExamplesMatchTheHandDesignedGaits) {
  Schedule roll = read_schedule(kExamples + "rolling.yaml");
  EXPECT_EQ(roll.matrix, rolling_matrix());
  EXPECT_EQ(roll.orientation_deg, 0);
  EXPECT_EQ(roll.core_pressure_pa, 12000);
  EXPECT_EQ(roll.total_columns(), 16);
  EXPECT_NEAR(roll.duration(), 19.792, 1e-9);  // 16 x 1.237 s

  Schedule inch = read_schedule(kExamples + "inching.yaml");
  EXPECT_EQ(inch.matrix, inching_matrix());
  EXPECT_EQ(inch.orientation_deg, 90);
  EXPECT_EQ(inch.core_pressure_pa, 0);

  Schedule genome = read_schedule(kExamples + "rolling_genome.yaml");
  EXPECT_EQ(genome.matrix, rolling_matrix());
  ASSERT_TRUE(genome.genome.has_value());
  EXPECT_EQ(genome.core_pressure_pa, 12000);
}

TEST(ScheduleFile, ListRowsAndLevels) {
  std::string text = R"(morphfem_schedule: 1
column_s: 0.5
matrix:
  - [1, 0]
  - [0, 1]
  - "00"
  - "00"
  - "00"
  - "00"
  - "00"
  - "00"
  - "11"
  - "01"
pressures:
  bladders: {inflate_pa: 20000, deflate_pa: 1000, ramp_s: 0.1}
  b2: {inflate_pa: 30000}
  feet: {inflate_pa: 40000, deflate_pa: -50000}
  core: {pressure_pa: 8000}
)";
  Schedule s = parse_schedule(text, "x.yaml");
  EXPECT_EQ(s.columns(), 2);
  EXPECT_EQ(s.levels[0].inflate_pa, 20000);
  EXPECT_EQ(s.levels[1].inflate_pa, 30000);
  EXPECT_EQ(s.levels[1].deflate_pa, 1000);
  EXPECT_EQ(s.levels[1].inflate_ramp_s, 0.1);
  EXPECT_EQ(s.levels[kChannelFootA].deflate_pa, -50000);
  EXPECT_EQ(s.levels[kChannelCore].inflate_pa, 8000);
  // Round trip through to_yaml.
  Schedule back = parse_schedule(s.to_yaml(), "roundtrip.yaml");
  EXPECT_EQ(back.matrix, s.matrix);
  for (int c = 0; c < kNumChannels; ++c) {
    EXPECT_EQ(back.levels[c].inflate_pa, s.levels[c].inflate_pa);
    EXPECT_EQ(back.levels[c].deflate_pa, s.levels[c].deflate_pa);
    EXPECT_EQ(back.levels[c].inflate_ramp_s, s.levels[c].inflate_ramp_s);
  }
}

TEST(ScheduleFile, ErrorsNameFileLineAndKey) {
  const std::string head = "morphfem_schedule: 1\n";
  auto rows = [](int n, const std::string& row) {
    std::string s = "matrix:\n";
    for (int i = 0; i < n; ++i) s += "  - \"" + row + "\"\n";
    return s;
  };
  std::string e;
  e = expect_error(head + rows(9, "0101"));
  EXPECT_NE(e.find("bad.yaml:3:3: matrix"), std::string::npos) << e;
  EXPECT_NE(e.find("expected 10 rows"), std::string::npos) << e;

  e = expect_error(head + "matrix:\n  - \"0102\"\n" + rows(9, "0101").substr(8));
  EXPECT_NE(e.find("bad.yaml:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("matrix[0]"), std::string::npos) << e;
  EXPECT_NE(e.find("'2'"), std::string::npos) << e;

  e = expect_error(head + "matrix:\n  - \"0101\"\n  - \"011\"\n" + rows(8, "0101").substr(8));
  EXPECT_NE(e.find("bad.yaml:4:"), std::string::npos) << e;
  EXPECT_NE(e.find("3 columns"), std::string::npos) << e;

  e = expect_error(head + "colum_s: 1\n" + rows(10, "01"));
  EXPECT_NE(e.find("bad.yaml:2:"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key 'colum_s'"), std::string::npos) << e;

  e = expect_error(head + "column_s: fast\n" + rows(10, "01"));
  EXPECT_NE(e.find("bad.yaml:2:11: column_s"), std::string::npos) << e;
  EXPECT_NE(e.find("expected a number, got 'fast'"), std::string::npos) << e;

  e = expect_error(head + "core_pressure_pa: -200000\n" + rows(10, "01"));  // below vacuum
  EXPECT_NE(e.find("core_pressure_pa"), std::string::npos) << e;
  EXPECT_NE(e.find("outside the allowed range"), std::string::npos) << e;

  e = expect_error(head + "genome:\n  rows: [[0,0],[0,0],[0,0],[0,0],[0,0],[0,0],[0,0],[0,0],[0,0],[9,1]]\n");
  EXPECT_NE(e.find("genome.rows[9].f"), std::string::npos) << e;
  EXPECT_NE(e.find("bad.yaml:3:"), std::string::npos) << e;

  e = expect_error(head + rows(10, "01") + "pressures:\n  b9: {inflate_pa: 1}\n");
  EXPECT_NE(e.find("unknown key 'b9'"), std::string::npos) << e;

  e = expect_error(head + rows(10, "01") + "pressures:\n  bladders: {inflate_pa: 1, ramp_s: 1, inflate_ramp_s: 2}\n");
  EXPECT_NE(e.find("not both"), std::string::npos) << e;

  e = expect_error(head + "matrix: [\n");
  EXPECT_NE(e.find("YAML syntax error"), std::string::npos) << e;

  e = expect_error(rows(10, "01"));
  EXPECT_NE(e.find("morphfem_schedule"), std::string::npos) << e;

  e = expect_error(head);
  EXPECT_NE(e.find("missing 'matrix'"), std::string::npos) << e;

  try {
    read_schedule("/nonexistent/x.yaml");
    ADD_FAILURE();
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("/nonexistent/x.yaml"), std::string::npos);
  }
}

// The cadence block: settle mode with its hold and timeout, kept by to_yaml; an
// unknown mode, a negative hold, a timeout of 0 or an unknown key name the file,
// line and key.
TEST(ScheduleFile, CadenceKeys) {
  std::string matrix = "matrix:\n";
  for (int i = 0; i < kNumRows; ++i) matrix += "  - \"01\"\n";
  const std::string head = "morphfem_schedule: 1\n";
  Schedule fixed = parse_schedule(head + matrix, "fixed.yaml");
  EXPECT_EQ(fixed.cadence.mode, Cadence::Mode::fixed);
  Schedule s = parse_schedule(head + "cadence: {mode: settle, min_hold_s: 0.4, timeout_s: 12}\n" + matrix, "s.yaml");
  EXPECT_EQ(s.cadence.mode, Cadence::Mode::settle);
  EXPECT_EQ(s.cadence.min_hold_s, 0.4);
  EXPECT_EQ(s.cadence.timeout_s, 12);
  Schedule back = parse_schedule(s.to_yaml(), "roundtrip.yaml");
  EXPECT_EQ(back.cadence.mode, Cadence::Mode::settle);
  EXPECT_EQ(back.cadence.min_hold_s, 0.4);
  EXPECT_EQ(back.cadence.timeout_s, 12);
  std::string e = expect_error(head + "cadence: {mode: eager}\n" + matrix);
  EXPECT_NE(e.find("bad.yaml:2:17: cadence.mode"), std::string::npos) << e;
  EXPECT_NE(e.find("expected fixed or settle, got 'eager'"), std::string::npos) << e;
  e = expect_error(head + "cadence: {mode: settle, min_hold_s: -0.5}\n" + matrix);
  EXPECT_NE(e.find("bad.yaml:2:37: cadence.min_hold_s"), std::string::npos) << e;
  EXPECT_NE(e.find("outside the allowed range"), std::string::npos) << e;
  e = expect_error(head + "cadence: {mode: settle, timeout_s: 0}\n" + matrix);
  EXPECT_NE(e.find("cadence.timeout_s"), std::string::npos) << e;
  e = expect_error(head + "cadence: {mode: settle, hold_s: 1}\n" + matrix);
  EXPECT_NE(e.find("unknown key 'hold_s'"), std::string::npos) << e;
  e = expect_error(head + "cadence: settle\n" + matrix);
  EXPECT_NE(e.find("bad.yaml:2:10: cadence"), std::string::npos) << e;
  // Built in code: validate() names the key.
  Schedule code = Schedule::from_matrix(s.matrix);
  code.cadence.min_hold_s = -1;
  EXPECT_THROW(code.validate(), InputError);
}

// A channel has settled when its ramp is over and its pressure is within the
// tolerance; a column may end once every channel has and the hold has passed.
TEST(ScheduleCadence, SettledAndHeld) {
  EXPECT_TRUE(channel_settled(23100, 25000, 25000, 2000));
  EXPECT_FALSE(channel_settled(22900, 25000, 25000, 2000));
  EXPECT_FALSE(channel_settled(24000, 24000, 25000, 2000)) << "setpoint still ramping";
  const Cadence c{Cadence::Mode::settle, 0.5, 10};
  EXPECT_FALSE(c.may_end(-1, 0.9, 1.0, true)) << "the rest phase lasts rest_s";
  EXPECT_TRUE(c.may_end(-1, 1.0, 1.0, true));
  EXPECT_FALSE(c.may_end(3, 0.4, 1.0, true));
  EXPECT_TRUE(c.may_end(3, 0.5, 1.0, true));
  EXPECT_FALSE(c.may_end(3, 2.0, 1.0, false));
  EXPECT_FALSE(c.timed_out(-1, 100)) << "the rest phase has no timeout";
  EXPECT_TRUE(c.timed_out(0, 10.1));
}

TEST(ScheduleQuery, StatesAndStepSetpoints) {
  Schedule s = Schedule::from_matrix(rolling_matrix(), 1.237, 2, 0, 12000);
  // Column 1 (t in [0, 1.237)): bladder 8 inflated; column 9 wraps to column 1.
  for (double t : {0.0, 0.6, 1.2369, 9.896 + 0.1}) {
    ScheduleState st = s.at(t);
    for (int b = 0; b < 8; ++b) EXPECT_EQ(st.bladder_inflated[b], b == 7) << "t " << t << " b " << b;
    EXPECT_FALSE(st.foot_a_active);
    EXPECT_FALSE(st.foot_b_active);
    EXPECT_DOUBLE_EQ(st.pressure_pa[7], 25000);
    EXPECT_DOUBLE_EQ(st.pressure_pa[0], 0);
    EXPECT_DOUBLE_EQ(st.pressure_pa[kChannelFootA], -80000);
    EXPECT_DOUBLE_EQ(st.pressure_pa[kChannelCore], 12000);
  }
  EXPECT_EQ(s.at(1.237 * 7 + 0.01).column, 7);
  EXPECT_TRUE(s.at(1.237 * 7 + 0.01).bladder_inflated[0]);
  // Rest before and after: bladders deflated, feet active.
  for (double t : {-1.0, 19.8, 100.0}) {
    ScheduleState st = s.at(t);
    EXPECT_EQ(st.column, -1);
    EXPECT_TRUE(st.foot_a_active && st.foot_b_active);
    EXPECT_DOUBLE_EQ(st.pressure_pa[7], 0);
    EXPECT_DOUBLE_EQ(st.pressure_pa[kChannelFootB], 50000);
  }
}

TEST(ScheduleQuery, RampsArePiecewiseLinearAndContinuous) {
  Schedule s = Schedule::from_matrix(inching_matrix(), 1.0, 1);
  s.levels[0] = {20000, 0, 0.4, 0.8};  // rise 50 kPa/s, fall 25 kPa/s
  // Column 1 inflates bladder 1 from the rest level 0.
  EXPECT_NEAR(s.at(0.0).pressure_pa[0], 0, 1e-9);
  EXPECT_NEAR(s.at(0.2).pressure_pa[0], 10000, 1e-6);
  EXPECT_NEAR(s.at(0.5).pressure_pa[0], 20000, 1e-6);
  // Column 2 deflates it at 25 kPa/s.
  EXPECT_NEAR(s.at(1.4).pressure_pa[0], 10000, 1e-6);
  EXPECT_NEAR(s.at(1.9).pressure_pa[0], 0, 1e-6);
  // A ramp longer than a column is cut short and continues from where it was.
  s.levels[0] = {20000, 0, 2.0, 2.0};  // 10 kPa/s
  EXPECT_NEAR(s.at(1.0).pressure_pa[0], 10000, 1e-6);
  EXPECT_NEAR(s.at(1.5).pressure_pa[0], 5000, 1e-6);
  // Continuity: no jumps anywhere.
  double prev = s.at(0).pressure_pa[0];
  for (double t = 0.001; t < 8.5; t += 0.001) {
    double v = s.at(t).pressure_pa[0];
    EXPECT_LE(std::abs(v - prev), 10000 * 0.001 + 1e-6) << "t " << t;
    prev = v;
  }
  // The core ramps up during settling.
  s.settle_s = 2;
  s.levels[kChannelCore] = {12000, 0, 1.0, 1.0};
  EXPECT_NEAR(s.at(-2).pressure_pa[kChannelCore], 0, 1e-9);
  EXPECT_NEAR(s.at(-1.5).pressure_pa[kChannelCore], 6000, 1e-6);
  EXPECT_NEAR(s.at(0).pressure_pa[kChannelCore], 12000, 1e-6);
}

TEST(PressureLog, ReadsSamplesEventsAndRecoversTheMatrix) {
  std::string path = std::string(MORPHFEM_BINARY_DIR) + "/test_schedule_log.csv";
  Schedule s = Schedule::from_matrix(inching_matrix(), 0.5, 1);
  {
    std::ofstream o(path);
    o << "# morphfem hw log v1\n# column_s: 0.5\n";
    o << "t_s,kind,column";
    for (int c = 0; c < kNumChannels; ++c) o << ",cmd_" << channel_name(c);
    for (int c = 0; c < kNumChannels; ++c) o << ",meas_" << channel_name(c);
    o << ",message\n";
    o << "0,event,,";
    for (int c = 0; c < 2 * kNumChannels; ++c) o << ",";
    o << "start\n";
    for (double t = 0; t < 4.0; t += 0.05) {
      ScheduleState st = s.at(t);
      o << t << ",sample," << st.column;
      for (int c = 0; c < kNumChannels; ++c) o << "," << st.pressure_pa[c];
      for (int c = 0; c < kNumChannels; ++c) o << "," << st.pressure_pa[c] * 0.9;
      o << ",\n";
    }
    o << "4.0,sample,7,1,2";  // a line cut short by a crash
  }
  PressureTrace tr = read_pressure_log(path);
  EXPECT_EQ(tr.channels.size(), 11u);
  ASSERT_EQ(tr.events.size(), 1u);
  EXPECT_EQ(tr.events[0].message, "start");
  ASSERT_EQ(tr.metadata.size(), 1u);
  EXPECT_EQ(tr.metadata[0].first, "column_s");
  EXPECT_EQ(tr.metadata[0].second, "0.5");
  EXPECT_NEAR(tr.measured_at(0, 0.25), 22500, 1e-6);
  EXPECT_NEAR(tr.commanded_at(kChannelFootA, 0.75), 50000, 1e-6);
  EXPECT_EQ(tr.to_matrix(0.5, 8, s.levels), inching_matrix());
  std::remove(path.c_str());
}
