// HSystemModel::read_ssl: the SSL partial lists of SFC 51 (h_ssl.hpp has the layouts and the
// decisions). Every expected octet is derived here from the documented layout.
#include "h_system_fixture.hpp"

namespace pbvbus::devices {
namespace {

// Fixture timing (h_system_fixture.hpp): both CPUs on at 12 ms, Solo at 1.012 s, the standby's
// UPDATE at 3.012 s, Redundant at 3.012 s + 145 ms = 3.157 s; bring_up() runs to 3.457 s.

Bytes header(std::uint16_t lenthdr, std::uint16_t n_dr) {
  return {static_cast<std::uint8_t>(lenthdr >> 8), static_cast<std::uint8_t>(lenthdr),
          static_cast<std::uint8_t>(n_dr >> 8), static_cast<std::uint8_t>(n_dr)};
}
Bytes cat(Bytes a, const Bytes& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}
/// The xy71 record: redinf 0012, mwstat1, mwstat2, hsfcinfo 0, samfehl 0, bz_cpu_0, bz_cpu_1,
/// bz_cpu_2 0, cpu_valid, byte 15 = 0.
Bytes h_state(std::uint8_t mw1, std::uint8_t mw2, std::uint16_t bz0, std::uint16_t bz1,
              std::uint8_t valid) {
  return {0x00, 0x12, mw1, mw2, 0, 0, 0, 0, static_cast<std::uint8_t>(bz0 >> 8),
          static_cast<std::uint8_t>(bz0), static_cast<std::uint8_t>(bz1 >> 8),
          static_cast<std::uint8_t>(bz1), 0, 0, valid, 0};
}

TEST(HSsl, HStateRecordRedundantSoloAndLinkCut) {
  HSys s;
  s.bring_up();
  SslResult r = s.h->read_ssl(0x0071, 0);
  ASSERT_EQ(r.ret_val, 0);
  // Redundant: rack 0 master (mwstat1 bit 4 = 0x10); mwstat2 bit 0 (sync possible) = 0x01, bits
  // 4/5 are 0 in redundant mode; both CPUs RUN-R W#16#0009; cpu_valid 0x03 (link whole).
  EXPECT_EQ(r.data, cat(header(0x0010, 1), h_state(0x10, 0x01, 0x0009, 0x0009, 0x03)));
  // Standby to STOP at 5 s: Solo; mwstat2 = 0x01 | 0x10 | 0x20 = 0x31; RUN (solo) 0008, STOP
  // (internal) 0004.
  s.at(5000 * kMs);
  s.h->switch_to_stop(1);
  r = s.h->read_ssl(0x0071, 0);
  EXPECT_EQ(r.data, cat(header(0x0010, 1), h_state(0x10, 0x31, 0x0008, 0x0004, 0x03)));
  // One fibre cut at 6 s: no synchronisation possible (bit 0 = 0: 0x30) and the partner's
  // state is not known over the link: cpu_valid = 0x01 (rack 0 answers).
  s.at(6000 * kMs);
  s.h->cut_fibre(0);
  r = s.h->read_ssl(0x0071, 0);
  EXPECT_EQ(r.data, cat(header(0x0010, 1), h_state(0x10, 0x30, 0x0008, 0x0004, 0x01)));
  EXPECT_EQ(s.h->read_ssl(0x0071, 1).ret_val, kRetSslIndex);
  EXPECT_TRUE(s.h->read_ssl(0x0071, 1).data.empty());
  r = s.h->read_ssl(0x0F71, 0);  // header only
  EXPECT_EQ(r.ret_val, 0);
  EXPECT_EQ(r.data, header(0x0010, 1));
}

TEST(HSsl, DuringTheUpdate8085AndUnknownId8082) {
  HSys s;
  s.at(kT0);
  s.h->power_on_both();
  s.at(kUpdate + 1 * kMs);  // inside [t1, t5)
  EXPECT_EQ(s.h->read_ssl(0x0071, 0).ret_val, 0x8085);
  EXPECT_EQ(s.h->read_ssl(0x0222, 72).ret_val, 0x8085);
  s.at(kRedundant);
  EXPECT_EQ(s.h->read_ssl(0x0071, 0).ret_val, 0);
  EXPECT_EQ(s.h->read_ssl(0x0011, 0).ret_val, 0x8082);
}

TEST(HSsl, Protection0232Index4ByteZeroF8F1InRedundantF8Solo) {
  HSys s;
  s.bring_up();
  // Record (19 words): index (byte 0 = 1111 b3=master b2..0=rack, byte 1 = 04), sch_schal 1,
  // sch_par 0, sch_rel 1, bart_sch 1 (RUN), anl_sch 0, ken_rel + 4 ken_ver + 8 res = 13 zero words.
  const auto rec = [](std::uint8_t id, std::uint8_t bart) {
    Bytes b{id, 0x04, 0, 1, 0, 0, 0, 1, 0, bart, 0, 0};
    b.insert(b.end(), 26, 0);
    return b;
  };
  SslResult r = s.h->read_ssl(0x0232, 4);
  ASSERT_EQ(r.ret_val, 0);
  // Redundant: the master's first: F8 (master, rack 0) + F1 (standby, rack 1).
  EXPECT_EQ(r.data, cat(cat(header(38, 2), rec(0xF8, 1)), rec(0xF1, 1)));
  // F1 at 5 s: CPU 1 master alone (Solo): F9 only.
  s.at(5000 * kMs);
  s.h->power_off(0);
  r = s.h->read_ssl(0x0232, 4);
  EXPECT_EQ(r.data, cat(header(38, 1), rec(0xF9, 1)));
  EXPECT_EQ(s.h->read_ssl(0x0232, 5).ret_val, kRetSslIndex);
}

TEST(HSsl, LedsOneLedPerCpuInRedundantAllLedsInSolo) {
  HSys s;
  s.bring_up();
  // 0174 REDF (0D) in Redundant: one record per CPU, rack 0 first: REDF off (00 00).
  SslResult r = s.h->read_ssl(0x0174, 0x0D);
  EXPECT_EQ(r.data, cat(header(4, 2), Bytes{0xF8, 0x0D, 0, 0, 0xF1, 0x0D, 0, 0}));
  r = s.h->read_ssl(0x0174, 0x0E);  // MSTR: on on the master only
  EXPECT_EQ(r.data, cat(header(4, 2), Bytes{0xF8, 0x0E, 1, 0, 0xF1, 0x0E, 0, 0}));
  EXPECT_EQ(s.h->read_ssl(0x0019, 0).ret_val, 0x8085);  // non-redundant modes only
  EXPECT_EQ(s.h->read_ssl(0x0174, 0x04).ret_val, kRetSslIndex);  // RUN LED: not modelled
  // Standby to STOP at 5 s (Solo): 0019 = the master's BUS1F 0B off, REDF 0D on, MSTR 0E on,
  // RACK0 0F on, RACK1 10 off, IFM1F 12 off, IFM2F 13 off: 7 records.
  s.at(5000 * kMs);
  s.h->switch_to_stop(1);
  r = s.h->read_ssl(0x0019, 0);
  ASSERT_EQ(r.ret_val, 0);
  EXPECT_EQ(r.data, cat(header(4, 7), Bytes{0xF8, 0x0B, 0, 0, 0xF8, 0x0D, 1, 0, 0xF8, 0x0E, 1, 0,
                                            0xF8, 0x0F, 1, 0, 0xF8, 0x10, 0, 0, 0xF8, 0x12, 0, 0,
                                            0xF8, 0x13, 0, 0}));
  // STOP -> RUN at 6 s: LINK-UP 6 s .. 8 s: REDF flashes 0.5 Hz: led_on 0, led_blink 2.
  s.at(6000 * kMs);
  s.h->switch_to_run(1);
  s.at(7000 * kMs);
  r = s.h->read_ssl(0x0174, 0x0D);
  EXPECT_EQ(r.data, cat(header(4, 1), Bytes{0xF8, 0x0D, 0, 2}));
  // Fibre 1 (lower) cut at 9 s... first wait for Redundant (8 s + 145 ms), then IFM2F on both.
  s.at(9000 * kMs);
  s.h->cut_fibre(1);
  r = s.h->read_ssl(0x0174, 0x13);  // Solo now: the master's record only
  EXPECT_EQ(r.data, cat(header(4, 1), Bytes{0xF8, 0x13, 1, 0}));
}

TEST(HSsl, SwitchedSlave0C75NamesTheRackOfTheActiveChannel) {
  HSys s;
  s.bring_up();
  // INDEX = (DP master system ID 1 << 8) | station 5 = 0x0105; adr1_bgt0 = 0x0105 while line A
  // (rack 0) is active, adr1_bgt1 = 0; logadr = 0x0105.
  SslResult r = s.h->read_ssl(0x0C75, 0x0105);
  ASSERT_EQ(r.ret_val, 0);
  EXPECT_EQ(r.data, cat(header(0x0010, 1),
                        Bytes{0x01, 0x05, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x01, 0x05, 0, 0}));
  // F1 at 5 s: the stations switch to line B (rack 1).
  s.at(5000 * kMs);
  s.h->power_off(0);
  s.at(6000 * kMs);
  ASSERT_EQ(s.ms().active(kFast), 1);
  r = s.h->read_ssl(0x0C75, 0x0105);
  EXPECT_EQ(r.data, cat(header(0x0010, 1),
                        Bytes{0, 0, 0, 0, 0x01, 0x05, 0, 0, 0, 0, 0, 0, 0x01, 0x05, 0, 0}));
  EXPECT_EQ(s.h->read_ssl(0x0C75, 0x010A).ret_val, kRetSslIndex);  // one-sided station 10
  EXPECT_EQ(s.h->read_ssl(0x0C75, 0x0205).ret_val, kRetSslIndex);  // no DP master system 2
  EXPECT_EQ(s.h->read_ssl(0x0C75, 0x0007).ret_val, kRetSslIndex);  // system ID 0
}

TEST(HSsl, Interrupt0222StartInfoOfTheLastOb70AndOb72) {
  HSys s;
  s.bring_up();
  // 28 bytes: EV_CLASS/FLT_ID, priority 0, OB number, 16 zero bytes, al 1 = 0010, 6 zeros.
  const auto rec = [](std::uint16_t id, std::uint8_t ob) {
    Bytes b{static_cast<std::uint8_t>(id >> 8), static_cast<std::uint8_t>(id), 0, ob};
    b.insert(b.end(), 16, 0);
    b.push_back(0x00);
    b.push_back(0x10);
    b.insert(b.end(), 6, 0);
    return b;
  };
  // Nothing yet: event 0.
  EXPECT_EQ(s.h->read_ssl(0x0222, 70).data, cat(header(0x001C, 1), rec(0, 70)));
  // The line-A interface of station 5 fails at 5 s: OB 70 W#16#73A3.
  s.at(5000 * kMs);
  s.station(kFast).fail_interface(0);
  s.at(6000 * kMs);
  EXPECT_EQ(s.h->read_ssl(0x0222, 70).data, cat(header(0x001C, 1), rec(0x73A3, 70)));
  // W#16#0048 is the redundancy class = OB 72; after F1 its event ID is 0 (none in the seeds).
  s.h->power_off(1);
  EXPECT_EQ(s.h->read_ssl(0x0222, 0x0048).data, cat(header(0x001C, 1), rec(0, 72)));
  EXPECT_EQ(s.h->read_ssl(0x0222, 1).ret_val, kRetSslIndex);
}

}  // namespace
}  // namespace pbvbus::devices
