#pragma once
// FDL passive station (IEC 61158-4-3 Passive_Idle; protocol-facts.md §B, §C.2, §C.6): a DP
// slave's layer 2. It answers requests addressed to it (or broadcast SDN) after its station
// delay TSDR, answers Request FDL Status by itself, filters repeats by FCB per source address,
// and hands everything else to its ResponderUser.
//
// Rules implemented:
//  - Frames with error flags or that fail decoding are dropped, as are request frames seen after
//    less than TSYN (33 t_bit) of idle line: a receiver only synchronises on a start delimiter
//    after TSYN of idle (§A, §C.2).
//  - The reply's first start bit goes out exactly TSDR after the request's last stop bit. TSDR
//    is the station's own delay (constructor), kept within [min TSDR, max TSDR]; min TSDR can be
//    raised by the user (Set_Prm octet 4 via Reply::new_min_tsdr) and falls back to the bus
//    parameter value at power-on. If a requested min TSDR exceeds max TSDR the min wins: the
//    master asked for it.
//  - SDN (including broadcasts to DA 127) is never answered.
//  - Reply::new_address / new_min_tsdr take effect at the end of the reply's last character
//    (immediately if there is no reply). The address survives a power cycle (real slaves keep a
//    Set_Slave_Add address in non-volatile memory); min TSDR does not.
//  - No heap allocation per frame: the Reply handed to the user is a member, reused.
//  - Mutations (PassiveMutation, test-only: devices/slave_mutant.hpp, docs/mutants.md) each
//    break one of the rules above on purpose: a fixed reply delay outside the [min TSDR,
//    max TSDR] bounds (only a larger requested min TSDR still wins), a requested min TSDR not
//    applied, or FCB repeats executed as new requests (their FCB is still stored).

#include <cstdint>
#include <optional>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/fdl/responder.hpp"
#include "pbvbus/fdl/station.hpp"

namespace pbvbus::fdl {

struct PassiveStats {
  std::uint64_t requests = 0;         ///< valid requests addressed to this station (incl. broadcast)
  std::uint64_t replies = 0;          ///< frames sent
  std::uint64_t repeats = 0;          ///< FCB repeats answered from the stored reply
  std::uint64_t fdl_status = 0;       ///< Request FDL Status answered
  std::uint64_t dropped_errors = 0;   ///< frames with error flags or decode errors
  std::uint64_t dropped_tsyn = 0;     ///< requests after less than TSYN idle
};

/// Test-only: breaks one rule on purpose (devices/slave_mutant.hpp). Default: conformant.
struct PassiveMutation {
  /// tsdr_too_late: reply after exactly this many t_bit (or the requested min TSDR if larger),
  /// NOT clamped to max TSDR.
  std::optional<std::uint32_t> fixed_tsdr;
  bool ignore_min_tsdr = false;  ///< ignore_min_tsdr: Reply::new_min_tsdr is never applied
  bool ignore_fcb = false;       ///< ignore_fcb: an FCB repeat goes to the user as a new request
  bool shared_fcb = false;       ///< fcb_global: one FCB and stored reply for all requesters
  bool any() const { return fixed_tsdr || ignore_min_tsdr || ignore_fcb || shared_fcb; }
};

class PassiveStation final : public bus::Device {
 public:
  /// `tsdr` = the station's own response delay in t_bit; 0 = min TSDR (a fast ASIC).
  PassiveStation(std::uint8_t address, const BusParams& params, ResponderUser& user,
                 std::uint32_t tsdr = 0);

  void on_power_on(bus::Ticks now) override;
  void on_power_off(bus::Ticks now) override;
  void on_frame(const bus::RxFrame& frame) override;
  void on_timer(bus::Ticks now) override;
  int receive_filter() const override { return m_address; }
  const char* kind() const override { return "passive station"; }

  std::uint8_t address() const { return m_address; }
  /// Changes the station address at once (management, the Flying Redundancy address swap;
  /// Set_Slave_Add goes through Reply). A new address forgets the stored FCBs and reply: the
  /// masters' FCB sequences were kept for the old address, so the first request to the new one
  /// is executed whatever its FCB (as after power-on).
  void set_address(std::uint8_t address) {
    if (address != m_address) m_responder.reset();
    m_address = address;
    if (bound()) port().receive_filter_changed();  // the line caches receive filters
  }
  std::uint32_t min_tsdr() const { return m_min_tsdr; }
  /// The delay actually used for the next reply, in t_bit.
  std::uint32_t response_delay() const;
  const BusParams& params() const { return m_params; }
  const PassiveStats& stats() const { return m_stats; }
  /// Test-only (mutant slaves): breaks one FDL rule on purpose; see PassiveMutation.
  void set_mutation(const PassiveMutation& m) {
    m_mutation = m;
    m_responder.set_shared_fcb(m.shared_fcb);
  }
  const PassiveMutation& mutation() const { return m_mutation; }

 private:
  void apply_pending();
  void rearm();

  BusParams m_params;
  ResponderUser& m_user;
  std::uint8_t m_address;
  std::uint32_t m_own_tsdr;
  std::uint32_t m_min_tsdr;
  Responder m_responder;
  Reply m_reply;
  // Changes from the last reply, applied at `m_pending_at`.
  bool m_pending = false;
  bus::Ticks m_pending_at = bus::kNever;
  std::optional<std::uint8_t> m_pending_address;
  std::optional<std::uint32_t> m_pending_min_tsdr;
  PassiveStats m_stats;
  PassiveMutation m_mutation;
  bool m_powered = false;
};

}  // namespace pbvbus::fdl
