// Group "DP-V1" (V1-nn): MSAC_C1 Read/Write with their error responses and the alarm handshake
// (IEC 61158-6 DP-V1 MSAC_C1; protocol-facts.md §E.1 function numbers, §E.2 PDUs, §E.3 error
// decoding, §E.5 alarms, §D.5 alarm block, §D.2 DPV1_Status_1..3; docs/dp-slave.md MSAC_C1).
//
// MSAC_C1 requests go from the tester's SSAP 51 to DSAP 51 (Read/Write) or DSAP 50 (Alarm_Ack).
//
// Decisions:
// - The whole group is n/a unless the GSD says DPV1_Slave = 1.
// - Set_Prm carries the GSD-assembled User_Prm_Data with DPV1_Enable (DPV1_Status_1 bit 7) set;
//   V1-05's DP-V0 mode clears DPV1_Enable and DPV1_Status_2 (alarm enables, Check_Cfg_Mode),
//   which only mean something with DPV1_Enable.
// - A known record: the GSD names no data records and the shipped models register none, so V1-02
//   is white box — it registers a read handler for slot 1, index 1 answering `AB CD` on the
//   model's application and reads it; n/a for an outside slave.
// - Unknown index: slot 0 (the device; always a valid slot), index 254. The answer must be the
//   negative Read response with Error_Decode 80 and Error_Code_1 B0 (access, invalid index):
//   `DE 80 B0 xx` (Error_Code_2 is user-specific and not judged).
// - Write with a wrong length: `5F 00 FE 04 AA BB` (Length 4, two octets follow) → `DF 80 B1 xx`
//   (access, write length error): the PDU is malformed before any record is looked up.
// - Alarms (white box, model only, GSD Process_Alarm_supp = 1): Set_Prm also enables process
//   alarms (DPV1_Status_2 bit 6); the model raises a process alarm on module 0
//   (SlaveFault::process_alarm); the owner's next Data_Exchange must answer DH, the diagnosis
//   must carry the alarm block (type 02), Alarm_Ack `5C slot 02 specifier` must be echoed and
//   the alarm gone from the next diagnosis; a second, now unmatched Alarm_Ack must get
//   `DC 80 B5 xx` (access, state conflict; slave_engine.hpp).

#include <algorithm>
#include <string>

#include "group_support.hpp"

#include "pbvbus/dp/dpv1_pdu.hpp"
#include "pbvbus/dp/prm.hpp"
#include "pbvbus/dp/sap.hpp"

namespace pbvbus::conformance::detail {
namespace {

constexpr const char* kDpv1Group = "DP-V1";

/// The same before any session is opened (an n/a test needs no starting state).
bool dpv1_slave(TestContext& ctx, TestResult& res) {
  if (!ctx.spec().gsd->dpv1().dpv1_slave) {
    not_applicable(res, "the GSD does not say DPV1_Slave = 1");
    return false;
  }
  return true;
}

bool dpv1_slave(Run& run) {
  if (!run.ctx().spec().gsd->dpv1().dpv1_slave) {
    run.na("the GSD does not say DPV1_Slave = 1");
    return false;
  }
  return true;
}

dp::SlaveParams dpv1_params(const TestContext& ctx, bool enable = true) {
  dp::SlaveParams p = ctx.params();
  if (p.user_prm.size() < 3) p.user_prm.resize(3, 0);
  if (enable)
    p.user_prm[0] |= dp::kDpv1Enable;
  else {
    // DP-V0 compatibility mode: the alarm enables and Check_Cfg_Mode of DPV1_Status_2 belong to
    // DP-V1 and go with it (a slave refuses them without DPV1_Enable).
    p.user_prm[0] &= static_cast<std::uint8_t>(~dp::kDpv1Enable);
    p.user_prm[1] = 0;
  }
  return p;
}

/// A DP-V1 negative response `fn|80 80 code_1 xx`?
bool negative(const Reply& r, std::uint8_t fn, std::uint8_t code_1) {
  return r.ok_with_data() && r.data.size() == 4 && r.data[0] == (fn | dp::kFnErrorBit) &&
         r.data[1] == dp::kErrorDecodeDpv1 && r.data[2] == code_1;
}

bool start_dpv1(Run& run, const dp::SlaveParams& p) {
  std::string why;
  if (run.start_up(why, &p)) return true;
  run.fail("Set_Prm with DPV1_Enable: " + why);
  return false;
}

void dpv1_start_up(TestContext& ctx, TestResult& res) {
  if (!dpv1_slave(ctx, res)) return;
  Run run(ctx, res);
  if (!run || !dpv1_slave(run)) return;
  const auto p = dpv1_params(ctx);
  if (!start_dpv1(run, p)) return;
  const Reply dx = reply_of(run.data_exchange(run.outputs(0x00), "Data_Exchange"));
  if (!(dx.ok_with_data() || (dx.kind == Reply::Kind::Sc && ctx.input_len() == 0)))
    return run.fail("Data_Exchange after the DP-V1 start-up answered " + dx.describe());
  run.pass("Set_Prm with DPV1_Status " + hex(std::span(p.user_prm).first(3)) +
           " accepted; the slave entered data exchange");
}

void read_known(TestContext& ctx, TestResult& res) {
  if (!dpv1_slave(ctx, res)) return;
  if (!ctx.spec().gsd->dpv1().c1_read_write_supp)
    return not_applicable(res, "the GSD says C1_Read_Write_supp = 0");
  if (ctx.outside())
    return not_applicable(
        res, "the GSD names no data record, so the battery knows none to read on an outside slave");
  Run run(ctx, res);
  if (!run || !dpv1_slave(run)) return;
  run.model()->application().on_read(1, 1, [](const dp::RecordCall&, std::span<std::uint8_t> out) {
    const std::uint8_t v[2] = {0xAB, 0xCD};
    const std::size_t n = std::min<std::size_t>(out.size(), 2);
    std::copy_n(v, n, out.begin());
    return dp::RecordResult::ok(n);
  });
  if (!start_dpv1(run, dpv1_params(ctx))) return;
  const std::uint8_t rq[4] = {dp::kFnRead, 0x01, 0x01, 0x40};
  const Reply r =
      reply_of(run.c1(dp::kSapC1ReadWrite, rq, "MSAC_C1 Read slot 1 index 1 length 64"));
  const std::vector<std::uint8_t> want = {0x5E, 0x01, 0x01, 0x02, 0xAB, 0xCD};
  if (!r.ok_with_data() || r.data != want)
    return run.fail("MSAC_C1 Read of slot 1 index 1 answered " + r.describe() + ", expected DL " +
                    hex(want));
  run.pass("MSAC_C1 Read of a known record answered " + hex(want));
}

void read_unknown_index(TestContext& ctx, TestResult& res) {
  if (!dpv1_slave(ctx, res)) return;
  if (!ctx.spec().gsd->dpv1().c1_read_write_supp)
    return not_applicable(res, "the GSD says C1_Read_Write_supp = 0");
  Run run(ctx, res);
  if (!run || !dpv1_slave(run)) return;
  if (!start_dpv1(run, dpv1_params(ctx))) return;
  const std::uint8_t rq[4] = {dp::kFnRead, 0x00, 0xFE, 0x10};
  const Reply r =
      reply_of(run.c1(dp::kSapC1ReadWrite, rq, "MSAC_C1 Read slot 0 index 254 (unknown)"));
  if (!negative(r, dp::kFnRead, dp::dpv1_err::kInvalidIndex))
    return run.fail("MSAC_C1 Read of an unknown index answered " + r.describe() +
                    ", expected the negative response DL DE 80 B0 xx (invalid index)");
  run.pass("MSAC_C1 Read of an unknown index answered " + hex(r.data));
}

void write_wrong_length(TestContext& ctx, TestResult& res) {
  if (!dpv1_slave(ctx, res)) return;
  if (!ctx.spec().gsd->dpv1().c1_read_write_supp)
    return not_applicable(res, "the GSD says C1_Read_Write_supp = 0");
  Run run(ctx, res);
  if (!run || !dpv1_slave(run)) return;
  if (!start_dpv1(run, dpv1_params(ctx))) return;
  const std::uint8_t rq[6] = {dp::kFnWrite, 0x00, 0xFE, 0x04, 0xAA, 0xBB};
  const Reply r =
      reply_of(run.c1(dp::kSapC1ReadWrite, rq, "MSAC_C1 Write, Length 4 with 2 octets"));
  if (!negative(r, dp::kFnWrite, dp::dpv1_err::kWriteLengthError))
    return run.fail("MSAC_C1 Write whose Length (4) disagrees with its data (2 octets) answered " +
                    r.describe() + ", expected DL DF 80 B1 xx (write length error)");
  run.pass("MSAC_C1 Write with a wrong length answered " + hex(r.data));
}

void not_enabled(TestContext& ctx, TestResult& res) {
  if (!dpv1_slave(ctx, res)) return;
  if (!ctx.spec().gsd->dpv1().c1_read_write_supp)
    return not_applicable(res, "the GSD says C1_Read_Write_supp = 0");
  Run run(ctx, res);
  if (!run || !dpv1_slave(run)) return;
  const auto p = dpv1_params(ctx, false);
  std::string why;
  if (!run.start_up(why, &p)) return run.fail("Set_Prm without DPV1_Enable (DP-V0 mode): " + why);
  const std::uint8_t rq[4] = {dp::kFnRead, 0x00, 0x01, 0x10};
  const Reply r = reply_of(run.c1(dp::kSapC1ReadWrite, rq, "MSAC_C1 Read without DPV1_Enable"));
  if (!r.rs())
    return run.fail("MSAC_C1 Read to a slave parameterised without DPV1_Enable answered " +
                    r.describe() + ", expected RS (SAP 51 not activated)");
  const std::uint8_t wr[5] = {dp::kFnWrite, 0x00, 0x01, 0x01, 0x00};
  const Reply w = reply_of(run.c1(dp::kSapC1ReadWrite, wr, "MSAC_C1 Write without DPV1_Enable"));
  if (!w.rs())
    return run.fail("MSAC_C1 Write to a slave parameterised without DPV1_Enable answered " +
                    w.describe() + ", expected RS");
  run.pass("MSAC_C1 Read and Write without DPV1_Enable were answered RS");
}

/// The first DP-V1 alarm block of type `type` in a diagnosis DU: {slot, specifier}.
std::optional<std::pair<std::uint8_t, std::uint8_t>> find_alarm(std::span<const std::uint8_t> du,
                                                                std::uint8_t type) {
  if (du.size() <= dp::kStdDiagLen) return std::nullopt;
  std::vector<dp::ExtDiagBlock> blocks;
  if (!dp::split_ext_diag(du.subspan(dp::kStdDiagLen), blocks)) return std::nullopt;
  for (const auto& b : blocks)
    if (b.kind == dp::kBlockDevice && b.bytes.size() >= 4 && b.bytes[1] == type)
      return std::pair{b.bytes[2], b.bytes[3]};
  return std::nullopt;
}

void alarm_ack(TestContext& ctx, TestResult& res) {
  if (!dpv1_slave(ctx, res)) return;
  if (!ctx.spec().gsd->dpv1().process_alarm_supp)
    return not_applicable(res, "the GSD says Process_Alarm_supp = 0");
  if (ctx.outside())
    return not_applicable(res, "an outside slave cannot be made to raise an alarm on demand (white box only)");
  Run run(ctx, res);
  if (!run || !dpv1_slave(run)) return;
  auto p = dpv1_params(ctx);
  p.user_prm[1] |= dp::kEnableProcessAlarm;
  if (!start_dpv1(run, p)) return;
  const std::string err = run.model()->apply(devices::SlaveFault::process_alarm(0, {0x01}));
  if (!err.empty()) return run.error("the test could not make the model raise a process alarm: " + err);
  const Reply dx = reply_of(run.data_exchange(run.outputs(0x00), "Data_Exchange after the alarm"));
  if (dx.kind != Reply::Kind::Telegram || dx.status != fdl::ResponseStatus::DH)
    return run.fail("after a process alarm the owner's Data_Exchange answered " + dx.describe() +
                    ", expected DH (new diagnosis)");
  const Reply dg = reply_of(run.slave_diag("Slave_Diag with the alarm"));
  if (!dg.ok_with_data()) return run.fail("Slave_Diag answered " + dg.describe());
  const auto al = find_alarm(dg.data, 0x02);
  if (!al)
    return run.fail("the diagnosis " + hex(dg.data) + " carries no process alarm block (type 02)");
  const std::uint8_t ack[4] = {dp::kFnAlarmAck, al->first, 0x02, al->second};
  const Reply r = reply_of(run.c1(dp::kSapC1Alarm, ack, "Alarm_Ack"));
  const std::vector<std::uint8_t> echo(ack, ack + 4);
  if (!r.ok_with_data() || r.data != echo)
    return run.fail("Alarm_Ack " + hex(echo) + " answered " + r.describe() +
                    ", expected the echo " + hex(echo));
  const Reply dg2 = reply_of(run.slave_diag("Slave_Diag after Alarm_Ack"));
  if (!dg2.ok_with_data()) return run.fail("Slave_Diag answered " + dg2.describe());
  if (find_alarm(dg2.data, 0x02))
    return run.fail("the acknowledged alarm is still in the diagnosis " + hex(dg2.data));
  const Reply r2 = reply_of(run.c1(dp::kSapC1Alarm, ack, "Alarm_Ack again (no such alarm)"));
  if (!negative(r2, dp::kFnAlarmAck, dp::dpv1_err::kStateConflict))
    return run.fail("an Alarm_Ack for no outstanding alarm answered " + r2.describe() +
                    ", expected DL DC 80 B5 xx (state conflict)");
  run.pass("process alarm: DH, alarm block in the diagnosis, Alarm_Ack " + hex(echo) +
           " echoed and the alarm gone; a wrong Alarm_Ack answered " + hex(r2.data));
}

}  // namespace

void add_dpv1_tests(std::vector<TestCase>& out) {
  using devices::SlaveMutant;
  out.push_back(make_case(
      "V1-01", kDpv1Group, "Set_Prm with DPV1_Enable",
      "A DP-V1 slave accepts Set_Prm whose User_Prm_Data starts with DPV1_Status_1..3 and "
      "DPV1_Enable set, and enters data exchange (IEC 61158-6 DP-V1; protocol-facts.md §D.2)",
      {}, dpv1_start_up));
  out.push_back(make_case(
      "V1-02", kDpv1Group, "MSAC_C1 Read of a known record",
      "MSAC_C1 Read of an existing record is answered `5E Slot Index Length Data` in the same SRD "
      "(or after polls) (IEC 61158-6 DP-V1 MSAC_C1; protocol-facts.md §E.2, §E.4)",
      {}, read_known));
  out.push_back(make_case(
      "V1-03", kDpv1Group, "MSAC_C1 Read of an unknown index",
      "MSAC_C1 Read of an index the slave does not have is answered with the negative response "
      "`DE 80 B0 xx` (Error_Decode DP-V1, access class, invalid index) (IEC 61158-6 DP-V1; "
      "protocol-facts.md §E.2, §E.3)",
      {SlaveMutant::Dpv1BadIndexAccepted}, read_unknown_index));
  out.push_back(make_case(
      "V1-04", kDpv1Group, "MSAC_C1 Write with a wrong length",
      "MSAC_C1 Write whose Length disagrees with the data is answered `DF 80 B1 xx` (write length "
      "error) (IEC 61158-6 DP-V1; protocol-facts.md §E.2, §E.3)",
      {}, write_wrong_length));
  out.push_back(
      make_case("V1-05", kDpv1Group, "MSAC_C1 without DPV1_Enable refused",
                "MSAC_C1 is open only when Set_Prm set DPV1_Enable; otherwise Read/Write get RS "
                "(IEC 61158-6 DP-V1; protocol-facts.md §D.2 DPV1_Status_1, docs/dp-slave.md)",
                {}, not_enabled));
  out.push_back(make_case(
      "V1-06", kDpv1Group, "Alarm and Alarm_Ack",
      "An enabled alarm makes the owner's Data_Exchange answer DH and appears in the diagnosis "
      "until the master acknowledges it with Alarm_Ack (slot, type, Seq_Nr), which is echoed; an "
      "Alarm_Ack for no outstanding alarm gets `DC 80 B5 xx` (IEC 61158-6 DP-V1 alarms; "
      "protocol-facts.md §E.5, §D.5)",
      {}, alarm_ack));
}

}  // namespace pbvbus::conformance::detail
