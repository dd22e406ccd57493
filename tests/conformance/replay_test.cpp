// The replay core (conformance/replay*.hpp) on hand-made captures: roles and pairing, the
// Replayer's send times under both pacings (worked out in bit times below), and every kind of
// difference against a scripted slave whose replies are written here by hand.
// The end-to-end replay of examples/dp-basic.textproto (same scenario, mutants, damaged
// captures) runs through the CLI: tests/integration/replay_cli_test.cpp.
#include <gtest/gtest.h>

#include <deque>

#include "../captures/capture_fixture.hpp"

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/conformance/replay.hpp"

namespace pbvbus::conformance {
namespace {

using Bytes = std::vector<std::uint8_t>;
using captures::test::tap_frame;

// 1.5 Mbit/s: one bit time = 3 636 000 000 / 1 500 000 = 2424 ticks. DP defaults there
// (protocol-facts.md §C.1): TSL 300, min TSDR 11, max TSDR 150; TSYN 33.
constexpr bus::Ticks kBit = 2424;
constexpr bus::Ticks bits(std::int64_t n) { return n * kBit; }

// Frames (protocol-facts.md Appendix 1 and §B), FCS = sum of DA..DU mod 256:
const Bytes kToken = {0xDC, 0x01, 0x01};  // SD4 DA 1 SA 1 (master 1 keeps the token)
// Slave_Diag request: SD2 LE 5, DA 0x8A (10 + ext), SA 0x81 (1 + ext), FC 6D (SRD high, FCV,
// FCB 1), DSAP 60 (3C), SSAP 62 (3E); FCS 8A+81+6D+3C+3E = 0x1F2 -> F2.
const Bytes kDiagReq = {0x68, 0x05, 0x05, 0x68, 0x8A, 0x81, 0x6D, 0x3C, 0x3E, 0xF2, 0x16};
// Slave_Diag reply: SD3, DA 0x81, SA 0x8A, FC 08 (DL), DSAP 62, SSAP 60, DU 02 05 00 FF 12 34;
// FCS 81+8A+08+3E+3C+02+05+00+FF+12+34 = 0x3D9 -> D9.
const Bytes kDiagRes = {0xA2, 0x81, 0x8A, 0x08, 0x3E, 0x3C, 0x02, 0x05, 0x00, 0xFF, 0x12, 0x34, 0xD9, 0x16};
// Data_Exchange: SD2 LE 5, DA 10, SA 1, FC 5D (SRD high, FCV, FCB 0), DU AA 55;
// FCS 0A+01+5D+AA+55 = 0x167 -> 67. The next one toggles FCB: FC 7D, FCS 0x187 -> 87.
const Bytes kDx1 = {0x68, 0x05, 0x05, 0x68, 0x0A, 0x01, 0x5D, 0xAA, 0x55, 0x67, 0x16};
const Bytes kDx2 = {0x68, 0x05, 0x05, 0x68, 0x0A, 0x01, 0x7D, 0xAA, 0x55, 0x87, 0x16};
// Data_Exchange reply: SD2 LE 4, DA 1, SA 10, FC 08 (DL), DU 3C; FCS 01+0A+08+3C = 0x4F.
const Bytes kDxRes = {0x68, 0x04, 0x04, 0x68, 0x01, 0x0A, 0x08, 0x3C, 0x4F, 0x16};
// The same with input octet 3D (FCS 0x50) and with status DH (FC 0A, FCS 0x51).
const Bytes kDxRes3D = {0x68, 0x04, 0x04, 0x68, 0x01, 0x0A, 0x08, 0x3D, 0x50, 0x16};
const Bytes kSc = {0xE5};
// Global_Control Clear to 127: SD2 LE 7, DA 0xFF, SA 0x81, FC 46 (SDN high), DSAP 58, SSAP 62,
// DU 02 00; FCS FF+81+46+3A+3E+02+00 = 0x240 -> 40.
const Bytes kGc = {0x68, 0x07, 0x07, 0x68, 0xFF, 0x81, 0x46, 0x3A, 0x3E, 0x02, 0x00, 0x40, 0x16};

// The recording (start times in bit times):
//   0 token (33 bits); 100 Slave_Diag req (11 octets, ends 221), reply at 232 (TSDR 11);
//   500 DX1 (ends 621), reply at 632; 900 Global_Control; 1200 DX2 (ends 1321), reply at 1332.
Bytes recording(std::uint16_t diag_reply_flags = 0) {
  bus::Scheduler sched;
  bus::Line line(sched, "dp0", bus::Baud::k1_5M);
  captures::test::MemorySink mem;
  captures::PcapngWriter w(mem.sink());
  w.add_line(line);
  w.write_frame(tap_frame(line, kToken, bits(0)));
  w.write_frame(tap_frame(line, kDiagReq, bits(100)));
  w.write_frame(tap_frame(line, kDiagRes, bits(232), diag_reply_flags));
  w.write_frame(tap_frame(line, kDx1, bits(500)));
  w.write_frame(tap_frame(line, kDxRes, bits(632)));
  w.write_frame(tap_frame(line, kGc, bits(900)));
  w.write_frame(tap_frame(line, kDx2, bits(1200)));
  w.write_frame(tap_frame(line, kDxRes, bits(1332)));
  w.flush();
  return mem.data;
}

ReplayInput input_of(const Bytes& file) {
  std::string err;
  auto in = build_replay_input(file, {}, err);
  EXPECT_TRUE(in) << err;
  return in ? *in : ReplayInput{};
}

TEST(ReplayInput, RolesPairingAndTimes) {
  const ReplayInput in = input_of(recording());
  EXPECT_EQ(in.line, "dp0");
  EXPECT_EQ(in.baud, bus::Baud::k1_5M);
  EXPECT_EQ(in.tsl, 300u);
  ASSERT_EQ(in.frames.size(), 8u);
  const ReplayRole roles[] = {ReplayRole::Token,   ReplayRole::Request,  ReplayRole::Response,
                              ReplayRole::Request, ReplayRole::Response, ReplayRole::Request,
                              ReplayRole::Request, ReplayRole::Response};
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(in.frames[i].role, roles[i]) << i;
  EXPECT_EQ(in.frames[1].reply, 2);
  EXPECT_EQ(in.frames[3].reply, 4);
  EXPECT_EQ(in.frames[6].reply, 7);
  EXPECT_FALSE(in.frames[5].expects_reply);  // SDN to 127
  EXPECT_EQ(in.comparable_requests(), 3u);
  // Times: ns from the writer back to ticks; frame 2 starts at 232 bit times, 14 octets long.
  EXPECT_EQ(in.frames[2].start, bits(232));
  EXPECT_EQ(in.frames[2].end, bits(232 + 14 * 11));
  EXPECT_EQ(in.frames[1].dsap, std::optional<std::uint8_t>(60));
  EXPECT_EQ(replay_service_name(in.frames[1]), "Slave_Diag");
  EXPECT_EQ(replay_service_name(in.frames[3]), "Data_Exchange");
  EXPECT_EQ(replay_service_name(in.frames[5]), "Global_Control");
  EXPECT_EQ(replay_service_name(in.frames[0]), "Token");
}

TEST(ReplayInput, DamagedReplyIsUnusableAndItsRequestNotCompared) {
  const ReplayInput in = input_of(recording(bus::kRxCollision));
  EXPECT_EQ(in.frames[2].role, ReplayRole::Unusable);
  EXPECT_EQ(in.frames[2].unusable_reason, "collision");
  EXPECT_TRUE(in.frames[1].reply_unusable);
  EXPECT_EQ(in.comparable_requests(), 2u);
}

TEST(ReplayInput, ReplyOutsideTheSlotTimeOrFromAnotherStationIsNotPaired) {
  bus::Scheduler sched;
  bus::Line line(sched, "dp0", bus::Baud::k1_5M);
  captures::test::MemorySink mem;
  captures::PcapngWriter w(mem.sink());
  w.write_frame(tap_frame(line, kDx1, bits(0)));         // ends 121
  w.write_frame(tap_frame(line, kDxRes, bits(121 + 301)));  // 301 > TSL 300 after its end
  w.write_frame(tap_frame(line, kDx2, bits(1000)));      // ends 1121
  // A reply from station 11 (SA 0x0B; FCS 01+0B+08+3C = 0x50) is not station 10's.
  w.write_frame(tap_frame(line, {0x68, 0x04, 0x04, 0x68, 0x01, 0x0B, 0x08, 0x3C, 0x50, 0x16}, bits(1132)));
  w.flush();
  const ReplayInput in = input_of(mem.data);
  EXPECT_EQ(in.frames[0].reply, -1);
  EXPECT_EQ(in.frames[2].reply, -1);
  EXPECT_EQ(in.frames[1].request, -1);
}

/// A slave at address 10 that answers each request to it from a script: the reply octets
/// (none = silent), the TSDR in bit times, and optionally a second frame after the reply.
class ScriptedSlave final : public bus::Device {
 public:
  struct Step {
    Bytes reply;
    std::int64_t tsdr = 11;
    Bytes second;
  };
  std::deque<Step> script;
  bool answer_broadcast = false;
  void on_power_on(bus::Ticks) override {}
  void on_timer(bus::Ticks) override {}
  void on_frame(const bus::RxFrame& f) override {
    if (f.bytes.empty() || !f.intact()) return;
    const std::uint8_t sd = f.bytes[0];
    const std::size_t da_at = sd == 0x68 ? 4 : 1;
    if (sd == 0xDC || f.bytes.size() <= da_at) return;
    const int da = f.bytes[da_at] & 0x7F;
    if (da == 127) {
      if (answer_broadcast) port().transmit(f.end + bits(11), kSc);
      return;
    }
    if (da != 10 || script.empty()) return;
    const Step s = script.front();
    script.pop_front();
    if (s.reply.empty()) return;
    port().transmit(f.end + bits(s.tsdr), s.reply);
    if (!s.second.empty())
      port().transmit(f.end + bits(s.tsdr) + bus::chars_to_ticks(static_cast<std::int64_t>(s.reply.size()),
                                                                  bus::Baud::k1_5M) + bits(20),
                      s.second);
  }
};

struct Replayed {
  ReplayInput in;
  std::unique_ptr<Replayer> rp;
  ReplayResult res;
};

Replayed replay(const Bytes& file, std::deque<ScriptedSlave::Step> script, ReplayPacing pacing,
           std::optional<std::uint8_t> station = {}, std::vector<ReplayMask> masks = {},
           bool answer_broadcast = false) {
  Replayed r;
  r.in = input_of(file);
  bus::Scheduler sched;
  bus::Line line(sched, "dp0", bus::Baud::k1_5M);
  ScriptedSlave slave;
  slave.script = std::move(script);
  slave.answer_broadcast = answer_broadcast;
  r.rp = std::make_unique<Replayer>(r.in, ReplayerOptions{pacing, station});
  line.attach(*r.rp, "replayer");
  line.attach(slave, "slave 10");
  line.start();
  for (int i = 0; i < 100 && !r.rp->finished(); ++i) sched.run_until(sched.now() + bus::kTicksPerMs);
  EXPECT_TRUE(r.rp->finished());
  ReplayCompareOptions co;
  co.masks = std::move(masks);
  r.res = compare_replay(r.in, *r.rp, co);
  return r;
}

std::deque<ScriptedSlave::Step> as_recorded() { return {{kDiagRes, 11, {}}, {kDxRes, 11, {}}, {kDxRes, 11, {}}}; }

std::vector<std::int64_t> sent_starts(const Replayer& rp) {
  std::vector<std::int64_t> v;
  for (const auto& s : rp.sent()) v.push_back(s.start / kBit);
  return v;
}

TEST(Replayer, SameRepliesNoDifferenceFastPacing) {
  const Replayed r = replay(recording(), as_recorded(), ReplayPacing::Fast);
  // Fast: first frame TSYN after power-on (33); token 3 octets ends 66, +33 -> Slave_Diag at
  // 99, ends 220, reply 231..385 (14 octets), +33 -> DX1 at 418, ends 539, reply 550..660,
  // +33 -> GC at 693, 13 octets ends 836, no reply expected: +33 -> DX2 at 869.
  EXPECT_EQ(sent_starts(*r.rp), (std::vector<std::int64_t>{33, 99, 418, 693, 869}));
  EXPECT_EQ(r.res.requests_replayed, 4u);
  EXPECT_EQ(r.res.tokens_replayed, 1u);
  EXPECT_EQ(r.res.compared, 3u);
  EXPECT_EQ(r.res.matches, 3u);
  EXPECT_EQ(r.res.differences(), 0u);
  EXPECT_EQ(replay_exit_status(r.res), 0);
}

TEST(Replayer, AsRecordedPacingKeepsTheRecordedOffsets) {
  const Replayed r = replay(recording(), as_recorded(), ReplayPacing::AsRecorded);
  // t0 = 33; every frame at 33 + its recorded start: 0, 100, 500, 900, 1200.
  EXPECT_EQ(sent_starts(*r.rp), (std::vector<std::int64_t>{33, 133, 533, 933, 1233}));
  EXPECT_EQ(r.res.pacing_slips, 0u);
  EXPECT_EQ(r.res.differences(), 0u);
}

TEST(Replayer, LateReplyIsATimingDifferenceAndAPacingSlip) {
  auto script = as_recorded();
  script[1].tsdr = 200;  // > max TSDR 150, < TSL 300
  const Replayed r = replay(recording(), script, ReplayPacing::AsRecorded);
  // DX1 at 533, ends 654; reply at 854, 10 octets, ends 964. GC wanted at 933: the line is
  // busy, it waits for TSYN after 964 -> 997 (one slip); DX2 at 1233 as recorded.
  EXPECT_EQ(sent_starts(*r.rp), (std::vector<std::int64_t>{33, 133, 533, 997, 1233}));
  EXPECT_EQ(r.res.pacing_slips, 1u);
  ASSERT_EQ(r.res.differences(), 1u);
  const ReplayDiff& d = r.res.diffs[0];
  EXPECT_EQ(d.kind, DiffKind::Timing);
  EXPECT_EQ(d.tsdr_bits, 200);
  EXPECT_EQ(d.station, 10);
  EXPECT_EQ(d.service, "Data_Exchange");
  EXPECT_EQ(r.res.by_kind[static_cast<int>(DiffKind::Timing)], 1u);
  EXPECT_EQ(replay_exit_status(r.res), 1);
}

TEST(Replayer, OtherDataNamesTheOctetsAndTheInputsMaskHidesThem) {
  auto script = as_recorded();
  script[1].reply = kDxRes3D;
  Replayed r = replay(recording(), script, ReplayPacing::Fast);
  ASSERT_EQ(r.res.differences(), 1u);
  EXPECT_EQ(r.res.diffs[0].kind, DiffKind::OtherData);
  // Frame octet 7 is the DU's first (SD LE LEr SD DA SA FC DU), octet 8 the FCS.
  EXPECT_EQ(r.res.diffs[0].frame_offsets, (std::vector<std::size_t>{7, 8}));
  EXPECT_EQ(r.res.diffs[0].du_offsets, (std::vector<std::size_t>{0}));
  const std::string text = replay_text(r.res);
  EXPECT_NE(text.find("    field    SD   LE   LEr  SD   DA   SA   FC   DU   FCS  ED\n"
                      "    recorded 68   04   04   68   01   0A   08   3C   4F   16\n"
                      "    replayed 68   04   04   68   01   0A   08   3D   50   16\n"
                      "                                                ^^   ^^\n"),
            std::string::npos)
      << text;

  std::string e;
  auto inputs = parse_replay_mask("inputs", e);
  ASSERT_TRUE(inputs);
  r = replay(recording(), script, ReplayPacing::Fast, {}, {*inputs});
  EXPECT_EQ(r.res.differences(), 0u);
  ASSERT_EQ(r.res.masks.size(), 1u);
  EXPECT_EQ(r.res.masks[0].second, 1u);
  // The same octet by the general rule ADDR:SAP:OFFSET; offset 1 would not hide it.
  r = replay(recording(), script, ReplayPacing::Fast, {}, {*parse_replay_mask("10:dx:0", e)});
  EXPECT_EQ(r.res.differences(), 0u);
  r = replay(recording(), script, ReplayPacing::Fast, {}, {*parse_replay_mask("counter:10:1-2", e)});
  EXPECT_EQ(r.res.differences(), 1u);
}

TEST(Replayer, OtherFcMissingAndExtraReplies) {
  auto script = as_recorded();
  script[0].reply.clear();         // Slave_Diag: silent -> missing reply
  script[2].reply = kSc;           // DX2: SC instead of DL data -> other FC
  script[1].second = kDxRes;       // DX1: a second frame after the reply -> extra reply
  const Replayed r = replay(recording(), script, ReplayPacing::Fast, {}, {}, /*answer_broadcast=*/true);
  ASSERT_EQ(r.res.differences(), 4u) << replay_text(r.res);
  EXPECT_EQ(r.res.diffs[0].kind, DiffKind::MissingReply);
  EXPECT_EQ(r.res.diffs[0].service, "Slave_Diag");
  EXPECT_EQ(r.res.diffs[1].kind, DiffKind::ExtraReply);  // DX1's second frame
  EXPECT_EQ(r.res.diffs[2].kind, DiffKind::ExtraReply);  // an answer to Global_Control
  EXPECT_EQ(r.res.diffs[2].service, "Global_Control");
  EXPECT_EQ(r.res.diffs[3].kind, DiffKind::OtherFc);
  EXPECT_EQ(r.res.matches, 0u);
  EXPECT_EQ(r.res.compared, 3u);
  const std::string json = replay_json(r.res);
  EXPECT_NE(json.find("\"by_kind\":{\"missing_reply\":1,\"extra_reply\":2,\"other_fc\":1,\"other_data\":0,"
                      "\"timing\":0}"),
            std::string::npos)
      << json;
}

TEST(Replayer, OneStationTargetSkipsTokensAndOtherTraffic) {
  const Replayed r = replay(recording(), as_recorded(), ReplayPacing::Fast, 10);
  EXPECT_EQ(r.res.tokens_replayed, 0u);
  EXPECT_EQ(r.res.requests_replayed, 4u);  // Slave_Diag, DX1, the broadcast, DX2
  EXPECT_EQ(r.res.differences(), 0u);
  EXPECT_EQ(replay_plan(r.in, 11).size(), 1u);  // only the broadcast
}

TEST(Replayer, DamagedRecordedReplyIsListedNotCompared) {
  const Replayed r = replay(recording(bus::kRxCollision), as_recorded(), ReplayPacing::Fast);
  EXPECT_EQ(r.res.compared, 2u);
  EXPECT_EQ(r.res.not_compared_unusable, 1u);
  ASSERT_EQ(r.res.unusable.size(), 1u);
  EXPECT_EQ(r.res.differences(), 0u);
  EXPECT_NE(replay_text(r.res).find("): collision\n"), std::string::npos);
}

TEST(ReplayMask, Rules) {
  std::string e;
  auto m = parse_replay_mask("5:60:6-9", e);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->station, 5);
  EXPECT_EQ(m->sap, std::optional<std::uint8_t>(60));
  EXPECT_EQ(m->first, 6u);
  EXPECT_EQ(m->last, 9u);
  EXPECT_TRUE(parse_replay_mask("diag-ext", e));
  for (const char* bad : {"", "input", "5:64:1", "127:dx:0", "counter:5", "5:dx:3-1", "5:dx:x"})
    EXPECT_FALSE(parse_replay_mask(bad, e)) << bad;
}

TEST(ReplayReport, FieldNames) {
  using V = std::vector<std::string>;
  EXPECT_EQ(frame_field_names(kDiagReq), (V{"SD", "LE", "LEr", "SD", "DA", "SA", "FC", "DSAP", "SSAP", "FCS", "ED"}));
  EXPECT_EQ(frame_field_names(kDiagRes),
            (V{"SD", "DA", "SA", "FC", "DSAP", "SSAP", "DU", "DU", "DU", "DU", "DU", "DU", "FCS", "ED"}));
  EXPECT_EQ(frame_field_names(kToken), (V{"SD", "DA", "SA"}));
  EXPECT_EQ(frame_field_names(kSc), (V{"SC"}));
}

}  // namespace
}  // namespace pbvbus::conformance
