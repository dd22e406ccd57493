// The `pbvbus inspect` summary: counts, bad-frame reasons, time span, minimum idle gap in bit
// times and events, in text and JSON, for a capture whose timing is laid out by hand.

#include "pbvbus/captures/inspect.hpp"

#include <gtest/gtest.h>

#include "capture_fixture.hpp"

#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;

// 1.5 Mbit/s: one bit = 2424 ticks. Frames placed in bit times from t = 1 ms.
Bytes make_capture() {
  bus::Scheduler sched;
  bus::Line line(sched, "dp0", bus::Baud::k1_5M);
  test::MemorySink mem;
  PcapngWriter w(mem.sink());
  const bus::Ticks bit = bus::ticks_per_bit(bus::Baud::k1_5M);
  const bus::Ticks t0 = bus::kTicksPerMs;
  bus::Ticks t = t0;
  auto put = [&](const Bytes& b, bus::Ticks idle_bits, std::uint16_t flags = 0,
                 std::uint32_t sent = 0) {
    t += idle_bits * bit;
    w.on_frame(test::tap_frame(line, b, t, flags, sent));
    t += static_cast<bus::Ticks>(b.size()) * 11 * bit;
  };
  put(test::kSlaveDiagReq, 0);          // SRD_high, Slave_Diag.req
  put(test::kSlaveDiagRes, 11);         // DL, Slave_Diag.res: 11 bit times after the request
  put(test::kToken_2_to_5, 33);         // SD4
  put(test::kDataExchange, 40);         // SRD_high, Data_Exchange.req
  put(test::kSc, 12);                   // SC
  put(test::kGlobalControlClear, 100);  // SDN_high, Global_Control.req
  const Bytes part(test::kSetPrm.begin(), test::kSetPrm.begin() + 4);
  put(part, 50, bus::kRxPartial, 18);  // partial: 4 of 18 octets
  Bytes hit = test::kChkCfg;
  hit[10] = 0x21;
  put(hit, 60, bus::kRxCollision);  // collision, FCS mismatch
  // An overlapping frame (the other side of the collision): starts 5 bits before the end.
  t -= 5 * bit;
  w.on_frame(test::tap_frame(line, Bytes{0x55}, t, bus::kRxCollision | bus::kRxBabble));
  EventRecord e;
  e.category = EventCategory::Station;
  e.a = 10;
  e.text = "slave \"10\" failed";
  w.write_event(2 * bus::kTicksPerMs, e);
  w.flush();
  return mem.data;
}

TEST(Inspect, SummarisesCounts) {
  PcapngReader reader(make_capture());
  PcapngError err;
  auto s = summarize(reader, err);
  ASSERT_TRUE(s) << err.to_string();
  EXPECT_EQ(s->records, 10u);
  ASSERT_EQ(s->interfaces.size(), 2u);
  const InterfaceSummary& i = s->interfaces[0];
  EXPECT_EQ(i.frames, 9u);
  using M = std::map<std::string, std::uint64_t>;
  EXPECT_EQ(i.by_type, (M{{"SD2", 5}, {"SD3", 1}, {"SD4", 1}, {"SC", 1}, {"garbage", 1}}));
  EXPECT_EQ(i.by_request, (M{{"SRD_high", 2}, {"SDN_high", 1}}));
  EXPECT_EQ(i.by_response, (M{{"DL", 1}}));
  EXPECT_EQ(i.by_service, (M{{"Slave_Diag.req", 1},
                             {"Slave_Diag.res", 1},
                             {"Data_Exchange.req", 1},
                             {"Global_Control.req", 1}}));
  EXPECT_EQ(i.bad_frames, 3u);
  EXPECT_EQ(i.bad_by_reason, (M{{"partial", 1},
                                {"collision", 2},
                                {"FCS mismatch", 1},
                                {"babbling transmitter", 1},
                                {"unknown start delimiter", 1}}));
  EXPECT_EQ(i.min_idle_bits, 11);
  EXPECT_EQ(i.overlaps, 1u);
  EXPECT_EQ(i.first_ns, 1'000'000);
  ASSERT_EQ(s->events.size(), 1u);
  EXPECT_EQ(s->events[0].ts_ns, 2'000'000);
  EXPECT_EQ(s->events[0].category, "station");
}

TEST(Inspect, TextReport) {
  PcapngReader reader(make_capture());
  PcapngError err;
  auto s = summarize(reader, err);
  ASSERT_TRUE(s);
  // Frame starts in bit times after 1 ms (length 11 bits per octet, then the idle gap):
  // 0, 121+11 = 132, 286+33 = 319, 352+40 = 392, 513+12 = 525, 536+100 = 636, 779+50 = 829,
  // 873+60 = 933, and the overlapping octet at 1076-5 = 1071 bits = 714 us.
  // Octets: 11+14+3+11+1+13+4+13+1 = 71; the event record 24 + 17 octets of text.
  const std::string expected =
      "Records: 10 (1 events)\n"
      "Time span: 0.001000000 s .. 0.002000000 s (0.001000000 s)\n"
      "Interface 0 'dp0' (USER0, 1.5 Mbit/s): 9 records, 71 octets\n"
      "  time span: 0.001000000 s .. 0.001714000 s\n"
      "  frame types: SC 1, SD2 5, SD3 1, SD4 1, garbage 1\n"
      "  requests: SDN_high 1, SRD_high 2\n"
      "  responses: DL 1\n"
      "  DP services: Data_Exchange.req 1, Global_Control.req 1, Slave_Diag.req 1, Slave_Diag.res "
      "1\n"
      "  bad frames: 3 (FCS mismatch 1, babbling transmitter 1, collision 2, partial 1, unknown "
      "start delimiter 1)\n"
      "  min idle gap: 11 bit times, 1 overlapping frames\n"
      "Interface 1 'events' (USER1, speed unknown): 1 records, 41 octets\n"
      "  time span: 0.002000000 s .. 0.002000000 s\n"
      "Events: 1\n"
      "  0.002000000 s  [station] slave \"10\" failed\n";
  EXPECT_EQ(to_text(*s), expected);
}

TEST(Inspect, JsonReport) {
  PcapngReader reader(make_capture());
  PcapngError err;
  auto s = summarize(reader, err);
  ASSERT_TRUE(s);
  const std::string j = to_json(*s);
  EXPECT_EQ(
      j.rfind("{\"records\":10,\"first_ns\":1000000,\"last_ns\":2000000,\"interfaces\":[{\"id\":0,"
              "\"name\":\"dp0\",\"description\":\"PROFIBUS-DP 1.5 Mbit/s\",\"link_type\":147,"
              "\"speed\":1500000,\"records\":9,\"octets\":71,",
              0),
      0u)
      << j;
  EXPECT_NE(
      j.find("\"bad_by_reason\":{\"FCS mismatch\":1,\"babbling transmitter\":1,\"collision\":2,"
             "\"partial\":1,\"unknown start delimiter\":1},\"min_idle_bits\":11,\"overlaps\":1}"),
      std::string::npos)
      << j;
  EXPECT_NE(j.find("\"events\":[{\"ts_ns\":2000000,\"category\":\"station\",\"code\":0,\"line\":-1,"
                   "\"a\":10,\"b\":-1,\"value\":0,\"text\":\"slave \\\"10\\\" "
                   "failed\"}],\"bad_event_records\":0}"),
            std::string::npos)
      << j;
}

TEST(Inspect, BrokenFileGivesTheReaderError) {
  Bytes f = make_capture();
  f.resize(f.size() - 3);
  PcapngReader reader(f);
  PcapngError err;
  EXPECT_FALSE(summarize(reader, err));
  EXPECT_NE(err.to_string().find("runs past the end of the file"), std::string::npos)
      << err.to_string();
  EXPECT_FALSE(inspect_file("/nonexistent.pcapng", err));
}

}  // namespace
}  // namespace pbvbus::captures
