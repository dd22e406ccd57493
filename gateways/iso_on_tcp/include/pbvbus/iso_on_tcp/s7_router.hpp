#pragma once
// Where the ISO-on-TCP door sends a connection (docs/iso-on-tcp.md "Routing"). On a COTP CR the
// door hands both TSAPs to the owner's S7Router; the router refuses (the door answers a COTP DR
// with the router's reason) or opens an S7Channel, which carries S7 PDUs to a CPU and back: a
// local CPU answers at once, a CPU across MPI later in virtual time.
//
// Threading: everything is called on the door's io_context thread, and the channel calls back
// on that thread too (a router on the paced runner's io_context, as the simulation's nodes are).
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/s7/tsap.hpp"

namespace pbvbus::iso_on_tcp {

/// The TSAPs of a CR. `calling`/`called` are the rack/slot reading of 2-octet TSAPs
/// (stacks/s7 tsap.hpp), nullopt for other lengths (e.g. libnodave's 28-octet routing TSAP,
/// whose raw octets the router still sees).
struct RouteRequest {
  std::vector<std::uint8_t> calling_tsap;
  std::vector<std::uint8_t> called_tsap;
  std::optional<s7::S7Tsap> calling;
  std::optional<s7::S7Tsap> called;
  std::uint64_t connection_id = 0;  ///< the door's number of the TCP connection (1, 2, ...)
};

/// One routed S7 connection. Destroying it ends the route (the CPU's connection resource is
/// free again); the door does that when the TCP connection ends.
class S7Channel {
 public:
  /// The answer to one request: the S7 PDU, or empty when the CPU refuses the octets as no S7
  /// job at all (the door then closes the connection, as for garbage).
  using Reply = std::function<void(std::vector<std::uint8_t> answer)>;
  /// The connection the channel rides on broke (MPI link lost, CPU off): the door sends a COTP
  /// DR and closes the TCP connection. `reason` goes into the door's log line.
  using Closed = std::function<void(const std::string& reason)>;

  virtual ~S7Channel() = default;
  /// One S7 PDU (a Job or Userdata, the octets after `02 F0 80`). `reply` is called exactly once
  /// unless the channel closes first, synchronously or later, on the door's thread.
  virtual void request(std::vector<std::uint8_t> pdu, Reply reply) = 0;
  /// Set by the door right after open(); the channel keeps it and calls it at most once.
  virtual void on_closed(Closed closed) = 0;
};

/// A refusal (the door's COTP DR carries `dr_reason`, ISO 8073 §13.5.3 d; stacks/s7
/// cotp_disconnect.hpp) or an open channel.
struct RouteResult {
  std::unique_ptr<S7Channel> channel;
  std::uint8_t dr_reason = 0;
  std::string why;  ///< for the door's log line when refused

  static RouteResult refuse(std::uint8_t reason, std::string why_) {
    RouteResult r;
    r.dr_reason = reason;
    r.why = std::move(why_);
    return r;
  }
};

class S7Router {
 public:
  virtual ~S7Router() = default;
  virtual RouteResult open(const RouteRequest& request) = 0;
};

}  // namespace pbvbus::iso_on_tcp
