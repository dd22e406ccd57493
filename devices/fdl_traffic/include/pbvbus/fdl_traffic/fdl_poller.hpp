#pragma once
// A traffic-generating user of an FDL active station (IEC 61158-4-3 initiator; protocol-facts.md
// §C.3): while its master holds the token it polls a fixed list of stations round-robin, one
// request per station and token visit, and counts what comes back. It is the plain-FDL stand-in
// for a DP master in scenarios and benchmarks.
//
// Behaviour:
//  - Each token visit (InitiatorUser::on_token) every poll item may be sent once. The active
//    station asks for high-priority work first, then low priority while the token hold time
//    lasts (§C.3); an item left over when the hold time ran out is the first one offered at
//    the next visit (the cursor persists), so no station starves.
//  - The request data of item k is `length` octets counting up from a per-item sequence number,
//    so consecutive requests differ (as process outputs would).
//  - Token rotation times (the TRR the station reports with each token) are kept for the
//    report: min/median/max. Memory: 8 octets per token received.

#include <cstdint>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/fdl/station.hpp"

namespace pbvbus::devices {

struct PollItem {
  std::uint8_t da = 0;
  fdl::RequestFn fn = fdl::RequestFn::SrdLow;  ///< SRD/SDA/SDN, low or high
  std::uint16_t length = 0;                    ///< request data octets
};

/// Outcome counters of one poll item (one destination).
struct PollStats {
  std::uint64_t requests = 0;     ///< confirmations received (one per request handed out)
  std::uint64_t ok = 0;           ///< acknowledged or answered
  std::uint64_t no_response = 0;  ///< no valid reply after all retries
  std::uint64_t sent = 0;         ///< SDN: sent, nothing expected
  std::uint64_t retries = 0;      ///< repeats the station needed
  std::uint64_t data_octets = 0;  ///< response data received
};

class FdlPoller final : public fdl::InitiatorUser {
 public:
  explicit FdlPoller(std::vector<PollItem> items);

  const std::vector<PollItem>& items() const { return m_items; }
  const PollStats& stats(std::size_t item) const { return m_stats.at(item); }
  PollStats total() const;

  std::uint64_t tokens() const { return m_tokens; }
  /// Real rotation times reported with each token received, in ticks, in arrival order; the
  /// first token after power-on or ring entry (reported as 0: nothing to measure from) is left
  /// out.
  const std::vector<bus::Ticks>& rotation_times() const { return m_trr; }

  // fdl::InitiatorUser
  void on_power_on(bus::Ticks now) override;
  bool next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) override;
  void on_confirmation(const fdl::Confirmation& con) override;
  void on_token(bus::Ticks now, bus::Ticks trr) override;

 private:
  std::vector<PollItem> m_items;
  std::vector<PollStats> m_stats;
  std::vector<std::uint64_t> m_visit_done;  ///< visit number in which item k was last sent
  std::vector<std::uint8_t> m_seq;          ///< per-item data counter
  std::uint64_t m_visit = 1;
  std::vector<std::size_t> m_by_prio[2];  ///< item indices per priority (High, Low)
  std::size_t m_cursor[2] = {0, 0};       ///< position in m_by_prio[p] to look at first
  std::uint64_t m_tokens = 0;
  std::vector<bus::Ticks> m_trr;
};

}  // namespace pbvbus::devices
