// Connection resources and broken connections of MPI stations on a real line (docs/mpi.md
// "MPI stations on a line"): refusal beyond the CPU's connections with FDL RR, a CPU powered
// off, a cable cut between PG and CPU, token loss, and four PG/OP stations sharing one CPU.

#include <gtest/gtest.h>

#include "mpi_line_helpers.hpp"

namespace pbvbus::mpi_station::test {
namespace {

constexpr const char* kSetup960 = "32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 03 C0";
constexpr const char* kReadDb1Dbb0x10 = "32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02 00 0A 00 01 84 00 00 00";

/// Events kept per station (the handler sees them as they happen, with their time).
struct Log {
  void attach(MpiStation& s) {
    s.set_event_handler([this](const StationEvent& e) { events.push_back(e); });
  }
  std::vector<StationEvent> of(EventKind k) const { return of_kind(events, k); }
  std::vector<StationEvent> events;
};

class Faults : public ::testing::Test {
 protected:
  /// PG 0, OP 1, CPU 2 in this cable order; CPU with `max_conn` connections.
  void build(std::size_t max_conn = 8) {
    pg = &l.add_client(0);
    op = &l.add_client(1);
    cpu = &l.add_cpu(2, max_conn);
    for (MpiStation* s : {pg, op, cpu}) logs[s->address()].attach(*s);
    l.memory.create_db(1, 16);
    l.start();
    ASSERT_TRUE(l.run_until([&] { return l.ring_formed(); }, 2000));
  }
  /// Runs until the last frame on the wire is `token` (that station holds the token now).
  void run_until_token(const std::string& token) {
    const std::size_t from = l.rec.size();
    for (int i = 0; i < 100000; ++i) {
      if (l.rec.size() > from && l.rec.hex(l.rec.size() - 1) == token) return;
      l.sched.run_until(l.sched.now() + 11 * l.line.bit_ticks());
    }
    FAIL() << "no " << token;
  }
  Handle connect(MpiStation& s) {
    const auto h = s.open(2);
    EXPECT_TRUE(h.has_value());
    EXPECT_TRUE(l.run_until([&] { return s.state(*h) == mpi::State::Connected; }, 1000));
    return h.value_or(0);
  }

  MpiLine l;
  MpiStation* pg = nullptr;
  MpiStation* op = nullptr;
  MpiStation* cpu = nullptr;
  Log logs[5];
};

TEST_F(Faults, BeyondMaxConnectionsTheCpuAnswersRrAndTheClientIsRefused) {
  build(2);
  const Handle a = connect(*pg);
  const Handle b = connect(*pg);
  EXPECT_EQ(cpu->server_connections(), 2u);
  // The PG's two connections: its own SAPs 0x14 and 0x15, the CPU's 0x14 and 0x15.
  const auto accepted = logs[2].of(EventKind::Accepted);
  ASSERT_EQ(accepted.size(), 2u);
  EXPECT_EQ(accepted[0].local_sap, 0x14);
  EXPECT_EQ(accepted[1].local_sap, 0x15);

  const std::size_t from = l.rec.size();
  const auto c = op->open(2);
  ASSERT_TRUE(c.has_value());
  l.run_ms(30);
  // The OP's connect request (SA 1 | 0x80 = 81; FCS = the trace's ED + 1 = EE), answered by
  // the CPU's FDL with status RR (no resources, §B.3) instead of SC: SD1, FC = station type
  // "master in ring" (3 << 4) | RR (2) = 32; FCS = 01 + 02 + 32 = 35.
  const std::size_t cr = l.find("68 11 11 68 82 81 6D 00 14 E0 04 00 80 00 02 00 02 01 00 01 00 EE 16", from);
  ASSERT_LT(cr, l.rec.size());
  EXPECT_EQ(l.rec.hex(cr + 1), "10 01 02 32 35 16");
  EXPECT_EQ(l.rec.start_bits(cr + 1), l.rec.end_bits(cr) + 20);
  // Nothing more for the OP: no confirm, no repeat of the request.
  EXPECT_EQ(l.find_prefix("68 11 11 68 81 82", from), l.rec.size());
  EXPECT_EQ(l.find("68 11 11 68 82 81 6D 00 14 E0 04 00 80 00 02 00 02 01 00 01 00 EE 16", cr + 1), l.rec.size());
  const auto refused = logs[1].of(EventKind::Refused);
  ASSERT_EQ(refused.size(), 1u);
  EXPECT_EQ(refused[0].handle, *c);
  EXPECT_EQ(refused[0].reason, EndReason::PeerRefused);
  EXPECT_EQ(op->state(*c), mpi::State::Closed);
  EXPECT_EQ(cpu->stats().connects_refused, 1u);
  EXPECT_EQ(op->stats().refusals_received, 1u);
  EXPECT_EQ(cpu->server_connections(), 2u);

  // Once the PG frees one, the OP gets in.
  ASSERT_EQ(pg->close(b), mpi::RequestError::None);
  ASSERT_TRUE(l.run_until([&] { return cpu->server_connections() == 1; }, 1000));
  const Handle d = connect(*op);
  EXPECT_EQ(op->state(d), mpi::State::Connected);
  EXPECT_EQ(pg->state(a), mpi::State::Connected);
  EXPECT_EQ(cpu->server_connections(), 2u);
}

TEST_F(Faults, CpuPoweredOffBreaksEveryConnection) {
  build();
  const Handle idle = connect(*pg);
  const Handle busy = connect(*op);
  // Off while the PG holds the token: the ring goes on (the OP drops the CPU after three failed
  // token passes); no station loses the token.
  run_until_token("DC 00 02");
  const bus::Ticks off = l.sched.now();
  l.line.set_power(l.id_of(*cpu), false);
  // The CPU's own connections end with its power.
  const auto cpu_broken = logs[2].of(EventKind::Broken);
  ASSERT_EQ(cpu_broken.size(), 2u);
  for (const auto& e : cpu_broken) {
    EXPECT_EQ(e.reason, EndReason::PowerLoss);
    EXPECT_EQ(e.role, Role::Server);
  }
  // The OP sends a job to the dead CPU: its FDL gets no answer after the retry -> PeerGone.
  ASSERT_EQ(op->submit(busy, bytes_from_hex(kSetup960)), mpi::RequestError::None);
  l.run_ms(2500);
  const auto op_broken = logs[1].of(EventKind::Broken);
  ASSERT_EQ(op_broken.size(), 1u);
  EXPECT_EQ(op_broken[0].handle, busy);
  EXPECT_EQ(op_broken[0].reason, EndReason::PeerGone);
  EXPECT_GE(op->stats().frames_unanswered, 1u);
  // The PG's idle connection: the CPU left the token ring (dropped from the LAS after three
  // failed token passes); after peer_absent_timeout (1 s) the connection is broken.
  const auto pg_broken = logs[0].of(EventKind::Broken);
  ASSERT_EQ(pg_broken.size(), 1u);
  EXPECT_EQ(pg_broken[0].handle, idle);
  EXPECT_EQ(pg_broken[0].reason, EndReason::PeerLeftRing);
  EXPECT_GE(pg_broken[0].at, off + bus::kTicksPerSecond);
  EXPECT_LT(pg_broken[0].at, off + bus::kTicksPerSecond + 200 * bus::kTicksPerMs);
  EXPECT_LT(op_broken[0].at, pg_broken[0].at);
  EXPECT_FALSE(pg->mac().las_contains(2));
  EXPECT_EQ(pg->stats().broken[static_cast<std::size_t>(EndReason::PeerLeftRing)], 1u);
  // Each connection is reported once, and nothing else is reported.
  EXPECT_TRUE(logs[0].of(EventKind::Closed).empty());
  EXPECT_TRUE(logs[1].of(EventKind::Closed).empty());
  EXPECT_EQ(pg->state(idle), mpi::State::Closed);
  EXPECT_EQ(op->state(busy), mpi::State::Closed);

  // Power back: the CPU rejoins the ring and serves again from scratch.
  l.line.set_power(l.id_of(*cpu), true);
  ASSERT_TRUE(l.run_until([&] { return l.ring_formed(); }, 2000));
  const Handle again = connect(*pg);
  EXPECT_EQ(pg->state(again), mpi::State::Connected);
  EXPECT_EQ(cpu->server_connections(), 1u);
}

TEST_F(Faults, LineCutBetweenPgAndCpuBreaksBothEnds) {
  build();
  const Handle h = connect(*pg);
  EXPECT_EQ(cpu->server_connections(), 1u);
  // Cut while the CPU holds the token: it drops the PG and the OP after failed token passes and
  // goes on alone; the PG claims the token after its TTO and forms a ring with the OP.
  run_until_token("DC 02 01");
  const bus::Ticks cut = l.sched.now();
  // Cable order PG, OP, CPU: the cut separates the CPU from both.
  l.line.set_cut_between(l.id_of(*op), l.id_of(*cpu), true);
  l.run_ms(2500);
  const auto pg_broken = logs[0].of(EventKind::Broken);
  ASSERT_EQ(pg_broken.size(), 1u);
  EXPECT_EQ(pg_broken[0].handle, h);
  EXPECT_EQ(pg_broken[0].reason, EndReason::PeerLeftRing);
  EXPECT_GE(pg_broken[0].at, cut + bus::kTicksPerSecond);
  const auto cpu_broken = logs[2].of(EventKind::Broken);
  ASSERT_EQ(cpu_broken.size(), 1u);
  EXPECT_EQ(cpu_broken[0].role, Role::Server);
  EXPECT_EQ(cpu_broken[0].peer, 0);
  EXPECT_EQ(cpu_broken[0].reason, EndReason::PeerLeftRing);
  // The CPU released its connection resource (its disconnect request to the PG went unanswered).
  EXPECT_EQ(cpu->server_connections(), 0u);
  EXPECT_EQ(pg->mac().las(), (std::vector<std::uint8_t>{0, 1}));
  EXPECT_EQ(cpu->mac().las(), (std::vector<std::uint8_t>{2}));

  // Repaired: one ring again, and the PG reads through a new connection.
  l.line.set_cut_between(l.id_of(*op), l.id_of(*cpu), false);
  ASSERT_TRUE(l.run_until([&] { return l.ring_formed(); }, 3000));
  const Handle again = connect(*pg);
  ASSERT_EQ(pg->submit(again, bytes_from_hex(kSetup960)), mpi::RequestError::None);
  ASSERT_TRUE(l.run_until([&] { return !logs[0].of(EventKind::Reply).empty(); }, 1000));
}

TEST_F(Faults, ShortTokenLossHealsLongOneBreaksAsTokenLost) {
  build();
  const Handle h = connect(*pg);
  // 20 ms of short circuit: every station loses the token and claims it; the ring forms again
  // well within peer_absent_timeout, so the connection survives and carries a job.
  l.line.set_short_circuit(true);
  l.run_ms(20);
  l.line.set_short_circuit(false);
  ASSERT_TRUE(l.run_until([&] { return l.ring_formed(); }, 900));
  EXPECT_GE(pg->mac().stats().token_losses, 1u);
  ASSERT_EQ(pg->submit(h, bytes_from_hex(kSetup960)), mpi::RequestError::None);
  ASSERT_TRUE(l.run_until([&] { return !logs[0].of(EventKind::Reply).empty(); }, 500));
  EXPECT_TRUE(logs[0].of(EventKind::Broken).empty());
  l.run_ms(50);  // the PG's data ack of the answer reaches the CPU

  // 1.5 s of short circuit, starting right after the OP passed the token to the CPU: the CPU
  // holds it, the OP still checks its pass; both keep it (their passes fail, they drop their
  // peers from the LAS one by one and go on alone) and never lose it. The PG, idle, loses it
  // (TTO), claims it and stays alone longer than peer_absent_timeout: Broken/TokenLost. The
  // CPU sees the PG leave its ring: Broken/PeerLeftRing.
  run_until_token("DC 02 01");
  l.line.set_short_circuit(true);
  l.run_ms(1500);
  l.line.set_short_circuit(false);
  l.run_ms(100);
  const auto pg_broken = logs[0].of(EventKind::Broken);
  ASSERT_EQ(pg_broken.size(), 1u);
  EXPECT_EQ(pg_broken[0].reason, EndReason::TokenLost);
  EXPECT_EQ(pg->stats().broken[static_cast<std::size_t>(EndReason::TokenLost)], 1u);
  const auto cpu_broken = logs[2].of(EventKind::Broken);
  ASSERT_EQ(cpu_broken.size(), 1u);
  EXPECT_EQ(cpu_broken[0].reason, EndReason::PeerLeftRing);
}

TEST(FourClients, FourPgOpStationsReadFromOneCpu) {
  MpiLine l;
  std::vector<MpiStation*> clients;
  for (std::uint8_t a : {std::uint8_t{0}, std::uint8_t{1}}) clients.push_back(&l.add_client(a));
  MpiStation& cpu = l.add_cpu(2);
  for (std::uint8_t a : {std::uint8_t{3}, std::uint8_t{4}}) clients.push_back(&l.add_client(a));
  l.memory.create_db(1, 16);
  for (int i = 0; i < 10; ++i) (*l.memory.db(1))[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(0x10 + i);
  l.start();
  ASSERT_TRUE(l.run_until([&] { return l.ring_formed(); }, 3000));
  for (const auto* s : clients) EXPECT_EQ(s->mac().las(), (std::vector<std::uint8_t>{0, 1, 2, 3, 4}));

  std::vector<Handle> handles;
  for (auto* s : clients) handles.push_back(*s->open(2));
  ASSERT_TRUE(l.run_until([&] {
    for (std::size_t i = 0; i < clients.size(); ++i)
      if (clients[i]->state(handles[i]) != mpi::State::Connected) return false;
    return true;
  }));
  EXPECT_EQ(cpu.server_connections(), 4u);
  for (std::size_t i = 0; i < clients.size(); ++i) {
    (void)clients[i]->take_events();
    ASSERT_EQ(clients[i]->submit(handles[i], bytes_from_hex(kSetup960)), mpi::RequestError::None);
    ASSERT_EQ(clients[i]->submit(handles[i], bytes_from_hex(kReadDb1Dbb0x10)), mpi::RequestError::None);
  }
  ASSERT_TRUE(l.run_until([&] {
    for (auto* s : clients)
      if (s->stats().pdus_received < 2) return false;
    return true;
  }));
  for (auto* s : clients) {
    const auto replies = of_kind(s->take_events(), EventKind::Reply);
    ASSERT_EQ(replies.size(), 2u);
    EXPECT_EQ(to_hex(replies[1].pdu),
              "32 03 00 00 00 01 00 02 00 0E 00 00 04 01 FF 04 00 50 10 11 12 13 14 15 16 17 18 19");
  }
  // Each client uses its own SAP 0x14; the CPU gives each connection its own SAP, 0x14 .. 0x17,
  // in the order the connect requests arrived (token order 0, 1, 3, 4).
  std::vector<std::uint8_t> saps;
  for (const auto& e : of_kind(cpu.take_events(), EventKind::Accepted)) saps.push_back(e.local_sap);
  EXPECT_EQ(saps, (std::vector<std::uint8_t>{0x14, 0x15, 0x16, 0x17}));
}

}  // namespace
}  // namespace pbvbus::mpi_station::test
