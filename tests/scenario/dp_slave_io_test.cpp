// dp_slave `io` behaviours and the DP slave faults in scenario files: what the loader plans
// (scenario/include/pbvbus/scenario/dp_plan.hpp DpIoPlan, scenario.hpp PlanFault) and its errors at
// FILE:LINE:COLUMN.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

const std::string kFile = PBVBUS_SOURCE_DIR "/examples/test.textproto";
constexpr bus::Ticks kMs = bus::kTicksPerSecond / 1000;

// Lines 1..4; the slave opens on line 5, its modules are on line 6, entries follow from line 7.
std::string slave(const std::string& body, const std::string& after = "") {
  return "name: \"t\"\nduration: \"1s\"\nline { name: \"A\" baud: \"1.5M\" }\n"
         "dp_master { address: 1 line: \"A\" }\n"
         "dp_slave { address: 6 line: \"A\" gsd: \"gsd/PBVB0A02.gsd\" master: 1\n"
         "  modules: [\"8DI DC24V\", \"16DO DC24V/0.5A\", \"4AI U/I 16 bit\", \"16DI DC24V\"]\n" +
         body + "}\n" + after;
}

std::vector<std::string> errors_of(const std::string& text) {
  const auto r = parse_scenario(text, kFile);
  std::vector<std::string> out;
  for (const auto& e : r.errors) out.push_back(e.str());
  return out;
}

TEST(DpSlaveIo, PlansEveryBehaviour) {
  const auto r = parse_scenario(
      slave("  io { module: \"8DI DC24V\" constant { value: 0x1A5 } }\n"
            "  io { module_index: 2 offset: 2 width: 2 ramp { min: -100 max: 100 period: \"1s\" } }\n"
            "  io { module: \"4AI U/I 16 bit\" width: 2 table { row { at: \"0ms\" value: 7 }\n"
            "       row { at: \"100ms\" value: 9 } repeat: true period: \"200ms\" } }\n"
            "  io { module: \"16DI DC24V\" counter { period: \"10ms\" step: 3 start: 1 } }\n"
            "  io { module_index: 3 offset: 1 echo { from_module: \"16DO DC24V/0.5A\" } }\n"),
      kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  const auto& io = r.plan->dp_slaves.at(0).io_behaviours;
  ASSERT_EQ(io.size(), 5u);
  using K = devices::IoBehaviour::Kind;
  // 0x1A5 over the one octet of 8DI: its low octet.
  EXPECT_EQ(io[0].module, 0u);
  EXPECT_TRUE(io[0].whole);
  EXPECT_EQ(io[0].behaviour.kind, K::Constant);
  EXPECT_EQ(io[0].behaviour.constant, (std::vector<std::uint8_t>{0xA5}));
  EXPECT_EQ(io[1].module, 2u);
  EXPECT_FALSE(io[1].whole);
  EXPECT_EQ(io[1].offset, 2u);
  EXPECT_EQ(io[1].width, 2u);
  EXPECT_EQ(io[1].behaviour.kind, K::Ramp);
  EXPECT_EQ(io[1].behaviour.min, -100);
  EXPECT_EQ(io[1].behaviour.max, 100);
  EXPECT_EQ(io[1].behaviour.period, bus::kTicksPerSecond);
  EXPECT_EQ(io[2].offset, 0u);
  EXPECT_EQ(io[2].width, 2u);
  EXPECT_EQ(io[2].behaviour.kind, K::Table);
  ASSERT_EQ(io[2].behaviour.rows.size(), 2u);
  EXPECT_EQ(io[2].behaviour.rows[1], (std::pair<bus::Ticks, std::int64_t>(100 * kMs, 9)));
  EXPECT_TRUE(io[2].behaviour.repeat);
  EXPECT_EQ(io[2].behaviour.period, 200 * kMs);
  EXPECT_EQ(io[3].behaviour.kind, K::Counter);
  EXPECT_EQ(io[3].behaviour.period, 10 * kMs);
  EXPECT_EQ(io[3].behaviour.step, 3u);
  EXPECT_EQ(io[3].behaviour.start, 1u);
  // Offset without width: the rest of the module (16DI has 2 input octets).
  EXPECT_EQ(io[4].offset, 1u);
  EXPECT_EQ(io[4].width, 1u);
  EXPECT_EQ(io[4].behaviour.kind, K::Echo);
  EXPECT_EQ(io[4].behaviour.source_module, std::optional<std::size_t>(1));
}

TEST(DpSlaveIo, CounterWithoutPeriodCountsDpCyclesWithStepOne) {
  const auto r = parse_scenario(slave("  io { module_index: 0 counter { } }\n"), kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  const auto& b = r.plan->dp_slaves.at(0).io_behaviours.at(0).behaviour;
  EXPECT_EQ(b.period, 0);
  EXPECT_EQ(b.step, 1u);
}

TEST(DpSlaveIo, ErrorsNameFileLineAndColumnOfTheIoEntry) {
  const auto unknown = errors_of(slave("  io { module: \"99DI\" constant { value: 1 } }\n"));
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_EQ(unknown[0], kFile + ":7:3: io module \"99DI\" is not one of the slave's modules");

  const auto index = errors_of(slave("\n    io { module_index: 4 constant { value: 1 } }\n"));
  ASSERT_EQ(index.size(), 1u);
  EXPECT_EQ(index[0], kFile + ":8:5: io module_index 4 is not below the 4 modules of the slave");

  const auto width = errors_of(slave("  io { module_index: 2 offset: 6 width: 4 constant { value: 1 } }\n"));
  ASSERT_EQ(width.size(), 1u);
  EXPECT_EQ(width[0], kFile +
                          ":7:3: channel offset 6 width 4 is outside the 8 input octets of module "
                          "\"4AI U/I 16 bit\"");

  const auto no_inputs = errors_of(slave("  io { module_index: 1 constant { value: 1 } }\n"));
  ASSERT_EQ(no_inputs.size(), 1u);
  EXPECT_EQ(no_inputs[0], kFile + ":7:3: module \"16DO DC24V/0.5A\" has no inputs");

  const auto duration = errors_of(
      slave("  io { module_index: 0 table { row { at: \"0ms\" value: 1 } row { at: \"5 parsecs\" value: 2 } } }\n"));
  ASSERT_EQ(duration.size(), 1u);
  EXPECT_EQ(duration[0], kFile + ":7:3: bad duration \"5 parsecs\" for table row (e.g. \"100ms\")");

  const auto ramp = errors_of(slave("  io { module_index: 0 ramp { min: 0 max: 9 period: \"1x\" } }\n"));
  ASSERT_EQ(ramp.size(), 1u);
  EXPECT_EQ(ramp[0], kFile + ":7:3: bad duration \"1x\" for ramp period (e.g. \"100ms\")");

  const auto repeat = errors_of(slave(
      "  io { module_index: 0 table { row { at: \"0ms\" value: 1 } row { at: \"50ms\" value: 2 } repeat: true } }\n"));
  ASSERT_EQ(repeat.size(), 1u);
  EXPECT_EQ(repeat[0], kFile + ":7:3: repeating table needs a period longer than its last row time");

  const auto echo = errors_of(slave("  io { module_index: 0 echo { from_module_index: 2 } }\n"));
  ASSERT_EQ(echo.size(), 1u);
  EXPECT_EQ(echo[0], kFile + ":7:3: echo source module \"4AI U/I 16 bit\" has no outputs");

  const auto none = errors_of(slave("  io { module_index: 0 }\n"));
  ASSERT_EQ(none.size(), 1u);
  EXPECT_EQ(none[0], kFile + ":7:3: io needs a behaviour: constant, counter, ramp, table or echo");
}

TEST(DpSlaveFaults, PlansEveryKindWithItsDescription) {
  const auto r = parse_scenario(
      slave("", "fault { at: \"100ms\" repair_at: \"200ms\" slave_mute { line: \"A\" address: 6 } }\n"
                "fault { at: \"300ms\" repair_at: \"400ms\" channel_diag { line: \"A\" address: 6\n"
                "  module: \"4AI U/I 16 bit\" channel: 3 error_type: 1 } }\n"
                "fault { at: \"500ms\" repair_at: \"600ms\" module_pull { line: \"A\" address: 6 module_index: 0 } }\n"),
      kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  const auto& f = r.plan->faults;
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0].kind, PlanFault::Kind::SlaveMute);
  EXPECT_EQ(f[0].slave, 6);
  EXPECT_EQ(f[0].description, "mute DP slave 6 on line A");
  EXPECT_EQ(f[1].kind, PlanFault::Kind::ChannelDiag);
  EXPECT_EQ(f[1].module, 2u);
  EXPECT_EQ(f[1].channel, 3);
  EXPECT_EQ(f[1].error_type, 1);
  EXPECT_TRUE(f[1].word_channel);  // 4AI: identifier 0xD3, word format
  EXPECT_FALSE(f[1].output_channel);
  EXPECT_EQ(f[1].description,
            "channel diagnosis (error type 1) on channel 3 of module 2 (4AI U/I 16 bit) of DP slave 6 "
            "on line A");
  EXPECT_EQ(f[2].kind, PlanFault::Kind::ModulePull);
  EXPECT_EQ(f[2].module, 0u);
  EXPECT_EQ(f[2].repair_at, std::optional<bus::Ticks>(600 * kMs));
  EXPECT_EQ(f[2].description, "pulled module 0 (8DI DC24V) of DP slave 6 on line A");
}

TEST(DpSlaveFaults, ErrorsNameFileLineAndColumn) {
  // The fault is on line 8; columns are those of the offending field (counted 1-based).
  const auto no_slave = errors_of(slave("", "fault { at: \"1ms\" slave_mute { line: \"A\" address: 1 } }\n"));
  ASSERT_EQ(no_slave.size(), 1u);
  EXPECT_EQ(no_slave[0], kFile + ":8:42: slave_mute: no dp_slave 1 on line \"A\"");

  const auto module = errors_of(slave("", "fault { at: \"1ms\" module_pull { line: \"A\" address: 6 module: \"2AO\" } }\n"));
  ASSERT_EQ(module.size(), 1u);
  EXPECT_EQ(module[0], kFile + ":8:54: module_pull: module \"2AO\" is not one of the modules of dp_slave 6");

  const auto error_type = errors_of(slave(
      "", "fault { at: \"1ms\" channel_diag { line: \"A\" address: 6 module_index: 0 error_type: 32 } }\n"));
  ASSERT_EQ(error_type.size(), 1u);
  EXPECT_EQ(error_type[0], kFile + ":8:71: channel_diag: error_type 32 is out of range 1..31");

  const auto dpv1 = errors_of(slave("", "fault { at: \"1ms\" process_alarm { line: \"A\" address: 6 module_index: 0 } }\n"));
  ASSERT_EQ(dpv1.size(), 1u);
  EXPECT_EQ(dpv1[0], kFile + ":8:45: process_alarm: dp_slave 6 (pbvbus MS8 modular station) is not a DP-V1 slave");
}

}  // namespace
}  // namespace pbvbus::tools
