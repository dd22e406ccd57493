// H-system CPU events in captures (captures/cpu_event.hpp): the record layout checked octet by
// octet against the encoding written by hand, and the Lua dissector's pbevent.cpu.* fields
// checked with Debian's tshark (skipped without it).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "capture_fixture.hpp"
#include "tshark_helpers.hpp"

#include "pbvbus/captures/cpu_event.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::captures {
namespace {

namespace ts = ::pbvbus::test;

CpuEventFields ob72_master_lost() {
  CpuEventFields f;
  f.kind = CpuEventKind::Ob;
  f.rack = 1;
  f.role = 1;  // master after the takeover
  f.ob = 72;
  f.reason = 1;  // master CPU lost
  f.text = "CPU 1: OB 72 (master CPU lost)";
  return f;
}

// value = event id 0 | 72 << 16 | 1 << 24 = 0x0148'0000; little-endian at offsets 16..23:
// 00 00 48 01 00 00 00 00. code 3 (OB) -> 03 00; line -1 -> FF FF FF FF; a = 1; b = 1.
TEST(CpuEventRecord, LayoutAsWrittenByHand) {
  const EventRecord r = cpu_event_record(ob72_master_lost());
  EXPECT_EQ(r.category, EventCategory::Cpu);
  EXPECT_EQ(r.value, 0x0148'0000u);
  std::vector<std::uint8_t> b(encoded_event_size(r));
  ASSERT_EQ(encode_event(r, b), 24u + 30u);
  const std::vector<std::uint8_t> head(b.begin(), b.begin() + 24);
  EXPECT_EQ(head, (std::vector<std::uint8_t>{1, 5, 3, 0, 0xFF, 0xFF, 0xFF, 0xFF, 1, 0, 0, 0, 1, 0, 0, 0,
                                             0x00, 0x00, 0x48, 0x01, 0, 0, 0, 0}));
  // A state change: from STOP (1) to STARTUP (2): value = 2 << 32 | 1 << 40 = 0x0102'0000'0000.
  CpuEventFields s;
  s.kind = CpuEventKind::State;
  s.rack = 0;
  s.role = 1;
  s.from = 1;
  s.to = 2;
  EXPECT_EQ(cpu_event_record(s).value, 0x0102'0000'0000u);
  // And back.
  const auto f = cpu_event_fields(r);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->kind, CpuEventKind::Ob);
  EXPECT_EQ(f->ob, 72);
  EXPECT_EQ(f->reason, 1);
  EXPECT_EQ(f->rack, 1);
  EXPECT_EQ(f->text, "CPU 1: OB 72 (master CPU lost)");
  EventRecord other;
  other.category = EventCategory::Redundancy;
  EXPECT_FALSE(cpu_event_fields(other).has_value());
  EventRecord bad = r;
  bad.code = 9;
  EXPECT_FALSE(cpu_event_fields(bad).has_value());
}

class TsharkCpuEvents : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    s_path = test::temp_capture_path("pbvbus_tshark_cpu");
    auto w = PcapngWriter::open(s_path, {});
    ASSERT_TRUE(w);
    CpuEventFields s;  // 1: CPU 0 STOP -> STARTUP
    s.kind = CpuEventKind::State;
    s.rack = 0;
    s.role = 1;
    s.from = 1;
    s.to = 2;
    s.text = "CPU 0: STOP -> STARTUP";
    w->write_event(1 * bus::kTicksPerMs, cpu_event_record(s));
    CpuEventFields m;  // 2: system mode Solo -> Link-up
    m.kind = CpuEventKind::SystemMode;
    m.role = 1;
    m.from = 2;
    m.to = 3;
    m.text = "system mode Solo -> Link-up";
    w->write_event(2 * bus::kTicksPerMs, cpu_event_record(m));
    w->write_event(3 * bus::kTicksPerMs, cpu_event_record(ob72_master_lost()));  // 3
    CpuEventFields r;  // 4: CPU 1 role none -> standby
    r.kind = CpuEventKind::Role;
    r.rack = 1;
    r.role = 2;
    r.from = 0;
    r.to = 2;
    r.text = "CPU 1: role none -> standby";
    w->write_event(4 * bus::kTicksPerMs, cpu_event_record(r));
    CpuEventFields e = ob72_master_lost();  // 5: an OB with an event ID
    e.rack = 0;
    e.event_id = 0x5966;
    e.reason = 8;
    e.text = "CPU 0: OB 72 W#16#5966 (master/standby swap)";
    w->write_event(5 * bus::kTicksPerMs, cpu_event_record(e));
  }
  static void TearDownTestSuite() { std::filesystem::remove(s_path); }
  void SetUp() override {
    if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  }
  static std::string s_path;
};
std::string TsharkCpuEvents::s_path;

using R = std::vector<std::string>;

TEST_F(TsharkCpuEvents, FieldsAreNamed) {
  const auto rows = ts::tshark_fields(
      s_path, {"pbevent.category", "pbevent.code_name", "pbevent.cpu.rack", "pbevent.cpu.role",
               "pbevent.cpu.from", "pbevent.cpu.to", "pbevent.cpu.ob", "pbevent.cpu.ob_name",
               "pbevent.cpu.reason", "pbevent.s7"});
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[0], (R{"5", "state change", "0", "1", "STOP", "STARTUP", "", "", "", ""}));
  EXPECT_EQ(rows[1], (R{"5", "system mode change", "0", "1", "Solo", "Link-up", "", "", "", ""}));
  EXPECT_EQ(rows[2], (R{"5", "OB", "1", "1", "", "", "72", "OB 72", "1", ""}));
  EXPECT_EQ(rows[3], (R{"5", "role change", "1", "2", "none", "standby", "", "", "", ""}));
  EXPECT_EQ(rows[4], (R{"5", "OB", "0", "1", "", "", "72", "OB 72", "8", "W#16#5966"}));
}

TEST_F(TsharkCpuEvents, InfoColumnShowsTheText) {
  const auto info = ts::tshark_info(s_path);
  ASSERT_EQ(info.size(), 5u);
  EXPECT_EQ(info[0], "[cpu] CPU 0: STOP -> STARTUP");
  EXPECT_EQ(info[2], "[cpu] CPU 1: OB 72 (master CPU lost)");
  EXPECT_EQ(info[4], "[cpu] CPU 0: OB 72 W#16#5966 (master/standby swap)");
}

}  // namespace
}  // namespace pbvbus::captures
