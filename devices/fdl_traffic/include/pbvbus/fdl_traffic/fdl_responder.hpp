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

#include <cstdint>
#include <vector>

#include "pbvbus/fdl/station.hpp"

namespace pbvbus::devices {

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
