// examples/multimaster.textproto run whole in fast mode: the ring splits at the cable cut and
// re-forms after the repair; the capture (from the default probe, next to master 1: what an
// analyzer there sees) is deterministic, opens in tshark, and every frame in it obeys the FDL
// framing and timing rules (TSYN before requests and tokens, TSDR for replies), the cut
// included. capture_check_test.cpp checks the same capture with an independent program.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <set>

#include "../captures/tshark_helpers.hpp"
#include "frame_recorder.hpp"
#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/fdl_traffic/fdl_poller.hpp"
#include "pbvbus/fdl_traffic/fdl_responder.hpp"
#include "pbvbus/fdl/telegram.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

struct SimRun {
  std::vector<std::uint8_t> pcap;
  std::unique_ptr<Simulation> sim;
  std::uint64_t frames = 0;
  std::uint64_t events = 0;
};

SimRun run_multimaster(std::optional<std::uint64_t> seed = std::nullopt) {
  SimRun r;
  const auto loaded = load_scenario_file(PBVBUS_SOURCE_DIR "/examples/multimaster.textproto");
  EXPECT_TRUE(loaded.ok());
  if (!loaded.ok()) return r;
  captures::PcapngWriter w([&r](std::span<const std::uint8_t> b) {
    r.pcap.insert(r.pcap.end(), b.begin(), b.end());
    return true;
  });
  SimulationOptions o;
  o.capture = &w;
  o.seed = seed;
  r.sim = std::make_unique<Simulation>(*loaded.plan, o);
  r.sim->run_until(*r.sim->duration());
  w.flush();
  r.frames = w.frames_written();
  r.events = w.events_written();
  return r;
}

/// A frame of the capture on the line interface, with its times in bit times.
struct WireFrame {
  std::int64_t start_ns;
  std::int64_t end_ns;
  std::vector<std::uint8_t> bytes;
  std::uint32_t flags;
  std::string comment;
};

struct Capture {
  std::uint64_t baud = 0;
  std::vector<WireFrame> frames;
  std::vector<std::string> events;
};

Capture parse(const std::vector<std::uint8_t>& pcap) {
  Capture c;
  captures::PcapngError err;
  auto cap = captures::read_pcapng(pcap, err);
  EXPECT_TRUE(cap.has_value()) << err.to_string();
  if (!cap) return c;
  int line_if = -1;
  for (std::size_t i = 0; i < cap->interfaces.size(); ++i) {
    if (cap->interfaces[i].name == "A") {
      line_if = static_cast<int>(i);
      c.baud = cap->interfaces[i].speed;
    }
  }
  EXPECT_GE(line_if, 0);
  EXPECT_EQ(c.baud, 1'500'000u);
  for (auto& r : cap->records) {
    if (static_cast<int>(r.interface) != line_if) {
      c.events.push_back(r.comment);
      continue;
    }
    // 11 bits per character; ns = bits * 1e9 / baud.
    const auto len_ns = static_cast<std::int64_t>(r.bytes.size()) * 11 * kNsPerS /
                        static_cast<std::int64_t>(c.baud);
    c.frames.push_back({r.ts_ns, r.ts_ns + len_ns, std::move(r.bytes), r.flags, r.comment});
  }
  std::stable_sort(c.frames.begin(), c.frames.end(),
                   [](const WireFrame& a, const WireFrame& b) { return a.start_ns < b.start_ns; });
  return c;
}

/// Bit times in `ns` at `baud`, rounded to the nearest (timestamps are rounded down to ns).
std::int64_t bits(std::int64_t ns, std::uint64_t baud) {
  return (ns * static_cast<std::int64_t>(baud) + kNsPerS / 2) / kNsPerS;
}

/// Token passes (SA -> DA) seen in [from, to) seconds.
std::set<std::pair<int, int>> token_passes(const Capture& c, double from, double to) {
  std::set<std::pair<int, int>> s;
  for (const auto& f : c.frames) {
    if (f.start_ns < static_cast<std::int64_t>(from * kNsPerS) ||
        f.start_ns >= static_cast<std::int64_t>(to * kNsPerS) || f.flags != 0)
      continue;
    fdl::Telegram t;
    if (fdl::decode(f.bytes, t) == fdl::DecodeError::None && t.type == fdl::FrameType::SD4)
      s.insert({t.sa, t.da});
  }
  return s;
}

using Passes = std::set<std::pair<int, int>>;

class Multimaster : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { s_run = new SimRun(run_multimaster()); }
  static void TearDownTestSuite() {
    delete s_run;
    s_run = nullptr;
  }
  static SimRun* s_run;
};
SimRun* Multimaster::s_run = nullptr;

TEST_F(Multimaster, RingSplitsAtTheCutAndMergesAfterTheRepair) {
  const Capture c = parse(s_run->pcap);
  // One ring 1 -> 2 -> 3 -> 1 before the cut ...
  EXPECT_EQ(token_passes(c, 1.0, 2.0), (Passes{{1, 2}, {2, 3}, {3, 1}}));
  // ... during it, on master 1's side of the cut, 1 <-> 2 (master 3 alone passing to itself
  // on the other side does not reach the probe).
  EXPECT_EQ(token_passes(c, 2.5, 3.0), (Passes{{1, 2}, {2, 1}}));
  // ... and one again well after the repair.
  EXPECT_EQ(token_passes(c, 4.0, 5.0), (Passes{{1, 2}, {2, 3}, {3, 1}}));

  // The stations' counters tell the same story.
  const Report r = s_run->sim->report(0);
  ASSERT_EQ(r.lines.size(), 1u);
  const auto& masters = r.lines[0].masters;
  ASSERT_EQ(masters.size(), 3u);
  for (const auto& m : masters) {
    EXPECT_TRUE(m.in_ring) << int(m.address);
    EXPECT_EQ(m.las, (std::vector<std::uint8_t>{1, 2, 3})) << int(m.address);
  }
  EXPECT_GE(masters[2].token_losses, 1u);  // master 3 lost the token at the cut and claimed it
  // Masters 1 and 2 gave up passing to 3 (one of them dropped it from the LAS).
  EXPECT_GE(masters[0].stations_dropped + masters[1].stations_dropped, 1u);
  // Master 3's polls of 13 and 14 failed during the cut, and only then.
  EXPECT_GT(masters[2].polls.no_response, 0u);
  EXPECT_EQ(masters[2].polls.ok + masters[2].polls.no_response, masters[2].polls.requests);
  // Live list after the merge: three masters in the ring and five slaves.
  std::map<int, fdl::StationType> live;
  for (const auto& e : r.lines[0].live) live[e.address] = e.type;
  EXPECT_EQ(live, (std::map<int, fdl::StationType>{{1, fdl::StationType::MasterInRing},
                                                   {2, fdl::StationType::MasterInRing},
                                                   {3, fdl::StationType::MasterInRing},
                                                   {10, fdl::StationType::Slave},
                                                   {11, fdl::StationType::Slave},
                                                   {12, fdl::StationType::Slave},
                                                   {13, fdl::StationType::Slave},
                                                   {14, fdl::StationType::Slave}}));
  // The cut and the repair are in the events and in the report.
  ASSERT_EQ(r.lines[0].traffic.faults.size(), 2u);
  EXPECT_EQ(r.lines[0].traffic.faults[0].time, 2 * bus::kTicksPerSecond);
  EXPECT_EQ(r.lines[0].traffic.faults[0].text, "A: cable cut between 'slave 14' and 'master 3'");
  EXPECT_EQ(r.lines[0].traffic.faults[1].time, 3 * bus::kTicksPerSecond);
}

TEST_F(Multimaster, SameSeedGivesAByteIdenticalCapture) {
  const SimRun again = run_multimaster();
  ASSERT_FALSE(again.pcap.empty());
  EXPECT_TRUE(again.pcap == s_run->pcap) << "captures differ: " << again.pcap.size() << " vs "
                                         << s_run->pcap.size() << " octets";
}

TEST_F(Multimaster, CaptureOpensInTsharkWithEveryPacket) {
  if (!test::tshark_available()) GTEST_SKIP() << test::kNoTshark;
  const std::string path = PBVBUS_BINARY_DIR "/multimaster_test.pcapng";
  {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(s_run->pcap.data()),
            static_cast<std::streamsize>(s_run->pcap.size()));
  }
  const auto r = test::tshark(path, {"-T", "fields", "-e", "frame.number"}, false);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto lines = static_cast<std::uint64_t>(std::count(r.out.begin(), r.out.end(), '\n'));
  EXPECT_EQ(lines, s_run->frames + s_run->events);
  EXPECT_GT(s_run->frames, 10'000u);
}

TEST_F(Multimaster, EveryUnflaggedFrameIsAValidTelegram) {
  const Capture c = parse(s_run->pcap);
  ASSERT_FALSE(c.frames.empty());
  std::size_t flagged = 0;
  for (const auto& f : c.frames) {
    fdl::Telegram t;
    const auto e = fdl::decode(f.bytes, t);
    if (f.flags == 0) {
      EXPECT_EQ(e, fdl::DecodeError::None) << "at " << f.start_ns << " ns: " << fdl::to_string(e);
    } else {
      ++flagged;
      EXPECT_FALSE(f.comment.empty());
    }
  }
  // Damaged frames only around the repair, where two token holders meet for a moment (frames
  // that started up to a 255-octet telegram before it, and the first few ms after it); none
  // during the cut, which the probe's side of the cable does not notice.
  for (const auto& f : c.frames) {
    if (f.flags == 0) continue;
    EXPECT_TRUE(f.start_ns >= 3 * kNsPerS - 1'870'000 && f.start_ns < 3 * kNsPerS + 10'000'000)
        << "damaged frame at " << f.start_ns << " ns: " << f.comment;
  }
  EXPECT_GT(flagged, 0u);
}

TEST_F(Multimaster, GapsRespectTsynAndTsdr) {
  const Capture c = parse(s_run->pcap);
  const auto& p = s_run->sim->plan().lines[0].params;
  std::size_t requests = 0, responses = 0;
  for (std::size_t i = 1; i < c.frames.size(); ++i) {
    const WireFrame& prev = c.frames[i - 1];
    const WireFrame& f = c.frames[i];
    if (f.flags != 0 || prev.flags != 0) continue;
    fdl::Telegram t, pt;
    if (fdl::decode(f.bytes, t) != fdl::DecodeError::None) continue;
    if (fdl::decode(prev.bytes, pt) != fdl::DecodeError::None) continue;
    const std::int64_t gap = bits(f.start_ns - prev.end_ns, c.baud);
    if (t.type == fdl::FrameType::SD4 || t.is_request()) {
      ++requests;
      EXPECT_GE(gap, 33) << "request/token at " << f.start_ns << " ns after only " << gap
                         << " bit times of idle";
    } else if (pt.is_request() && fdl::fn_expects_reply(fdl::fc_request_fn(pt.fc))) {
      ++responses;
      EXPECT_GE(gap, static_cast<std::int64_t>(p.min_tsdr)) << "response at " << f.start_ns;
      EXPECT_LE(gap, static_cast<std::int64_t>(p.max_tsdr)) << "response at " << f.start_ns;
      if (t.type != fdl::FrameType::SC) {
        EXPECT_EQ(t.sa, pt.da) << "response at " << f.start_ns;
      }
    }
  }
  EXPECT_GT(requests, 10'000u);
  EXPECT_GT(responses, 10'000u);
}

// After the repair the two logical rings (1 <-> 2 on one side, 3 alone on the other) meet.
// Measured from a whole-line tap (every frame once, from its sender's side), in bit times at
// 1.5 Mbit/s since the repair at 3 s.
struct MergeTimes {
  std::int64_t first_ring12_token = -1;  ///< first valid token frame of master 1 or 2
  std::int64_t last_lone_token = -1;     ///< last valid DC 03 03 (master 3 alone)
  std::int64_t ring_whole = -1;          ///< first DC 01 03 (3 passes to 1: one ring 1-2-3)
};

MergeTimes merge_times(const test::FrameRecorder& rec, bus::Ticks repair, bus::Ticks bit) {
  MergeTimes m;
  for (const auto& f : rec.frames()) {
    if (f.start < repair || !f.intact()) continue;
    fdl::Telegram t;
    if (fdl::decode(f.bytes, t) != fdl::DecodeError::None || t.type != fdl::FrameType::SD4) continue;
    const std::int64_t at = (f.start - repair) / bit;
    if ((t.sa == 1 || t.sa == 2) && m.first_ring12_token < 0) m.first_ring12_token = at;
    if (t.sa == 3 && t.da == 3) m.last_lone_token = at;
    if (t.sa == 3 && t.da == 1 && m.ring_whole < 0) m.ring_whole = at;
  }
  return m;
}

TEST(MultimasterMerge, NoTwoTokensAfterTheRepair) {
  // IEC 61158-4-3 token procedures (docs/fdl-stations.md "Two rings meet"): a station that
  // holds the token or checks its pass and hears a valid frame it did not expect gives its token
  // up, so after the repair one token survives the first intact frame. Here the frames of both
  // sides collide until master 3's SRD at 695 bits (ends 838): master 1, checking its pass to 2
  // (DC 02 01 at 599, destroyed), gives ring 1-2's token up, and masters 1 and 2 send nothing
  // until master 3's GAP poll reaches address 1 (59th poll, 1112 + 58 * 1236 = 72 800 bits;
  // derivation in tests/fdl/token_merge_test.cpp, which builds the same stations by hand).
  const auto loaded = load_scenario_file(PBVBUS_SOURCE_DIR "/examples/multimaster.textproto");
  ASSERT_TRUE(loaded.ok());
  Simulation sim(*loaded.plan);
  test::FrameRecorder rec;
  sim.line(0).add_tap(rec);
  sim.run_until(4 * bus::kTicksPerSecond);
  const bus::Ticks bit = bus::ticks_per_bit(bus::Baud::k1_5M);
  const MergeTimes m = merge_times(rec, 3 * bus::kTicksPerSecond, bit);
  // Token frames of the two rings never interleave: master 3's last token to itself comes
  // before the first token of master 1 or 2 (the span of interleaving is zero).
  EXPECT_EQ(m.last_lone_token, 71'930);
  EXPECT_EQ(m.ring_whole, 72'980);
  EXPECT_EQ(m.first_ring12_token, 73'050);  // 1 passes to 2 after its own cycles
  EXPECT_LT(m.last_lone_token, m.first_ring12_token);
  // And no frame of master 1 or 2 (intact or not) starts after 838 until the poll of 1.
  for (const auto& f : rec.frames()) {
    if (f.start < 3 * bus::kTicksPerSecond) continue;
    const std::int64_t at = (f.start - 3 * bus::kTicksPerSecond) / bit;
    if (at >= 72'800) break;
    fdl::Telegram t;
    const bool from12 = f.intact() && fdl::decode(f.bytes, t) == fdl::DecodeError::None &&
                        t.type != fdl::FrameType::SC && (t.sa == 1 || t.sa == 2) &&
                        !(t.type == fdl::FrameType::SD1 && !t.is_request());
    EXPECT_FALSE(from12 && at >= 838) << "frame from master " << int(t.sa) << " at " << at;
  }
}

}  // namespace
}  // namespace pbvbus::tools
