#pragma once
// Configuration identifiers of Chk_Cfg / Get_Cfg (IEC 61158-6 DP; protocol-facts.md §D.3),
// shared by the slave engine and the master: general format (one octet) and special format
// (identifier, [output length octet], [input length octet], [manufacturer octets]).
//
// Equivalence: the slave compares identifiers by meaning, not by octets, so a general
// identifier `0x13` (4 bytes in) matches the special form `0x40 0x03`. Manufacturer-specific
// octets must be equal unless the Chk_Cfg count is 15 ("do not check").

#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace pbvbus::dp {

// General format.
inline constexpr std::uint8_t kCfgConsistent = 0x80;
inline constexpr std::uint8_t kCfgWords = 0x40;
inline constexpr std::uint8_t kCfgInput = 0x10;
inline constexpr std::uint8_t kCfgOutput = 0x20;
inline constexpr std::uint8_t kCfgLengthMask = 0x0F;
// Special format.
inline constexpr std::uint8_t kCfgSfOutput = 0x80;
inline constexpr std::uint8_t kCfgSfInput = 0x40;
inline constexpr std::uint8_t kCfgSfMfrMask = 0x0F;
inline constexpr std::uint8_t kCfgSfMfrSkip = 15;
inline constexpr std::uint8_t kCfgSfLengthMask = 0x3F;
inline constexpr std::size_t kMaxIoLen = 244;  ///< per slave and direction

/// One direction of an identifier. `units` = 0 when absent.
struct CfgIo {
  std::uint8_t units = 0;   ///< 1..16 (general) or 1..64 (special)
  bool words = false;       ///< units of 2 octets
  bool consistent = false;  ///< consistent over the whole length
  std::size_t bytes() const { return static_cast<std::size_t>(units) * (words ? 2u : 1u); }
  bool operator==(const CfgIo&) const = default;
};

/// One identifier (general or special format) as decoded.
struct CfgIdentifier {
  bool special = false;
  CfgIo input;
  CfgIo output;
  std::uint8_t mfr_count = 0;             ///< 0..14, or 15 = not checked (Chk_Cfg only)
  std::array<std::uint8_t, 14> mfr{};     ///< manufacturer-specific octets
  std::size_t offset = 0;                 ///< first octet in the identifier list
  std::size_t size = 0;                   ///< octets it occupies
  bool empty() const { return input.units == 0 && output.units == 0; }
};

enum class CfgError : std::uint8_t {
  None = 0,
  Truncated,       ///< a length or manufacturer octet is missing
  MfrSkipInReal,   ///< manufacturer count 15 where it is not allowed (Get_Cfg / real config)
  TooLong,         ///< more than 244 octets of inputs or outputs in total
};
std::string_view to_string(CfgError e);

/// Decodes an identifier list. `allow_skip` = the list is a Chk_Cfg (count 15 allowed).
CfgError parse_cfg(std::span<const std::uint8_t> octets, std::vector<CfgIdentifier>& out,
                   bool allow_skip);

/// Whether a configured (Chk_Cfg) identifier describes the same thing as a real one.
bool cfg_matches(const CfgIdentifier& configured, const CfgIdentifier& real);

/// Total input and output bytes of a list.
struct CfgTotals {
  std::size_t inputs = 0;
  std::size_t outputs = 0;
};
CfgTotals cfg_totals(std::span<const CfgIdentifier> ids);

/// General identifier octet for `units` (1..16) of a direction (kCfgInput, kCfgOutput or both).
constexpr std::uint8_t general_identifier(std::uint8_t dir, std::uint8_t units, bool words = false,
                                          bool consistent = false) {
  return static_cast<std::uint8_t>((consistent ? kCfgConsistent : 0) | (words ? kCfgWords : 0) |
                                   dir | ((units - 1) & kCfgLengthMask));
}

}  // namespace pbvbus::dp
