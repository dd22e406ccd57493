// F2 (load-memory access error) and F18 (sync error) as operations (seeds-digest.md §7 F2:
// "that CPU -> STOP + reset request; partner -> Solo"; F18: "sync error -> Solo, one CPU STOP";
// docs/h-system.md rules 24 and 25): HCpuPair::load_memory_error on the pair, and
// HSystemModel::load_memory_error / inject_sync_error on the model with one redundant DP master
// system (h_system_fixture.hpp).
//
// Pair times (defaults): STARTUP 1 s, LINK-UP 2 s, UPDATE 75 ms + 0.7 ms x 100 KB = 145 ms.
// bring_up(): CPU 0 on at 0 -> RUN (Solo) at 1 s; CPU 1 on at 5 s -> LINK-UP 5 s .. 7 s ->
// UPDATE 7 s .. 7.145 s -> Redundant at 7.145 s.
// Model times: h_system_fixture.hpp (power_on_both at 12 ms, Redundant at 3.157 s).
#include "h_system_fixture.hpp"

namespace pbvbus::devices {
namespace {

using bus::Ticks;
constexpr Ticks ms(std::int64_t v) { return v * bus::kTicksPerMs; }
constexpr Ticks sec(std::int64_t v) { return v * bus::kTicksPerSecond; }
constexpr Ticks kCpu1On = sec(5);
constexpr Ticks kRedundantAt = kCpu1On + sec(2) + ms(145);  // 5 + 2 + 0.145 = 7.145 s
constexpr const char* kF2Entry = "load-memory access error: STOP, reset request (memory reset needed)";

void bring_up(HCpuPair& p) {
  p.power_on(0, 0);
  p.on_time(sec(1));
  p.power_on(1, kCpu1On);
  p.on_time(kCpu1On + sec(2));
  p.on_time(kRedundantAt);
  ASSERT_EQ(p.system_mode(), SystemMode::Redundant);
}

std::vector<HEvent> obs(const HCpuPair& p) {
  std::vector<HEvent> v;
  for (const HEvent& e : p.events())
    if (e.kind == HEvent::Kind::Ob) v.push_back(e);
  return v;
}

bool has_entry(const std::deque<DiagEntry>& d, Ticks at, const std::string& text) {
  return std::any_of(d.begin(), d.end(),
                     [&](const DiagEntry& e) { return e.at == at && e.text == text; });
}

// F2 on the master in Redundant mode: it STOPs with a reset request, the standby becomes master
// in Solo with OB 72 "master CPU in STOP" (decision: no new reason, the buffer says why). A
// STOP -> RUN is refused until the memory reset; the MRES does not start it; the STOP -> RUN
// after it links up as standby: LINK-UP 22 s -> UPDATE 24 s -> Redundant 24.145 s.
TEST(HF2Pair, MasterInRedundantStopsWithResetRequestPartnerSolo) {
  HCpuPair p;
  bring_up(p);
  const std::size_t before = obs(p).size();
  ASSERT_TRUE(p.load_memory_error(0, sec(8)));
  EXPECT_EQ(p.state(0), CpuState::Stop);
  EXPECT_EQ(p.role(0), CpuRole::Standby);
  EXPECT_TRUE(p.reset_request(0));
  EXPECT_TRUE(p.switch_at_run(0));  // the mode switch is not moved by a fault
  EXPECT_EQ(p.master(), 1);
  EXPECT_EQ(p.state(1), CpuState::Run);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  const auto ob = obs(p);
  ASSERT_EQ(ob.size(), before + 1);
  EXPECT_EQ(ob.back().ob, 72);
  EXPECT_EQ(ob.back().rack, 1);
  EXPECT_EQ(ob.back().role, CpuRole::Master);
  EXPECT_EQ(ob.back().reason, HReason::MasterStop);
  EXPECT_EQ(ob.back().at, sec(8));
  EXPECT_TRUE(has_entry(p.diag_buffer(0), sec(8), kF2Entry));
  EXPECT_TRUE(has_entry(p.diag_buffer(0), sec(8), "RUN -> STOP (load-memory access error)"));

  p.switch_to_run(0, sec(9));
  EXPECT_TRUE(has_entry(p.diag_buffer(0), sec(9),
                        "STOP -> RUN refused: reset request (memory reset needed)"));
  p.on_time(sec(20));
  EXPECT_EQ(p.state(0), CpuState::Stop);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);

  ASSERT_TRUE(p.memory_reset(0, sec(21)));
  EXPECT_FALSE(p.reset_request(0));
  EXPECT_EQ(p.state(0), CpuState::Stop);  // MRES does not start the CPU
  p.switch_to_run(0, sec(22));
  EXPECT_EQ(p.state(0), CpuState::LinkUp);
  p.on_time(sec(24) - 1);
  EXPECT_EQ(p.state(0), CpuState::LinkUp);
  p.on_time(sec(24));  // 22 s + LINK-UP 2 s
  EXPECT_EQ(p.state(0), CpuState::Update);
  p.on_time(sec(24) + ms(145));  // + UPDATE 145 ms
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.master(), 1);
}

// F2 on the standby in Redundant mode: standby STOP + reset request, Solo, OB 72 "standby CPU
// in STOP" on the master; the switch STOP -> RUN is refused until the MRES.
TEST(HF2Pair, StandbyInRedundantStopsMasterGetsOb72) {
  HCpuPair p;
  bring_up(p);
  const std::size_t before = obs(p).size();
  ASSERT_TRUE(p.load_memory_error(1, sec(8)));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_EQ(p.role(1), CpuRole::Standby);
  EXPECT_TRUE(p.reset_request(1));
  EXPECT_EQ(p.master(), 0);
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  const auto ob = obs(p);
  ASSERT_EQ(ob.size(), before + 1);
  EXPECT_EQ(ob.back().ob, 72);
  EXPECT_EQ(ob.back().rack, 0);
  EXPECT_EQ(ob.back().reason, HReason::StandbyStop);
  EXPECT_EQ(ob.back().at, sec(8));
  EXPECT_TRUE(has_entry(p.diag_buffer(1), sec(8), kF2Entry));
  p.switch_to_stop(1, sec(9));
  p.switch_to_run(1, sec(10));  // refused: reset request
  p.on_time(sec(15));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  ASSERT_TRUE(p.memory_reset(1, sec(16)));
  p.switch_to_run(1, sec(17));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  p.on_time(sec(19) + ms(145));  // 17 s + 2 s + 145 ms
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
}

// F2 on the lone master in Solo (partner off): system STOP, no OB 72 (nobody runs); the master
// stays master in STOP. After the MRES a STOP -> RUN at 5 s: STARTUP 5 s -> RUN 6 s.
TEST(HF2Pair, LoneMasterInSoloIsSystemStop) {
  HCpuPair p;
  p.power_on(0, 0);
  p.on_time(sec(1));
  ASSERT_EQ(p.system_mode(), SystemMode::Solo);
  ASSERT_TRUE(p.load_memory_error(0, sec(2)));
  EXPECT_EQ(p.state(0), CpuState::Stop);
  EXPECT_EQ(p.master(), 0);
  EXPECT_EQ(p.system_mode(), SystemMode::Stop);
  EXPECT_FALSE(p.dp_master_operate(0));
  EXPECT_TRUE(obs(p).empty());
  p.switch_to_run(0, sec(3));
  p.on_time(sec(4));
  EXPECT_EQ(p.state(0), CpuState::Stop);  // refused: reset request
  ASSERT_TRUE(p.memory_reset(0, sec(4)));
  p.switch_to_run(0, sec(5));
  EXPECT_EQ(p.state(0), CpuState::Startup);
  p.on_time(sec(6) - 1);
  EXPECT_EQ(p.state(0), CpuState::Startup);
  p.on_time(sec(6));  // 5 s + STARTUP 1 s
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
}

// F2 on the standby in LINK-UP (6 s, 1 s into the link-up 5 s .. 7 s): the link-up is aborted,
// the standby STOPs with the reset request, Solo stays; no OB 72 (Redundant was never reached).
// A CPU that is off has no load memory access: refused, nothing changes.
TEST(HF2Pair, DuringLinkUpAbortsAndOffIsRefused) {
  HCpuPair p;
  EXPECT_FALSE(p.load_memory_error(1, 0));  // off
  EXPECT_TRUE(p.events().empty());
  EXPECT_FALSE(p.reset_request(1));
  p.power_on(0, 0);
  p.on_time(sec(1));
  p.power_on(1, kCpu1On);
  ASSERT_EQ(p.state(1), CpuState::LinkUp);
  ASSERT_TRUE(p.load_memory_error(1, sec(6)));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_TRUE(p.reset_request(1));
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  EXPECT_TRUE(obs(p).empty());
  p.on_time(sec(10));
  EXPECT_EQ(p.state(1), CpuState::Stop);  // the link-up's end (7 s) passed: it stays down
}

// F2 on the master CPU of the model in Redundant at 4 s: OB 72 on CPU 1 (new master), then one
// W#16#39C3 for line A (CPU 0's DP master stops: LineLoss::MasterStop), no per-station event,
// every switched station on line B, no output pulse.
TEST(HF2Model, MasterCpuOneMasterSystemFailureNoPulse) {
  HSys s;
  Sampler smp(s);
  s.bring_up();
  const Ticks tf = 4000 * kMs;
  s.at(tf);
  EXPECT_FALSE(s.h->load_memory_error(2));  // bad rack: nothing
  EXPECT_TRUE(s.h->events().empty());
  ASSERT_TRUE(s.h->load_memory_error(0));
  EXPECT_EQ(s.h->pair().state(0), CpuState::Stop);
  EXPECT_TRUE(s.h->pair().reset_request(0));
  EXPECT_EQ(s.h->pair().master(), 1);
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Stop);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Operate);
  const auto ev = s.h->events();
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].source, Src::Cpu);
  EXPECT_EQ(ev[0].ob, 72);
  EXPECT_EQ(ev[0].rack, 1);
  EXPECT_EQ(ev[0].time, tf);
  EXPECT_EQ(ev[0].text, "OB 72 master CPU in STOP");
  EXPECT_EQ(ev[1].source, Src::Io);
  EXPECT_EQ(ev[1].ob, 86);
  EXPECT_EQ(ev[1].code, 0x39C3);
  EXPECT_EQ(ev[1].rack, 1);
  EXPECT_EQ(ev[1].line, 0);
  EXPECT_EQ(ev[1].time, tf);
  s.run_until(tf + 2000 * kMs);
  ASSERT_EQ(s.s7().size(), 1u);  // exactly one 39C3
  EXPECT_EQ(*s.ms().line_loss(0), redundancy::LineLoss::MasterStop);
  for (std::uint8_t a : {kFast, kSlow}) EXPECT_EQ(s.ms().active(a), 1) << int(a);
  smp.expect_no_pulse(0);
}

// F18 injected at 4 s in Redundant (hook program, no ProgramSpec): standby (CPU 1) STOP, Solo,
// OB 72 "standby CPU in STOP" on CPU 0, one 39C3 for line B, the "sync error" entry in both
// buffers; a second one in Solo is refused.
TEST(HF18Model, InjectedSyncErrorStandbyStop) {
  HSys s;
  Sampler smp(s);
  EXPECT_FALSE(s.h->inject_sync_error());  // both CPUs off: not Redundant
  s.bring_up();
  const Ticks tf = 4000 * kMs;
  s.at(tf);
  ASSERT_TRUE(s.h->inject_sync_error());
  EXPECT_EQ(s.h->pair().state(1), CpuState::Stop);
  EXPECT_EQ(s.h->pair().state(0), CpuState::Run);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Solo);
  EXPECT_FALSE(s.h->pair().reset_request(1));  // F18 is a fault STOP, no reset request
  const auto ev = s.h->events();
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].ob, 72);
  EXPECT_EQ(ev[0].rack, 0);
  EXPECT_EQ(ev[0].time, tf);
  EXPECT_EQ(ev[0].text, "OB 72 standby CPU in STOP");
  EXPECT_EQ(ev[1].code, 0x39C3);
  EXPECT_EQ(ev[1].line, 1);
  const std::string entry = "sync error (F18): diverging uninitialised data; standby rack 1 to STOP";
  for (int r = 0; r < 2; ++r) {
    const auto d = s.h->diag_buffer(r);
    EXPECT_TRUE(std::any_of(d.begin(), d.end(), [&](const DiagEntry& e) {
      return e.at == tf && e.text == entry;
    })) << r;
  }
  s.at(tf + 100 * kMs);
  EXPECT_FALSE(s.h->inject_sync_error());  // Solo
  // No second OB 72 (the OB 85 for slave 11, gone with line B, may follow at the next scan).
  EXPECT_EQ(s.events(Src::Cpu).size(), 1u);
  s.run_until(tf + 1000 * kMs);
  smp.expect_no_pulse(0);
}

}  // namespace
}  // namespace pbvbus::devices
