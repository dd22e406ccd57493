#pragma once
// Slave_Diag response layout (IEC 61158-6 DP; protocol-facts.md §D.4, §D.5, §E.5), shared by
// the slave engine (builds it) and the master (evaluates it): the six standard octets, then the
// extended diagnosis blocks: identifier-related, channel-related, device-related, and the
// DP-V1 alarm and status PDUs (which use the device-related header format).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace pbvbus::dp {

// Station_Status_1.
inline constexpr std::uint8_t kDiagStationNonExistent = 0x01;  ///< master-set
inline constexpr std::uint8_t kDiagStationNotReady = 0x02;
inline constexpr std::uint8_t kDiagCfgFault = 0x04;
inline constexpr std::uint8_t kDiagExtDiag = 0x08;
inline constexpr std::uint8_t kDiagNotSupported = 0x10;
inline constexpr std::uint8_t kDiagInvalidSlaveResponse = 0x20;  ///< master-set
inline constexpr std::uint8_t kDiagPrmFault = 0x40;
inline constexpr std::uint8_t kDiagMasterLock = 0x80;  ///< master-set
// Station_Status_2.
inline constexpr std::uint8_t kDiagPrmReq = 0x01;
inline constexpr std::uint8_t kDiagStatDiag = 0x02;
inline constexpr std::uint8_t kDiagAlways1 = 0x04;
inline constexpr std::uint8_t kDiagWdOn = 0x08;
inline constexpr std::uint8_t kDiagFreezeMode = 0x10;
inline constexpr std::uint8_t kDiagSyncMode = 0x20;
inline constexpr std::uint8_t kDiagDeactivated = 0x80;  ///< master-set
// Station_Status_3.
inline constexpr std::uint8_t kDiagExtDiagOverflow = 0x80;

inline constexpr std::size_t kStdDiagLen = 6;
inline constexpr std::size_t kMaxDiagLen = 244;

// Extended diagnosis block headers (bits 7..6).
inline constexpr std::uint8_t kBlockTypeMask = 0xC0;
inline constexpr std::uint8_t kBlockDevice = 0x00;      ///< also DP-V1 alarm/status PDUs
inline constexpr std::uint8_t kBlockIdentifier = 0x40;
inline constexpr std::uint8_t kBlockChannel = 0x80;
inline constexpr std::uint8_t kBlockLengthMask = 0x3F;

// DP-V1 status types (bit 7 set) and alarm types (bit 7 clear), §D.5 / §E.5.
inline constexpr std::uint8_t kStatusMessage = 0x81;
inline constexpr std::uint8_t kModuleStatus = 0x82;
inline constexpr std::uint8_t kDxbLinkStatus = 0x83;
inline constexpr std::uint8_t kPrmCmdAck = 0x9E;
inline constexpr std::uint8_t kRedState = 0x9F;

enum class AlarmType : std::uint8_t {
  Diagnostic = 1,
  Process = 2,
  Pull = 3,
  Plug = 4,
  Status = 5,
  Update = 6,
  // 32..126 manufacturer-specific
};
/// The DPV1_Status_2 enable bit that governs an alarm type (pull and plug share one).
constexpr std::uint8_t alarm_enable_bit(std::uint8_t type) {
  switch (type) {
    case 1: return 0x20;
    case 2: return 0x40;
    case 3:
    case 4: return 0x80;
    case 5: return 0x08;
    case 6: return 0x04;
    default: return type >= 32 && type <= 126 ? 0x10 : 0;
  }
}

/// Alarm_Specifier bits 1..0 (and status specifier bits 1..0).
enum class AlarmSpec : std::uint8_t {
  None = 0,
  Appears = 1,            ///< error appears, slot disturbed
  Disappears = 2,         ///< error disappears, slot OK
  DisappearsStillBad = 3  ///< error disappears, slot still disturbed
};
constexpr std::uint8_t alarm_specifier(std::uint8_t seq_nr, bool add_ack, AlarmSpec spec) {
  return static_cast<std::uint8_t>(((seq_nr & 0x1F) << 3) | (add_ack ? 0x04 : 0) |
                                   static_cast<std::uint8_t>(spec));
}
constexpr std::uint8_t alarm_seq_nr(std::uint8_t specifier) { return specifier >> 3; }

/// Channel-related diagnosis (three octets).
enum class ChannelDirection : std::uint8_t { Input = 1, Output = 2, InOut = 3 };
enum class ChannelType : std::uint8_t {
  Unspecified = 0, Bit = 1, Bit2 = 2, Bit4 = 3, Byte = 4, Word = 5, Dword = 6
};
/// Error types 1..9 from the standard; 16..31 manufacturer-specific.
enum class ChannelError : std::uint8_t {
  ShortCircuit = 1,
  Undervoltage = 2,
  Overvoltage = 3,
  Overload = 4,
  Overtemperature = 5,
  LineBreak = 6,
  UpperLimit = 7,
  LowerLimit = 8,
  Error = 9,
};
struct ChannelDiag {
  std::uint8_t module = 0;   ///< identifier number 0..63 (Chk_Cfg order)
  std::uint8_t channel = 0;  ///< 0..63
  ChannelDirection direction = ChannelDirection::Input;
  ChannelType type = ChannelType::Unspecified;
  std::uint8_t error = 0;    ///< 0..31
  std::array<std::uint8_t, 3> encode() const {
    return {static_cast<std::uint8_t>(kBlockChannel | (module & 0x3F)),
            static_cast<std::uint8_t>((static_cast<std::uint8_t>(direction) << 6) | (channel & 0x3F)),
            static_cast<std::uint8_t>((static_cast<std::uint8_t>(type) << 5) | (error & 0x1F))};
  }
  bool operator==(const ChannelDiag&) const = default;
};

/// DP-V1 Module_Status values, 2 bits per module.
enum class ModuleState : std::uint8_t { Ok = 0, Fault = 1, WrongModule = 2, NoModule = 3 };

/// The six standard octets.
struct StandardDiag {
  std::uint8_t status_1 = 0;
  std::uint8_t status_2 = kDiagAlways1;
  std::uint8_t status_3 = 0;
  std::uint8_t master_add = 0xFF;
  std::uint16_t ident = 0;
  std::array<std::uint8_t, kStdDiagLen> encode() const {
    return {status_1, status_2, status_3, master_add, static_cast<std::uint8_t>(ident >> 8),
            static_cast<std::uint8_t>(ident & 0xFF)};
  }
  /// False if `du` is shorter than six octets.
  static bool decode(std::span<const std::uint8_t> du, StandardDiag& out);
};

/// A fixed-capacity Slave_Diag under construction; appends fail (return false) once the
/// configured maximum would be exceeded, which the slave reports as Ext_Diag_Overflow.
class DiagBuilder {
 public:
  explicit DiagBuilder(std::size_t max_len = kMaxDiagLen)
      : m_max(max_len < kStdDiagLen ? kStdDiagLen : (max_len > kMaxDiagLen ? kMaxDiagLen : max_len)) {}
  void reset() { m_len = kStdDiagLen; m_overflow = false; }
  void set_standard(const StandardDiag& d);
  /// Identifier-related block: bit n set for every n in `faulty_modules` (n < 8 × 62).
  bool add_identifier_block(std::span<const std::uint16_t> faulty_modules, std::size_t module_count);
  bool add_channel(const ChannelDiag& c);
  /// Device-related block (header 00LLLLLL, data up to 62 octets).
  bool add_device_block(std::span<const std::uint8_t> data);
  /// DP-V1 alarm PDU: header, type, slot, specifier, data.
  bool add_alarm(std::uint8_t type, std::uint8_t slot, std::uint8_t specifier,
                 std::span<const std::uint8_t> data);
  /// DP-V1 status PDU: header, status type, slot, specifier, data.
  bool add_status(std::uint8_t status_type, std::uint8_t slot, std::uint8_t specifier,
                  std::span<const std::uint8_t> data);
  /// DP-V1 Module_Status block (status type 0x82, slot 0, 2 bits per module).
  bool add_module_status(std::span<const ModuleState> states, AlarmSpec spec = AlarmSpec::None);

  bool overflow() const { return m_overflow; }
  std::size_t size() const { return m_len; }
  bool has_ext() const { return m_len > kStdDiagLen; }
  std::span<const std::uint8_t> bytes() const { return {m_buf.data(), m_len}; }
  std::uint8_t& at(std::size_t i) { return m_buf[i]; }

 private:
  bool room(std::size_t n);
  std::array<std::uint8_t, kMaxDiagLen> m_buf{};
  std::size_t m_len = kStdDiagLen;
  std::size_t m_max;
  bool m_overflow = false;
};

/// One extended-diagnosis block as found by split_ext_diag (master side).
struct ExtDiagBlock {
  std::uint8_t kind = 0;  ///< kBlockDevice, kBlockIdentifier, kBlockChannel
  std::span<const std::uint8_t> bytes;  ///< including the header
};
/// Splits the octets after the six standard ones into blocks; false if a length is broken.
bool split_ext_diag(std::span<const std::uint8_t> ext, std::vector<ExtDiagBlock>& out);

}  // namespace pbvbus::dp
