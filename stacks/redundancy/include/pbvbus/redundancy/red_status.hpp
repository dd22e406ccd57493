#pragma once
// The redundancy status blocks of PI 2.212 (protocol-facts.md §G.3): 8-octet DP-V1 status PDUs
// in the extended diagnosis, `08 <type> 00 <spec/Seq_Nr> <Function> <Red_State_1>
// <Red_State_2> <Red_State_3>`, type 0x9E Prm_Cmd_Ack (answer to a PrmCmd) or 0x9F Red_Status.
//
// assumption: modelled as PI 2.212 System Redundancy; the Siemens IM 153-2 wire protocol is
// not public. Decisions on the [U] items (docs/redundancy.md):
//  - Red_State bits as AUMA (closer to PI than VIPA's type 0x80 block): bit 0 Backup, bit 1
//    Primary, bit 2 Hardware_defective, bit 3 Data_Exchange, bit 4 Master_State_Clear, bit 5
//    Baudrate_found, bit 6 Output_Hold_Time started, bit 7 reserved. Backup and Primary
//    together are an error; neither = not decided yet (start-up alternation).
//  - Red_State_1 = the interface sending the diagnosis, Red_State_2 = its partner,
//    Red_State_3 reserved (0).
//  - Prm_Cmd_Ack: octet 4 echoes the PrmCmd's Seq_Nr (specifier bits 0), octet 5 echoes its
//    Function. Red_Status: octet 4 carries the Seq_Nr of the last PrmCmd (0 before any),
//    octet 5 is 0.

#include <array>
#include <cstdint>
#include <span>
#include <string_view>

namespace pbvbus::redundancy {

inline constexpr std::size_t kRedStatusLen = 8;
inline constexpr std::uint8_t kStatusPrmCmdAck = 0x9E;
inline constexpr std::uint8_t kStatusRedStatus = 0x9F;

// Red_State bits.
inline constexpr std::uint8_t kRsBackup = 0x01;
inline constexpr std::uint8_t kRsPrimary = 0x02;
inline constexpr std::uint8_t kRsHardwareDefective = 0x04;
inline constexpr std::uint8_t kRsDataExchange = 0x08;
inline constexpr std::uint8_t kRsMasterStateClear = 0x10;
inline constexpr std::uint8_t kRsBaudrateFound = 0x20;
inline constexpr std::uint8_t kRsOutputHoldStarted = 0x40;
inline constexpr std::uint8_t kRsReserved = 0x80;

struct RedState {
  bool backup = false;
  bool primary = false;
  bool hardware_defective = false;
  bool data_exchange = false;
  bool master_state_clear = false;
  bool baudrate_found = false;
  bool output_hold_started = false;
  std::uint8_t octet() const;
  static RedState from_octet(std::uint8_t b);  ///< ignores bit 7
  bool operator==(const RedState&) const = default;
};

struct RedStatusBlock {
  std::uint8_t type = kStatusRedStatus;  ///< kStatusPrmCmdAck or kStatusRedStatus
  std::uint8_t seq_nr = 0;               ///< 0..31
  std::uint8_t specifier = 0;            ///< 0..3
  std::uint8_t function = 0;             ///< PrmCmd Function echo (reserved bits must be 0)
  RedState own;                          ///< Red_State_1
  RedState partner;                      ///< Red_State_2
  std::uint8_t red_state_3 = 0;          ///< reserved, 0
  std::uint8_t specifier_octet() const {
    return static_cast<std::uint8_t>(((seq_nr & 0x1F) << 3) | (specifier & 0x03));
  }
  /// Octets 5..8: what SlaveApplication::set_status() takes as data.
  std::array<std::uint8_t, 4> data() const {
    return {function, own.octet(), partner.octet(), red_state_3};
  }
  bool operator==(const RedStatusBlock&) const = default;
};

enum class RedStatusError : std::uint8_t {
  None,
  TooShort,
  TooLong,
  BadHeader,        ///< octet 1 is not 0x08 (device-related, length 8)
  BadType,          ///< octet 2 is neither 0x9E nor 0x9F
  BadSlot,          ///< octet 3 is not 0
  ReservedBits,     ///< reserved bits of octets 4, 5, 6, 7 set, or octet 8 not 0
  PrimaryAndBackup, ///< a Red_State with both Primary and Backup
  BadSeqNr,         ///< encode only
  BadSpecifier,     ///< encode only
};
std::string_view to_string(RedStatusError e);

RedStatusError decode_red_status(std::span<const std::uint8_t> block, RedStatusBlock& out);
RedStatusError encode_red_status(const RedStatusBlock& b,
                                 std::array<std::uint8_t, kRedStatusLen>& out);

}  // namespace pbvbus::redundancy
