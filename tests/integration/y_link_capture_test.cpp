// The capture of examples/y-link.textproto (docs/dp-link.md): the upper lines DP_A and DP_B
// and the Y-link's lower line "Y" are interfaces of one pcapng. At 1 s DP_A's master stops:
// on the upper lines the link's active channel moves from A to B (PrmCmd and Red_Status bytes
// worked out by hand below), while on "Y" the coupler's master keeps polling with no gap longer
// than one lower cycle + a margin (bit times by hand below).
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr std::int64_t kNsPerMs = 1'000'000;
constexpr std::uint8_t kLink = 6;

const captures::PcapngCapture& capture() {
  static const captures::PcapngCapture c = [] {
    std::vector<std::uint8_t> pcap;
    const auto loaded = load_scenario_file(PBVBUS_SOURCE_DIR "/examples/y-link.textproto");
    EXPECT_TRUE(loaded.ok());
    if (!loaded.ok()) return captures::PcapngCapture{};
    captures::PcapngWriter w([&pcap](std::span<const std::uint8_t> b) {
      pcap.insert(pcap.end(), b.begin(), b.end());
      return true;
    });
    SimulationOptions o;
    o.capture = &w;
    Simulation sim(*loaded.plan, o);
    sim.run_until(2 * bus::kTicksPerSecond);
    w.flush();
    captures::PcapngError err;
    auto cap = captures::read_pcapng(pcap, err);
    EXPECT_TRUE(cap.has_value()) << err.to_string();
    return cap ? *cap : captures::PcapngCapture{};
  }();
  return c;
}

std::optional<std::uint32_t> interface(const std::string& name) {
  const auto& ifs = capture().interfaces;
  for (std::size_t i = 0; i < ifs.size(); ++i)
    if (ifs[i].name == name) return static_cast<std::uint32_t>(i);
  return std::nullopt;
}

/// An SD2 telegram with SAPs: 68 LE LEr 68 DA SA FC DSAP SSAP DU... FCS 16.
struct Sd2 {
  std::int64_t ts = 0;
  std::uint8_t da = 0, sa = 0, dsap = 0, ssap = 0;
  Bytes du;
};
std::vector<Sd2> sap_frames(const std::string& line) {
  std::vector<Sd2> out;
  const auto li = interface(line);
  if (!li) return out;
  for (const auto& r : capture().records) {
    const auto& b = r.bytes;
    if (r.interface != *li || b.size() < 11 || b[0] != 0x68) continue;
    const std::size_t le = b[1];
    if (b.size() < 6 + le || (b[4] & 0x80) == 0 || le < 5) continue;
    out.push_back({r.ts_ns, static_cast<std::uint8_t>(b[4] & 0x7F),
                   static_cast<std::uint8_t>(b[5] & 0x7F), b[7], b[8],
                   Bytes(b.begin() + 9, b.begin() + 4 + static_cast<std::ptrdiff_t>(le))});
  }
  return out;
}

/// The PrmCmd block of a Set_Prm (DSAP 61) to the link: the DU's last 8 octets.
std::vector<std::pair<std::int64_t, Bytes>> prm_cmds(const std::string& line) {
  std::vector<std::pair<std::int64_t, Bytes>> out;
  for (const auto& f : sap_frames(line))
    if (f.da == kLink && f.dsap == 61 && f.du.size() >= 18)
      out.emplace_back(f.ts, Bytes(f.du.end() - 8, f.du.end()));
  return out;
}

/// The Red_Status blocks (08 9F 00 ..) in the link's Slave_Diag responses (SSAP 60).
std::vector<std::pair<std::int64_t, Bytes>> red_status(const std::string& line) {
  std::vector<std::pair<std::int64_t, Bytes>> out;
  for (const auto& f : sap_frames(line)) {
    if (f.sa != kLink || f.ssap != 60) continue;
    for (std::size_t i = 6; i + 8 <= f.du.size(); ++i)
      if (f.du[i] == 0x08 && f.du[i + 1] == 0x9F && f.du[i + 2] == 0x00)
        out.emplace_back(f.ts, Bytes(f.du.begin() + static_cast<std::ptrdiff_t>(i),
                                     f.du.begin() + static_cast<std::ptrdiff_t>(i) + 8));
  }
  return out;
}

TEST(YLinkCapture, UpperLinesAndTheLowerLineAreInterfaces) {
  EXPECT_TRUE(interface("DP_A"));
  EXPECT_TRUE(interface("DP_B"));
  EXPECT_TRUE(interface("Y"));
}

TEST(YLinkCapture, TheActiveChannelMovesFromAToB) {
  // PrmCmd (PI 2.212, prm_cmd.hpp): 08 02 00 <Seq_Nr << 3> <Function> <Properties> <OHT>:
  // Function 02 = Primary_Request, 00 = none; Properties 04 = Address_Change (System
  // Redundancy); Output_Hold_Time "1s" = 100 x 10 ms = 00 64.
  const auto a = prm_cmds("DP_A");
  const auto b = prm_cmds("DP_B");
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  // Start-up: A's Set_Prm asks for the primary, B's does not.
  EXPECT_EQ(a.front().second, (Bytes{0x08, 0x02, 0x00, a.front().second[3], 0x02, 0x04, 0x00, 0x64}));
  EXPECT_EQ(b.front().second, (Bytes{0x08, 0x02, 0x00, b.front().second[3], 0x00, 0x04, 0x00, 0x64}));
  EXPECT_LT(b.front().first, 1000 * kNsPerMs);
  // At 1 s (master A stops): a pure PrmCmd with Primary_Request on DP_B.
  const auto cmd = std::find_if(b.begin(), b.end(), [](const auto& p) {
    return p.first >= 1000 * kNsPerMs && p.second[4] == 0x02;
  });
  ASSERT_NE(cmd, b.end());
  EXPECT_LT(cmd->first, 1010 * kNsPerMs);
  EXPECT_EQ(cmd->second, (Bytes{0x08, 0x02, 0x00, cmd->second[3], 0x02, 0x04, 0x00, 0x64}));
  EXPECT_EQ(cmd->second[3] & 0x07, 0);  // Specifier 0, Seq_Nr in bits 7..3
  // Red_Status (red_status.hpp): 08 9F 00 <Seq_Nr << 3> 00 <Red_State_1 = the sender>
  // <Red_State_2 = its partner> 00; bits: 01 Backup, 02 Primary, 08 Data_Exchange, 20
  // Baudrate_found. Before 1 s interface B is not the primary; after the switchover (T_SLAVE_UM =
  // 100 ms) it reports Primary + Data_Exchange + Baudrate_found = 2A, its partner A Backup.
  const auto rb = red_status("DP_B");
  ASSERT_FALSE(rb.empty());
  bool primary_after = false;
  for (const auto& [ts, s] : rb) {
    if (ts < 1000 * kNsPerMs) {  // S_WAITING (00) at start-up, then Backup (01): never Primary
      EXPECT_EQ(s[5] & 0x02, 0x00) << "B before the switchover at " << ts;
    } else if (ts >= 1100 * kNsPerMs && s[5] == 0x2A) {
      primary_after = true;
      EXPECT_EQ(s[6] & 0x03, 0x01) << "partner A at " << ts;
    }
  }
  EXPECT_TRUE(primary_after);
  const auto ra = red_status("DP_A");
  ASSERT_FALSE(ra.empty());
  EXPECT_EQ(ra.front().second[5] & 0x03, 0x02);  // A primary at start-up
}

TEST(YLinkCapture, TheLowerLinePollsOnThroughTheUpperSwitchover) {
  // Data_Exchange requests to lower station 3 on "Y": SD2, DA 3 without SAPs, FC request bit.
  const auto y = interface("Y");
  ASSERT_TRUE(y);
  std::vector<std::int64_t> at;
  for (const auto& r : capture().records) {
    const auto& b = r.bytes;
    if (r.interface == *y && b.size() >= 9 && b[0] == 0x68 && b[4] == 3 && (b[6] & 0x40) != 0)
      at.push_back(r.ts_ns);
  }
  // The lower cycle at 1.5 Mbit/s (t_bit = 2/3 us), by hand: per slave a Data_Exchange of 2
  // octets each way: request 9 + 2 = 11 octets x 11 = 121, TSDR <= max TSDR 150 (the line's,
  // PBVB0A01 MaxTsdr_1.5M), response 121, Tid1 = 33 + Tsm 4 = 37: 429; 3 slaves 1287; the
  // token to itself (SD4, 3 octets: 33 + 37) 70: cycle 1357. Margin: one GAP poll (FDL Status
  // SD1 6 octets 66 + TSL 300 + 37 = 403) and one Global_Control (13 octets 143 + Tid2 = max
  // TSDR 150 after an SDN: 293): 696. Bound 2053 t_bit = 2053 x 2/3 us = 1368.7 us.
  const std::int64_t bound_ns = 2053 * 2000 / 3;
  const std::int64_t from = 900 * kNsPerMs, to = 1300 * kNsPerMs;  // the switchover: 1.0 .. 1.1 s
  std::int64_t gap = 0;
  std::size_t n = 0;
  for (std::size_t i = 1; i < at.size(); ++i) {
    if (at[i] <= from || at[i - 1] >= to) continue;
    gap = std::max(gap, at[i] - at[i - 1]);
    ++n;
  }
  EXPECT_LE(gap, bound_ns);
  EXPECT_GE(static_cast<std::int64_t>(n), (to - from) / bound_ns);
}

}  // namespace
}  // namespace pbvbus::tools
