// Frame encoding/parsing of both protocols, and fuzzing of the reply parsers.
#include <gtest/gtest.h>

#include <random>

#include "core/errors.h"
#include "hardware/emulator.h"
#include "hardware/protocols.h"

using namespace morphfem::hw;

TEST(Alicat, CommandsAndFrames) {
  EXPECT_EQ(alicat_poll('A'), "A\r");
  EXPECT_EQ(alicat_setpoint('C', -80000), "CS -80.000\r");
  AlicatFrame f{'B', 24991, 25000, {"HLD"}};
  std::string s = format_alicat_frame(f);
  EXPECT_EQ(s, "B +024.991 +025.000 HLD\r");
  AlicatReply r = parse_alicat_reply(s, 'B');
  ASSERT_EQ(r.status, ReplyStatus::ok);
  EXPECT_NEAR(r.frame.pressure_pa, 24991, 1e-6);
  EXPECT_NEAR(r.frame.setpoint_pa, 25000, 1e-6);
  EXPECT_EQ(r.frame.status.at(0), "HLD");
  EXPECT_EQ(parse_alicat_reply("?\r", 'B').status, ReplyStatus::rejected);
  EXPECT_EQ(parse_alicat_reply(s, 'A').status, ReplyStatus::malformed);  // wrong unit
  EXPECT_EQ(parse_alicat_reply("B +02#.991 +025.000\r", 'B').status, ReplyStatus::malformed);
  EXPECT_EQ(parse_alicat_reply("B +024.991\r", 'B').status, ReplyStatus::malformed);
  EXPECT_EQ(parse_alicat_reply("B +1 +2 toolong\r", 'B').status, ReplyStatus::malformed);
}

TEST(Booth, SensorTransferFunctionAndRegisters) {
  booth::Sensor s;                    // -100..100 kPa
  EXPECT_EQ(s.counts(-100000), 102);  // 10 % of 1023
  EXPECT_EQ(s.counts(100000), 921);   // 90 %
  EXPECT_EQ(s.counts(0), 512);
  EXPECT_EQ(s.counts(-1e9), 0);
  EXPECT_EQ(s.counts(1e9), 1023);
  for (int c = 102; c <= 921; ++c) EXPECT_EQ(s.counts(s.pressure(c)), c);
  std::uint8_t hi, lo;
  booth::put_counts(614, hi, lo);
  EXPECT_EQ(hi, 0x99);
  EXPECT_EQ(lo, 0x80);
  EXPECT_EQ(booth::get_counts(hi, lo), 614);
}

TEST(Booth, FramesRoundTrip) {
  auto req = booth::write_request(0x11, booth::kRegSetpointHi, {0x99, 0x80, 1});
  ASSERT_EQ(req.size(), 9u);
  EXPECT_EQ(req[0], 0xA5);
  booth::Frame f;
  std::size_t used;
  std::string err;
  ASSERT_EQ(booth::parse_request(req.data(), req.size(), f, used, err), booth::Parse::ok);
  EXPECT_EQ(used, req.size());
  EXPECT_EQ(f.addr, 0x11);
  EXPECT_EQ(f.reg, 16);
  EXPECT_EQ(f.data, (std::vector<std::uint8_t>{0x99, 0x80, 1}));
  auto rep = booth::reply_frame(booth::kStatusAck, 0x11, {0x80, 0x40});
  ASSERT_EQ(booth::parse_reply(rep.data(), rep.size(), f, used, err), booth::Parse::ok);
  EXPECT_EQ(f.data.size(), 2u);
  // Every truncation needs more bytes; a flipped CRC is bad.
  for (std::size_t n = 0; n < rep.size(); ++n)
    EXPECT_EQ(booth::parse_reply(rep.data(), n, f, used, err), booth::Parse::need_more) << n;
  rep.back() ^= 1;
  EXPECT_EQ(booth::parse_reply(rep.data(), rep.size(), f, used, err), booth::Parse::bad);
  EXPECT_EQ(booth::crc8(reinterpret_cast<const std::uint8_t*>("123456789"), 9), 0xF4);  // CRC-8/SMBUS check value
}

TEST(Fuzz, ReplyParsersSurviveRandomBytes) {
  std::mt19937_64 rng(12345);
  std::uniform_int_distribution<int> byte(0, 255), len(0, 48), printable(0x20, 0x7e);
  int alicat_ok = 0, booth_ok = 0;
  AlicatFrame good{'A', 12345, 25000, {"EXH"}};
  const std::string good_alicat = format_alicat_frame(good);
  const auto good_booth = booth::reply_frame(0, 0x11, {0x99, 0x80});
  for (int i = 0; i < 20000; ++i) {
    std::string s;
    std::vector<std::uint8_t> b;
    switch (i % 4) {
      case 0:  // random bytes
        for (int n = len(rng); n > 0; --n) s += static_cast<char>(byte(rng));
        break;
      case 1:  // random printable text
        for (int n = len(rng); n > 0; --n) s += static_cast<char>(printable(rng));
        break;
      case 2:  // truncated good frame
        s = good_alicat.substr(0, len(rng) % good_alicat.size());
        break;
      default:  // good frame with one byte replaced
        s = good_alicat;
        s[len(rng) % s.size()] = static_cast<char>(byte(rng));
    }
    alicat_ok += parse_alicat_reply(s, 'A').status == ReplyStatus::ok;
    b.assign(s.begin(), s.end());
    if (i % 4 == 2) b.assign(good_booth.begin(), good_booth.begin() + (len(rng) % good_booth.size()));
    if (i % 4 == 3) {
      b = good_booth;
      b[len(rng) % b.size()] ^= static_cast<std::uint8_t>(1 + byte(rng) % 255);
    }
    if (i % 8 == 1 && !b.empty()) b[0] = booth::kReplySync;  // get past the sync byte
    // Consume the buffer as the driver would.
    std::size_t pos = 0;
    while (pos < b.size()) {
      booth::Frame f;
      std::size_t used = 0;
      std::string err;
      auto r = booth::parse_reply(b.data() + pos, b.size() - pos, f, used, err);
      if (r == booth::Parse::need_more) break;
      ASSERT_GE(used, 1u);
      ASSERT_LE(pos + used, b.size());
      if (r == booth::Parse::ok) ++booth_ok;
      pos += used;
    }
  }
  // Corrupted frames must essentially never be accepted (CRC-8 lets ~1/256 through
  // only when more than one byte changes; a single changed byte is always caught).
  EXPECT_LT(booth_ok, 20);
  EXPECT_LT(alicat_ok, 5000);
}

TEST(EmulatorFaults, SpecParsing) {
  auto f = parse_fault("garble@2.5:3");
  EXPECT_EQ(f.kind, EmulatorFault::garble);
  EXPECT_EQ(f.at_s, 2.5);
  EXPECT_EQ(f.arg, 3);
  EXPECT_EQ(parse_fault("stuck@1:b3").channel, 2);
  EXPECT_THROW(parse_fault("melt@1"), morphfem::InputError);
  EXPECT_THROW(parse_fault("stuck@1:b9"), morphfem::InputError);
  EXPECT_THROW(parse_fault("garble@x"), morphfem::InputError);
}
