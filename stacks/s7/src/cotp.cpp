// What all COTP TPDUs share: LI and code (ISO 8073 §13.2; cotp.hpp).
#include "pbvbus/s7/cotp.hpp"

namespace pbvbus::s7 {

Decoded<std::uint8_t> cotp_code(std::span<const std::uint8_t> tpdu) {
  if (tpdu.size() < 2) return {0, Error::CotpTooShort, tpdu.size()};
  const std::size_t li = tpdu[0];
  // LI 255 is reserved (ISO 8073 §13.2.1); the header must hold at least the code octet.
  if (li == 0 || li == 255 || li + 1 > tpdu.size()) return {0, Error::CotpBadLengthIndicator, 0};
  return {static_cast<std::uint8_t>(tpdu[1] & 0xF0)};
}

}  // namespace pbvbus::s7
