// The scenario side of F3, F15 and OB 122 (docs/h-scenarios.md: fault slave_stop, program copy
// `direct`): planned, refused with FILE:LINE:COLUMN, and run through the Simulation
// (HSystemNode -> HSystemModel), asserted from the report's I/O events (OB, code, racks,
// mdl_addr, mdl_stop) and its JSON.
//
// The run (pair defaults as examples/h-system.textproto: startup 1 s, link-up 2 s, update
// 145 ms): Redundant from 3.145 s. I/O map (addresses sorted): station 3 IB 0..1 / QB 0..1,
// station 20 (DP-V0, PBVB0A02) 8DI IB 2 / 8DO QB 2, station 21 (DP-V1, PBVB0A03) 8DI IB 3 / 8DO
// QB 3. Program: copy IB 2 -> QB 2 direct.
//   5 s / 6 s   slave_stop of 20 and back to RUN: OB 82 3942 MDL_STOP 1 / 3842 MDL_STOP 0
//   7 s / 8 s   channel_diag on 21's module 0 (no alarm: the diagnosis change): OB 82 3942/3842
//   9 s / 10 s  module_pull of 21's module 1 (DP-V1 pull/plug alarms): OB 83 3961 / 3861
//   11 s / 12 s slave_mute of 20: OB 86 39C4, then OB 122 2942/2943 at every scan until back
// The OB times are the master's Slave_Diag confirmations after the slave's DH answer: within
// one DP cycle plus one Slave_Diag (< 20 ms at 1.5 Mbit/s with three slaves) of the fault.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "scenario_run_support.hpp"
#include "pbvbus/bus/tap.hpp"
#include "pbvbus/simulation/h_report.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"
#include "pbvbus/reports/run_report.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr bus::Ticks kS = bus::kTicksPerSecond;
using K = PlanFault::Kind;
const std::string kFile = PBVBUS_SOURCE_DIR "/examples/test.textproto";

const std::string kHead = R"(name: "f3-f15"
duration: "14s"
line { name: "DP_A" baud: "1.5M" }
line { name: "DP_B" baud: "1.5M" }
dp_master { address: 1 line: "DP_A" watchdog: "100ms" }
dp_master { address: 1 line: "DP_B" watchdog: "100ms" }
redundant_master_system { name: "S" line_a: "DP_A" master_a: 1 line_b: "DP_B" master_b: 1 }
switched_station { system: "S" address: 3 gsd: "gsd/PBVB0A10.gsd" modules: ["16DI DC24V", "16DO DC24V/0.5A"] }
dp_slave { address: 20 line: "DP_A" gsd: "gsd/PBVB0A02.gsd" master: 1 modules: ["8DI DC24V", "8DO DC24V/0.5A"] }
dp_slave { address: 21 line: "DP_A" gsd: "gsd/PBVB0A03.gsd" master: 1 modules: ["8DI with process alarm", "8DO DC24V/0.5A"] }
h_system {
  name: "H"
  dp_system { system: "S" t_pto: "1250ms" }
  cpu { cpu0 { power_on: "0s" } cpu1 { power_on: "0s" } startup_time: "1s" link_up_time: "2s" }
  program { scan_time: "10ms" copy { from_input: 2 to_output: 2 direct: true } }
}
)";
const std::string kFaults = R"(fault { at: "5s" repair_at: "6s" slave_stop { line: "DP_A" address: 20 } }
fault { at: "7s" repair_at: "8s" channel_diag { line: "DP_A" address: 21 module_index: 0 channel: 2 error_type: 6 } }
fault { at: "9s" repair_at: "10s" module_pull { line: "DP_A" address: 21 module_index: 1 } }
fault { at: "11s" repair_at: "12s" slave_mute { line: "DP_A" address: 20 } }
)";

std::vector<std::string> errors_of(const std::string& text) {
  return test::scenario_errors(text, kFile);
}

TEST(HF3F15Scenario, SlaveStopAndDirectArePlanned) {
  const auto r = parse_scenario(kHead + kFaults, kFile);
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const auto& f = r.plan->faults;
  ASSERT_EQ(f.size(), 4u);
  EXPECT_EQ(f[0].kind, K::SlaveStop);
  EXPECT_EQ(f[0].at, 5 * kS);
  EXPECT_EQ(f[0].repair_at, 6 * kS);
  EXPECT_EQ(f[0].slave, 20);
  EXPECT_EQ(f[0].description, "CPU of DP slave 20 on line DP_A to STOP");
  EXPECT_FALSE(is_h_fault(K::SlaveStop));
  ASSERT_EQ(r.plan->h_systems.size(), 1u);
  ASSERT_TRUE(r.plan->h_systems[0].runtime.has_value());
  const auto& copies = r.plan->h_systems[0].runtime->program.copies;
  ASSERT_EQ(copies.size(), 1u);
  EXPECT_TRUE(copies[0].direct);
}

// Columns by hand: `fault { at: "1s" ` is 17 characters -> the kind at 18; `slave_stop { ` is
// 13 more -> its fields at 31.
TEST(HF3F15Scenario, SlaveStopRefusalsCarryTheirPositions) {
  EXPECT_EQ(errors_of(kHead + "fault { at: \"1s\" slave_stop { line: \"DP_A\" address: 20 module_index: 0 } }\n"),
            (std::vector<std::string>{kFile + ":17:18: slave_stop takes no module"}));
  EXPECT_EQ(errors_of(kHead + "fault { at: \"1s\" slave_stop { line: \"DP_A\" address: 22 } }\n"),
            (std::vector<std::string>{
                // `line: "DP_A" ` is 13 more -> address at 44.
                kFile + ":17:44: slave_stop: no dp_slave 22 on line \"DP_A\""}));
  EXPECT_EQ(errors_of(kHead + "fault { at: \"1s\" slave_stop { line: \"DP_A\" } }\n"),
            (std::vector<std::string>{
                kFile + ":17:18: slave_stop needs the address of a dp_slave"}));
}

TEST(HF3F15Scenario, RunShowsOb82MdlStopOb83AndOb122) {
  const test::ScenarioRun done = test::run_scenario(kHead + kFaults, kFile);
  ASSERT_TRUE(done.report) << done.error;
  const Report& rep = *done.report;
  ASSERT_EQ(rep.h_systems.size(), 1u);
  const auto& io = rep.h_systems[0].io_events;
  auto find = [&](int ob, std::uint16_t code, bus::Ticks from) -> const HIoEvent* {
    for (const auto& e : io)
      if (e.ob == ob && e.code == code && e.at >= from) return &e;
    return nullptr;
  };
  auto within = [](const HIoEvent* e, bus::Ticks at) { return e->at > at && e->at < at + 20 * kMs; };
  const std::vector<int> both{0, 1};

  const HIoEvent* stop = find(82, 0x3942, 5 * kS);
  ASSERT_NE(stop, nullptr);
  EXPECT_TRUE(within(stop, 5 * kS)) << stop->at;
  EXPECT_EQ(stop->racks, both);
  // D1/D2: station 20's diagnostic address (master system 16383, station 3 16382, 20 16381).
  EXPECT_EQ(stop->mdl_addr, std::optional<std::uint16_t>(16381));
  EXPECT_TRUE(stop->mdl_stop);
  const HIoEvent* run = find(82, 0x3842, 6 * kS);
  ASSERT_NE(run, nullptr);
  EXPECT_TRUE(within(run, 6 * kS)) << run->at;
  EXPECT_FALSE(run->mdl_stop);
  EXPECT_EQ(run->mdl_addr, std::optional<std::uint16_t>(16381));

  const HIoEvent* diag = find(82, 0x3942, 7 * kS);
  ASSERT_NE(diag, nullptr);
  EXPECT_TRUE(within(diag, 7 * kS)) << diag->at;
  EXPECT_EQ(diag->mdl_addr, std::optional<std::uint16_t>(3));
  EXPECT_FALSE(diag->mdl_stop);
  EXPECT_EQ(diag->racks, both);
  const HIoEvent* gone = find(82, 0x3842, 8 * kS);
  ASSERT_NE(gone, nullptr);
  EXPECT_TRUE(within(gone, 8 * kS)) << gone->at;

  const HIoEvent* pull = find(83, 0x3961, 9 * kS);
  ASSERT_NE(pull, nullptr);
  EXPECT_TRUE(within(pull, 9 * kS)) << pull->at;
  EXPECT_EQ(pull->racks, both);
  EXPECT_EQ(pull->mdl_addr, std::optional<std::uint16_t>(3));  // 21's 8DO: QB 3
  const HIoEvent* plug = find(83, 0x3861, 10 * kS);
  ASSERT_NE(plug, nullptr);
  EXPECT_TRUE(within(plug, 10 * kS)) << plug->at;

  const HIoEvent* failure = find(86, 0x39C4, 11 * kS);
  ASSERT_NE(failure, nullptr);
  EXPECT_EQ(failure->racks, both);  // F12: OB 86 on both CPUs
  // D1: the slave's diagnostic address (docs/h-diag-address.md): a 417-4H (the default
  // cpu_type) counts down from 16383: master system S 16383, station 3 16382, 20 16381.
  EXPECT_EQ(failure->mdl_addr, std::optional<std::uint16_t>(16381));
  const HIoEvent* rd = find(122, 0x2942, 11 * kS);
  const HIoEvent* wr = find(122, 0x2943, 11 * kS);
  ASSERT_NE(rd, nullptr);
  ASSERT_NE(wr, nullptr);
  EXPECT_GE(rd->at, failure->at);
  EXPECT_EQ(rd->at, wr->at);  // the same scan
  EXPECT_EQ(rd->mdl_addr, std::optional<std::uint16_t>(2));
  EXPECT_EQ(rd->racks, both);
  // Nothing before 11 s (the slave stopped at 5 s stays reachable), nothing after the return.
  for (const auto& e : io) {
    if (e.ob == 122) {
      EXPECT_TRUE(e.at >= failure->at && e.at < 12500 * kMs) << e.at;
    }
  }
  // No OB 82 twice: exactly the four above.
  int n82 = 0;
  for (const auto& e : io) n82 += e.ob == 82;
  EXPECT_EQ(n82, 4);
  // The JSON report carries mdl_addr and mdl_stop.
  std::ostringstream os;
  write_h_json(rep.h_systems, os);
  const std::string json = os.str();
  EXPECT_NE(json.find("\"ob\":82,\"code\":14658,\"mdl_addr\":16381,\"mdl_stop\":true"),
            std::string::npos);
  EXPECT_NE(json.find("\"ob\":86,\"code\":14788,\"mdl_addr\":16381"), std::string::npos);  // 39C4
}

// F3 automatic re-parameterisation from a scenario (docs/h-reparameterisation.md): station 21's
// 8DO (module 1 = slot 2) has the records 1 = 12 34 and 2 = AB; the module is pulled at 1.5 s
// and plugged at 2 s (the master CPU runs Solo from 1 s). After the plug's OB 83 the master writes
// both records over MSAC_C1 and the station takes them. Responses by hand (SD2, DA 81, SA 95 =
// 0x80 | 21, FC 08, DSAP = SSAP = 33): `5F 02 01 02` and `5F 02 02 01`, FCS = 81+95+08+33+33 =
// 0x184, + 5F+02+01+02 = 0x1E8 -> E8 and + 5F+02+02+01 = 0x1E8 -> E8.
TEST(HF3F15Scenario, PlugWritesTheModulesParameterRecordsAndTheStationTakesThem) {
  std::string text = kHead;
  const std::string v1 = R"(modules: ["8DI with process alarm", "8DO DC24V/0.5A"] })";
  const auto at = text.find(v1);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, v1.size(),
               R"(modules: ["8DI with process alarm", "8DO DC24V/0.5A"]
  parameter_record { module: "8DO DC24V/0.5A" index: 1 data: "12 34" }
  parameter_record { module_index: 1 index: 2 data: "AB" } })");
  text.replace(text.find("duration: \"14s\""), 15, "duration: \"2500ms\"");
  // Switched station 3: its 16DO (module 1, slot 2) has record 1 = 00 01 and is pulled too.
  const std::string sw = R"(modules: ["16DI DC24V", "16DO DC24V/0.5A"] })";
  ASSERT_NE(text.find(sw), std::string::npos);
  text.replace(text.find(sw), sw.size(),
               R"(modules: ["16DI DC24V", "16DO DC24V/0.5A"] parameter_record { module_index: 1 index: 1 data: "00 01" } })");
  text += R"(fault { at: "1500ms" repair_at: "2s" module_pull { line: "DP_A" address: 21 module_index: 1 } }
fault { at: "1500ms" repair_at: "2s" module_pull { line: "DP_B" address: 3 module_index: 1 } }
)";
  const auto loaded = parse_scenario(text, kFile);
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].str();
  const auto* sp = [&]() -> const DpSlavePlan* {
    for (const auto& d : loaded.plan->dp_slaves)
      if (d.address == 21) return &d;
    return nullptr;
  }();
  ASSERT_NE(sp, nullptr);
  EXPECT_EQ(sp->prm_records, (std::vector<DpPrmRecordPlan>{{1, 1, {0x12, 0x34}}, {1, 2, {0xAB}}}));

  struct C1Tap final : bus::Tap {
    std::vector<std::pair<bus::Ticks, std::vector<std::uint8_t>>> from21, from3;  // SAP 51 -> 51
    void on_frame(const bus::TapFrame& f) override {
      const auto b = f.bytes;
      if (b.size() < 11 || b[0] != 0x68 || b[7] != 0x33 || b[8] != 0x33) return;
      if (b[5] == 0x95) from21.emplace_back(f.end, std::vector<std::uint8_t>(b.begin(), b.end()));
      if (b[5] == 0x83) from3.emplace_back(f.end, std::vector<std::uint8_t>(b.begin(), b.end()));
    }
  } tap;
  Simulation sim(*loaded.plan);
  sim.line(0).add_tap(tap);
  sim.start();
  sim.run_until(*sim.duration());
  const Report rep = sim.report(1.0);
  const HIoEvent* plug = nullptr;
  const HIoEvent* plug3 = nullptr;
  int pulls = 0;
  for (const auto& e : rep.h_systems.at(0).io_events) {
    pulls += e.ob == 83 && e.code == 0x3961;
    if (e.ob == 83 && e.code == 0x3861) (e.text.find("station 3") != std::string::npos ? plug3 : plug) = &e;
  }
  EXPECT_EQ(pulls, 2);
  ASSERT_NE(plug, nullptr);
  ASSERT_NE(plug3, nullptr);
  // Station 3 (switched; line A its active channel): `5F 02 01 02` from SA 83, FCS = 81+83+08+
  // 33+33+5F+02+01+02 = 0x1D6 -> D6. The module's MDL_ADDR: the 16DO's QB 0.
  EXPECT_EQ(plug3->mdl_addr, std::optional<std::uint16_t>(0));
  ASSERT_EQ(tap.from3.size(), 1u);
  EXPECT_EQ(tap.from3[0].second, (std::vector<std::uint8_t>{0x68, 0x09, 0x09, 0x68, 0x81, 0x83,
                                                            0x08, 0x33, 0x33, 0x5F, 0x02, 0x01,
                                                            0x02, 0xD6, 0x16}));
  EXPECT_GT(tap.from3[0].first, plug3->at);
  ASSERT_EQ(tap.from21.size(), 2u);
  EXPECT_EQ(tap.from21[0].second, (std::vector<std::uint8_t>{0x68, 0x09, 0x09, 0x68, 0x81, 0x95,
                                                             0x08, 0x33, 0x33, 0x5F, 0x02, 0x01,
                                                             0x02, 0xE8, 0x16}));
  EXPECT_EQ(tap.from21[1].second, (std::vector<std::uint8_t>{0x68, 0x09, 0x09, 0x68, 0x81, 0x95,
                                                             0x08, 0x33, 0x33, 0x5F, 0x02, 0x02,
                                                             0x01, 0xE8, 0x16}));
  EXPECT_GT(tap.from21[0].first, plug->at);
  EXPECT_LT(tap.from21[1].first, plug->at + 20 * kMs);
}

// Columns by hand: the dp_slave line 10 of kHead; `parameter_record` refusals at the entry.
TEST(HF3F15Scenario, ParameterRecordRefusals) {
  const std::string v0 = R"(modules: ["8DI DC24V", "8DO DC24V/0.5A"] })";
  auto with = [&](const std::string& rec) {
    std::string text = kHead;
    text.replace(text.find(v0), v0.size(), R"(modules: ["8DI DC24V", "8DO DC24V/0.5A"] )" + rec + " }");
    return errors_of(text);
  };
  // Station 20 (PBVB0A02) is DP-V0: no data records.
  auto e = with(R"(parameter_record { module_index: 0 index: 1 data: "01" })");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("parameter_record: the station is not a DP-V1 slave with C1_Read_Write_supp"),
            std::string::npos) << e[0];
  const std::string v1 = R"(modules: ["8DI with process alarm", "8DO DC24V/0.5A"] })";
  auto with21 = [&](const std::string& rec) {
    std::string text = kHead;
    text.replace(text.find(v1), v1.size(),
                 R"(modules: ["8DI with process alarm", "8DO DC24V/0.5A"] )" + rec + " }");
    return errors_of(text);
  };
  auto one = [](const std::vector<std::string>& v) { return v.size() == 1 ? v[0] : std::string("?"); };
  EXPECT_NE(one(with21(R"(parameter_record { module_index: 2 index: 1 data: "01" })"))
                .find("module_index 2 is not below the 2 modules of the station"),
            std::string::npos);
  EXPECT_NE(one(with21(R"(parameter_record { module: "16DO" index: 1 data: "01" })"))
                .find("module \"16DO\" is not one of the station's modules"),
            std::string::npos);
  EXPECT_NE(one(with21(R"(parameter_record { module_index: 1 index: 255 data: "01" })"))
                .find("index 255 is above 254"),
            std::string::npos);
  EXPECT_NE(one(with21(R"(parameter_record { module_index: 1 index: 1 data: "1" })"))
                .find("data \"1\": octet at 1 needs two hex digits"),
            std::string::npos);
  EXPECT_NE(one(with21(R"(parameter_record { module_index: 1 index: 1 })")).find("no octets"),
            std::string::npos);
  EXPECT_NE(one(with21(R"(parameter_record { index: 1 data: "01" })")).find("needs a module"),
            std::string::npos);
  EXPECT_NE(one(with21(R"(parameter_record { module_index: 1 index: 1 data: "01" } parameter_record { module_index: 1 index: 1 data: "02" })"))
                .find("module 1 record 1 is given twice"),
            std::string::npos);
  // 241 octets: above C1_Max_Data_Len.
  EXPECT_NE(one(with21(R"(parameter_record { module_index: 1 index: 1 data: ")" + std::string(482, 'A') + "\" }"))
                .find("241 octets, at most 240"),
            std::string::npos);
}

}  // namespace
}  // namespace pbvbus::tools
