// The H-system report writer (tools/h_report.hpp): a real devices::HCpuPair driven through R1
// (power-on CPU 0, then CPU 1: STOP -> STARTUP -> Solo -> Link-up -> Update -> Redundant), F5
// (one fibre cut while Redundant) and F1 (the master fails and returns as standby), then the
// exact text lines, JSON keys and capture records.
//
// Times (HCpuPairParams defaults): startup 1 s, link-up 2 s, update 75 ms + 0.7 ms x 100 KB =
// 145 ms.
//   0 s      CPU 0 powers on: master (first ever), STOP -> STARTUP
//   0.5 s    CPU 1 powers on: standby (its partner is master over a whole link), waits in STOP
//   1 s      CPU 0 STARTUP -> RUN (Solo); CPU 1 STOP -> LINK-UP
//   3 s      CPU 1 LINK-UP -> UPDATE (1 s + 2 s)
//   3.145 s  CPU 1 UPDATE -> RUN: Redundant (3 s + 145 ms)
//   5 s      F5: fibre 0 cut: CPU 1 RUN -> STOP, OB 72 (redundant link lost) on CPU 0: Solo
//   6 s      fibre repaired, CPU 1 STOP -> RUN request: LINK-UP 6 s -> 8 s, UPDATE -> 8.145 s
//   10 s     F1: CPU 0 off: CPU 1 becomes master, OB 72 (master CPU lost) on CPU 1, Solo
//   12 s     CPU 0 powers on: standby, LINK-UP 12 s -> 14 s, UPDATE -> 14.145 s Redundant
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/captures/cpu_event.hpp"
#include "pbvbus/simulation/h_report.hpp"
#include "pbvbus/reports/h_report.hpp"

namespace pbvbus::tools {
namespace {

using bus::kTicksPerMs;
using bus::kTicksPerSecond;
using devices::CpuState;
using devices::HCpuPair;

HCpuPair driven_pair() {
  HCpuPair p;
  p.power_on(0, 0);
  p.power_on(1, 500 * kTicksPerMs);
  p.on_time(3145 * kTicksPerMs);  // runs every deadline due up to Redundant
  p.cut_fibre(0, 5 * kTicksPerSecond);
  p.repair_fibre(0, 6 * kTicksPerSecond);
  p.switch_to_run(1, 6 * kTicksPerSecond);
  p.on_time(9 * kTicksPerSecond);
  p.power_off(0, 10 * kTicksPerSecond);
  p.power_on(0, 12 * kTicksPerSecond);
  p.on_time(15 * kTicksPerSecond);
  return p;
}

std::vector<std::string> lines_of(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

bool has_line(const std::vector<std::string>& lines, const std::string& l) {
  for (const auto& x : lines)
    if (x == l) return true;
  return false;
}

TEST(HReport, TextShowsEachCpusTimelineThroughR1F5F1) {
  const HCpuPair p = driven_pair();
  const HSystemReport r = make_h_report("H-CPU", p);
  std::ostringstream os;
  write_h_text({r}, os);
  const auto lines = lines_of(os.str());
  for (const std::string& want : {
           std::string("H-system \"H-CPU\" (S7-400H): system mode Redundant"),
           // F1 swapped the roles: CPU 1 is master now, CPU 0 the returned standby.
           std::string("  CPU 0 (rack 0): RUN, standby, sees Redundant; LEDs MSTR off, RACK0 on, REDF off, "
                       "IFM1F off, IFM2F off"),
           std::string("  CPU 1 (rack 1): RUN, master, sees Redundant; LEDs MSTR on, RACK1 on, REDF off, "
                       "IFM1F off, IFM2F off"),
           std::string("    time [s]  state        role     system mode   REDF   MSTR OB              event"),
           // R1 on CPU 0: STARTUP at 0, Solo/Link-up at 1 s, Update at 3 s, Redundant at 3.145 s.
           std::string("    0.000     STARTUP      master   Stop          on     on                   "
                       "CPU 0: STOP -> STARTUP"),
           std::string("    1.000     RUN          master   Link-up       0.5 Hz on                   "
                       "system mode Startup -> Link-up"),
           std::string("    3.000     RUN          master   Update        2 Hz   on                   "
                       "system mode Link-up -> Update"),
           std::string("    3.145     RUN          master   Redundant     off    on                   "
                       "system mode Update -> Redundant"),
           // R1 on CPU 1.
           std::string("    0.500     STOP         standby  Startup       on     off                  "
                       "CPU 1: role none -> standby"),
           std::string("    1.000     LINK-UP      standby  Startup       on     off                  "
                       "CPU 1: STOP -> LINK-UP"),
           std::string("    3.145     RUN          standby  Update        2 Hz   off                  "
                       "CPU 1: UPDATE -> RUN"),
           // F5 at 5 s: OB 72 on the master, the standby STOPs, Solo.
           std::string("    5.000     RUN          master   Redundant     off    on   OB 72           "
                       "CPU 0: OB 72 (redundant link lost)"),
           std::string("    5.000     STOP         standby  Redundant     off    off                  "
                       "CPU 1: RUN -> STOP"),
           std::string("    5.000     STOP         standby  Solo          on     off                  "
                       "system mode Redundant -> Solo"),
           // F1 at 10 s: CPU 0 dark, CPU 1 takes over with OB 72.
           std::string("    10.000    OFF          master   Redundant     off    off                  "
                       "CPU 0: RUN -> OFF"),
           std::string("    10.000    RUN          master   Redundant     off    on                   "
                       "CPU 1: role standby -> master"),
           std::string("    10.000    RUN          master   Redundant     off    on   OB 72           "
                       "CPU 1: OB 72 (master CPU lost)"),
           std::string("    10.000    RUN          master   Solo          on     on                   "
                       "system mode Redundant -> Solo"),
           // CPU 0 back at 12 s as standby: link-up 12 -> 14 s, update -> 14.145 s.
           std::string("    12.000    STOP         standby  Solo          on     off                  "
                       "CPU 0: role none -> standby"),
           std::string("    14.145    RUN          standby  Redundant     off    off                  "
                       "system mode Update -> Redundant"),
           // 15 state/role/OB/fibre entries, plus the update phases' own: "LINK-UP: copying the
           // load memory" at its two link-ups as standby and "UPDATE: ..." at each of the three
           // updates (as standby at 3 and 6 s, as master at 14 s) = 20.
           std::string("  CPU 1 (rack 1) diagnostic buffer (20 entries):"),
           std::string("    10.000    master   OB 72: master CPU lost"),
           std::string("  I/O events: none"),
           std::string("    CPU 1: t1 3.000 s, t5 3.145 s (145.000 ms); T_P15 window - / planned -: not measured; "
                       "T_PH window - / planned -: not measured"),
           std::string("    CPU 0: t1 14.000 s, t5 14.145 s (145.000 ms); T_P15 window - / planned -: not measured; "
                       "T_PH window - / planned -: not measured"),
       })
    EXPECT_TRUE(has_line(lines, want)) << want << "\n" << os.str();
  // Rows: CPU 0 has 4 at 0 s, 2 at 1 s, 1 each at 3, 3.145, 6, 8, 8.145 s, 2 at 5 s, 3 at 10 s,
  // 4 at 12 s, 2 each at 14 and 14.145 s = 24; CPU 1 has 1 + 2 (0.5 s) + 2 each at 1, 3,
  // 3.145, 5, 6, 8, 8.145 s + 3 (10 s) + 1 each at 12, 14, 14.145 s = 23.
  EXPECT_EQ(r.cpus[0].timeline.size(), 24u);
  EXPECT_EQ(r.cpus[1].timeline.size(), 23u);
  ASSERT_EQ(r.updates.size(), 3u);
  EXPECT_EQ(r.updates[1].rack, 1);
  EXPECT_EQ(r.updates[1].t1, 8 * kTicksPerSecond);             // 6 s + 2 s link-up
  EXPECT_EQ(r.updates[1].t5, 8145 * kTicksPerMs);              // + 145 ms update
  EXPECT_EQ(r.updates[2].rack, 0);
  EXPECT_TRUE(r.updates[2].completed);
}

// Measured windows against the plan: T_P15 window t5 - t3 = 145 - 50 = 95 ms <= 194 ms (within);
// T_PH window t5 - t4 = 100 ms > 90 ms (EXCEEDED). Equal is within.
TEST(HReport, UpdateWindowsAgainstThePlan) {
  const HCpuPair p = driven_pair();
  HSystemReport r = make_h_report("H-CPU", p);
  r.planned_t_p15 = 194 * kTicksPerMs;
  r.planned_t_ph = 90 * kTicksPerMs;
  r.updates[0].t3 = r.updates[0].t1 + 50 * kTicksPerMs;
  r.updates[0].t4 = r.updates[0].t5 - 100 * kTicksPerMs;
  std::ostringstream os;
  write_h_text({r}, os);
  EXPECT_TRUE(has_line(lines_of(os.str()),
                       "    CPU 1: t1 3.000 s, t5 3.145 s (145.000 ms); T_P15 window 95.000 ms / planned "
                       "194.000 ms: within; T_PH window 100.000 ms / planned 90.000 ms: EXCEEDED"))
      << os.str();
  EXPECT_EQ(window_verdict(90 * kTicksPerMs, 90 * kTicksPerMs), "within");
  EXPECT_EQ(window_verdict(90 * kTicksPerMs + 1, 90 * kTicksPerMs), "EXCEEDED");
  std::ostringstream js;
  write_h_json({r}, js);
  // 95 ms = 95 000 000 ns; 3.050 s = t3.
  EXPECT_NE(js.str().find("{\"rack\":1,\"t1_ns\":3000000000,\"t1_ms\":3000.000,\"t3_ns\":3050000000,"
                          "\"t3_ms\":3050.000,\"t4_ns\":3045000000,\"t4_ms\":3045.000,\"t5_ns\":3145000000,"
                          "\"t5_ms\":3145.000,\"completed\":true,\"t_p15_window_ns\":95000000,"
                          "\"t_p15_window_ms\":95.000,\"planned_t_p15_ns\":194000000,\"planned_t_p15_ms\":194.000,"
                          "\"t_p15_verdict\":\"within\",\"t_ph_window_ns\":100000000,\"t_ph_window_ms\":100.000,"
                          "\"planned_t_ph_ns\":90000000,\"planned_t_ph_ms\":90.000,\"t_ph_verdict\":\"EXCEEDED\","
                       "\"last_io_before_ns\":null,\"last_io_before_ms\":null,\"first_io_after_ns\":null,"
                       "\"first_io_after_ms\":null}"),
            std::string::npos)
      << js.str();
}

TEST(HReport, JsonKeysAndTimes) {
  const HSystemReport r = make_h_report("H-CPU", driven_pair());
  std::ostringstream js;
  write_h_json({r}, js);
  const std::string j = js.str();
  EXPECT_EQ(j.rfind(",\"h_systems_run\":[{\"name\":\"H-CPU\",\"profile\":\"S7-400H\",\"system_mode\":\"Redundant\","
                    "\"cpus\":[{\"rack\":0,\"state\":\"RUN\",\"role\":\"standby\",\"system_mode\":\"Redundant\","
                    "\"leds\":{\"mstr\":false,\"rack0\":true,\"rack1\":false,\"redf\":\"off\",\"ifm1f\":false,"
                    "\"ifm2f\":false,\"busf\":[]},\"diag\":[{\"time_ns\":0,\"time_ms\":0.000,\"role\":\"none\",\"code\":0,"
                    "\"text\":\"OFF -> STOP (power on)\"}",
                    0),
            0u)
      << j;
  // F1 at 10 s = 10^10 ns on CPU 1.
  EXPECT_NE(j.find("{\"time_ns\":10000000000,\"time_ms\":10000.000,\"kind\":\"ob\",\"change\":\"CPU 1: OB 72 "
                   "(master CPU lost)\",\"state\":\"RUN\",\"role\":\"master\",\"system_mode\":\"Redundant\","
                   "\"redf\":\"off\",\"mstr\":true,\"ob\":72,\"code\":0,\"reason\":\"master CPU lost\"}"),
            std::string::npos)
      << j;
  // F5 at 5 s on CPU 0.
  EXPECT_NE(j.find("{\"time_ns\":5000000000,\"time_ms\":5000.000,\"kind\":\"ob\",\"change\":\"CPU 0: OB 72 "
                   "(redundant link lost)\""),
            std::string::npos)
      << j;
  EXPECT_NE(j.find("],\"io_events\":[],\"updates\":[{\"rack\":1,"), std::string::npos) << j;
  EXPECT_EQ(j.back(), ']');
  std::ostringstream none;
  write_h_json({}, none);
  EXPECT_EQ(none.str(), "");
}

TEST(HReport, IoEventsArePrinted) {
  HSystemReport r = make_h_report("H-CPU", driven_pair());
  r.io_events.push_back(
      {10 * kTicksPerSecond, {0, 1}, 70, 0x73A3, "switched station 3: redundancy loss", {}, false});
  std::ostringstream os;
  write_h_text({r}, os);
  EXPECT_TRUE(has_line(lines_of(os.str()),
                       "    10.000    CPU 0+1   OB 70 W#16#73A3 switched station 3: redundancy loss"))
      << os.str();
  std::ostringstream js;
  write_h_json({r}, js);
  EXPECT_NE(js.str().find("\"io_events\":[{\"time_ns\":10000000000,\"time_ms\":10000.000,\"racks\":[0,1],"
                          "\"ob\":70,\"code\":29603,\"text\":\"switched station 3: redundancy loss\"}]"),
            std::string::npos)
      << js.str();  // 0x73A3 = 29603
}

// The pair's events as capture records (captures/cpu_event.hpp).
TEST(HReport, CaptureRecordsOfThePairsEvents) {
  const HCpuPair p = driven_pair();
  const devices::HEvent* ob = nullptr;
  const devices::HEvent* stop = nullptr;
  for (const auto& e : p.events()) {
    if (e.kind == devices::HEvent::Kind::Ob && e.rack == 1) ob = &e;
    if (e.kind == devices::HEvent::Kind::State && e.rack == 1 && e.to_state == CpuState::Stop &&
        e.from_state == CpuState::Run)
      stop = &e;
  }
  ASSERT_NE(ob, nullptr);
  ASSERT_NE(stop, nullptr);
  const auto r = h_event_record(*ob, devices::HProfile::S7_400H, "H-CPU");
  EXPECT_EQ(r.category, captures::EventCategory::Cpu);
  EXPECT_EQ(r.code, 3);  // OB
  EXPECT_EQ(r.line, -1);
  EXPECT_EQ(r.a, 1);
  EXPECT_EQ(r.b, 1);                 // master after the takeover
  EXPECT_EQ(r.value, 0x0148'0000u);  // 72 << 16 | reason 1 (master CPU lost) << 24
  EXPECT_EQ(r.text, "H-CPU: CPU 1: OB 72 (master CPU lost)");
  const auto s = h_event_record(*stop, devices::HProfile::S7_400H);
  EXPECT_EQ(s.code, 0);
  EXPECT_EQ(s.b, 2);                      // standby
  EXPECT_EQ(s.value, 0x0301'0000'0000u);  // to STOP (1) << 32 | from RUN (3) << 40
  EXPECT_EQ(s.text, "CPU 1: RUN -> STOP");
}

// R10 in the 1500 profile: the profile's names in the text, 400H names in the JSON; the
// backup's SYNCUP is the update window (1 s + 2 s link-up + 145 ms update = 3.145 s).
TEST(HReport, ProfileNamesOfThe1500) {
  devices::HCpuPairParams prm;
  prm.profile = devices::HProfile::S7_1500RH;
  HCpuPair p(prm);
  p.power_on_both(0);
  p.on_time(4 * kTicksPerSecond);
  const HSystemReport r = make_h_report("R", p);
  std::ostringstream os;
  write_h_text({r}, os);
  const auto lines = lines_of(os.str());
  EXPECT_TRUE(has_line(lines, "H-system \"R\" (S7-1500R/H): system mode RUN-Redundant")) << os.str();
  EXPECT_TRUE(has_line(lines, "  CPU 0 (rack 0): RUN, primary, sees RUN-Redundant; LEDs MSTR on, RACK0 on, "
                              "REDF off, IFM1F off, IFM2F off"))
      << os.str();
  ASSERT_EQ(r.updates.size(), 1u);
  EXPECT_EQ(r.updates[0].rack, 1);
  EXPECT_EQ(r.updates[0].t1, 1 * kTicksPerSecond);
  EXPECT_EQ(r.updates[0].t5, 3145 * kTicksPerMs);
  std::ostringstream js;
  write_h_json({r}, js);
  EXPECT_NE(js.str().find("\"profile\":\"S7-1500R/H\",\"system_mode\":\"Redundant\""), std::string::npos);
  EXPECT_NE(js.str().find("\"role\":\"master\""), std::string::npos);
}

TEST(HReport, SecondsWithMilliseconds) {
  EXPECT_EQ(format_s_ms(0), "0.000");
  EXPECT_EQ(format_s_ms(3145 * kTicksPerMs), "3.145");
  EXPECT_EQ(format_s_ms(3145 * kTicksPerMs - 1), "3.144");  // rounded down
  EXPECT_EQ(format_s_ms(125 * kTicksPerSecond + 7 * kTicksPerMs), "125.007");
}

}  // namespace
}  // namespace pbvbus::tools
