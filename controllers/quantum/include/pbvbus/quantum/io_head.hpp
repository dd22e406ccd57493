#pragma once
// The remote I/O head of one rack of the Quantum Hot Standby pair (seeds-digest.md §8 "RIO"):
// the seed's pair drives remote I/O that both racks' heads reach; in pbvbus that is one DP line
// on which each rack has a DP master module at the same address (dp_head.hpp). The pair
// (hsby_pair.hpp) tells each head its role and moves the process data between state RAM and
// the head at the scan's edges; the head tells the pair whether the active master is still
// heard on the line, which lets a standby tell a failed primary (fibre and line both silent)
// from a failed fibre (the line still carries the primary's traffic).

#include <cstdint>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/quantum/state_ram.hpp"

namespace pbvbus::quantum {

enum class HeadRole : std::uint8_t {
  Off,      ///< the rack is unpowered: the module neither sends nor listens
  Passive,  ///< standby or offline unit: listens to the line, never sends, not in the ring
  Active,   ///< primary: in the token ring, exchanging data with the slaves
};

class IoHead {
 public:
  virtual ~IoHead() = default;
  /// The pair's decision for this rack's head (called on every change, at `now`).
  virtual void set_role(bus::Ticks now, HeadRole role) = 0;
  /// Primary, at the start of a scan: the slaves' latest inputs into 1x/3x (I/O map).
  virtual void read_inputs(StateRam& ram) = 0;
  /// Primary, at the end of a scan's logic: 0x/4x (I/O map) become the slaves' outputs.
  virtual void write_outputs(const StateRam& ram) = 0;
  /// Passive head: a frame sent by the active master (same address) was heard within the
  /// head's own silence bound before `now`.
  virtual bool hears_active_master(bus::Ticks now) const = 0;
  /// Passive head: a frame sent by the active master STARTED at or after `since` (the pair's
  /// second question, docs/quantum-hsby-campaign.md F2: a frame already on the wire when the
  /// primary failed may end after the first question and must not count as a sign of life).
  /// Heads that cannot tell answer hears_active_master(now).
  virtual bool heard_since(bus::Ticks since, bus::Ticks now) const {
    (void)since;
    return hears_active_master(now);
  }
};

}  // namespace pbvbus::quantum
