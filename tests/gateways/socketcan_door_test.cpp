// SocketcanDoor (socketcan_door.hpp). Without AF_CAN (this machine: errno 97) open() must
// report the reason and leave nothing open; with a vcan0 interface (the CI machine) frames go
// both ways through a second raw socket on vcan0, compared field by field with struct can_frame.
#include "pbvbus/gateways/socketcan_door.hpp"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/scheduler.hpp"

namespace pbvbus::gateways {
namespace {

using namespace std::chrono_literals;

TEST(SocketcanDoor, MissingInterfaceIsAnErrorTextNotAThrow) {
  bus::Scheduler sched;
  bus::PacedRunner runner(sched);
  CanHub hub;
  SocketcanDoor::Options o;
  o.interface = "pbvbus-none0";  // no such interface, whether or not the kernel has AF_CAN
  SocketcanDoor door(runner, hub, o);
  const std::string err = door.open();
  EXPECT_FALSE(err.empty());
  EXPECT_FALSE(door.is_open());
  EXPECT_EQ(hub.ports(), 0u);
  o.interface = std::string(40, 'x');  // longer than IFNAMSIZ
  SocketcanDoor door2(runner, hub, o);
  EXPECT_FALSE(door2.open().empty());
}

TEST(SocketcanDoor, FramesBothWaysOnVcan0) {
  bus::Scheduler sched;
  bus::PacedRunner runner(sched);
  CanHub hub;
  std::vector<CanFrame> seen;
  const auto me = hub.add_port("test", [&](const CanFrame& f, bus::Ticks) { seen.push_back(f); });
  SocketcanDoor door(runner, hub, SocketcanDoor::Options{});
  if (auto err = door.open(); !err.empty())
    GTEST_SKIP() << "no vcan0 here (" << err << "); needs AF_CAN and `ip link add vcan0 type vcan`";
  // The peer: a second raw socket on vcan0.
  const int s = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  ASSERT_GE(s, 0);
  ifreq ifr{};
  std::strcpy(ifr.ifr_name, "vcan0");
  ASSERT_EQ(::ioctl(s, SIOCGIFINDEX, &ifr), 0);
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  ASSERT_EQ(::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  // Peer -> door: extended 0x18FF0001 [01 02 03] is can_id 0x18FF0001 | CAN_EFF_FLAG 0x80000000.
  can_frame k{};
  k.can_id = 0x18FF0001u | CAN_EFF_FLAG;
  k.can_dlc = 3;
  k.data[0] = 1;
  k.data[1] = 2;
  k.data[2] = 3;
  ASSERT_EQ(::write(s, &k, sizeof k), static_cast<ssize_t>(sizeof k));
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (seen.empty() && std::chrono::steady_clock::now() < end) runner.run_for(2 * bus::kTicksPerMs);
  ASSERT_EQ(seen.size(), 1u);
  CanFrame want;
  want.id = 0x18FF0001;
  want.extended = true;
  want.dlc = 3;
  want.data = {1, 2, 3};
  EXPECT_EQ(seen[0], want);
  // Door -> peer: standard RTR 0x705, DLC 1: can_id 0x705 | CAN_RTR_FLAG 0x40000000.
  CanFrame rtr;
  rtr.id = 0x705;
  rtr.rtr = true;
  rtr.dlc = 1;
  hub.send(me, rtr, sched.now());
  pollfd p{s, POLLIN, 0};
  ASSERT_EQ(::poll(&p, 1, 10'000), 1);
  can_frame got{};
  ASSERT_EQ(::read(s, &got, sizeof got), static_cast<ssize_t>(sizeof got));
  EXPECT_EQ(got.can_id, 0x705u | CAN_RTR_FLAG);
  EXPECT_EQ(got.can_dlc, 1);
  ::close(s);
  EXPECT_EQ(door.stats().frames_in, 1u);
  EXPECT_EQ(door.stats().frames_out, 1u);
}

}  // namespace
}  // namespace pbvbus::gateways
