#pragma once
// Redundant two-channel I/O with passivation: the "Functional I/O Redundancy" block library of
// the S7-400H (001 §7.4 L5766-5785: FC 450 RED_INIT, FC 451 RED_DEPA, FB 450 RED_IN, FB 451
// RED_OUT, FB 452 RED_DIAG, FB 453 RED_STATUS). docs/h-redundant-io.md has the rules with the
// manual's lines, every decision and the events table; the events are in
// h_redundant_io_events.hpp.
//
// Sans-I/O: no bus, no threads, no clock. The owner (the H-system model, or a test) drives it
// with the virtual time `now` (bus::Ticks, the H-system's clock):
//   after the inputs are read, before OB 1:  red_in(now, pii)     (FB 450 RED_IN)
//   after OB 1, before the outputs go out:    red_out(piq)         (FB 451 RED_OUT)
//   on OB 82 / OB 85 of a module of a pair:   module_fault(...)    (FB 452 RED_DIAG)
//   on OB 100, OB 72 "Redundant", a change in operation, FC 451:  request_depassivation(...)
//   status:  modul_status_word(pair) (FB 453 RED_STATUS, 001 Table 7-5), status_byte()
//            (FB_RED_IN.STATUS_CONTROL_W, 001 Table 7-4), pair(i) for the plain state.
//
// A pair is module_L (the lower address: the valid value lives there, 001 L5819-5822) and
// module_H. red_in() reads the raw values of both modules from the PII bytes at their
// addresses and writes the valid value over module_L's bytes; module_H's bytes keep its raw
// reading ("values at the higher addresses have no meaning for the application"). red_out()
// takes the value the program wrote at module_L's address and writes what each module must
// output at both addresses.
//
// Digital values are bit-wise (one discrepancy timer per bit, "время рассогласования бита",
// 001 L5938); analog values are S7 words, big-endian, signed, one per channel (2 octets).
// Passivation is per module (the manual passivates "the module", 001 L5957-5959, L6170-6176).
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/s7h/h_redundant_io_events.hpp"

namespace pbvbus::devices {

/// HW Config "reaction to discrepancy" of a DI pair (001 L5925-5926, L5953-5954): what the
/// program sees from the expiry of the discrepancy time until the next signal change.
enum class DiReaction : std::uint8_t {
  LastValidValue,  ///< the last value on which both modules agreed (the default)
  Value1,          ///< 1
};

/// HW Config "accepted value" of an AI pair (001 L6156-6158, L6170-6176).
enum class AiAcceptedValue : std::uint8_t { Max, Min };

struct RedIoPairSpec {
  RedIoKind kind = RedIoKind::DI;
  std::uint32_t address_low = 0;   ///< module_L: first octet in the PII (DI/AI) or PIQ (DO/AO)
  std::uint32_t address_high = 0;  ///< module_H
  std::uint32_t length = 1;        ///< octets per module (AI/AO: even, 2 per channel)
  bus::Ticks discrepancy_time = 0;  ///< DI, AI (ignored for outputs)
  DiReaction di_reaction = DiReaction::LastValidValue;
  /// AI: tolerance window in per mille of the end value of the measuring range (5 % = 50).
  std::uint32_t tolerance_permille = 0;
  /// AI: end value of the measuring range in S7 units (the nominal range ends at 27648).
  std::int32_t end_value = 27648;
  AiAcceptedValue accepted = AiAcceptedValue::Max;
};

/// Which module of a pair.
enum class RedModule : std::uint8_t { L = 0, H = 1 };

/// What a depassivation was requested by (001 L6585-6591).
enum class DepassivationTrigger : std::uint8_t {
  Startup,       ///< start-up of the H system (OB 100)
  Redundant,     ///< the H system entered Redundant mode (OB 72)
  Modification,  ///< after a change of the plant in operation
  Fc451,         ///< FC 451 RED_DEPA
};
std::string_view to_string(DepassivationTrigger t);

/// The state of one pair (what RED_STATUS reports, in plain fields).
struct RedIoPairState {
  bool passivated[2] = {false, false};         ///< module_L, module_H
  RedIoCause cause[2] = {RedIoCause::None, RedIoCause::None};  ///< why passivated
  bool fault_present[2] = {false, false};      ///< an OB 82/85 fault not yet gone
  bool discrepant = false;                      ///< some bit/channel differs now (inputs)
  bool expired = false;                         ///< its discrepancy time has expired (inputs)
  bool overflow = false;                        ///< AI: a module reads 7FFF or 8000
};

class RedundantIo {
 public:
  /// FC 450 RED_INIT. Throws std::invalid_argument with the first problem of the spec list
  /// (see validate()).
  explicit RedundantIo(std::vector<RedIoPairSpec> pairs);
  /// "" or the first problem: length 0; AI/AO length odd; the two modules' byte ranges overlap;
  /// a module overlaps a module of another pair in the same image (inputs: DI/AI share the
  /// PII; outputs: DO/AO share the PIQ); negative discrepancy time; AI end value ≤ 0.
  static std::string validate(const std::vector<RedIoPairSpec>& pairs);

  /// FB 450 RED_IN: first a pending depassivation (001 L6596-6598), then every DI/AI pair.
  /// Pairs whose bytes lie outside `pii` are skipped. Negative `now`: nothing.
  void red_in(bus::Ticks now, std::span<std::uint8_t> pii);
  /// FB 451 RED_OUT: the bytes to send to the I/O: a copy of the program's PIQ in which every
  /// DO/AO pair's two modules get what they must output (module_L's value from the PIQ; pairs
  /// outside `piq` are left as they are). The PIQ itself is not changed, so the program's value
  /// stays (and the RAM/output-image comparison sees the program's bytes only).
  std::vector<std::uint8_t> red_out(std::span<const std::uint8_t> piq) const;

  /// FB 452 RED_DIAG on OB 82 (a diagnostic interrupt of the module) or OB 85 (an access error:
  /// the module or its station is not reachable). incoming: the module is passivated at once
  /// (if not yet). outgoing: the fault has gone; the module stays passivated until the next
  /// depassivation, which it now may take (001 Table 7-5 byte 2 bits 2-5). False for a bad
  /// pair index or a cause other than Ob82/Ob85.
  bool module_fault(bus::Ticks now, std::size_t pair, RedModule m, RedIoCause cause,
                    bool incoming);
  /// Finds the pair with a module at this address in the inputs (DI/AI) or outputs (DO/AO).
  std::optional<std::size_t> find_pair(std::uint32_t address, bool output) const;
  std::optional<RedModule> module_at(std::size_t pair, std::uint32_t address) const;

  /// Requests a depassivation; it is carried out at the next red_in() (001 L6596). FC 451 is
  /// refused (false) unless at least one module is passivated (001 L6590-6591); the other
  /// triggers are always taken.
  bool request_depassivation(bus::Ticks now, DepassivationTrigger t);
  bool depassivation_pending() const { return m_depa_pending.has_value(); }

  std::size_t size() const { return m_specs.size(); }
  const RedIoPairSpec& spec(std::size_t i) const { return m_specs.at(i); }
  const RedIoPairState& pair(std::size_t i) const { return m_state.at(i); }
  bool passivated(std::size_t i, RedModule m) const {
    return m_state.at(i).passivated[static_cast<int>(m)];
  }
  /// FB 453 RED_STATUS MODUL_STATUS_WORD (001 Table 7-5): byte 1 in the high octet, byte 2 in
  /// the low octet. Throws std::out_of_range for a bad index.
  std::uint16_t modul_status_word(std::size_t i) const;
  /// FB 450 STATUS_CONTROL_W status byte (001 Table 7-4).
  std::uint8_t status_byte() const;

  /// Every event so far, in order (h_redundant_io_events.hpp).
  const std::vector<RedIoEvent>& events() const { return m_events; }

 private:
  struct Track {  // per bit (DI) or channel (AI) of a pair
    bool differing = false;
    bool reported = false;  // 7960 raised for this episode (DI)
    bus::Ticks since = 0;
  };
  struct Work {
    std::vector<std::uint8_t> last_raw[2];  // previous raw reading of each module (DI/AI)
    std::vector<std::uint8_t> last_valid;   // last agreed (DI) / last valid (AI) value
    std::vector<Track> track;
    bool seen = false;  // a raw reading has been taken
  };

  void depassivate(bus::Ticks now);
  void passivate(bus::Ticks now, std::size_t i, RedModule m, RedIoCause cause,
                 std::uint16_t code);
  void run_di(bus::Ticks now, std::size_t i, std::span<std::uint8_t> pii);
  void run_ai(bus::Ticks now, std::size_t i, std::span<std::uint8_t> pii);
  void reset_tracks(std::size_t i);
  void add(RedIoEvent e) { m_events.push_back(std::move(e)); }

  std::vector<RedIoPairSpec> m_specs;
  std::vector<RedIoPairState> m_state;
  std::vector<Work> m_work;
  std::optional<DepassivationTrigger> m_depa_pending;
  std::vector<RedIoEvent> m_events;
};

}  // namespace pbvbus::devices
