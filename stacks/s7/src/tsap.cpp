// S7 rack/slot TSAPs (tsap.hpp).
#include "pbvbus/s7/tsap.hpp"

namespace pbvbus::s7 {

std::optional<S7Tsap> parse_s7_tsap(std::span<const std::uint8_t> tsap) {
  if (tsap.size() != 2) return std::nullopt;
  return S7Tsap{tsap[0], static_cast<std::uint8_t>(tsap[1] >> 5),
                static_cast<std::uint8_t>(tsap[1] & 0x1F)};
}

}  // namespace pbvbus::s7
