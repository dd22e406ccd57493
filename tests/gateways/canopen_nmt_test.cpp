// NMT (COB-ID 0x000, data [cs, node]) at the CANopen gateway: start/stop/pre-operational become
// Operate/Stop/Clear of the whole master system (a DP master has one mode for all its slaves),
// reset node/communication re-announce the addressed nodes; node 0 = all, a node we do not serve
// is ignored. Slaves 5 and 7 are the gateway's nodes; node 9 is someone else's.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "fake_source.hpp"
#include "pbvbus/gateways/canopen_gateway.hpp"

namespace pbvbus::gateways {
namespace {

constexpr bus::Ticks ms = bus::kTicksPerMs;
using M = dp::MasterMode;

class CanopenNmtTest : public ::testing::Test {
 protected:
  bus::Scheduler sched;
  test::FakeSource src;
  CanHub hub;
  std::vector<std::string> rec;  ///< "<ms> <frame>" of heartbeats and boot-ups (0x700 + node)
  CanHub::PortId tool = hub.add_port("tool", [this](const CanFrame& f, bus::Ticks now) {
    if ((f.id & 0x780) == 0x700) rec.push_back(std::to_string(now / ms) + "ms " + to_string(f));
  });
  std::unique_ptr<CanopenGateway> gw;

  void SetUp() override {
    SourceModule m;
    m.name = "1 in";
    m.in_len = 1;
    src.add_slave(5, 0x0A05, {m});
    src.add_slave(7, 0x0A07, {m});
  }
  void make(CanopenOptions o = {}) {
    gw = std::make_unique<CanopenGateway>(sched, src, hub, o);
    gw->start(0);
    sched.run_until(0);
    rec.clear();
  }
  /// NMT frame with `dlc` octets of {cs, node}.
  void nmt(std::uint8_t cs, std::uint8_t node, std::uint8_t dlc = 2) {
    CanFrame f;
    f.id = 0x000;
    f.dlc = dlc;
    f.data[0] = cs;
    f.data[1] = node;
    hub.send(tool, f, sched.now());
  }
};

TEST_F(CanopenNmtTest, EachCommandSpecifierToOneOfOurNodes) {
  make();
  nmt(0x02, 5);  // stop
  nmt(0x80, 7);  // pre-operational → Clear
  nmt(0x01, 5);  // start → Operate
  EXPECT_EQ(src.commands(), (std::vector<M>{M::Stop, M::Clear, M::Operate}));
  EXPECT_EQ(gw->stats().nmt_received, 3u);
  EXPECT_TRUE(rec.empty());  // a mode change answers with no frame; the heartbeat shows it
}

TEST_F(CanopenNmtTest, NodeZeroIsAllAndAForeignNodeIsIgnored) {
  make();
  nmt(0x02, 0);
  EXPECT_EQ(src.commands(), (std::vector<M>{M::Stop}));  // one master: one command
  nmt(0x01, 9);                                          // node 9 is not ours
  EXPECT_EQ(src.commands().size(), 1u);
  EXPECT_EQ(gw->stats().ignored, 1u);
  EXPECT_EQ(gw->stats().nmt_received, 1u);
}

TEST_F(CanopenNmtTest, StopShowsInTheHeartbeat) {
  make();
  sched.run_until(500 * ms);
  nmt(0x02, 0);
  sched.run_until(1500 * ms);
  nmt(0x80, 0);
  sched.run_until(2500 * ms);
  nmt(0x01, 0);
  sched.run_until(3500 * ms);
  // 0x04 stopped, 0x7F pre-operational (Clear, still in data exchange), 0x05 operational.
  EXPECT_EQ(rec, (std::vector<std::string>{"1000ms 705#04", "1000ms 707#04", "2000ms 705#7F",
                                           "2000ms 707#7F", "3000ms 705#05", "3000ms 707#05"}));
}

TEST_F(CanopenNmtTest, ResetNodeAnnouncesThatNodeAndRestartsItsHeartbeat) {
  make();
  sched.run_until(1300 * ms);
  // Node 5's heartbeat time was changed over SDO (0x2B: 2 octets, 0x01F4 = 500 ms).
  CanFrame sdo;
  sdo.id = 0x605;
  sdo.dlc = 8;
  sdo.data = {0x2B, 0x17, 0x10, 0x00, 0xF4, 0x01, 0x00, 0x00};
  hub.send(tool, sdo, sched.now());
  sched.run_until(1400 * ms);
  rec.clear();
  nmt(0x81, 5);  // reset node: 0x1017 back to 1000 ms, boot-up now, heartbeat from now
  EXPECT_EQ(gw->heartbeat_ms(5), 1000);
  sched.run_until(2500 * ms);
  // Node 7 keeps its phase (2000 ms); node 5 boots at 1400 and beats at 2400 (not 1800).
  EXPECT_EQ(rec, (std::vector<std::string>{"1400ms 705#00", "2000ms 707#05", "2400ms 705#05"}));
  EXPECT_TRUE(src.commands().empty());  // a reset does not touch the master's mode
}

TEST_F(CanopenNmtTest, ResetCommunicationOfAllNodesSkipsAnAbsentSlave) {
  src.data(7).status.state = dp::SlaveStatusState::NotPresent;
  make();
  sched.run_until(300 * ms);
  rec.clear();
  nmt(0x82, 0);
  // Only node 5 is present; node 7 has no heartbeat, so it does not boot either.
  EXPECT_EQ(rec, (std::vector<std::string>{"300ms 705#00"}));
  EXPECT_EQ(gw->stats().nmt_received, 1u);
  EXPECT_EQ(gw->stats().bootup_sent, 2u);  // start + reset
}

TEST_F(CanopenNmtTest, MalformedAndRefusedCommandsAreCounted) {
  make();
  nmt(0x01, 5, 1);  // DLC 1
  nmt(0x01, 5, 3);  // DLC 3
  nmt(0x03, 5);     // no such command specifier
  EXPECT_EQ(gw->stats().bad, 3u);
  src.set_accept_commands(false);  // e.g. an H-system's masters follow their CPUs
  nmt(0x01, 0);
  EXPECT_EQ(gw->stats().nmt_refused, 1u);
  EXPECT_EQ(src.commands(), (std::vector<M>{M::Operate}));  // asked, refused by the source
  EXPECT_EQ(gw->stats().nmt_received, 0u);
}

TEST_F(CanopenNmtTest, NmtCanBeSwitchedOff) {
  CanopenOptions o;
  o.accept_nmt = false;
  make(o);
  nmt(0x02, 0);
  nmt(0x81, 5);
  EXPECT_TRUE(src.commands().empty());
  EXPECT_TRUE(rec.empty());
  EXPECT_EQ(gw->stats().nmt_refused, 2u);
}

}  // namespace
}  // namespace pbvbus::gateways
