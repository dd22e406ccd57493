// PrmCmd, Prm_Cmd_Ack and Red_Status codecs (protocol-facts.md §G.2, §G.3). Golden octets are
// written out by hand from the reference tables, not produced by the encoder. Also runs under
// ASan+UBSan (sanitize_redundancy): every malformed input is an error value, never a crash.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "pbvbus/redundancy/prm_cmd.hpp"
#include "pbvbus/redundancy/red_status.hpp"

namespace pbvbus::redundancy {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes enc(const PrmCmd& c) {
  std::array<std::uint8_t, kPrmCmdLen> o{};
  EXPECT_EQ(encode_prm_cmd(c, o), PrmCmdError::None);
  return {o.begin(), o.end()};
}
Bytes enc(const RedStatusBlock& r) {
  std::array<std::uint8_t, kRedStatusLen> o{};
  EXPECT_EQ(encode_red_status(r, o), RedStatusError::None);
  return {o.begin(), o.end()};
}

TEST(PrmCmdCodec, GoldenPrimaryRequest) {
  // Primary_Request, Seq_Nr 1, system redundancy (Properties Address_Change = bit 2 = 0x04),
  // Output_Hold_Time 300 ms = 30 × 10 ms = 0x001E:
  //   08 Structure_Length, 02 PrmCmd, 00 slot,
  //   specifier octet = Seq_Nr 1 << 3 = 0x08 (bits 1..0 = 0, bit 2 reserved),
  //   Function = Primary_Request bit 1 = 0x02, Properties = 0x04, 00 1E big-endian.
  const Bytes golden{0x08, 0x02, 0x00, 0x08, 0x02, 0x04, 0x00, 0x1E};
  PrmCmd c;
  c.seq_nr = 1;
  c.primary_request = true;
  c.address_change = true;
  c.output_hold_time = 30;
  EXPECT_EQ(enc(c), golden);
  PrmCmd d;
  ASSERT_EQ(decode_prm_cmd(golden, d), PrmCmdError::None);
  EXPECT_EQ(d, c);
  EXPECT_EQ(d.output_hold_ticks(), 300 * bus::kTicksPerMs);
}

TEST(PrmCmdCodec, GoldenEveryFunctionAndPropertyBit) {
  // Seq_Nr 31, Specifier 3 → 31 << 3 | 3 = 0xF8 | 0x03 = 0xFB.
  // Function: Primary_Request 0x02 | Start_MSAC1S 0x08 | Check_Properties 0x10 |
  //           Master_State_Clear 0x40 = 0x5A.
  // Properties: 0x01 | 0x02 | 0x04 | 0x08 = 0x0F (flying redundancy, all "used" bits).
  // Output_Hold_Time 655.35 s = 65535 × 10 ms = FF FF.
  const Bytes golden{0x08, 0x02, 0x00, 0xFB, 0x5A, 0x0F, 0xFF, 0xFF};
  PrmCmd d;
  ASSERT_EQ(decode_prm_cmd(golden, d), PrmCmdError::None);
  EXPECT_EQ(d.seq_nr, 31);
  EXPECT_EQ(d.specifier, 3);
  EXPECT_TRUE(d.primary_request && d.start_msac1s && d.check_properties && d.master_state_clear);
  EXPECT_FALSE(d.stop_msac1s);
  EXPECT_TRUE(d.primary_req_ms0_ms1_used && d.start_stop_msac1s_used && d.address_change &&
              d.address_offset64);
  EXPECT_EQ(d.output_hold_time, 65535);
  EXPECT_EQ(enc(d), golden);
  // Stop_MSAC1S alone: Function 0x04; Master_State_Clear alone 0x40; hold 0.
  const Bytes stop{0x08, 0x02, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00};
  ASSERT_EQ(decode_prm_cmd(stop, d), PrmCmdError::None);
  EXPECT_TRUE(d.stop_msac1s);
  EXPECT_FALSE(d.primary_request);
  const Bytes msc{0x08, 0x02, 0x00, 0x10, 0x40, 0x00, 0x01, 0x00};  // Seq_Nr 2, hold 2.56 s
  ASSERT_EQ(decode_prm_cmd(msc, d), PrmCmdError::None);
  EXPECT_EQ(d.seq_nr, 2);
  EXPECT_TRUE(d.master_state_clear);
  EXPECT_EQ(d.output_hold_time, 256);
}

TEST(PrmCmdCodec, MalformedBlocks) {
  PrmCmd d;
  const Bytes good{0x08, 0x02, 0x00, 0x08, 0x02, 0x04, 0x00, 0x1E};
  for (std::size_t n = 0; n < good.size(); ++n)
    EXPECT_EQ(decode_prm_cmd(std::span(good).first(n), d), PrmCmdError::TooShort) << n;
  Bytes longer = good;
  longer.push_back(0);
  EXPECT_EQ(decode_prm_cmd(longer, d), PrmCmdError::TooLong);
  auto with = [&](std::size_t i, std::uint8_t v) {
    Bytes b = good;
    b[i] = v;
    return decode_prm_cmd(b, d);
  };
  EXPECT_EQ(with(0, 0x07), PrmCmdError::BadStructureLength);
  EXPECT_EQ(with(0, 0x09), PrmCmdError::BadStructureLength);
  EXPECT_EQ(with(1, 0x03), PrmCmdError::BadStructureType);
  EXPECT_EQ(with(1, 0x81), PrmCmdError::BadStructureType);
  EXPECT_EQ(with(2, 0x01), PrmCmdError::BadSlot);
  EXPECT_EQ(with(3, 0x0C), PrmCmdError::ReservedBits);  // specifier bit 2
  for (int bit : {0x01, 0x20, 0x80})           // Function bits 0, 5, 7
    EXPECT_EQ(with(4, static_cast<std::uint8_t>(0x02 | bit)), PrmCmdError::ReservedBits) << bit;
  for (int bit : {0x10, 0x20, 0x40, 0x80})     // Properties bits 4..7
    EXPECT_EQ(with(5, static_cast<std::uint8_t>(0x04 | bit)), PrmCmdError::ReservedBits) << bit;
  EXPECT_EQ(with(4, 0x0C), PrmCmdError::Msac1sConflict);  // Stop 0x04 + Start 0x08
  // The encoder refuses what the decoder would not read back.
  std::array<std::uint8_t, kPrmCmdLen> o{};
  PrmCmd c;
  c.seq_nr = 32;
  EXPECT_EQ(encode_prm_cmd(c, o), PrmCmdError::BadSeqNr);
  c = {};
  c.specifier = 4;
  EXPECT_EQ(encode_prm_cmd(c, o), PrmCmdError::BadSpecifier);
  c = {};
  c.stop_msac1s = c.start_msac1s = true;
  EXPECT_EQ(encode_prm_cmd(c, o), PrmCmdError::Msac1sConflict);
  for (auto e : {PrmCmdError::None, PrmCmdError::TooShort, PrmCmdError::BadSpecifier})
    EXPECT_FALSE(to_string(e).empty());
}

TEST(PrmCmdCodec, RoundTripEveryValidSpecifierFunctionProperty) {
  for (unsigned spec = 0; spec < 256; ++spec) {
    if (spec & kSpecReserved) continue;
    for (unsigned fn = 0; fn < 256; ++fn) {
      if ((fn & kFnReserved) || ((fn & kFnStopMsac1s) && (fn & kFnStartMsac1s))) continue;
      const Bytes b{0x08, 0x02, 0x00, static_cast<std::uint8_t>(spec),
                    static_cast<std::uint8_t>(fn), static_cast<std::uint8_t>(spec & 0x0F),
                    static_cast<std::uint8_t>(fn), static_cast<std::uint8_t>(spec)};
      PrmCmd d;
      ASSERT_EQ(decode_prm_cmd(b, d), PrmCmdError::None);
      ASSERT_EQ(enc(d), b);
    }
  }
}

TEST(RedStatusCodec, GoldenPrmCmdAckAndRedStatus) {
  // Prm_Cmd_Ack to the Primary_Request above (Seq_Nr 1 → 0x08, Function 0x02) from the interface
  // that is now primary and in data exchange: Red_State_1 = Primary 0x02 | Data_Exchange 0x08
  // = 0x0A; its partner is backup in data exchange: Backup 0x01 | Data_Exchange 0x08 = 0x09.
  const Bytes ack{0x08, 0x9E, 0x00, 0x08, 0x02, 0x0A, 0x09, 0x00};
  RedStatusBlock r;
  r.type = kStatusPrmCmdAck;
  r.seq_nr = 1;
  r.function = kFnPrimaryRequest;
  r.own.primary = r.own.data_exchange = true;
  r.partner.backup = r.partner.data_exchange = true;
  EXPECT_EQ(enc(r), ack);
  RedStatusBlock d;
  ASSERT_EQ(decode_red_status(ack, d), RedStatusError::None);
  EXPECT_EQ(d, r);
  // Red_Status of the backup during a hold: Backup 0x01 | Data_Exchange 0x08 | Baudrate_found
  // 0x20 = 0x29; partner Primary 0x02 | Output_Hold_Time started 0x40 | Master_State_Clear
  // 0x10 | Hardware_defective 0x04 = 0x56.
  const Bytes st{0x08, 0x9F, 0x00, 0x00, 0x00, 0x29, 0x56, 0x00};
  ASSERT_EQ(decode_red_status(st, d), RedStatusError::None);
  EXPECT_EQ(d.type, kStatusRedStatus);
  EXPECT_TRUE(d.own.backup && d.own.data_exchange && d.own.baudrate_found);
  EXPECT_FALSE(d.own.primary);
  EXPECT_TRUE(d.partner.primary && d.partner.output_hold_started &&
              d.partner.master_state_clear && d.partner.hardware_defective);
  EXPECT_EQ(enc(d), st);
  EXPECT_EQ(d.data(), (std::array<std::uint8_t, 4>{0x00, 0x29, 0x56, 0x00}));
}

TEST(RedStatusCodec, MalformedBlocks) {
  RedStatusBlock d;
  const Bytes good{0x08, 0x9E, 0x00, 0x08, 0x02, 0x0A, 0x09, 0x00};
  for (std::size_t n = 0; n < good.size(); ++n)
    EXPECT_EQ(decode_red_status(std::span(good).first(n), d), RedStatusError::TooShort);
  Bytes longer = good;
  longer.push_back(0);
  EXPECT_EQ(decode_red_status(longer, d), RedStatusError::TooLong);
  auto with = [&](std::size_t i, std::uint8_t v) {
    Bytes b = good;
    b[i] = v;
    return decode_red_status(b, d);
  };
  EXPECT_EQ(with(0, 0x07), RedStatusError::BadHeader);
  EXPECT_EQ(with(0, 0x48), RedStatusError::BadHeader);  // identifier-related header
  EXPECT_EQ(with(1, 0x80), RedStatusError::BadType);    // VIPA's type: not PI
  EXPECT_EQ(with(1, 0x81), RedStatusError::BadType);
  EXPECT_EQ(with(2, 0x01), RedStatusError::BadSlot);
  EXPECT_EQ(with(3, 0x0C), RedStatusError::ReservedBits);
  EXPECT_EQ(with(4, 0x82), RedStatusError::ReservedBits);
  EXPECT_EQ(with(5, 0x8A), RedStatusError::ReservedBits);
  EXPECT_EQ(with(6, 0x89), RedStatusError::ReservedBits);
  EXPECT_EQ(with(7, 0x01), RedStatusError::ReservedBits);
  EXPECT_EQ(with(5, 0x03), RedStatusError::PrimaryAndBackup);
  EXPECT_EQ(with(6, 0x0B), RedStatusError::PrimaryAndBackup);
  std::array<std::uint8_t, kRedStatusLen> o{};
  RedStatusBlock r;
  r.type = 0x80;
  EXPECT_EQ(encode_red_status(r, o), RedStatusError::BadType);
  r = {};
  r.seq_nr = 32;
  EXPECT_EQ(encode_red_status(r, o), RedStatusError::BadSeqNr);
  r = {};
  r.own.primary = r.own.backup = true;
  EXPECT_EQ(encode_red_status(r, o), RedStatusError::PrimaryAndBackup);
  r = {};
  r.function = 0x01;
  EXPECT_EQ(encode_red_status(r, o), RedStatusError::ReservedBits);
  EXPECT_EQ(to_string(RedStatusError::PrimaryAndBackup), "Red_State both Primary and Backup");
}

TEST(RedStatusCodec, RoundTripEveryRedState) {
  for (unsigned own = 0; own < 0x80; ++own) {
    if ((own & 3) == 3) continue;
    for (unsigned partner = 0; partner < 0x80; partner += 5) {
      if ((partner & 3) == 3) continue;
      const Bytes b{0x08, 0x9F, 0x00, 0x53, 0x40, static_cast<std::uint8_t>(own),
                    static_cast<std::uint8_t>(partner), 0x00};
      RedStatusBlock d;
      ASSERT_EQ(decode_red_status(b, d), RedStatusError::None);
      ASSERT_EQ(enc(d), b);
    }
  }
}

TEST(RedundancyCodecs, SeededMutationsNeverCrashAndRoundTrip) {
  // Mutate valid blocks (bit flips, truncation, extension, random octets) and check the oracle:
  // whatever decodes re-encodes to the same octets; nothing else crashes or throws.
  std::mt19937 rng(20240607);
  const std::vector<Bytes> seeds{{0x08, 0x02, 0x00, 0x08, 0x02, 0x04, 0x00, 0x1E},
                                 {0x08, 0x9E, 0x00, 0x08, 0x02, 0x0A, 0x09, 0x00},
                                 {0x08, 0x9F, 0x00, 0x00, 0x00, 0x29, 0x56, 0x00}};
  std::size_t decoded = 0;
  for (int i = 0; i < 200000; ++i) {
    Bytes b = seeds[rng() % seeds.size()];
    const int n = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < n; ++k) {
      switch (rng() % 5) {
        case 0: b[rng() % b.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8)); break;
        case 1: b[rng() % b.size()] = static_cast<std::uint8_t>(rng()); break;
        case 2: if (!b.empty()) b.resize(rng() % b.size()); break;
        case 3: b.push_back(static_cast<std::uint8_t>(rng())); break;
        default: break;
      }
      if (b.empty()) b.push_back(static_cast<std::uint8_t>(rng()));
    }
    PrmCmd c;
    if (decode_prm_cmd(b, c) == PrmCmdError::None) {
      ++decoded;
      ASSERT_EQ(enc(c), b);
    }
    RedStatusBlock r;
    if (decode_red_status(b, r) == RedStatusError::None) {
      ++decoded;
      ASSERT_EQ(enc(r), b);
    }
  }
  EXPECT_GT(decoded, 1000u);
}

}  // namespace
}  // namespace pbvbus::redundancy
