#pragma once
// One rack's DP master module (docs/quantum-hsby-dp.md): the remote I/O head of the Quantum
// Hot Standby pair on PROFIBUS. Both racks' modules sit on one DP line at the same address with
// the same slave parameters; the pair's decision (IoHead::set_role) makes a module
//   Off      — its attachment unpowered (the rack has no power);
//   Passive  — powered, its ActiveStation listen-only (sends nothing, not in the ring) and its
//              dp::Master in hot standby, shadowing the active master's exchanges;
//   Active   — from Passive: dp::Master::take_over (slaves seen in data exchange resume at
//              once, no Set_Prm) and the station leaves passive (claims the token after TTO of
//              silence); from Off: a normal start-up.
// The pair orders the calls so that a module leaves Active before the other enters it.
//
// Process data: each mapped slave's whole input telegram goes to state RAM at the primary's
// scan start (3x: two octets a register, first octet in the high byte; 1x: one input per bit,
// the first octet's LSB first), and its whole output telegram comes from 4x/0x the same way at
// the end of the scan's logic, module by module (DPWR_DAT). An odd octet count leaves the last
// register's low byte unused.
//
// hears_active_master(now): a frame sent with this module's address was heard no longer than
// `silence_bound` before `now`. A lone DP master is never silent longer than one message cycle
// (request, slot time, retries) or a token pass; the default bound is TTO = 6·TSL + 2·n·TSL
// (protocol-facts.md §C.4), the silence after which any FDL station takes the token for lost.
// heard_since(since, now): such a frame STARTED at or after `since` (for the pair's second
// question: a frame already on the wire at the primary's failure is no sign of life).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/quantum/io_head.hpp"
#include "pbvbus/quantum/reference.hpp"

namespace pbvbus::quantum {

/// Where one slave's data lives in state RAM (inputs 3x or 1x, outputs 4x or 0x).
struct DpIoMap {
  std::uint8_t slave = 0;
  Reference inputs{RefType::Register3x, 0};
  Reference outputs{RefType::Register4x, 0};
};

/// TTO for station `address` (protocol-facts.md §C.4), in ticks at the line's baud.
inline bus::Ticks token_timeout(const fdl::BusParams& p, std::uint8_t address) {
  return bus::bits_to_ticks(p.tto(address), p.baud);
}

class DpHead final : public IoHead, public fdl::InitiatorUser {
 public:
  /// `master` is the module's configuration (the dp_master's), `slaves` its slave database.
  DpHead(const dp::MasterParams& master, std::vector<dp::SlaveParams> slaves,
         const fdl::BusParams& params, std::vector<DpIoMap> map, bus::Ticks silence_bound);

  /// Attaches the module to `line` (unpowered until set_role says otherwise).
  void attach(bus::Line& line, std::string label);
  bus::AttachmentId attachment() const { return m_att; }

  fdl::ActiveStation& station() { return *m_station; }
  const fdl::ActiveStation& station() const { return *m_station; }
  dp::Master& master() { return m_master; }
  const dp::Master& master() const { return m_master; }
  HeadRole role() const { return m_role; }
  bus::Ticks silence_bound() const { return m_bound; }
  std::uint64_t takeovers() const { return m_master.hsby_stats().takeovers; }

  // IoHead
  void set_role(bus::Ticks now, HeadRole role) override;
  void read_inputs(StateRam& ram) override;
  void write_outputs(const StateRam& ram) override;
  bool hears_active_master(bus::Ticks now) const override;
  /// A frame with this module's address started at or after `since` (start = the end reported
  /// by the station minus the frame's octets x 11 bit times).
  bool heard_since(bus::Ticks since, bus::Ticks now) const override;

  // fdl::InitiatorUser (forwarded to the master)
  void on_power_on(bus::Ticks now) override;
  bool next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) override;
  void on_confirmation(const fdl::Confirmation& con) override;
  void on_request(const fdl::Indication& ind, fdl::Reply& reply) override;
  void on_token(bus::Ticks now, bus::Ticks trr) override;
  void on_observed(bus::Ticks now, const fdl::Telegram& t) override;
  /// Equidistance (docs/dp-equidistance.md): the master's pause.
  bus::Ticks pause_until(bus::Ticks now) override { return m_master.pause_until(now); }

 private:
  dp::Master m_master;
  std::unique_ptr<fdl::ActiveStation> m_station;
  std::vector<DpIoMap> m_map;
  bus::Ticks m_bound = 0;
  bus::Line* m_line = nullptr;
  bus::AttachmentId m_att{};
  HeadRole m_role = HeadRole::Off;
  bus::Ticks m_last_heard = bus::kNever;
  bus::Ticks m_last_start = bus::kNever;
  bus::Ticks m_tbit = 0;
  std::vector<std::uint8_t> m_buf;
};

}  // namespace pbvbus::quantum
