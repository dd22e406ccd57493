#pragma once
// A plain FDL passive-station user (IEC 61158-4-3 responder; protocol-facts.md §B.3): answers
// SRD with `response_length` octets of data that change every cycle, SDA with SC (E5), and
// ignores SDN. The stand-in for a slave's process inputs in scenarios and benchmarks.
//
// Decisions:
//  - Response data octet i of cycle c is (c + i) mod 256: it changes every cycle, so a capture
//    shows fresh data, and a reader can check continuity.
//  - An SRD with response_length 0 is answered with SC, as the FDL allows for "SRD without
//    response data" (station.hpp Reply::ShortAck).
//  - Other services (Ident, LSAP status, ...) keep the station's default reply RS ("SAP not
//    activated"); FDL status requests are answered by the station itself.

#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "pbvbus/fdl/station.hpp"

namespace pbvbus::devices {

/// The data pattern of the FDL traffic users (this responder's replies, FdlPoller's requests):
/// out[i] = (first + i) mod 256. Eight octets per step (it is written for every frame): each
/// octet of a word is added to separately, so a carry never crosses into the next octet.
inline void fill_counting(std::span<std::uint8_t> out, std::uint8_t first) {
  constexpr std::uint64_t kHigh = 0x8080808080808080ULL;
  // Octet-wise a + b for b < 0x80 in every octet: add the low seven bits, put bit 7 back.
  auto add = [](std::uint64_t a, std::uint64_t b) { return ((a & ~kHigh) + b) ^ (a & kHigh); };
  std::uint64_t w = add(first * 0x0101010101010101ULL, 0x0706050403020100ULL);
  std::size_t i = 0;
  if constexpr (std::endian::native == std::endian::little) {  // octet k of w is out[i + k]
    for (; i + 8 <= out.size(); i += 8) {
      std::memcpy(out.data() + i, &w, 8);
      w = add(w, 0x0808080808080808ULL);
    }
  }
  for (; i < out.size(); ++i) out[i] = static_cast<std::uint8_t>(first + i);
}

class FdlResponder final : public fdl::ResponderUser {
 public:
  explicit FdlResponder(std::uint16_t response_length) : m_data(response_length) {}

  std::uint64_t srd() const { return m_srd; }
  std::uint64_t sda() const { return m_sda; }
  std::uint64_t sdn() const { return m_sdn; }
  std::uint64_t other() const { return m_other; }
  std::uint64_t cycle() const { return m_cycle; }

  void on_request(const fdl::Indication& ind, fdl::Reply& reply) override;

 private:
  std::vector<std::uint8_t> m_data;
  std::uint64_t m_cycle = 0;
  std::uint64_t m_srd = 0, m_sda = 0, m_sdn = 0, m_other = 0;
};

}  // namespace pbvbus::devices
