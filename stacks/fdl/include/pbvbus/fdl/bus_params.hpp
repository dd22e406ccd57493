#pragma once
// FDL bus parameter set (protocol-facts.md §C.1, §C.2). All times in bit times (t_bit).

#include <cstdint>
#include <string>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::fdl {

struct BusParams {
  bus::Baud baud = bus::Baud::k1_5M;
  std::uint32_t tsl = 300;        ///< slot time
  std::uint32_t min_tsdr = 11;    ///< min station delay of responders
  std::uint32_t max_tsdr = 150;   ///< max station delay of responders
  std::uint32_t tqui = 0;         ///< quiet time
  std::uint32_t tset = 1;         ///< setup time
  std::uint32_t ttr = 27'201;     ///< target rotation time
  std::uint32_t gap_factor = 10;  ///< G: GAP update every G token rotations
  std::uint8_t hsa = 126;         ///< highest station address
  std::uint8_t max_retry = 1;     ///< retries after the first attempt
  std::uint32_t tsdi = 0;         ///< initiator's own station delay (0: not given)

  static constexpr std::uint32_t kTsyn = 33;

  /// DP-profile defaults for a baud rate (§C.1).
  static BusParams defaults(bus::Baud baud);

  /// TSM = 2 + 2·TSET + TQUI.
  std::uint32_t tsm() const { return 2 + 2 * tset + tqui; }
  /// TID1 = max(TSYN + TSM, min TSDR, TSDI): idle after a reply, response or token received.
  std::uint32_t tid1() const;
  /// TID2 = max(TSYN + TSM, max TSDR): idle after an unacknowledged frame (SDN).
  std::uint32_t tid2() const;
  /// TTO = 6·TSL + 2·n·TSL for station address n: token-loss timeout.
  std::uint32_t tto(std::uint8_t address) const { return 6 * tsl + 2 * address * tsl; }

  /// Checks the constraints of §C.1; returns "" if valid, else the first violation in words.
  std::string validate() const;

  bus::Ticks ticks(std::int64_t bits) const { return bus::bits_to_ticks(bits, baud); }
};

}  // namespace pbvbus::fdl
