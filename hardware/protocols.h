// Wire protocols of the two regulator families, as pure encode/parse functions
// (no I/O), shared by the player and the emulator. Frames are documented here and
// in hardware/README.md.
//
// ---------------------------------------------------------------------------
// 1. ASCII protocol of Alicat-style pressure controllers (unit IDs A-Z share one
//    line; every command and reply ends with a carriage return '\r').
//      poll:         "<ID>\r"                 e.g. "A\r"
//      setpoint:     "<ID>S <kPa>\r"          e.g. "AS 25.000\r" (gauge kPa, may be negative)
//      reply (both): "<ID> <pressure> <setpoint> [STATUS ...]\r"
//                    e.g. "A +024.991 +025.000\r", "C -079.870 -080.000 OPR\r"
//                    pressures in gauge kPa with a sign and 3 decimals; status
//                    tokens are 3 upper-case letters (EXH valve exhausting,
//                    OPR over pressure range, HLD valve held, MOV valve moving).
//      rejected:     "?\r" (a command the unit understood but refuses, e.g. a bad number)
//      unsupported:  no reply at all (the driver times out).
//    Venting: setpoint 0 kPa (regulate to atmosphere).
//
// 2. Addressable pneumatic regulator of Booth et al. (RoboSoft 2018): each
//    regulator is an I2C slave with a 32-byte register array:
//      [16] setpoint high byte  [17] setpoint low byte   (10-bit, left-justified)
//      [18] desired state       (0 vent to atmosphere, 1 regulate, 2 hold/closed)
//      [19] pressure high byte  [20] pressure low byte   (10-bit, left-justified:
//                                counts = (r19 << 8 | r20) >> 6)
//      [21] half band           (dead band half-width in sensor counts)
//      [22] operation mode      (0 idle, 1 bang-bang regulation)
//      [23] only-send-pressure  (1: a default read returns only bytes 19-20)
//    Pressure <-> counts by the sensor's ratiometric transfer function
//      counts = 1023 * (0.1 + 0.8 * (p - p_min) / (p_max - p_min)),
//    (10 %..90 % of supply over the sensor range), setpoint in the same counts.
//    Serial-to-I2C bridge framing (defined by this project):
//      request: A5 | cmd | addr | reg | len | data[len if cmd = 'W'] | crc
//               cmd 'W' (0x57) writes len bytes from register reg,
//               cmd 'R' (0x52) reads len bytes from reg; len 0 = the regulator's
//               default read (32 bytes, or 2 pressure bytes if [23] = 1).
//      reply:   5A | status | addr | len | data[len] | crc
//               status 0 ACK, 1 NACK (no regulator at addr), 2 bad CRC,
//               3 bad register range, 4 unknown command; a write is answered
//               with len 0.
//      crc:     CRC-8, polynomial 0x07, initial value 0, over every byte after
//               the sync byte. reg + len must be <= 32; addr is 7-bit (1..127).
// ---------------------------------------------------------------------------
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace morphfem::hw {

// ---- Alicat-style ASCII -------------------------------------------------------
std::string alicat_poll(char id);
std::string alicat_setpoint(char id, double pa);

struct AlicatFrame {
  char id = 0;
  double pressure_pa = 0;
  double setpoint_pa = 0;
  std::vector<std::string> status;
};

enum class ReplyStatus { ok, rejected, malformed };

struct AlicatReply {
  ReplyStatus status = ReplyStatus::malformed;
  AlicatFrame frame;
  std::string error;  // why a reply is malformed
};

// Parses one reply line (without or with the trailing '\r'); expect_id is the
// unit that was addressed. Never throws.
AlicatReply parse_alicat_reply(std::string_view line, char expect_id);
std::string format_alicat_frame(const AlicatFrame& f);

// ---- Booth regulator over the serial-to-I2C bridge -------------------------
namespace booth {
constexpr std::uint8_t kRequestSync = 0xA5;
constexpr std::uint8_t kReplySync = 0x5A;
constexpr std::uint8_t kCmdWrite = 'W';
constexpr std::uint8_t kCmdRead = 'R';
constexpr int kRegisters = 32;
constexpr int kRegSetpointHi = 16, kRegSetpointLo = 17, kRegDesiredState = 18;
constexpr int kRegPressureHi = 19, kRegPressureLo = 20, kRegHalfBand = 21;
constexpr int kRegMode = 22, kRegOnlyPressure = 23;
constexpr std::uint8_t kStateVent = 0, kStateRegulate = 1, kStateHold = 2;
constexpr std::uint8_t kStatusAck = 0, kStatusNack = 1, kStatusBadCrc = 2, kStatusBadRange = 3, kStatusBadCommand = 4;

std::uint8_t crc8(const std::uint8_t* data, std::size_t n);

struct Sensor {
  double min_pa = -100000;
  double max_pa = 100000;
  int counts(double pa) const;        // 0..1023, clamped
  double pressure(int counts) const;  // inverse transfer function
  double resolution_pa() const { return (max_pa - min_pa) / (0.8 * 1023); }
};
// 10-bit counts <-> two left-justified bytes.
void put_counts(int counts, std::uint8_t& hi, std::uint8_t& lo);
int get_counts(std::uint8_t hi, std::uint8_t lo);

std::vector<std::uint8_t> write_request(int addr, int reg, const std::vector<std::uint8_t>& data);
std::vector<std::uint8_t> read_request(int addr, int reg, int len);
std::vector<std::uint8_t> reply_frame(std::uint8_t status, int addr, const std::vector<std::uint8_t>& data);

struct Frame {
  std::uint8_t cmd_or_status = 0;
  int addr = 0;
  int reg = 0;  // requests only
  std::vector<std::uint8_t> data;
};

enum class Parse { need_more, ok, bad };
// Parses a reply at the start of buf. ok: `consumed` bytes form `out`;
// need_more: incomplete; bad: not a valid frame (`error` says why, `consumed` = 1
// so the caller can resynchronise). Never reads beyond n, never throws.
Parse parse_reply(const std::uint8_t* buf, std::size_t n, Frame& out, std::size_t& consumed, std::string& error);
// Same for requests (used by the emulator).
Parse parse_request(const std::uint8_t* buf, std::size_t n, Frame& out, std::size_t& consumed, std::string& error);
}  // namespace booth

// Printable form of raw bytes for logs and dry runs ("A5 57 11 ..." or "AS 25.000\r").
std::string hex_bytes(const std::vector<std::uint8_t>& bytes);
std::string escape_ascii(std::string_view s);

}  // namespace morphfem::hw
