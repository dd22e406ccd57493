#pragma once
// FDL bus parameter set (IEC 61158-4-3 bus parameters; reference: protocol-facts.md §C.1, §C.2).
// All times are in bit times (t_bit) of the line's baud rate.
//
// Defaults per baud rate (defaults()) follow the DP-profile table of §C.1. Decisions where the
// table is uncertain or silent:
// - 45.45 kbit/s: the table has no confirmed column. We use the set Siemens configuration tools
//   use for DP/PA couplers at this rate: TSL 640, min TSDR 11, max TSDR 400, TQUI 0, TSET 95.
//   max TSDR 400 covers the S1 example GSD's MaxTsdr_45.45 = 250; TSL 640 >= 400 + 15 and
//   35 + 2*95 + 0 = 225 <= 400 satisfy §C.1; TID1 = 33 + 2 + 190 = 225.
// - 31.25 kbit/s (MBP/PA): the same set as 45.45 kbit/s. MBP segments carry the slow PA field
//   devices that the 45.45 kbit/s coupler set was made for; the UART framing of our line model
//   is the same at every rate.
// - TTR: a per-baud estimate from ttr_estimate(kDefaultTtrSlaves, kDefaultTtrOctets): one
//   rotation polls 32 DP slaves with 16 octets each way at worst-case responder delay, plus one
//   token pass and one GAP poll. Real values come from the scenario layer, which knows the
//   slaves; this default just gives a ring that works for a small installation.
// - Retry limit 1, G 10, HSA 126 (§C.1).
//
// validate() checks, in this order (first violation wins, with a message that names the
// parameter, its value and the bound):
//   TSL:       max TSDR + 15 <= TSL <= 16 383
//   max TSDR:  35 + 2*TSET + TQUI <= max TSDR <= 1023
//   min TSDR:  11 <= min TSDR <= max TSDR - 1, and min TSDR <= 255 (DP carries it in one
//              Set_Prm octet)
//   TQUI, TSET: <= 255 each (one octet in the Bus_Para record, §C.2)
//   TTR:       256 .. 16 777 960
//   G:         1 .. 100
//   HSA:       1 .. 126 (HSA 0 would leave no address for a master; 127 is broadcast)
//   retry:     0 .. 15 (S2 allows 1..15, tools 0..7, Beckhoff allows 0; we take the union)

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

  // Limits checked by validate() (§C.1).
  static constexpr std::uint32_t kTslMax = 16'383;
  static constexpr std::uint32_t kTslMargin = 15;  ///< TSL >= max TSDR + 15
  static constexpr std::uint32_t kMaxTsdrMax = 1023;
  static constexpr std::uint32_t kMinTsdrMin = 11;
  static constexpr std::uint32_t kMinTsdrMax = 255;
  static constexpr std::uint32_t kOctetMax = 255;  ///< TQUI, TSET
  static constexpr std::uint32_t kTtrMin = 256;
  static constexpr std::uint32_t kTtrMax = 16'777'960;
  static constexpr std::uint32_t kGapFactorMax = 100;
  static constexpr std::uint8_t kHsaMax = 126;
  static constexpr std::uint8_t kMaxRetryMax = 15;

  /// Load the default TTR is sized for (see the header comment).
  static constexpr unsigned kDefaultTtrSlaves = 32;
  static constexpr unsigned kDefaultTtrOctets = 16;

  /// DP-profile defaults for a baud rate (§C.1; decisions in the header comment).
  static BusParams defaults(bus::Baud baud);

  /// TSM = 2 + 2·TSET + TQUI.
  std::uint32_t tsm() const { return 2 + 2 * tset + tqui; }
  /// TID1 = max(TSYN + TSM, min TSDR, TSDI): idle after a reply, response or token received.
  std::uint32_t tid1() const;
  /// TID2 = max(TSYN + TSM, max TSDR): idle after an unacknowledged frame (SDN).
  std::uint32_t tid2() const;
  /// TTO = 6·TSL + 2·n·TSL for station address n: token-loss timeout.
  std::uint32_t tto(std::uint8_t address) const { return 6 * tsl + 2 * address * tsl; }

  /// Worst-case token rotation (bit times) for one master polling `slaves` DP slaves with SRD,
  /// `data_octets` octets of data each way, no SAPs (Data_Exchange): per slave the message cycle
  /// 11·(request octets) + max TSDR + 11·(response octets) + TID1 (§C.2, TTD neglected), then
  /// one token pass (11·3 + TID1) and one unanswered GAP poll (11·6 + TSL + TID1). Frames are
  /// SD1/SD3/SD2 by §B.1; a reply without data is an SC. Saturates at kTtrMax. A planning aid,
  /// not a substitute for the scenario layer's TTR calculation.
  std::uint32_t ttr_estimate(unsigned slaves, unsigned data_octets) const;

  /// Checks the constraints of §C.1; returns "" if valid, else the first violation in words.
  std::string validate() const;

  bus::Ticks ticks(std::int64_t bits) const { return bus::bits_to_ticks(bits, baud); }
};

}  // namespace pbvbus::fdl
