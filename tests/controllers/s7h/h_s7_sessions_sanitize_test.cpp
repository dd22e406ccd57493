// S7 sessions on the H system under seeded random operations (also built as
// sanitize_controllers_s7h, so ASan/UBSan watch the views into the CPUs' images and the
// sessions' lifetimes): sessions opened, used, closed and dropped while CPUs fail, stop, link up
// and CPs fail. Invariants after every step: the pair's ad-hoc connection count per CPU equals
// the alive ad-hoc sessions answered by that CPU; a closed session answers nothing; an alive one
// answers every request; client writes never cause a comparison error (F16).
#include <random>

#include "h_system_fixture.hpp"
#include "pbvbus/s7cpu/s7_server.hpp"

namespace pbvbus::devices {
namespace {

const Bytes kSetup{0x32, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00,
                   0xF0, 0x00, 0x00, 0x01, 0x00, 0x01, 0x01, 0xE0};

/// A Read Var or Write Var of one DB1 word (address `w` x 16 bits) or a Read SZL of 0424/0071.
Bytes request(std::mt19937& rng) {
  const auto w = static_cast<std::uint8_t>((rng() % 8) * 16);
  switch (rng() % 4) {
    case 0:
      return {0x32, 0x01, 0x00, 0x00, 0x00, 0x04, 0x00, 0x0E, 0x00, 0x00, 0x04, 0x01, 0x12, 0x0A,
              0x10, 0x02, 0x00, 0x02, 0x00, 0x01, 0x84, 0x00, 0x00, w};
    case 1:
      return {0x32, 0x01, 0x00, 0x00, 0x00, 0x03, 0x00, 0x0E, 0x00, 0x06, 0x05, 0x01,
              0x12, 0x0A, 0x10, 0x02, 0x00, 0x02, 0x00, 0x01, 0x84, 0x00, 0x00, w,
              0x00, 0x04, 0x00, 0x10, static_cast<std::uint8_t>(rng()), 0x5A};
    case 2:
      return {0x32, 0x07, 0x00, 0x00, 0x00, 0x14, 0x00, 0x08, 0x00, 0x08, 0x00, 0x01,
              0x12, 0x04, 0x11, 0x44, 0x01, 0x00, 0xFF, 0x09, 0x00, 0x04,
              static_cast<std::uint8_t>(rng() % 2 ? 0x04 : 0x00),
              static_cast<std::uint8_t>(rng() % 2 ? 0x24 : 0x71), 0x00, 0x00};
    default:
      return kSetup;
  }
}

TEST(HS7Sanitize, RandomSessionsAndFaultsKeepTheInvariants) {
  int total_redundant_writes = 0;  // writes answered in Redundant mode (mirrored)
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    std::mt19937 rng(seed);
    HSys s;
    ProgramSpec p;
    p.scan_time = kScan;
    p.counters.push_back({0, 2, 10 * kMs, 1, 0, 0, 0});
    s.h->set_program(p);
    HS7MemoryConfig m;
    m.dbs = {{1, 16}};
    s.h->set_s7_memory(m);
    ASSERT_EQ(s.h->add_cp({0, 0, CpKind::Cp443_1}), "");
    ASSERT_EQ(s.h->add_cp({1, 0, CpKind::Cp443_1}), "");
    ASSERT_EQ(s.h->add_connection({"s0", ConnectionKind::Standard, 0, 0}), "");
    ASSERT_EQ(s.h->add_connection({"ft", ConnectionKind::FaultTolerant, 0, 0}), "");
    s.bring_up();
    s7cpu::CpuMemory dev_mem;
    dev_mem.create_db(1, 16);
    s7cpu::CpuInfo dev_info;
    s7cpu::S7Server dev(dev_mem, dev_info);
    std::vector<HS7Session> sessions;
    int answered = 0, closed_by_fault = 0, refused = 0, redundant_writes = 0;
    bus::Ticks now = s.sched.now();
    for (int step = 0; step < 400; ++step) {
      switch (rng() % 16) {
        case 0: sessions.push_back(s.h->open_s7_adhoc(static_cast<int>(rng() % 2))); break;
        case 1: sessions.push_back(s.h->open_s7_connection(rng() % 2 ? "s0" : "ft")); break;
        case 2:
          sessions.push_back(s.h->open_s7_routing(
              0, rng() % 2 ? kFast : kSlow,
              [&dev](std::span<const std::uint8_t> pdu) { return dev.handle(pdu).value; }));
          break;
        case 3:
          if (!sessions.empty()) sessions.erase(sessions.begin() + rng() % sessions.size());
          break;
        case 4:
          if (!sessions.empty()) sessions[rng() % sessions.size()].close();
          break;
        case 5: {
          const int r = static_cast<int>(rng() % 2);
          if (s.h->pair().state(r) == CpuState::Off) s.h->power_on(r);
          else if (rng() % 3 == 0) s.h->power_off(r);
          break;
        }
        case 6: {
          const int r = static_cast<int>(rng() % 2);
          if (rng() % 4 == 0) s.h->switch_to_stop(r);
          else s.h->switch_to_run(r);
          break;
        }
        case 7: {
          const int r = static_cast<int>(rng() % 2);
          if (!s.h->cp_failure(r, 0)) s.h->repair_cp(r, 0);
          break;
        }
        default: {
          for (auto& x : sessions) {
            if (rng() % 2) continue;
            const bool alive = x.alive();
            Bytes q = request(rng);
            if (rng() % 50 == 0) q[0] = 0x33;  // garbage: the session closes
            const auto a = x.handle(kSetup);
            const auto b = x.handle(q);
            if (!alive) {
              EXPECT_TRUE(a.empty());
              EXPECT_TRUE(b.empty());
            } else if (q[0] == 0x32) {
              EXPECT_FALSE(a.empty());
              EXPECT_EQ(b.empty(), !x.alive());
              answered += b.empty() ? 0 : 1;
              if (q[1] == 0x01 && q[10] == 0x05 &&
                  s.h->pair().system_mode() == SystemMode::Redundant)
                ++redundant_writes;
            }
          }
          now += static_cast<bus::Ticks>(rng() % 1500) * kMs;
          s.run_until(now);
          break;
        }
      }
      for (const auto& x : sessions) {
        const auto why = x.close_reason();
        closed_by_fault += why == S7CloseReason::CpuLost || why == S7CloseReason::LinkUp ||
                           why == S7CloseReason::ConnectionLost ||
                           why == S7CloseReason::Switchover;
        refused += why == S7CloseReason::Refused;
      }
      for (int r = 0; r < 2; ++r) {
        int alive = 0;
        for (const auto& x : sessions)
          if (x.route() == S7Route::AdHoc && x.alive() && x.answering_rack() == r) ++alive;
        ASSERT_EQ(s.h->pair().connections(r), alive) << "seed " << seed << " step " << step;
      }
    }
    for (const HEvent& e : s.h->pair().events())
      EXPECT_NE(e.reason, HReason::ComparisonError) << "seed " << seed;
    // The run reached the cases it is for.
    EXPECT_GT(answered, 100) << "seed " << seed;
    EXPECT_GT(closed_by_fault, 0) << "seed " << seed;
    EXPECT_GT(refused, 0) << "seed " << seed;
    total_redundant_writes += redundant_writes;
  }
  EXPECT_GT(total_redundant_writes, 10);
}

}  // namespace
}  // namespace pbvbus::devices
