// MpiStation's API edges (docs/mpi.md "MPI stations on a line"): addresses, handles, SAP ranges,
// and a station with both roles (a CPU that also opens a connection to another CPU).

#include <gtest/gtest.h>

#include "mpi_line_helpers.hpp"

namespace pbvbus::mpi_station::test {
namespace {

TEST(MpiStationApi, RequestErrors) {
  MpiLine l;
  MpiStation& pg = l.add_client(0);
  EXPECT_FALSE(pg.open(0).has_value());    // its own address
  EXPECT_FALSE(pg.open(127).has_value());  // broadcast
  EXPECT_EQ(pg.submit(42, Bytes{0x32}), mpi::RequestError::WrongState);
  EXPECT_EQ(pg.close(42), mpi::RequestError::WrongState);
  EXPECT_EQ(pg.state(42), mpi::State::Closed);
  EXPECT_FALSE(pg.serves());
  // Client SAPs 0x14 .. 63: 44 connections at most, then no SAP is free.
  for (int i = 0; i < 44; ++i) ASSERT_TRUE(pg.open(2).has_value()) << i;
  EXPECT_FALSE(pg.open(2).has_value());
  EXPECT_EQ(pg.frames_queued(), 44u);  // connect requests waiting for the token
}

TEST(MpiStationApi, AServingStationKeepsItsClientSapsBelowThePool) {
  MpiLine l;
  MpiStation& cpu = l.add_cpu(2);  // pool from 0x14, client SAPs from 0x14 too: none left
  EXPECT_TRUE(cpu.serves());
  EXPECT_FALSE(cpu.open(3).has_value());
}

TEST(MpiStationApi, CpuToCpuConnectionWithBothRoles) {
  MpiLine l;
  MpiStationConfig a;
  a.address = 2;
  a.bus = l.params;
  a.client_first_sap = 0x0A;  // below the pool's 0x14
  MpiStation& cpu_a = l.attach(a, &l.factory);
  MpiStation& cpu_b = l.add_cpu(3);
  MpiStation& pg = l.add_client(0);
  l.memory.create_db(1, 16);
  (*l.memory.db(1))[0] = 0x5A;
  l.start();
  ASSERT_TRUE(l.run_until([&] { return l.ring_formed(); }, 2000));
  const auto h = cpu_a.open(3);
  ASSERT_TRUE(h.has_value());
  const auto p = pg.open(2);  // and a PG connects to CPU A's server side meanwhile
  ASSERT_TRUE(p.has_value());
  ASSERT_TRUE(l.run_until([&] { return cpu_a.state(*h) == mpi::State::Connected && pg.state(*p) == mpi::State::Connected; }));
  // A's connect request to B comes from its client SAP 0x0A: DA 3|80, SA 2|80, FC 6D, DSAP 00,
  // SSAP 0A; FCS = 83+82+6D+00+0A (0x17C) + E0+04+00+80+00+02+00+02+01+00+01+00 (0x16A) = 0x2E6.
  EXPECT_LT(l.find("68 11 11 68 83 82 6D 00 0A E0 04 00 80 00 02 00 02 01 00 01 00 E6 16"), l.rec.size());
  ASSERT_EQ(cpu_a.submit(*h, bytes_from_hex("32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 03 C0")),
            mpi::RequestError::None);
  ASSERT_TRUE(l.run_until([&] { return cpu_a.stats().pdus_received == 1; }));
  EXPECT_EQ(cpu_b.server_connections(), 1u);
  EXPECT_EQ(cpu_a.server_connections(), 1u);  // the PG's
  const auto replies = of_kind(cpu_a.take_events(), EventKind::Reply);
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].role, Role::Client);
  EXPECT_EQ(replies[0].local_sap, 0x0A);
  EXPECT_EQ(to_hex(replies[0].pdu), "32 03 00 00 00 00 00 08 00 00 00 00 F0 00 00 01 00 01 00 F0");
}

}  // namespace
}  // namespace pbvbus::mpi_station::test
