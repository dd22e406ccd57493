// DP master class 2 against the DP slave engine: Get_Cfg, Slave_Diag, Rd_Inp, Rd_Outp,
// Set_Slave_Add (Appendix 1 golden), MSAC_C2 initiate/read/write/abort with polling and
// keep-alive. Request frames are written by hand (FCS = sum of DA..DU mod 256, worked out in
// the comments).
#include <gtest/gtest.h>

#include "master_harness.hpp"
#include "pbvbus/dp/class2_master.hpp"

namespace pbvbus::dp {
namespace {

using test::Bytes;
using test::Harness;
using test::hex;
using test::MasterDriver;
using fdl::ResponseStatus;

constexpr std::uint8_t kS = 10;

SlaveConfig slave_config(bool dpv1 = false) {
  SlaveConfig c;
  c.ident = 0x1234;
  c.modules = {{{0x10}, "in"}, {{0x20}, "out"}};
  if (dpv1) {
    c.features.dpv1 = true;
    c.features.c2 = true;
    c.features.c2_connections = 2;
    c.min_user_prm_len = 3;
    c.max_user_prm_len = 3;
  }
  return c;
}

struct Results {
  std::vector<Class2Result> all;
  Class2Callback cb() {
    return [this](const Class2Result& r) { all.push_back(r); };
  }
};

/// Runs token visits until nothing is pending (at most 20).
void drain(MasterDriver& d, Class2Master& m) {
  for (int i = 0; i < 20 && m.pending() > 0; ++i) d.visit();
}

TEST(DpClass2, GetCfgAndSlaveDiag) {
  SlaveEngine e(slave_config());
  Class2Master m({2, 100});
  MasterDriver d(m, 2);
  d.attach(kS, e);
  Results res;
  ASSERT_NE(m.get_cfg(kS, res.cb()), 0u);
  ASSERT_NE(m.slave_diag(kS, res.cb()), 0u);
  d.token();
  // 8A+82+6D+3B+3E = 1F2.
  EXPECT_EQ(d.next(), "68 05 05 68 8A 82 6D 3B 3E F2 16");
  d.deliver();
  // 8A+82+5D+3C+3E = 1E3.
  EXPECT_EQ(d.next(), "68 05 05 68 8A 82 5D 3C 3E E3 16");
  d.deliver();
  EXPECT_EQ(d.next(), "");
  ASSERT_EQ(res.all.size(), 2u);
  EXPECT_EQ(res.all[0].service, Class2Service::GetCfg);
  EXPECT_EQ(res.all[0].status, AcyclicStatus::Ok);
  EXPECT_EQ(hex(res.all[0].data), "10 20");
  ASSERT_EQ(res.all[0].cfg.size(), 2u);
  EXPECT_EQ(res.all[0].inputs, 1u);
  EXPECT_EQ(res.all[0].outputs, 1u);
  EXPECT_EQ(res.all[1].service, Class2Service::SlaveDiag);
  EXPECT_EQ(res.all[1].status, AcyclicStatus::Ok);
  EXPECT_EQ(hex(res.all[1].data), "02 05 00 FF 12 34");
  EXPECT_EQ(res.all[1].diag.status_1, 0x02);
  EXPECT_EQ(res.all[1].diag.master_add, 0xFF);
  EXPECT_EQ(res.all[1].diag.ident, 0x1234);
  EXPECT_TRUE(res.all[1].diag_blocks.empty());
}

TEST(DpClass2, RdInpRdOutpOnlyInDataExchange) {
  SlaveEngine e(slave_config());
  Class2Master m({2, 100});
  MasterDriver d(m, 2);
  d.attach(kS, e);
  Results res;
  m.rd_inp(kS, res.cb());
  drain(d, m);
  ASSERT_EQ(res.all.size(), 1u);
  EXPECT_EQ(res.all[0].status, AcyclicStatus::NotAvailable);  // Wait_Prm: RS
  EXPECT_EQ(res.all[0].fdl_status, ResponseStatus::RS);

  // Master 1 brings the slave up and writes output 0x5A; the device sets input 0xC3.
  Harness h(e);
  ASSERT_EQ(h.req(1, kS, kSapSetPrm, {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00}), Bytes{0xE5});
  ASSERT_EQ(h.req(1, kS, kSapChkCfg, {0x10, 0x20}), Bytes{0xE5});
  const Bytes in{0xC3};
  e.application().write_inputs(0, in);
  h.req(1, kS, std::nullopt, {0x5A});

  d.token();
  m.rd_inp(kS, res.cb());
  m.rd_outp(kS, res.cb());
  // The RS answer above was a valid reply, so the FCB has moved on: 5D, then 7D.
  EXPECT_EQ(d.next(), "68 05 05 68 8A 82 5D 38 3E DF 16");  // 8A+82+5D+38+3E = 1DF
  d.deliver();
  EXPECT_EQ(d.next(), "68 05 05 68 8A 82 7D 39 3E 00 16");  // 8A+82+7D+39+3E = 200
  d.deliver();
  ASSERT_EQ(res.all.size(), 3u);
  EXPECT_EQ(res.all[1].status, AcyclicStatus::Ok);
  EXPECT_EQ(hex(res.all[1].data), "C3");
  EXPECT_EQ(res.all[2].status, AcyclicStatus::Ok);
  EXPECT_EQ(hex(res.all[2].data), "5A");
}

TEST(DpClass2, SetSlaveAddGolden) {
  SlaveConfig c = slave_config();
  c.features.set_slave_add = true;
  SlaveEngine e(c);
  Class2Master m({1, 100});
  MasterDriver d(m, 1);
  d.attach(126, e);
  Results res;
  EXPECT_EQ(m.set_slave_add(126, 126, 0x1234, false, res.cb()), 0u);  // 126 is no valid target
  ASSERT_NE(m.set_slave_add(126, 5, 0x1234, false, res.cb()), 0u);
  d.token();
  EXPECT_EQ(d.next(), "68 09 09 68 FE 81 6D 37 3E 05 12 34 00 AC 16");  // Appendix 1
  fdl::Reply r;
  fdl::Indication ind;
  ind.sa = 1;
  ind.da = 126;
  ind.fn = d.req.fn;
  ind.dsap = d.req.dsap;
  ind.ssap = d.req.ssap;
  ind.data = d.req.data;
  e.on_request(ind, r);
  EXPECT_EQ(r.kind, fdl::Reply::Kind::ShortAck);
  EXPECT_EQ(r.new_address, std::optional<std::uint8_t>(5));
  d.confirm_sc();
  ASSERT_EQ(res.all.size(), 1u);
  EXPECT_EQ(res.all[0].status, AcyclicStatus::Ok);
  EXPECT_EQ(to_string(res.all[0].service), "Set_Slave_Add");
}

TEST(DpClass2, NoResponseFromAbsentStation) {
  Class2Master m({2, 100});
  MasterDriver d(m, 2);
  Results res;
  m.slave_diag(33, res.cb());
  drain(d, m);
  ASSERT_EQ(res.all.size(), 1u);
  EXPECT_EQ(res.all[0].status, AcyclicStatus::NoResponse);
  EXPECT_EQ(m.get_cfg(2, res.cb()), 0u);    // own address
  EXPECT_EQ(m.get_cfg(127, res.cb()), 0u);  // broadcast
}

TEST(DpClass2, MsacC2InitiateReadWriteAbort) {
  SlaveEngine e(slave_config(true));
  e.application().on_read(0, 1, [](const RecordCall&, std::span<std::uint8_t> out) {
    out[0] = 0xAB;
    out[1] = 0xCD;
    return RecordResult::ok(2);
  });
  Bytes written;
  e.application().on_write(1, 2, [&](const RecordCall& c, std::span<const std::uint8_t> data) {
    EXPECT_TRUE(c.c2);
    written.assign(data.begin(), data.end());
    return RecordResult::ok();
  });
  Class2Master m({2, 100});
  MasterDriver d(m, 2);
  d.attach(kS, e);
  Results res;
  EXPECT_EQ(m.c2_read(kS, 0, 1, 2, res.cb()), 0u);  // no connection yet
  ASSERT_NE(m.c2_initiate(kS, res.cb()), 0u);
  ASSERT_NE(m.c2_read(kS, 0, 1, 4, res.cb()), 0u);  // queued behind the initiate
  const Bytes rec{0x11, 0x22};
  ASSERT_NE(m.c2_write(kS, 1, 2, rec, res.cb()), 0u);
  EXPECT_EQ(m.c2_initiate(kS, res.cb()), 0u);  // already opening

  d.token();
  // Initiate.req to the resource manager (DSAP 49 = 0x31, SSAP 50 = 0x32), 20 octets:
  // 8A+82+6D+31+32+57+64+01+02+02 = 29C.
  EXPECT_EQ(d.next(),
            "68 19 19 68 8A 82 6D 31 32 57 00 00 00 00 64 01 00 00 00 00 00 00 02 00 02 00 00 00 "
            "00 9C 16");
  d.deliver();
  EXPECT_EQ(hex(d.reply_data), "56 30 00 64");  // connection SAP 48, Send_Timeout 100
  // The same Initiate.req to SAP 48: 8A+82+5D+30+32+57+64+01+02+02 = 28B.
  EXPECT_EQ(d.next(),
            "68 19 19 68 8A 82 5D 30 32 57 00 00 00 00 64 01 00 00 00 00 00 00 02 00 02 00 00 00 "
            "00 8B 16");
  d.deliver();
  ASSERT_EQ(res.all.size(), 1u);
  EXPECT_EQ(res.all[0].status, AcyclicStatus::Ok);
  EXPECT_EQ(res.all[0].c2_sap, 48);
  EXPECT_EQ(res.all[0].max_len_data_unit, 240);
  EXPECT_EQ(res.all[0].features_1, 0x01);
  EXPECT_TRUE(m.c2_open(kS));
  // Read slot 0 index 1, 4 octets: 8A+82+7D+30+32+5E+00+01+04 = 24E.
  EXPECT_EQ(d.next(), "68 09 09 68 8A 82 7D 30 32 5E 00 01 04 4E 16");
  d.deliver();
  ASSERT_EQ(res.all.size(), 2u);
  EXPECT_EQ(res.all[1].status, AcyclicStatus::Ok);
  EXPECT_EQ(hex(res.all[1].data), "AB CD");
  // Write slot 1 index 2 (8 octets with the SAPs: SD3): 8A+82+5D+30+32+5F+01+02+02+11+22 = 262.
  EXPECT_EQ(d.next(), "A2 8A 82 5D 30 32 5F 01 02 02 11 22 62 16");
  d.deliver();
  ASSERT_EQ(res.all.size(), 3u);
  EXPECT_EQ(res.all[2].status, AcyclicStatus::Ok);
  EXPECT_EQ(written, rec);
  EXPECT_EQ(d.next(), "");

  // Unknown record: negative response decoded.
  m.c2_read(kS, 0, 9, 4, res.cb());
  drain(d, m);
  ASSERT_EQ(res.all.size(), 4u);
  EXPECT_EQ(res.all[3].status, AcyclicStatus::Negative);
  EXPECT_EQ(res.all[3].error, (Dpv1Error{0x80, 0xB0, 0x00}));
  EXPECT_EQ(hex(res.all[3].data), "DE 80 B0 00");

  // Abort: 58 00 20 00 (8A+82+5D+30+32+58+00+20+00 = 243, FCB after the read's 7D).
  ASSERT_NE(m.c2_abort(kS, res.cb()), 0u);
  d.token();
  EXPECT_EQ(d.next(), "68 09 09 68 8A 82 5D 30 32 58 00 20 00 43 16");
  d.deliver();
  ASSERT_EQ(res.all.size(), 5u);
  EXPECT_EQ(res.all[4].status, AcyclicStatus::Ok);
  EXPECT_FALSE(m.c2_open(kS));
  EXPECT_EQ(m.c2_read(kS, 0, 1, 2, res.cb()), 0u);
  // The slave's connection SAP is closed again: a request there gets RS.
  Harness h(e);
  h.req(2, kS, 48, {0x5E, 0x00, 0x01, 0x02});
  EXPECT_EQ(h.last.kind, fdl::Reply::Kind::Status);
}

TEST(DpClass2, MsacC2PendingAnswerIsPolledWithIdle) {
  SlaveEngine e(slave_config(true));
  std::uint32_t call = 0;
  e.application().on_read(0, 1, [&](const RecordCall& c, std::span<std::uint8_t>) {
    call = c.id;
    return RecordResult::pending();
  });
  Class2Master m({2, 100});
  MasterDriver d(m, 2);
  d.attach(kS, e);
  Results res;
  m.c2_initiate(kS, res.cb());
  m.c2_read(kS, 0, 1, 2, res.cb());
  d.token();
  d.next();
  d.deliver();  // RM
  d.next();
  d.deliver();  // Initiate
  d.next();
  d.deliver();  // Read → SC (pending)
  EXPECT_EQ(d.next(), "");  // the poll waits for the next visit
  d.token();
  // Idle poll 48 00: 8A+82+5D+30+32+48+00 = 213.
  EXPECT_EQ(d.next(), "68 07 07 68 8A 82 5D 30 32 48 00 13 16");
  d.deliver();  // still SC
  EXPECT_EQ(d.next(), "");
  const Bytes data{0x01, 0x02};
  e.application().complete_read(call, data);
  d.token();
  EXPECT_EQ(d.next(), "68 07 07 68 8A 82 7D 30 32 48 00 33 16");  // 213 + 20
  d.deliver();
  ASSERT_EQ(res.all.size(), 2u);
  EXPECT_EQ(res.all[1].status, AcyclicStatus::Ok);
  EXPECT_EQ(hex(res.all[1].data), "01 02");
}

TEST(DpClass2, MsacC2KeepAliveAndTimeout) {
  SlaveEngine e(slave_config(true));
  e.application().on_read(0, 1, [&](const RecordCall&, std::span<std::uint8_t>) {
    return RecordResult::pending();
  });
  Class2Master m({2, 10});  // Send_Timeout 100 ms
  MasterDriver d(m, 2);
  d.attach(kS, e);
  Results res;
  m.c2_initiate(kS, res.cb());
  drain(d, m);
  ASSERT_TRUE(m.c2_open(kS));
  // Nothing to do: an Idle goes out once 50 ms have passed since the last frame.
  d.now += 49 * bus::kTicksPerMs;
  d.token();
  EXPECT_EQ(d.next(), "");
  d.now += 2 * bus::kTicksPerMs;
  d.token();
  EXPECT_EQ(d.next(), "68 07 07 68 8A 82 7D 30 32 48 00 33 16");
  d.deliver();
  EXPECT_EQ(d.next(), "");
  EXPECT_TRUE(m.c2_open(kS));
  // A read that stays pending times out after Send_Timeout and closes the connection.
  m.c2_read(kS, 0, 1, 2, res.cb());
  for (int i = 0; i < 30 && m.pending() > 0; ++i) {
    d.visit();
    d.now += 10 * bus::kTicksPerMs;
  }
  ASSERT_EQ(res.all.size(), 2u);
  EXPECT_EQ(res.all[1].status, AcyclicStatus::Timeout);
  EXPECT_FALSE(m.c2_open(kS));
}

TEST(DpClass2, InitiateRefusedByResourceManager) {
  SlaveConfig c = slave_config(true);
  c.features.c2_connections = 1;
  SlaveEngine e(c);
  // Another class-2 master (address 3) holds the only connection.
  Harness h(e);
  Class2Master other({3, 100});
  h.req(3, kS, kSapC2ResourceManager, other.initiate_pdu());
  ASSERT_EQ(hex(h.last.data), "56 30 00 64");
  Class2Master m({2, 100});
  MasterDriver d(m, 2);
  d.attach(kS, e);
  Results res;
  m.c2_initiate(kS, res.cb());
  drain(d, m);
  ASSERT_EQ(res.all.size(), 1u);
  EXPECT_EQ(res.all[0].status, AcyclicStatus::Negative);
  EXPECT_EQ(describe(res.all[0].error), "DP-V1 resource: resource unavailable (C3), code 2 00");
  EXPECT_FALSE(m.c2_open(kS));
}

}  // namespace
}  // namespace pbvbus::dp
