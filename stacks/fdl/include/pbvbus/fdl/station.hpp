#pragma once
// FDL stations (IEC 61158-4-3; protocol-facts.md §B, §C): the interfaces between an FDL station
// and its user (the DP slave or master above it). Both station kinds are bus::Device objects:
// sans-I/O, driven by the line with frames and timer expiries.
//
// Implementations: passive_station.hpp (slaves) and active_station.hpp (masters).

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::fdl {

/// A request addressed to a station, after FCB filtering (a repeat never reaches the user).
struct Indication {
  bus::Ticks now = 0;
  std::uint8_t sa = 0;          ///< requester
  std::uint8_t da = 0;          ///< own address, or 127 for a broadcast
  RequestFn fn = RequestFn::SrdHigh;
  std::optional<std::uint8_t> dsap;
  std::optional<std::uint8_t> ssap;
  std::span<const std::uint8_t> data;
  bool broadcast() const { return da == kBroadcast; }
};

/// What the user answers to an Indication. SAPs are mirrored automatically (response DSAP =
/// request SSAP, response SSAP = request DSAP).
struct Reply {
  enum class Kind : std::uint8_t {
    None,      ///< say nothing (SDN, or a station that chooses to stay silent)
    ShortAck,  ///< SC (E5): SDA acknowledged, or SRD without response data
    Data,      ///< response with `status` DL or DH and `data` (may be empty)
    Status,    ///< short response frame with `status` (OK, UE, RR, RS, NR) and no data
  };
  Kind kind = Kind::Status;
  ResponseStatus status = ResponseStatus::RS;  ///< default: SAP not activated
  std::vector<std::uint8_t> data;
  /// Applied after the reply has gone out (Set_Slave_Add, Set_Prm's min TSDR).
  std::optional<std::uint8_t> new_address;
  std::optional<std::uint32_t> new_min_tsdr;
  /// Test-only (mutant slaves, docs/mutants.md): the reply carries the request's DSAP and SSAP
  /// as they came instead of mirrored (breaks §B.2 on purpose).
  bool saps_not_mirrored = false;

  void short_ack() { kind = Kind::ShortAck; }
  void respond(ResponseStatus s, std::span<const std::uint8_t> d) {
    kind = Kind::Data;
    status = s;
    data.assign(d.begin(), d.end());
  }
  void status_only(ResponseStatus s) {
    kind = Kind::Status;
    status = s;
  }
  void none() { kind = Kind::None; }
};

/// The upper layer of a passive station (a DP slave engine).
class ResponderUser {
 public:
  virtual void on_power_on(bus::Ticks /*now*/) {}
  /// A request addressed to this station (or broadcast). Fill `reply`; it comes preset to
  /// Status/RS ("SAP not activated").
  virtual void on_request(const Indication& ind, Reply& reply) = 0;
  /// Time-driven work such as the DP watchdog: the next time on_time() should be called.
  /// Re-read after every on_request() and on_time().
  virtual bus::Ticks next_deadline() const { return bus::kNever; }
  virtual void on_time(bus::Ticks /*now*/) {}

 protected:
  ~ResponderUser() = default;
};

// --- Initiator side (masters) -----------------------------------------------------------------

enum class Priority : std::uint8_t { High, Low };

/// A request a master wants to send while it holds the token.
struct Request {
  std::uint8_t da = 0;
  RequestFn fn = RequestFn::SrdHigh;
  std::optional<std::uint8_t> dsap;
  std::optional<std::uint8_t> ssap;
  std::vector<std::uint8_t> data;
  std::uint64_t tag = 0;  ///< the user's own reference, returned in the Confirmation
};

/// Outcome of a Request.
struct Confirmation {
  enum class Result : std::uint8_t {
    Ok,          ///< an acknowledgement or response arrived (see status / short_ack / data)
    NoResponse,  ///< no valid reply after all retries: the responder is now "non-operational"
    Sent,        ///< SDN: sent, nothing expected
  };
  bus::Ticks now = 0;
  std::uint64_t tag = 0;
  std::uint8_t da = 0;
  Result result = Result::NoResponse;
  bool short_ack = false;  ///< reply was SC (E5)
  ResponseStatus status = ResponseStatus::OK;
  StationType responder_type = StationType::Slave;
  std::optional<std::uint8_t> dsap;  ///< of the response
  std::optional<std::uint8_t> ssap;
  std::span<const std::uint8_t> data;  ///< valid only during on_confirmation()
  std::uint32_t retries = 0;           ///< how many repeats it took
};

/// The upper layer of an active station (a DP master).
class InitiatorUser {
 public:
  virtual void on_power_on(bus::Ticks /*now*/) {}
  /// Called while the station holds the token and may start a message cycle of priority
  /// `prio`. Fill `out` and return true to send it; return false when there is nothing to send
  /// at this priority now. One request is outstanding at a time.
  virtual bool next_request(Priority prio, bus::Ticks now, Request& out) = 0;
  virtual void on_confirmation(const Confirmation& con) = 0;
  /// A request addressed to this master by another station (MM services). Default: RS.
  virtual void on_request(const Indication& /*ind*/, Reply& /*reply*/) {}
  /// Token received (for statistics and the DP master's timing); trr = real rotation time.
  virtual void on_token(bus::Ticks /*now*/, bus::Ticks /*trr*/) {}
  /// Passive (listen-only) mode of the station (ActiveStation::set_passive): every valid frame
  /// heard on the line, `now` = its end. The telegram's data is valid only during the call.
  /// Used by a hot-standby DP master to shadow the active master at the same address
  /// (docs/quantum-hsby-dp.md).
  virtual void on_observed(bus::Ticks /*now*/, const Telegram& /*t*/) {}
  /// Equidistance (constant bus cycle time, docs/dp-equidistance.md): asked when a token visit
  /// has sent nothing yet and next_request() had nothing. A time later than `now` makes the
  /// station keep the token and pause until then instead of polling the GAP and passing the
  /// token (active pause: FDL Status requests to itself while one fits with its slot time;
  /// then a passive pause, silence), and ask next_request() again at its end. The pause does
  /// not use up the token hold time. Default: no pause.
  virtual bus::Ticks pause_until(bus::Ticks /*now*/) { return 0; }

 protected:
  ~InitiatorUser() = default;
};

}  // namespace pbvbus::fdl
