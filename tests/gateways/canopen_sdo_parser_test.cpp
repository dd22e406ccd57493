// The SDO request parser and response encoders (canopen_sdo.hpp), and the object dictionary
// behind them (canopen_objects.hpp). Golden octets are worked out by hand from CiA 301 §7.2.4.3:
// octet 0 is the command specifier, 1..2 the index little endian, 3 the sub-index, 4..7 data.
// Also built into sanitize_gateways (ASan+UBSan): every malformed input is tried.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "hex.hpp"
#include "pbvbus/gateways/canopen_objects.hpp"
#include "pbvbus/gateways/canopen_sdo.hpp"

namespace pbvbus::gateways::canopen {
namespace {

using test::bytes_from_hex;
using test::to_hex;

SdoRequest parse(std::string_view hex) {
  const auto b = bytes_from_hex(hex);
  return parse_sdo_request(b);
}

TEST(CanopenSdoParser, InitiateUpload) {
  // 0x40 = ccs 2 (010 in bits 7..5), reserved bits 0; index 0x1018 → 18 10; sub 2.
  const auto r = parse("40 18 10 02 00 00 00 00");
  EXPECT_EQ(r.kind, SdoRequestKind::Upload);
  EXPECT_EQ(r.index, 0x1018);
  EXPECT_EQ(r.sub, 2);
}

TEST(CanopenSdoParser, ExpeditedDownloadSizes) {
  // ccs 1 (001), n in bits 3..2, e = bit 1, s = bit 0: 0x2F = 001 0 11 1 1 → n = 3, 1 octet;
  // 0x2B → n = 2, 2 octets; 0x27 → n = 1, 3 octets; 0x23 → n = 0, 4 octets.
  auto r = parse("2F 17 10 00 11 22 33 44");
  EXPECT_EQ(r.kind, SdoRequestKind::Download);
  EXPECT_EQ(r.size, 1);
  EXPECT_EQ(r.value, 0x11u);  // only the data octets count
  r = parse("2B 17 10 00 E8 03 FF FF");
  EXPECT_EQ(r.size, 2);
  EXPECT_EQ(r.value, 0x03E8u);
  r = parse("27 17 10 00 01 02 03 04");
  EXPECT_EQ(r.size, 3);
  EXPECT_EQ(r.value, 0x030201u);
  r = parse("23 17 10 00 01 02 03 04");
  EXPECT_EQ(r.size, 4);
  EXPECT_EQ(r.value, 0x04030201u);
  // 0x22 = e = 1, s = 0: size not indicated, all four octets are read.
  r = parse("22 17 10 00 F4 01 00 00");
  EXPECT_EQ(r.kind, SdoRequestKind::Download);
  EXPECT_EQ(r.size, 0);
  EXPECT_EQ(r.value, 0x01F4u);
}

TEST(CanopenSdoParser, UnsupportedTransfersAreInvalidWithCommandSpecifierAbort) {
  // 0x21 = initiate download, e = 0, s = 1: segmented. 0x00/0x10 download segment, 0x60/0x70
  // upload segment (no transfer open), 0xA0 block upload, 0xC0 block download, 0xE0 ccs 7.
  for (const char* hex : {"21 17 10 00 02 00 00 00", "00 17 10 00 00 00 00 00",
                          "10 17 10 00 00 00 00 00", "60 17 10 00 00 00 00 00",
                          "70 00 00 00 00 00 00 00", "A0 17 10 00 00 00 00 00",
                          "C6 17 10 00 02 00 00 00", "E0 17 10 00 00 00 00 00"}) {
    const auto r = parse(hex);
    EXPECT_EQ(r.kind, SdoRequestKind::Invalid) << hex;
    EXPECT_EQ(r.abort, kAbortCommandSpecifier) << hex;
  }
  // The index/sub of the request are kept for the abort's multiplexer.
  const auto r = parse("21 17 10 00 02 00 00 00");
  EXPECT_EQ(r.index, 0x1017);
  EXPECT_EQ(r.sub, 0);
}

TEST(CanopenSdoParser, ClientAbort) {
  // ccs 4 = 0x80, abort code 0x05040000 (SDO timeout) LE.
  const auto r = parse("80 00 20 01 00 00 04 05");
  EXPECT_EQ(r.kind, SdoRequestKind::ClientAbort);
  EXPECT_EQ(r.index, 0x2000);
  EXPECT_EQ(r.sub, 1);
}

TEST(CanopenSdoParser, ShortFramesAreInvalidWithWhatMultiplexerIsThere) {
  EXPECT_EQ(parse("").kind, SdoRequestKind::Invalid);
  EXPECT_EQ(parse("").index, 0);
  auto r = parse("40 18");
  EXPECT_EQ(r.kind, SdoRequestKind::Invalid);
  EXPECT_EQ(r.abort, kAbortCommandSpecifier);
  EXPECT_EQ(r.index, 0x0018);  // high octet missing
  r = parse("40 18 10 02 00 00 00");  // 7 octets: an SDO frame is always 8
  EXPECT_EQ(r.kind, SdoRequestKind::Invalid);
  EXPECT_EQ(r.index, 0x1018);
  EXPECT_EQ(r.sub, 2);
}

TEST(CanopenSdoParser, EveryFirstOctetAndLengthIsHandled) {
  // No crash, and the kind follows the ccs for full frames.
  for (int cs = 0; cs < 256; ++cs) {
    for (std::size_t len = 0; len <= 8; ++len) {
      std::vector<std::uint8_t> d(len, 0xFF);
      if (len) d[0] = static_cast<std::uint8_t>(cs);
      const auto r = parse_sdo_request(d);
      if (len < 8) {
        EXPECT_EQ(r.kind, SdoRequestKind::Invalid);
        continue;
      }
      const int ccs = cs >> 5;
      const bool expedited_download = ccs == 1 && (cs & 0x02);
      const SdoRequestKind want = ccs == 2                ? SdoRequestKind::Upload
                                  : expedited_download    ? SdoRequestKind::Download
                                  : ccs == 4              ? SdoRequestKind::ClientAbort
                                                          : SdoRequestKind::Invalid;
      EXPECT_EQ(r.kind, want) << cs;
      if (want == SdoRequestKind::Invalid) {
        EXPECT_EQ(r.abort, kAbortCommandSpecifier) << cs;
      }
      if (want == SdoRequestKind::Download && r.size) {
        EXPECT_EQ(r.size, 4 - ((cs >> 2) & 3)) << cs;
      }
    }
  }
}

TEST(CanopenSdoEncode, UploadResponses) {
  // 0x43 | (4 - size) << 2: 4 → 0x43, 3 → 0x47, 2 → 0x4B, 1 → 0x4F. Data LE, rest 0.
  EXPECT_EQ(to_hex(sdo_upload_response(0x1018, 2, 0x0A03, 4)), "43 18 10 02 03 0A 00 00");
  EXPECT_EQ(to_hex(sdo_upload_response(0x1018, 2, 0x0A03, 2)), "4B 18 10 02 03 0A 00 00");
  EXPECT_EQ(to_hex(sdo_upload_response(0x2000, 1, 0x06, 1)), "4F 00 20 01 06 00 00 00");
  EXPECT_EQ(to_hex(sdo_upload_response(0x1234, 9, 0xAABBCC, 3)), "47 34 12 09 CC BB AA 00");
  // A value wider than its size is cut to the size.
  EXPECT_EQ(to_hex(sdo_upload_response(0x1001, 0, 0x1FF, 1)), "4F 01 10 00 FF 00 00 00");
}

TEST(CanopenSdoEncode, DownloadResponseAndAbort) {
  EXPECT_EQ(to_hex(sdo_download_response(0x1017, 0)), "60 17 10 00 00 00 00 00");
  // 0x06090011 LE = 11 00 09 06.
  EXPECT_EQ(to_hex(sdo_abort(0x1018, 5, kAbortNoSubIndex)), "80 18 10 05 11 00 09 06");
  EXPECT_EQ(to_hex(sdo_abort(0x3000, 0, kAbortNoObject)), "80 00 30 00 00 00 02 06");
}

// --- the object dictionary --------------------------------------------------------------------

struct CanopenDict : ::testing::Test {
  SourceSlave slave;
  NodeObjects node;
  void SetUp() override {
    slave.address = 5;
    slave.ident = 0x0A03;
    node.slave = &slave;
    node.status.state = dp::SlaveStatusState::DataExchange;
    node.status.data_valid = true;
    node.status.diag = {0x08, 0x0C, 0x00, 0x02, 0x0A, 0x03, 0x43, 0x01};
    node.status.data_exchanges = 0x1'2345'6789;  // the u32 object keeps the low 32 bits
    node.status.failures = 2;
    node.error_register = 0x81;
    node.heartbeat_ms = 1000;
  }
  std::string read(std::uint16_t i, std::uint8_t s) {
    const auto a = read_object(node, i, s);
    if (a.abort) return "abort " + std::to_string(a.abort);
    return std::to_string(a.size) + ":" + std::to_string(a.value);
  }
};

TEST_F(CanopenDict, StandardObjects) {
  EXPECT_EQ(read(0x1000, 0), "4:0");
  EXPECT_EQ(read(0x1001, 0), "1:129");  // 0x81
  EXPECT_EQ(read(0x1017, 0), "2:1000");
  EXPECT_EQ(read(0x1018, 0), "1:4");
  EXPECT_EQ(read(0x1018, 1), "4:0");
  EXPECT_EQ(read(0x1018, 2), "4:2563");  // 0x0A03
  EXPECT_EQ(read(0x1018, 3), "4:0");
  EXPECT_EQ(read(0x1018, 4), "4:5");
  EXPECT_EQ(read(0x1018, 5), "abort " + std::to_string(kAbortNoSubIndex));
  EXPECT_EQ(read(0x1000, 1), "abort " + std::to_string(kAbortNoSubIndex));
  EXPECT_EQ(read(0x1016, 0), "abort " + std::to_string(kAbortNoObject));
}

TEST_F(CanopenDict, StatusBlockAndDiagnosis) {
  EXPECT_EQ(read(0x2000, 0), "1:7");
  EXPECT_EQ(read(0x2000, 1), "1:6");       // DataExchange
  EXPECT_EQ(read(0x2000, 2), "1:3");       // data valid (bit 0) + ext diag (bit 1)
  EXPECT_EQ(read(0x2000, 3), "4:591751049");  // 0x23456789
  EXPECT_EQ(read(0x2000, 4), "2:2563");
  EXPECT_EQ(read(0x2000, 5), "1:255");     // not switched: 0xFF
  EXPECT_EQ(read(0x2000, 6), "4:2");
  EXPECT_EQ(read(0x2000, 7), "1:8");
  EXPECT_EQ(read(0x2000, 8), "abort " + std::to_string(kAbortNoSubIndex));
  EXPECT_EQ(read(0x2001, 0), "1:8");
  EXPECT_EQ(read(0x2001, 1), "1:8");
  EXPECT_EQ(read(0x2001, 7), "1:67");  // 0x43
  EXPECT_EQ(read(0x2001, 8), "1:1");
  EXPECT_EQ(read(0x2001, 9), "abort " + std::to_string(kAbortNoSubIndex));
  node.status.diag.clear();
  EXPECT_EQ(read(0x2001, 0), "1:0");
  EXPECT_EQ(read(0x2001, 1), "abort " + std::to_string(kAbortNoSubIndex));
}

TEST_F(CanopenDict, StateCodesAndFlags) {
  using S = dp::SlaveStatusState;
  const std::pair<S, int> codes[] = {{S::Inactive, 1},  {S::Diag, 2},         {S::Prm, 3},
                                     {S::Cfg, 4},       {S::CheckDiag, 5},    {S::DataExchange, 6},
                                     {S::NotPresent, 7}, {S::Locked, 8}};
  for (auto [s, c] : codes) EXPECT_EQ(dp_state_code(s), c);
  // Station_Status_1 0x45 = Station_Non_Existent (0x01) + Cfg_Fault (0x04) + Prm_Fault (0x40);
  // switched, redundancy lost, channel B: 0x04 | 0x10 | 0x08 | 0x20 | 0x40 | 0x80 = 0xFC.
  slave.switched = true;
  node.status = {};
  node.status.diag = {0x45, 0x04, 0x00};
  node.status.redundancy_lost = true;
  node.status.active_channel = 1;
  EXPECT_EQ(dp_status_flags(slave, node.status), 0xFC);
  EXPECT_EQ(read(0x2000, 5), "1:1");
  node.status.diag.clear();
  node.status.state = S::NotPresent;
  node.status.active_channel = 0;
  EXPECT_EQ(dp_status_flags(slave, node.status), 0x64);  // failure + switched + red. lost
}

TEST_F(CanopenDict, OnlyTheHeartbeatTimeIsWritable) {
  auto w = check_write(node, 0x1017, 0, 2, 500);
  EXPECT_EQ(w.abort, 0u);
  EXPECT_EQ(w.value, 500u);
  EXPECT_EQ(check_write(node, 0x1017, 0, 0, 0x12345).value, 0x2345u);  // size not indicated
  EXPECT_EQ(check_write(node, 0x1017, 0, 4, 500).abort, kAbortLength);
  EXPECT_EQ(check_write(node, 0x1017, 0, 1, 5).abort, kAbortLength);
  EXPECT_EQ(check_write(node, 0x1017, 1, 2, 5).abort, kAbortNoSubIndex);
  EXPECT_EQ(check_write(node, 0x1000, 0, 4, 5).abort, kAbortReadOnly);
  EXPECT_EQ(check_write(node, 0x2000, 1, 1, 5).abort, kAbortReadOnly);
  EXPECT_EQ(check_write(node, 0x2001, 9, 1, 5).abort, kAbortNoSubIndex);
  EXPECT_EQ(check_write(node, 0x6000, 0, 1, 5).abort, kAbortNoObject);
}

TEST(CanopenHeartbeatState, FromDpStateAndMasterMode) {
  using S = dp::SlaveStatusState;
  using M = dp::MasterMode;
  EXPECT_EQ(heartbeat_state(S::DataExchange, M::Operate), kStateOperational);
  EXPECT_EQ(heartbeat_state(S::DataExchange, M::Clear), kStatePreOperational);
  for (S s : {S::Diag, S::Prm, S::Cfg, S::CheckDiag})
    EXPECT_EQ(heartbeat_state(s, M::Operate), kStatePreOperational);
  EXPECT_EQ(heartbeat_state(S::Inactive, M::Stop), kStateStopped);
  EXPECT_EQ(heartbeat_state(S::DataExchange, M::Stop), kStateStopped);
  EXPECT_EQ(heartbeat_state(S::NotPresent, M::Operate), std::nullopt);
  EXPECT_EQ(heartbeat_state(S::NotPresent, M::Stop), std::nullopt);
  EXPECT_EQ(heartbeat_state(S::Locked, M::Clear), std::nullopt);
  EXPECT_EQ(heartbeat_state(S::Inactive, M::Operate), std::nullopt);
  EXPECT_EQ(heartbeat_state(S::Inactive, M::Offline), std::nullopt);
}

}  // namespace
}  // namespace pbvbus::gateways::canopen
