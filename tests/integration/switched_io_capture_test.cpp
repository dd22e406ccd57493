// The capture of examples/switched-io.textproto (docs/redundancy.md): both lines
// in one pcapng (one interface each, named after the line), the redundancy events on the events
// interface with their S7 ids, and Debian's tshark with the pbvbus Lua dissector reading it all:
// the PrmCmd Set_Prms on the wire (start-up and every commanded switchover) and the events.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"
#include "../captures/tshark_helpers.hpp"

namespace pbvbus::tools {
namespace {

struct Run {
  std::vector<std::uint8_t> pcap;
  std::uint64_t events = 0;
  Report report;
};

/// The example's first 6 s: F10, F11, F13 and the short circuit of F14.
const Run& run() {
  static const Run r = [] {
    Run out;
    const auto loaded = load_scenario_file(PBVBUS_SOURCE_DIR "/examples/switched-io.textproto");
    EXPECT_TRUE(loaded.ok());
    if (!loaded.ok()) return out;
    captures::PcapngWriter w([&out](std::span<const std::uint8_t> b) {
      out.pcap.insert(out.pcap.end(), b.begin(), b.end());
      return true;
    });
    SimulationOptions o;
    o.capture = &w;
    Simulation sim(*loaded.plan, o);
    sim.run_until(6 * bus::kTicksPerSecond);
    w.flush();
    out.events = w.events_written();
    out.report = sim.report(1.0);
    return out;
  }();
  return r;
}

std::string write(const std::string& name) {
  const std::string path = std::string(PBVBUS_BINARY_DIR) + "/" + name;
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(run().pcap.data()),
          static_cast<std::streamsize>(run().pcap.size()));
  return path;
}

TEST(SwitchedIoCapture, BothLinesAreInterfacesOfOneCaptureWithTheEvents) {
  const auto& r = run();
  ASSERT_FALSE(r.pcap.empty());
  captures::PcapngError err;
  const auto cap = captures::read_pcapng(r.pcap, err);
  ASSERT_TRUE(cap.has_value()) << err.to_string();
  std::vector<std::string> names;
  for (const auto& i : cap->interfaces) names.push_back(i.name);
  EXPECT_NE(std::find(names.begin(), names.end(), "DP_A"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "DP_B"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "events"), names.end());
  EXPECT_GT(r.events, 0u);
}

TEST(SwitchedIoCapture, TsharkShowsTheS7EventsAndThePrmCmds) {
  if (!test::tshark_available()) GTEST_SKIP() << test::kNoTshark;
  const std::string path = write("switched_io_capture_test.pcapng");
  // The S7 events as the dissector reads them: name, W#16# id, station.
  const auto rows = test::tshark_fields(
      path, {"pbevent.code_name", "pbevent.s7", "pbevent.a"}, "pbevent.category == 4 && pbevent.s7");
  // The first 6 s of the script (switched_io_scenario_test.cpp has the whole list).
  const std::vector<std::vector<std::string>> want = {
      {"redundancy loss", "W#16#73A3", "3"},     {"redundancy restored", "W#16#72A3", "3"},
      {"redundancy loss", "W#16#73A3", "4"},     {"station failure", "W#16#39C4", "4"},
      {"station return", "W#16#38C4", "4"},      {"redundancy restored", "W#16#72A3", "4"},
      {"station failure", "W#16#39C4", "10"},    {"redundancy loss", "W#16#73A3", "6"},
      {"redundancy restored", "W#16#72A3", "6"}, {"station return", "W#16#38C4", "10"},
      {"master system failure", "W#16#39C3", "-1"},
      {"master system return", "W#16#38C3", "-1"}};
  EXPECT_EQ(rows, want);
  // Switchover records: one start-up record per station (line DP_A), then station 3 to line B
  // first (F10).
  const auto sw = test::tshark_fields(path, {"pbevent.a", "pbevent.text"},
                                      "pbevent.category == 4 && pbevent.code == 6");
  ASSERT_GE(sw.size(), 5u);
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_NE(sw[i][1].find("to line DP_A (start-up)"), std::string::npos) << sw[i][1];
  EXPECT_EQ(sw[4][0], "3");
  EXPECT_NE(sw[4][1].find("to line DP_B"), std::string::npos) << sw[4][1];
  // PrmCmd blocks on the wire: start-up Set_Prms on both lines (Primary_Request on DP_A only),
  // then the pure PrmCmds of the commanded switchovers.
  const auto prm = test::tshark_fields(path, {"frame.interface_name", "pbdp.prmcmd.function"},
                                       "pbdp.prmcmd.function & 0x02");
  std::map<std::string, int> requests;
  for (const auto& row : prm) ++requests[row[0]];
  // DP_A: the 4 start-up requests plus the returns to DP_A at the short on DP_B (stations 3, 4,
  // 6). DP_B: stations 3 and 4 (F10, F11) and 6 (F13) as pure PrmCmds; station 4 after both
  // its interfaces failed: its re-start-up Set_Prm on DP_B carries the stored Primary_Request
  // (DP_B was its active line), and the system, seeing no primary when that channel reaches
  // data exchange, sends one more (a pure PrmCmd): 3 + 2.
  EXPECT_EQ(requests["DP_A"], 4 + 3);
  EXPECT_EQ(requests["DP_B"], 3 + 2);
}

}  // namespace
}  // namespace pbvbus::tools
