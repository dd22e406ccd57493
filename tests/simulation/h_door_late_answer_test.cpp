// S7 jobs held across an H update, through the S7 door (000 L1673-1680: "communication
// functions ... are delayed until the end of the update"; docs/h-sfc90.md "held jobs").
//
// The run (pair defaults: startup 1 s, link-up 2 s, update 75 ms + 0.7 ms x 100 KB = 145 ms):
//   0 s       both CPUs on: CPU 0 master STARTUP, CPU 1 standby in STOP
//   0.5 s     the client connects through the door (a PG connection to rack 0 slot 3)
//   1 s       CPU 0 RUN (Solo), CPU 1 LINK-UP
//   3 s       UPDATE: t1 = t3 = 3.000 s (interrupts and communication held)
//   3.145 s   t5: Redundant, the held jobs are answered (in RUN-R)
#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"
#include "hex.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr bus::Ticks kT1 = 3000 * kMs;
constexpr bus::Ticks kT5 = 3145 * kMs;  // 1 s + 2 s + (75 + 0.7 x 100) ms

const std::string kText = R"(name: "late"
duration: "5s"
h_system {
  name: "H-CPU"
  cpu { cpu0 { power_on: "0s" } cpu1 { power_on: "0s" } }
  work_memory_db_kb: 100
}
s7_door { name: "S7" listen: "127.0.0.1:10102" route { rack: 0 slot: 3 h_system: "H-CPU" } }
)";

std::vector<std::uint8_t> hex(std::string_view s) {
  std::string clean;
  for (const char ch : s)
    if (ch != '|') clean.push_back(ch);
  return test::bytes_from_hex(clean);
}
// Setup Communication (docs/s7.md): header 32 01, PDU ref 0, param length 8; param F0 00,
// max AmQ calling 1, called 1, PDU length 01 E0 = 480. The answer (32 03, error 00 00) offers
// 00 F0 = 240 (the CPU's PDU size).
const std::vector<std::uint8_t> kSetup = hex("32 01 00 00 00 00 00 08 00 00 | F0 00 00 01 00 01 01 E0");
const std::vector<std::uint8_t> kSetupAnswer =
    hex("32 03 00 00 00 00 00 08 00 00 00 00 | F0 00 00 01 00 01 00 F0");
// Userdata (32 07), param 8, data 8: function group 4 (CPU functions, request 0x44), subfunction
// 01 Read SZL; data FF 09 length 4, SZL-ID 04 24, index 00 00. The answer's octet 37 is the
// bzu_id state of the SZL 0424 record (docs/s7.md): 09 = RUN-R, 08 = RUN (Solo).
const std::vector<std::uint8_t> kSzl0424 =
    hex("32 07 00 00 00 14 00 08 00 08 | 00 01 12 04 11 44 01 00 | FF 09 00 04 04 24 00 00");

struct DoorRun {
  std::unique_ptr<Simulation> sim;
  std::unique_ptr<iso_on_tcp::S7Channel> ch;
  std::optional<std::string> closed;

  explicit DoorRun(const std::string& text = kText) {
    auto loaded = parse_scenario(text, "late.textproto");
    if (!loaded.ok()) throw std::runtime_error(loaded.errors.at(0).str());
    sim = std::make_unique<Simulation>(*loaded.plan);
    sim->start();
  }
  bus::Ticks now() { return sim->scheduler().now(); }
  void connect() {
    iso_on_tcp::RouteRequest rq;
    rq.called = s7::S7Tsap{s7::kTsapPg, 0, 3};
    auto r = sim->s7_door(0).open(rq);
    ASSERT_TRUE(r.channel) << r.why;
    ch = std::move(r.channel);
    ch->on_closed([this](const std::string& why) { closed = why; });
  }
};

struct Answer {
  std::optional<bus::Ticks> at;
  std::vector<std::uint8_t> pdu;
};

TEST(HDoorLateAnswer, JobDuringTheUpdateIsAnsweredAtT5InRunR) {
  DoorRun r;
  r.sim->run_until(500 * kMs);
  ASSERT_NO_FATAL_FAILURE(r.connect());
  Answer setup;
  r.ch->request(kSetup, [&](std::vector<std::uint8_t> a) { setup = {r.now(), std::move(a)}; });
  EXPECT_EQ(setup.at, 500 * kMs);  // outside an update: at once
  EXPECT_EQ(setup.pdu, kSetupAnswer);

  r.sim->run_until(kT1 + 50 * kMs);
  ASSERT_TRUE(r.sim->h_system(0).model().pair().interrupts_held());
  Answer szl, second;
  r.ch->request(kSzl0424, [&](std::vector<std::uint8_t> a) { szl = {r.now(), std::move(a)}; });
  r.ch->request(kSetup, [&](std::vector<std::uint8_t> a) {
    EXPECT_TRUE(szl.at.has_value());  // arrival order
    second = {r.now(), std::move(a)};
  });
  EXPECT_FALSE(szl.at);
  EXPECT_EQ(r.sim->h_system(0).model().held_s7_jobs(), 2u);
  r.sim->run_until(kT5 - 1);
  EXPECT_FALSE(szl.at);
  EXPECT_FALSE(second.at);
  r.sim->run_until(kT5);
  ASSERT_EQ(szl.at, kT5);
  ASSERT_GT(szl.pdu.size(), 37u);
  EXPECT_EQ(szl.pdu[37], 0x09);  // RUN-R: run after the update, in Redundant mode
  EXPECT_EQ(second.at, kT5);
  EXPECT_EQ(second.pdu, kSetupAnswer);
  EXPECT_FALSE(r.closed);

  Answer after;
  r.ch->request(kSzl0424, [&](std::vector<std::uint8_t> a) { after = {r.now(), std::move(a)}; });
  EXPECT_EQ(after.at, kT5);  // at once again
  ASSERT_GT(after.pdu.size(), 37u);
  EXPECT_EQ(after.pdu[37], 0x09);
}

TEST(HDoorLateAnswer, ChannelGoneWithAJobHeldIsNotAnsweredLater) {
  // The client's channel is torn down from the door's side while a job is held: the model drops
  // the job (nobody to answer), nothing is called back later on the gone channel.
  DoorRun r;
  r.sim->run_until(500 * kMs);
  ASSERT_NO_FATAL_FAILURE(r.connect());
  r.sim->run_until(kT1 + 50 * kMs);
  bool answered = false;
  r.ch->request(kSzl0424, [&](std::vector<std::uint8_t>) { answered = true; });
  EXPECT_EQ(r.sim->h_system(0).model().held_s7_jobs(), 1u);
  r.ch.reset();
  r.sim->run_until(kT5 + 10 * kMs);
  EXPECT_FALSE(answered);
  EXPECT_EQ(r.sim->h_system(0).model().held_s7_jobs(), 0u);
}

TEST(HDoorLateAnswer, SessionEndedWithAJobHeldGetsTheDisconnect) {
  // The master (CPU 0, the ad hoc session's CPU) fails inside the update: the update ends (abort)
  // and the held job finds its session ended (ConnectionLost with its CPU): the client gets a
  // DR (Closed), the held reply is not called.
  std::string text = kText;
  text += "fault { at: \"3050ms\" cpu_failure { rack: 0 } }\n";
  DoorRun r(text);
  r.sim->run_until(500 * kMs);
  ASSERT_NO_FATAL_FAILURE(r.connect());
  r.sim->run_until(kT1 + 10 * kMs);
  bool answered = false;
  r.ch->request(kSzl0424, [&](std::vector<std::uint8_t>) { answered = true; });
  EXPECT_EQ(r.sim->h_system(0).model().held_s7_jobs(), 1u);
  EXPECT_FALSE(r.closed);
  r.sim->run_until(kT1 + 60 * kMs);
  EXPECT_FALSE(answered);
  EXPECT_TRUE(r.closed);
  EXPECT_EQ(r.sim->h_system(0).model().held_s7_jobs(), 0u);
}

}  // namespace
}  // namespace pbvbus::tools
