// Quantum Hot Standby pair events in captures (captures/hsby_event.hpp): the record layout
// checked octet by octet against the encoding written by hand, the names, the pair's name in
// the text, and the Lua dissector's pbevent.hsby.* fields checked with Debian's tshark (skipped
// without it).
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "capture_fixture.hpp"
#include "tshark_helpers.hpp"

#include "pbvbus/captures/hsby_event.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::captures {
namespace {

namespace ts = ::pbvbus::test;

HsbyEventFields hsby_switchover_to_rack1() {
  HsbyEventFields f;
  f.kind = HsbyEventKind::Switchover;
  f.rack = 1;
  f.state = 2;  // primary after the takeover
  f.takeover_ns = 40'000'000;  // 40 ms
  f.text = "Q: rack 1: switchover";
  return f;
}

// 40 000 000 = 0x0262'5A00 -> little-endian at offsets 16..23: 00 5A 62 02 00 00 00 00.
// version 1, category 7, code 3 -> 03 00, line -1 -> FF FF FF FF, a = 1, b = 2.
TEST(HsbyEventRecord, LayoutAsWrittenByHand) {
  const EventRecord r = hsby_event_record(hsby_switchover_to_rack1());
  EXPECT_EQ(r.category, EventCategory::Hsby);
  std::vector<std::uint8_t> b(encoded_event_size(r));
  ASSERT_EQ(encode_event(r, b), 24u + 21u);
  const std::vector<std::uint8_t> head(b.begin(), b.begin() + 24);
  EXPECT_EQ(head, (std::vector<std::uint8_t>{1, 7, 3, 0, 0xFF, 0xFF, 0xFF, 0xFF, 1, 0, 0, 0, 2, 0, 0, 0,
                                             0x00, 0x5A, 0x62, 0x02, 0, 0, 0, 0}));
  EXPECT_EQ(std::string(b.begin() + 24, b.end()), "Q: rack 1: switchover");
  // A fibre event of the pair: code 7, a = b = -1, value 0.
  HsbyEventFields fib;
  fib.kind = HsbyEventKind::Fibre;
  fib.text = "Q: fibre cut";
  const EventRecord rf = hsby_event_record(fib);
  std::vector<std::uint8_t> bf(encoded_event_size(rf));
  ASSERT_EQ(encode_event(rf, bf), 24u + 12u);
  EXPECT_EQ(std::vector<std::uint8_t>(bf.begin(), bf.begin() + 24),
            (std::vector<std::uint8_t>{1, 7, 7, 0, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF,
                                       0xFF, 0xFF, 0xFF, 0, 0, 0, 0, 0, 0, 0, 0}));
  // And back, through the octets.
  const auto d = decode_event(b);
  ASSERT_TRUE(d.has_value());
  const auto f = hsby_event_fields(*d);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->kind, HsbyEventKind::Switchover);
  EXPECT_EQ(f->rack, 1);
  EXPECT_EQ(f->state, 2);
  EXPECT_EQ(f->takeover_ns, 40'000'000u);
  EXPECT_EQ(f->text, "Q: rack 1: switchover");
  EventRecord other;
  other.category = EventCategory::Cpu;
  EXPECT_FALSE(hsby_event_fields(other).has_value());
  EventRecord bad = r;
  bad.code = 12;  // no such kind
  EXPECT_FALSE(hsby_event_fields(bad).has_value());
}

// The numbers of the event_record.hpp comment (quantum::PairEventKind, quantum::CpuState).
TEST(HsbyEventRecord, Names) {
  const char* const kinds[] = {"power", "key",    "state",    "switchover", "transfer lost", "logic mismatch",
                               "duplicate designation", "fibre", "update", "override", "cpu", "ignored"};
  for (int k = 0; k < 12; ++k) EXPECT_EQ(hsby_kind_name(k), kinds[k]) << k;
  EXPECT_EQ(hsby_kind_name(12), "kind 12");
  EXPECT_EQ(static_cast<int>(HsbyEventKind::Ignored), 11);
  EXPECT_EQ(hsby_state_name(-1), "none");
  EXPECT_EQ(hsby_state_name(0), "off");
  EXPECT_EQ(hsby_state_name(1), "offline");
  EXPECT_EQ(hsby_state_name(2), "primary");
  EXPECT_EQ(hsby_state_name(3), "standby");
  EXPECT_EQ(hsby_state_name(4), "state 4");
}

TEST(HsbyEventRecord, PairName) {
  EXPECT_EQ(hsby_pair_name("PLC-Q: rack 0: offline -> primary (power on)", 0), "PLC-Q");
  EXPECT_EQ(hsby_pair_name("PLC-Q: rack 0: offline -> primary (power on)", 1), "");
  EXPECT_EQ(hsby_pair_name("rack 1: standby -> primary", 1), "");
  EXPECT_EQ(hsby_pair_name("PLC-Q: fibre cut", -1), "PLC-Q");
  EXPECT_EQ(hsby_pair_name("fibre cut", -1), "");
}

class TsharkHsbyEvents : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    s_path = test::temp_capture_path("pbvbus_tshark_hsby");
    auto w = PcapngWriter::open(s_path, {});
    ASSERT_TRUE(w);
    HsbyEventFields p;  // 1: rack 0 powered, still off
    p.kind = HsbyEventKind::Power;
    p.rack = 0;
    p.state = 0;
    p.text = "Q: rack 0: power on";
    w->write_event(1 * bus::kTicksPerMs, hsby_event_record(p));
    HsbyEventFields s;  // 2: rack 1 offline -> standby
    s.kind = HsbyEventKind::State;
    s.rack = 1;
    s.state = 3;
    s.text = "Q: rack 1: offline -> standby (transfer)";
    w->write_event(2 * bus::kTicksPerMs, hsby_event_record(s));
    w->write_event(3 * bus::kTicksPerMs, hsby_event_record(hsby_switchover_to_rack1()));  // 3
    HsbyEventFields f;  // 4: the fibre (a = b = -1)
    f.kind = HsbyEventKind::Fibre;
    f.text = "Q: fibre cut";
    w->write_event(4 * bus::kTicksPerMs, hsby_event_record(f));
    HsbyEventFields o = hsby_switchover_to_rack1();  // 5: 1.5 µs takeover, odd state 9
    o.takeover_ns = 1'500;
    o.state = 9;
    o.text = "Q: rack 1: switchover (odd)";
    w->write_event(5 * bus::kTicksPerMs, hsby_event_record(o));
  }
  static void TearDownTestSuite() { std::filesystem::remove(s_path); }
  void SetUp() override {
    if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  }
  static std::string s_path;
};
std::string TsharkHsbyEvents::s_path;

using Row = std::vector<std::string>;

TEST_F(TsharkHsbyEvents, FieldsAreNamed) {
  const auto rows = ts::tshark_fields(
      s_path, {"pbevent.category", "pbevent.code_name", "pbevent.hsby.kind_name", "pbevent.hsby.rack",
               "pbevent.hsby.state", "pbevent.hsby.state_name", "pbevent.hsby.takeover_ns",
               "pbevent.hsby.takeover"});
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[0], (Row{"7", "power", "power", "0", "0", "off", "", ""}));
  EXPECT_EQ(rows[1], (Row{"7", "state", "state", "1", "3", "standby", "", ""}));
  EXPECT_EQ(rows[2], (Row{"7", "switchover", "switchover", "1", "2", "primary", "40000000", "40.000000 ms"}));
  EXPECT_EQ(rows[3], (Row{"7", "fibre", "fibre", "-1", "-1", "none", "", ""}));
  EXPECT_EQ(rows[4], (Row{"7", "switchover", "switchover", "1", "9", "state 9", "1500", "0.001500 ms"}));
}

TEST_F(TsharkHsbyEvents, InfoColumnShowsTheText) {
  const auto info = ts::tshark_info(s_path);
  ASSERT_EQ(info.size(), 5u);
  EXPECT_EQ(info[0], "[hsby] Q: rack 0: power on");
  EXPECT_EQ(info[2], "[hsby] Q: rack 1: switchover");
  EXPECT_EQ(info[3], "[hsby] Q: fibre cut");
}

}  // namespace
}  // namespace pbvbus::captures
