// Switchover-time planner (switchover_timing.hpp): frame lengths checked against the FDL
// encoder, golden figures worked out by hand (arithmetic in the comments, not taken from the
// code under test), the plan checked against a simulated DP master on a line (DP cycle and
// NoResponse recognition), and edge cases.
#include "pbvbus/redundancy/switchover_timing.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/dp/slave_engine.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/fdl/passive_station.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::redundancy {
namespace {

constexpr bus::Baud kBaud = bus::Baud::k1_5M;
// 3 636 000 000 ticks/s / 1 500 000 bit/s = 2424 ticks per bit time.
constexpr bus::Ticks kTpb = 2424;
constexpr bus::Ticks kMs = 3'636'000;  // ticks per ms

bool has_note(const SwitchoverPlan& p, const std::string& part) {
  return std::any_of(p.notes.begin(), p.notes.end(),
                     [&](const std::string& n) { return n.find(part) != std::string::npos; });
}

// --- frame lengths against the encoder -----------------------------------------------------------

TEST(SwitchoverTiming, FrameLengthsMatchTheEncoder) {
  static_assert(bus::ticks_per_bit(kBaud) == kTpb);
  std::vector<std::uint8_t> du(fdl::kMaxDu, 0x5A);
  for (std::size_t n = 0; n <= fdl::kMaxDu; ++n) {
    // Without SAPs (Data_Exchange): n octets after FC.
    fdl::FrameSpec spec;
    spec.da = 5;
    spec.sa = 1;
    spec.fc = fdl::make_request_fc(fdl::RequestFn::SrdHigh, true, true);
    spec.data = std::span<const std::uint8_t>(du.data(), n);
    fdl::Frame f;
    ASSERT_EQ(fdl::encode(spec, f), fdl::EncodeError::None) << n;
    EXPECT_EQ(f.len, fc_frame_octets(n)) << "request, no SAPs, n = " << n;
    // A response carrying n octets (SC when there are none).
    spec.fc = fdl::make_response_fc(fdl::StationType::Slave, fdl::ResponseStatus::DL);
    if (n == 0) {
      EXPECT_EQ(fdl::encode_sc().len, reply_frame_octets(0));
    } else {
      ASSERT_EQ(fdl::encode(spec, f), fdl::EncodeError::None) << n;
      EXPECT_EQ(f.len, reply_frame_octets(n)) << "response, n = " << n;
    }
    // With DSAP/SSAP (Slave_Diag, Set_Prm, Global_Control): 2 + n octets after FC.
    if (n + kSapOctets <= fdl::kMaxDu) {
      spec.fc = fdl::make_request_fc(fdl::RequestFn::SrdHigh, true, false);
      spec.dsap = 61;
      spec.ssap = 62;
      ASSERT_EQ(fdl::encode(spec, f), fdl::EncodeError::None) << n;
      EXPECT_EQ(f.len, fc_frame_octets(n + kSapOctets)) << "with SAPs, n = " << n;
    }
  }
  EXPECT_EQ(fdl::encode_token(1, 1).len, kTokenOctets);
  // The fixed frames the planner uses: SD1 FDL Status, SD2 Slave_Diag request (11), SD3 standard
  // diagnosis reply (14), Global_Control (13), pure PrmCmd Set_Prm (29).
  EXPECT_EQ(kFdlStatusOctets, 6);
  EXPECT_EQ(fc_frame_octets(2), 11);
  EXPECT_EQ(fc_frame_octets(2 + 6), 14);
  EXPECT_EQ(fc_frame_octets(2 + 2), 13);
  EXPECT_EQ(fc_frame_octets(2 + 18), 29);
  fdl::FrameSpec status;
  status.da = 7;
  status.sa = 1;
  status.fc = fdl::make_request_fc(fdl::RequestFn::FdlStatus);
  fdl::Frame f;
  ASSERT_EQ(fdl::encode(status, f), fdl::EncodeError::None);
  EXPECT_EQ(f.len, kFdlStatusOctets);
}

// --- golden figures ----------------------------------------------------------------------------

// The worked example (docs/switchover-timing.md): 1.5 Mbit/s, default bus parameters.
// From bus_params.cpp's defaults table (1.5M row): TSL 300, min TSDR 11, max TSDR 150, TQUI 0,
// TSET 1, retry limit 1. So TSM = 2 + 2·1 + 0 = 4, TID1 = max(33 + 4, 11) = 37,
// TID2 = max(33 + 4, 150) = 150.
// Stations: two switched stations, 3 ("ET 200M fast", T_SLAVE_UM 30 ms) and 4 ("Y-link",
// 820 ms), 2 in / 2 out octets, diagnosis up to 14 octets; one one-sided slave per line, 5 on A
// and 6 on B, 1 in / 1 out, standard 6-octet diagnosis. Every slave planned with max TSDR 150.
std::vector<PlannedSlave> example_slaves() {
  std::vector<PlannedSlave> v;
  PlannedSlave s3;
  s3.address = 3;
  s3.name = "ET 200M fast";
  s3.in_len = 2;
  s3.out_len = 2;
  s3.max_tsdr_bits = 150;
  s3.max_diag_len = 14;
  s3.switched = true;
  s3.t_slave_um = 30 * kMs;
  v.push_back(s3);
  PlannedSlave s4 = s3;
  s4.address = 4;
  s4.name = "Y-link";
  s4.t_slave_um = 820 * kMs;
  v.push_back(s4);
  PlannedSlave s5;
  s5.address = 5;
  s5.name = "one-sided A";
  s5.in_len = 1;
  s5.out_len = 1;
  s5.max_tsdr_bits = 150;
  s5.max_diag_len = 6;
  s5.line = 0;
  v.push_back(s5);
  PlannedSlave s6 = s5;
  s6.address = 6;
  s6.name = "one-sided B";
  s6.line = 1;
  v.push_back(s6);
  return v;
}

TEST(SwitchoverTiming, GoldenFiguresAt1500k) {
  const fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  ASSERT_EQ(bp.tsl, 300u);
  ASSERT_EQ(bp.max_tsdr, 150u);
  ASSERT_EQ(bp.tid1(), 37u);
  ASSERT_EQ(bp.tid2(), 150u);
  ASSERT_EQ(bp.max_retry, 1u);
  const SwitchoverPlan p = plan_switchover(bp, example_slaves());
  EXPECT_TRUE(p.notes.empty()) << p.notes.front();

  for (int l = 0; l < 2; ++l) {
    SCOPED_TRACE(l == 0 ? "line A" : "line B");
    const LinePlan& lp = p.line[l];
    ASSERT_EQ(lp.slaves.size(), 3u);
    // Data_Exchange, 2 out / 2 in: request SD2 9 + 2 = 11 octets = 121 bits; TSDR 150; reply
    // 11 octets = 121; TID1 37. 121 + 150 + 121 + 37 = 429.
    EXPECT_EQ(lp.slaves[0].dx.request, 121);
    EXPECT_EQ(lp.slaves[0].dx.response, 121);
    EXPECT_EQ(lp.slaves[0].dx.total(), 429);
    EXPECT_EQ(lp.slaves[1].dx.total(), 429);
    // 1 out / 1 in: 10 octets = 110 each way: 110 + 150 + 110 + 37 = 407.
    EXPECT_EQ(lp.slaves[2].dx.total(), 407);
    EXPECT_EQ(lp.slaves[2].address, l == 0 ? 5 : 6);
    // Σ DX = 429 + 429 + 407 = 1265.
    EXPECT_EQ(lp.dx_bits, 1265);
    // Global_Control: SD2 9 + 2 SAPs + 2 DU = 13 octets = 143 bits, then TID2 150: 293.
    EXPECT_EQ(lp.gc.total(), 293);
    // Token to itself: 3 octets = 33 bits, then TID1 37: 70.
    EXPECT_EQ(lp.token.total(), 70);
    // GAP poll: unanswered 6 octets = 66 + TSL 300 = 366; answered by a slave 66 + 150 + 66 +
    // 37 = 319. The larger: 366.
    EXPECT_EQ(lp.gap.total(), 366);
    // Slave_Diag after DH, largest diagnosis 14 octets: request SD2 9 + 2 = 11 octets = 121;
    // TSDR 150; reply SD2 9 + 2 + 14 = 25 octets = 275; TID1 37: 583.
    EXPECT_EQ(lp.diag.response, 275);
    EXPECT_EQ(lp.diag.total(), 583);
    // One repeat: largest request 121 + TSL 300 = 421.
    EXPECT_EQ(lp.retry.total(), 421);
    // T_TR = 1265 + 293 + 70 + 366 + 583 + 421 = 2998 bits = 2998 · 2424 = 7 267 152 ticks
    // (1.998 ms).
    EXPECT_EQ(lp.t_tr_bits, 2998);
    EXPECT_EQ(lp.t_tr, 7'267'152);
    // Recognition = 2998 + (1 + 1)·(121 + 300) = 2998 + 842 = 3840 bits = 9 308 160 ticks.
    EXPECT_EQ(lp.recognition_bits, 3840);
    EXPECT_EQ(lp.recognition, 9'308'160);
    // Line loss: one T_TR.
    EXPECT_EQ(lp.line_loss_recognition_bits, 2998);
    EXPECT_EQ(lp.line_loss_recognition, 7'267'152);
  }

  ASSERT_EQ(p.stations.size(), 2u);
  for (const StationBound& sb : p.stations) {
    SCOPED_TRACE(sb.name);
    for (int from = 0; from < 2; ++from) {
      // PrmCmd Set_Prm: SD2 9 + 2 SAPs + 18 DU = 29 octets = 319 bits; TSDR 150; SC 11;
      // TID1 37: 517.
      EXPECT_EQ(sb.prm_cmd[1 - from].request, 319);
      EXPECT_EQ(sb.prm_cmd[1 - from].total(), 517);
      // T_DP_UM = 2998 + 517 + 2998 = 6513 bits = 15 787 512 ticks.
      EXPECT_EQ(sb.t_dp_um_bits[from], 6513);
      EXPECT_EQ(sb.t_dp_um[from], 15'787'512);
      EXPECT_EQ(sb.recognition[from], 9'308'160);
    }
  }
  // T_SLAVE_UM 30 ms = 30 · 3 636 000 = 109 080 000 ticks; 820 ms = 2 981 520 000 ticks.
  EXPECT_EQ(p.stations[0].t_slave_um, 109'080'000);
  EXPECT_EQ(p.stations[1].t_slave_um, 2'981'520'000);
  // Station 3: 9 308 160 + 15 787 512 + 109 080 000 = 134 175 672 ticks (36.902 ms).
  EXPECT_EQ(p.stations[0].bound[0], 134'175'672);
  EXPECT_EQ(p.stations[0].bound[1], 134'175'672);
  EXPECT_EQ(p.stations[0].worst(), 134'175'672);
  // Station 4: 9 308 160 + 15 787 512 + 2 981 520 000 = 3 006 615 672 ticks (826.902 ms).
  EXPECT_EQ(p.stations[1].bound[0], 3'006'615'672);
  // System: T_DP_UM_system = 2998 + 2·517 + 2998 = 7030 bits = 17 040 720 ticks.
  // Bound (line lost) = 2998 bits (7 267 152) + 17 040 720 + 2 981 520 000 (slowest station)
  // = 3 005 827 872 ticks; master stop: 17 040 720 + 2 981 520 000 = 2 998 560 720.
  for (int lost = 0; lost < 2; ++lost) {
    EXPECT_EQ(p.system_t_dp_um_bits[lost], 7030);
    EXPECT_EQ(p.system_t_dp_um[lost], 17'040'720);
    EXPECT_EQ(p.system_bound[lost], 3'005'827'872);
    EXPECT_EQ(p.system_bound_master_stop[lost], 2'998'560'720);
  }
  EXPECT_EQ(p.max_t_slave_um, 2'981'520'000);
}

// --- against the simulation --------------------------------------------------------------------

// Line A of the worked example as a real single-master system: master 1 (dp::Master on an
// fdl::ActiveStation), slaves 3 and 4 (2 in / 2 out) and 5 (1 in / 1 out), each an
// fdl::PassiveStation answering after TSDR 150 (the planned worst case) with a dp::SlaveEngine.
struct LineA {
  bus::Scheduler sched;
  bus::Line line{sched, "A", kBaud};
  fdl::BusParams bp;
  std::unique_ptr<dp::Master> master;
  std::unique_ptr<fdl::ActiveStation> station;
  std::vector<std::unique_ptr<dp::SlaveEngine>> engines;
  std::vector<std::unique_ptr<fdl::PassiveStation>> slaves;
  std::vector<bus::AttachmentId> att;
  std::vector<dp::MasterEvent> events;

  explicit LineA(fdl::BusParams params = fdl::BusParams::defaults(kBaud)) : bp(params) {
    struct Def {
      std::uint8_t address;
      std::uint16_t ident;
      std::vector<dp::SlaveModule> modules;
    };
    const std::vector<Def> defs = {
        {3, 0x1003, {{{0x11}, "DI 16"}, {{0x21}, "DO 16"}}},
        {4, 0x1004, {{{0x11}, "DI 16"}, {{0x21}, "DO 16"}}},
        {5, 0x1005, {{{0x10}, "DI 8"}, {{0x20}, "DO 8"}}},
    };
    std::vector<dp::SlaveParams> sp;
    for (const Def& d : defs) {
      dp::SlaveParams p;
      p.address = d.address;
      p.ident = d.ident;
      p.modules = d.modules;
      sp.push_back(p);
    }
    master = std::make_unique<dp::Master>(dp::MasterParams{}, std::move(sp));
    master->set_event_handler([this](const dp::MasterEvent& e) { events.push_back(e); });
    station = std::make_unique<fdl::ActiveStation>(1, bp, *master);
    line.attach(*station, "master 1");
    for (const Def& d : defs) {
      dp::SlaveConfig c;
      c.ident = d.ident;
      c.modules = d.modules;
      engines.push_back(std::make_unique<dp::SlaveEngine>(c));
      slaves.push_back(std::make_unique<fdl::PassiveStation>(d.address, bp, *engines.back(), 150));
      att.push_back(line.attach(*slaves.back(), "slave " + std::to_string(d.address)));
    }
    line.start();
  }
  void run_for(bus::Ticks t) { sched.run_until(sched.now() + t); }
};

TEST(SwitchoverTiming, PlannedTtrBoundsTheSimulatedDpCycle) {
  const SwitchoverPlan p = plan_switchover(fdl::BusParams::defaults(kBaud), example_slaves());
  const bus::Ticks t_tr = p.line[0].t_tr;
  LineA a;
  a.run_for(400 * kMs);  // some 250 passes of 1.3..2 ms, six Global_Controls (every 60 ms)
  for (std::uint8_t s : {std::uint8_t{3}, std::uint8_t{4}, std::uint8_t{5}}) {
    SCOPED_TRACE(static_cast<int>(s));
    ASSERT_EQ(a.master->slave_state(s), dp::SlaveStatusState::DataExchange);
    const auto& st = a.master->slave_stats(s);
    ASSERT_GT(st.cycle_count, 100u);
    EXPECT_LE(st.cycle_max, t_tr);
    // Not absurdly loose: every pass holds all three Data_Exchange cycles and the token pass,
    // 1265 + 70 = 1335 bits; the plan adds reserves for what need not happen in a pass
    // (Global_Control 293, GAP poll 366, Slave_Diag 583, repeat 421), 1663 bits, i.e. the
    // steady pass is 1335/2998 = 45 % of T_TR > 1/3, and the largest measured cycle (a pass
    // with GAP poll, often with Global_Control: up to 1994 bits) is larger still.
    EXPECT_GE(st.cycle_max, t_tr / 3);
    EXPECT_GE(st.cycle_min, 1335 * kTpb);
    RecordProperty("cycle_max_ticks_" + std::to_string(s), std::to_string(st.cycle_max));
  }
  EXPECT_EQ(std::count_if(a.events.begin(), a.events.end(),
                          [](const dp::MasterEvent& e) {
                            return e.kind == dp::MasterEvent::Kind::StationFailure;
                          }),
            0);
}

TEST(SwitchoverTiming, AnsweredGapPollWithTheSmallestSlotTime) {
  // TSL at its floor, max TSDR + 15 = 165: an unanswered GAP poll takes 66 + 165 = 231 bits, one
  // answered by a slave (the GAP walk reaches 3, 4 and 5) 66 + 150 + 66 + 37 = 319, so the plan
  // reserves 319. T_TR = 1265 + 293 + 70 + 319 + 583 + (121 + 165) = 2816 bits.
  // HSA 6 and G 1 make the GAP walk short (2, 3, 4, 5, 6, 0, then one pass without), so that
  // answered polls are frequent and some pass has one together with a Global_Control.
  fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  bp.tsl = 165;
  bp.hsa = 6;
  bp.gap_factor = 1;
  ASSERT_EQ(bp.validate(), "");
  const SwitchoverPlan p = plan_switchover(bp, example_slaves());
  EXPECT_EQ(p.line[0].gap.total(), 319);
  EXPECT_EQ(p.line[0].gap.response, 66);
  EXPECT_EQ(p.line[0].t_tr_bits, 2816);
  LineA a(bp);
  a.run_for(400 * kMs);
  EXPECT_GT(a.station->stats().gap_polls, 100u);
  for (std::uint8_t s : {std::uint8_t{3}, std::uint8_t{4}, std::uint8_t{5}}) {
    SCOPED_TRACE(static_cast<int>(s));
    ASSERT_EQ(a.master->slave_state(s), dp::SlaveStatusState::DataExchange);
    EXPECT_LE(a.master->slave_stats(s).cycle_max, p.line[0].t_tr);
    // A pass with Global_Control and an answered GAP poll: 1265 + 70 + 293 + 319 = 1947 bits.
    EXPECT_GE(a.master->slave_stats(s).cycle_max, 1947 * kTpb);
    RecordProperty("cycle_max_ticks_" + std::to_string(s),
                   std::to_string(a.master->slave_stats(s).cycle_max));
  }
}

TEST(SwitchoverTiming, NoResponseWithinRecognition) {
  const SwitchoverPlan p = plan_switchover(fdl::BusParams::defaults(kBaud), example_slaves());
  const bus::Ticks recognition = p.line[0].recognition;
  // The shortest possible recognition: the fault cuts slave 4's reply short; the corrupt reply
  // counts as the first failed attempt, the repeat follows TID1 after it and the NoResponse TSL
  // after the repeat: 37 + 121 + 300 = 458 bits. A fault before the request costs both
  // attempts, 2·(121 + 300) = 842 bits, plus the wait for the poll.
  const bus::Ticks floor = (37 + 121 + 300) * kTpb;
  bus::Ticks longest = 0;
  // Faults at eight points spread over one rotation.
  for (int k = 0; k < 8; ++k) {
    SCOPED_TRACE(k);
    LineA a;
    a.run_for(50 * kMs);
    ASSERT_EQ(a.master->slave_state(4), dp::SlaveStatusState::DataExchange);
    a.run_for(k * p.line[0].t_tr / 8 + 1);
    const bus::Ticks fault = a.sched.now();
    a.line.set_transceiver_ok(a.att[1], false);  // slave 4's interface
    a.run_for(20 * kMs);
    const auto it = std::find_if(a.events.begin(), a.events.end(), [](const dp::MasterEvent& e) {
      return e.kind == dp::MasterEvent::Kind::StationFailure;
    });
    ASSERT_NE(it, a.events.end());
    EXPECT_EQ(it->slave, 4);
    EXPECT_EQ(it->cause, dp::MasterEvent::Cause::NoResponse);
    const bus::Ticks took = it->time - fault;
    EXPECT_LE(took, recognition) << bus::format_duration(took);
    EXPECT_GE(took, floor) << bus::format_duration(took);
    longest = std::max(longest, took);
  }
  // For the report: how close the worst of the eight came to the plan.
  RecordProperty("longest_recognition_ticks", std::to_string(longest));
  RecordProperty("planned_recognition_ticks", std::to_string(recognition));
}

// --- edge cases --------------------------------------------------------------------------------

TEST(SwitchoverTiming, LineWithoutSlavesAndEmptyFrames) {
  fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  std::vector<PlannedSlave> v(2);
  // X: no inputs, no outputs, max TSDR 60 (within [11, 150]), standard diagnosis.
  v[0].address = 7;
  v[0].max_tsdr_bits = 60;
  // Y: 8 inputs (an SD3 reply), no outputs, max TSDR not given (bus max TSDR 150).
  v[1].address = 8;
  v[1].in_len = 8;
  const SwitchoverPlan p = plan_switchover(bp, v);
  const LinePlan& a = p.line[0];
  // X: request SD1 6 octets = 66; TSDR 60; SC 11; TID1 37: 174.
  EXPECT_EQ(a.slaves[0].dx.total(), 174);
  // Y: request SD1 66; TSDR 150; reply SD3 14 octets = 154; TID1 37: 407.
  EXPECT_EQ(a.slaves[1].dx.response, 154);
  EXPECT_EQ(a.slaves[1].dx.total(), 407);
  EXPECT_EQ(a.dx_bits, 581);
  // Diag: X 121 + 60 + 154 (SD3: 2 + 6 = 8) + 37 = 372; Y 121 + 150 + 154 + 37 = 462.
  EXPECT_EQ(a.diag.total(), 462);
  // Repeat: the largest request is 66 bits: 66 + 300 = 366.
  EXPECT_EQ(a.retry.total(), 366);
  // T_TR = 581 + 293 + 70 + 366 + 462 + 366 = 2138; recognition = 2138 + 2·366 = 2870.
  EXPECT_EQ(a.t_tr_bits, 2138);
  EXPECT_EQ(a.recognition_bits, 2870);
  EXPECT_EQ(a.t_tr, 2138 * kTpb);
  // Line B has no slaves: GC 293 + token 70 + unanswered GAP 366 = 729; nothing to recognise.
  const LinePlan& b = p.line[1];
  EXPECT_TRUE(b.slaves.empty());
  EXPECT_EQ(b.t_tr_bits, 729);
  EXPECT_EQ(b.recognition_bits, 0);
  EXPECT_EQ(b.recognition, 0);
  EXPECT_TRUE(has_note(p, "line B: no slaves"));
  EXPECT_TRUE(has_note(p, "no switched stations"));
  EXPECT_TRUE(p.stations.empty());
  // Without switched stations the system switchover is two rotations of the other line.
  EXPECT_EQ(p.system_t_dp_um_bits[0], 2 * 729);
  EXPECT_EQ(p.system_t_dp_um_bits[1], 2 * 2138);
}

TEST(SwitchoverTiming, StationWithoutSlaveSwitchoverTime) {
  auto v = example_slaves();
  v[1].t_slave_um.reset();  // the Y-link's time is not known
  const SwitchoverPlan p = plan_switchover(fdl::BusParams::defaults(kBaud), v);
  EXPECT_TRUE(has_note(p, "slave 4 (Y-link): no T_SLAVE_UM"));
  EXPECT_FALSE(p.stations[1].t_slave_um_given);
  EXPECT_EQ(p.stations[1].t_slave_um, 0);
  // 9 308 160 + 15 787 512 + 0.
  EXPECT_EQ(p.stations[1].bound[0], 25'095'672);
  // The slowest given station is now station 3 (30 ms): 7 267 152 + 17 040 720 + 109 080 000.
  EXPECT_EQ(p.max_t_slave_um, 109'080'000);
  EXPECT_EQ(p.system_bound[0], 133'387'872);
}

TEST(SwitchoverTiming, NotesAndRefusals) {
  fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  bp.ttr = 1000;  // below the plan's 2998
  auto v = example_slaves();
  v[2].max_tsdr_bits = 400;  // above the bus max TSDR 150: planned with 150
  const SwitchoverPlan p = plan_switchover(bp, v);
  EXPECT_TRUE(has_note(p, "line A: the bus TTR 1000 t_bit is below the planned T_TR 2998"));
  EXPECT_TRUE(has_note(p, "slave 5 (one-sided A): max TSDR 400"));
  EXPECT_EQ(p.line[0].t_tr_bits, 2998);

  auto bad = example_slaves();
  bad[0].in_len = 245;
  EXPECT_THROW(plan_switchover(bp, bad), std::invalid_argument);
  bad = example_slaves();
  bad[2].line = 2;
  EXPECT_THROW(plan_switchover(bp, bad), std::invalid_argument);
}

}  // namespace
}  // namespace pbvbus::redundancy
