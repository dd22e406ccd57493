// Configuration identifiers (protocol-facts.md §D.3).
#include "pbvbus/dp/cfg_identifier.hpp"

#include <algorithm>

namespace pbvbus::dp {

std::string_view to_string(CfgError e) {
  switch (e) {
    case CfgError::None: return "ok";
    case CfgError::Truncated: return "identifier list truncated";
    case CfgError::MfrSkipInReal: return "manufacturer count 15 in a real configuration";
    case CfgError::TooLong: return "more than 244 octets of inputs or outputs";
  }
  return "?";
}

namespace {
CfgIo special_length(std::uint8_t octet) {
  CfgIo io;
  io.units = static_cast<std::uint8_t>((octet & kCfgSfLengthMask) + 1);
  io.words = (octet & kCfgWords) != 0;
  io.consistent = (octet & kCfgConsistent) != 0;
  return io;
}
}  // namespace

CfgError parse_cfg(std::span<const std::uint8_t> octets, std::vector<CfgIdentifier>& out,
                   bool allow_skip) {
  out.clear();
  std::size_t i = 0;
  CfgTotals totals;
  while (i < octets.size()) {
    CfgIdentifier id;
    id.offset = i;
    const std::uint8_t b = octets[i++];
    if ((b & (kCfgInput | kCfgOutput)) != 0) {
      CfgIo io;
      io.units = static_cast<std::uint8_t>((b & kCfgLengthMask) + 1);
      io.words = (b & kCfgWords) != 0;
      io.consistent = (b & kCfgConsistent) != 0;
      if (b & kCfgInput) id.input = io;
      if (b & kCfgOutput) id.output = io;
    } else {
      id.special = true;
      // Output length octet first, then input (wire order of §D.3).
      if (b & kCfgSfOutput) {
        if (i >= octets.size()) return CfgError::Truncated;
        id.output = special_length(octets[i++]);
      }
      if (b & kCfgSfInput) {
        if (i >= octets.size()) return CfgError::Truncated;
        id.input = special_length(octets[i++]);
      }
      id.mfr_count = b & kCfgSfMfrMask;
      if (id.mfr_count == kCfgSfMfrSkip) {
        if (!allow_skip) return CfgError::MfrSkipInReal;
      } else {
        if (octets.size() - i < id.mfr_count) return CfgError::Truncated;
        std::copy_n(octets.begin() + static_cast<std::ptrdiff_t>(i), id.mfr_count, id.mfr.begin());
        i += id.mfr_count;
      }
    }
    id.size = i - id.offset;
    totals.inputs += id.input.bytes();
    totals.outputs += id.output.bytes();
    out.push_back(id);
  }
  if (totals.inputs > kMaxIoLen || totals.outputs > kMaxIoLen) return CfgError::TooLong;
  return CfgError::None;
}

bool cfg_matches(const CfgIdentifier& configured, const CfgIdentifier& real) {
  if (!(configured.input == real.input) || !(configured.output == real.output)) return false;
  if (configured.mfr_count == kCfgSfMfrSkip) return true;
  if (configured.mfr_count != real.mfr_count) return false;
  return std::equal(configured.mfr.begin(), configured.mfr.begin() + configured.mfr_count,
                    real.mfr.begin());
}

CfgTotals cfg_totals(std::span<const CfgIdentifier> ids) {
  CfgTotals t;
  for (const auto& id : ids) {
    t.inputs += id.input.bytes();
    t.outputs += id.output.bytes();
  }
  return t;
}

}  // namespace pbvbus::dp
