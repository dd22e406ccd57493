// dp_slave `io` behaviours and DP slave faults end to end: a scenario with one modular slave
// (examples/gsd/PBVB0A02.gsd, the module list of tests/devices/slaves/slave_model_test.cpp) run in fast
// mode; the bytes of its Data_Exchange answers and diagnoses are checked on the wire.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "frame_recorder.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr bus::Ticks kMs = bus::kTicksPerSecond / 1000;

// Slave 6 has 8DI (1 input octet), 16DO, 4AI (8), 2AO, 16DI (2): Data_Exchange answers carry
// 11 input octets, 8DI first and 16DI last. 8DI shows a constant, 16DI a table; the 4AI keeps
// the default counter.
const char* kScenario = R"(
name: "io"
duration: "1s"
line { name: "A" baud: "1.5M" }
dp_master { address: 1 line: "A" }
dp_slave {
  address: 6 line: "A" gsd: "gsd/PBVB0A02.gsd" master: 1
  modules: ["8DI DC24V", "16DO DC24V/0.5A", "4AI U/I 16 bit", "2AO U/I 16 bit", "16DI DC24V"]
  io { module: "8DI DC24V" constant { value: 0x5A } }
  io { module_index: 4 table { row { at: "0ms" value: 0x1234 } row { at: "100ms" value: 0xBEEF } } }
}
fault { at: "200ms" repair_at: "400ms" slave_mute { line: "A" address: 6 } }
fault { at: "600ms" repair_at: "700ms" channel_diag { line: "A" address: 6 module: "4AI U/I 16 bit" channel: 3 error_type: 1 } }
fault { at: "800ms" repair_at: "900ms" module_pull { line: "A" address: 6 module_index: 0 } }
)";

struct Run {
  std::unique_ptr<Simulation> sim;
  test::FrameRecorder rec;
};

std::unique_ptr<Run> start() {
  const auto loaded = parse_scenario(kScenario, PBVBUS_SOURCE_DIR "/examples/io.textproto");
  EXPECT_TRUE(loaded.ok()) << (loaded.errors.empty() ? "" : loaded.errors.front().str());
  if (!loaded.ok()) return nullptr;
  auto r = std::make_unique<Run>();
  r->sim = std::make_unique<Simulation>(*loaded.plan);
  r->sim->line(0).add_tap(r->rec);
  return r;
}

bool starts_with(const Bytes& b, const Bytes& head) {
  return b.size() >= head.size() && std::equal(head.begin(), head.end(), b.begin());
}

// A Data_Exchange request of master 1 to slave 6 (6 output octets) and the answer with data.
const Bytes kDxRequest{0x68, 0x09, 0x09, 0x68, 0x06, 0x01};
const Bytes kDxAnswer{0x68, 0x0E, 0x0E, 0x68, 0x01, 0x06};

TEST(DpSlaveIoRun, ConstantAndTableShowTheirBytesInDataExchangeAnswers) {
  auto r = start();
  ASSERT_NE(r, nullptr);
  r->sim->run_until(200 * kMs);
  int before = 0, after = 0;
  for (std::size_t i = 0; i + 1 < r->rec.size(); ++i) {
    const auto& req = r->rec.frame(i);
    const auto& ans = r->rec.frame(i + 1);
    if (!starts_with(req.bytes, kDxRequest) || !starts_with(ans.bytes, kDxAnswer)) continue;
    ASSERT_EQ(ans.bytes.size(), 20u);  // 9 + 11 input octets
    EXPECT_EQ(ans.bytes[7], 0x5A);     // 8DI: the constant
    // 16DI: the table value at the end of the request frame.
    if (req.end < 100 * kMs) {
      EXPECT_EQ(ans.bytes[16], 0x12);
      EXPECT_EQ(ans.bytes[17], 0x34);
      ++before;
    } else {
      EXPECT_EQ(ans.bytes[16], 0xBE);
      EXPECT_EQ(ans.bytes[17], 0xEF);
      ++after;
    }
  }
  EXPECT_GT(before, 100);
  EXPECT_GT(after, 100);
}

TEST(DpSlaveIoRun, FaultsShowOnTheWireInTheMasterAndInTheReport) {
  auto r = start();
  ASSERT_NE(r, nullptr);
  const DpMasterNode* m = r->sim->dp_master(0, 1);
  ASSERT_NE(m, nullptr);
  r->sim->run_until(199 * kMs);
  ASSERT_EQ(m->master().slave_state(6), dp::SlaveStatusState::DataExchange);
  EXPECT_EQ(m->master().slave_stats(6).failures, 0u);

  // Muted from 200 ms: the master reports the failure; after 400 ms the slave returns.
  r->sim->run_until(399 * kMs);
  EXPECT_NE(m->master().slave_state(6), dp::SlaveStatusState::DataExchange);
  EXPECT_EQ(m->master().slave_stats(6).failures, 1u);
  std::size_t first_muted = r->rec.size();
  for (std::size_t i = 0; i < r->rec.size(); ++i)
    if (r->rec.frame(i).start >= 201 * kMs) {
      first_muted = i;
      break;
    }
  for (std::size_t i = first_muted; i < r->rec.size(); ++i)
    EXPECT_FALSE(r->rec.frame(i).bytes.size() > 5 && r->rec.frame(i).bytes[0] == 0x68 &&
                 (r->rec.frame(i).bytes[5] & 0x7F) == 6)
        << "slave 6 answered while muted: " << r->rec.hex(i);
  r->sim->run_until(599 * kMs);
  EXPECT_EQ(m->master().slave_state(6), dp::SlaveStatusState::DataExchange);
  EXPECT_EQ(m->master().slave_stats(6).startups, 2u);

  // Channel diagnosis from 600 ms: a Data_Exchange answered DH (FC 0A), then the master's
  // Slave_Diag read gets Ext_Diag with the channel block 82 43 A1 (identifier 2 = the 4AI;
  // input, channel 3; word, short circuit) — the bytes of slave_model_test.cpp.
  const std::size_t mark = r->rec.size();
  r->sim->run_until(699 * kMs);
  std::size_t dh = 0, diag = 0;
  const std::string expected = "68 0E 0E 68 81 86 08 3E 3C 08 0C 00 01 0A 02 82 43 A1 10 16";
  for (std::size_t i = mark; i < r->rec.size(); ++i) {
    if (dh == 0 && r->rec.hex(i).rfind("68 0E 0E 68 01 06 0A ", 0) == 0) dh = i;
    if (diag == 0 && r->rec.hex(i) == expected) diag = i;
  }
  ASSERT_NE(dh, 0u);
  ASSERT_NE(diag, 0u);
  EXPECT_LT(dh, diag);
  EXPECT_GE(r->rec.frame(dh).start, 600 * kMs);
  EXPECT_EQ(m->master().slave_diag(6).size(), 9u);
  r->sim->run_until(799 * kMs);
  EXPECT_EQ(m->master().slave_state(6), dp::SlaveStatusState::DataExchange);
  EXPECT_EQ(Bytes(m->master().slave_diag(6).begin(), m->master().slave_diag(6).end()),
            (Bytes{0x00, 0x0C, 0x00, 0x01, 0x0A, 0x02}));

  // Module 0 pulled at 800 ms: identifier-related block 42 01 (one octet for five modules,
  // bit 0 = module 0) and its input octet reads 0; plugged again at 900 ms.
  r->sim->run_until(850 * kMs);
  EXPECT_EQ(Bytes(m->master().slave_diag(6).begin(), m->master().slave_diag(6).end()),
            (Bytes{0x08, 0x0C, 0x00, 0x01, 0x0A, 0x02, 0x42, 0x01}));
  Bytes in(1);
  ASSERT_EQ(m->master().image(6).read_inputs(0, in), dp::ImageAccess::Ok);
  EXPECT_EQ(in[0], 0x00);
  r->sim->run_until(1000 * kMs);
  EXPECT_EQ(Bytes(m->master().slave_diag(6).begin(), m->master().slave_diag(6).end()),
            (Bytes{0x00, 0x0C, 0x00, 0x01, 0x0A, 0x02}));
  ASSERT_EQ(m->master().image(6).read_inputs(0, in), dp::ImageAccess::Ok);
  EXPECT_EQ(in[0], 0x5A);
  EXPECT_EQ(m->master().slave_stats(6).failures, 1u);

  const Report rep = r->sim->report(0.0);
  ASSERT_EQ(rep.lines.size(), 1u);
  std::vector<std::string> lines;
  for (const auto& f : rep.lines[0].traffic.faults)
    lines.push_back(bus::format_duration(f.time) + ": " + f.text);
  const std::string d = "channel diagnosis (error type 1) on channel 3 of module 2 (4AI U/I 16 bit) of DP slave 6 on line A";
  EXPECT_EQ(lines, (std::vector<std::string>{
                       bus::format_duration(200 * kMs) + ": mute DP slave 6 on line A",
                       bus::format_duration(400 * kMs) + ": unmute DP slave 6 on line A",
                       bus::format_duration(600 * kMs) + ": " + d + " appears",
                       bus::format_duration(700 * kMs) + ": " + d + " disappears",
                       bus::format_duration(800 * kMs) + ": pulled module 0 (8DI DC24V) of DP slave 6 on line A",
                       bus::format_duration(900 * kMs) + ": plugged module 0 (8DI DC24V) of DP slave 6 on line A"}));
}

}  // namespace
}  // namespace pbvbus::tools

namespace pbvbus::tools {
namespace {

// examples/dp-faults.textproto runs clean: every slave ends in Data_Exchange; slave 3's mute is
// one failure and one return; slave 5's process alarm reaches the master once (acknowledged).
TEST(DpFaultsExample, RunsCleanWithEachFaultSeenByTheMaster) {
  const auto loaded = load_scenario_file(PBVBUS_SOURCE_DIR "/examples/dp-faults.textproto");
  ASSERT_TRUE(loaded.ok()) << loaded.errors.front().str();
  Simulation sim(*loaded.plan);
  sim.run_until(*sim.duration());
  const DpMasterNode* m = sim.dp_master(0, 1);
  ASSERT_NE(m, nullptr);
  for (std::uint8_t a : {std::uint8_t{3}, std::uint8_t{4}, std::uint8_t{5}})
    EXPECT_EQ(m->master().slave_state(a), dp::SlaveStatusState::DataExchange) << int(a);
  EXPECT_EQ(m->master().slave_stats(3).failures, 1u);
  EXPECT_EQ(m->master().slave_stats(3).returns, 1u);
  EXPECT_EQ(m->master().slave_stats(4).failures, 0u);
  EXPECT_EQ(m->master().slave_stats(5).alarms, 1u);
  EXPECT_EQ(m->master().slave_stats(5).alarm_acks, 1u);
  // DH for the channel diagnosis appearing and going, the pull and the plug.
  EXPECT_GE(m->master().slave_stats(4).dh, 4u);
  EXPECT_EQ(sim.report(0.0).lines.at(0).traffic.faults.size(), 7u);
}

}  // namespace
}  // namespace pbvbus::tools
