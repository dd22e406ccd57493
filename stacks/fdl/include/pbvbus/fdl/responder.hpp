#pragma once
// The responder half of an FDL station (IEC 61158-4-3; protocol-facts.md §B.2, §B.3, §C.6),
// shared by passive stations (slaves) and active stations (masters answering other masters):
// frame-count-bit filtering per source address and encoding of the reply.
//
// Decisions (the reference leaves them open):
//  - A request with FCV = 1 from a source address that has not sent a first frame since power-on
//    is executed and its FCB stored (there is nothing to compare it with).
//  - Only SDA and SRD frames with FCV = 1 take part in repeat detection; a repeat resends the
//    stored reply (SC, data or status frame) byte for byte without calling the user.
//  - A status-only reply (OK, UE, RR, RS, NR) goes out as SD1 without address extensions: in
//    IEC 61158-4-3 the DAE/SAE octets belong to the DATA_UNIT, which SD1 does not have, and DP
//    slave ASICs answer a deactivated SAP with a plain SD1 "RS". A Data reply always carries the
//    mirrored SAPs (response DSAP = request SSAP, response SSAP = request DSAP), also when its
//    data is empty.
//  - A Data reply too long for one frame is replaced by a status-only UE reply.

#include <array>
#include <cstdint>
#include <vector>

#include "pbvbus/fdl/station.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::fdl {

/// Action frames that carry a frame count bit (§C.6): SDA, SRD and MSRD. SDN, FDL Status,
/// Ident and the time event go with FCV = FCB = 0.
constexpr bool fn_uses_fcb(RequestFn fn) {
  return fn == RequestFn::SdaLow || fn == RequestFn::SdaHigh || fn == RequestFn::SrdLow ||
         fn == RequestFn::SrdHigh || fn == RequestFn::Msrd;
}

class Responder {
 public:
  enum class Check : std::uint8_t {
    Execute,  ///< hand the request to the user, then call finish()
    Repeat,   ///< a repeat of the SA's last action frame: send stored_reply() again
  };

  /// Forgets every stored FCB and reply (power-on).
  void reset();

  /// FCB/FCV filter for a decoded request addressed to this station.
  Check check(const Telegram& req);
  /// The reply stored for `sa` by the last finish(); empty if there was none.
  const Frame& stored_reply(std::uint8_t sa) const;

  /// Resets `reply` to its defaults (Status/RS) without giving up its data capacity.
  static void clear(Reply& reply);

  /// Encodes the user's reply to `req` from station `own` of type `type`, stores it for
  /// repeats when the request carried a valid FCB, and returns it (empty frame: say nothing).
  const Frame& finish(const Telegram& req, std::uint8_t own, StationType type, const Reply& reply);

  /// Encodes the FDL Status reply `10 SA DA FC FCS 16` with FC = type + OK.
  static Frame fdl_status_reply(const Telegram& req, std::uint8_t own, StationType type);

  /// Test-only (mutant slaves, docs/mutants.md): one FCB and one stored reply for every
  /// requester instead of one per source address (breaks §C.6 on purpose).
  void set_shared_fcb(bool shared) { m_shared = shared; }

 private:
  /// Where `sa`'s FCB and stored reply live: its own entry, or entry 0 for all (set_shared_fcb).
  std::uint8_t key(std::uint8_t sa) const { return m_shared ? 0 : sa; }
  static constexpr std::uint8_t kNone = 0xFF;
  // Last FCB per source address: kNone, 0 or 1.
  std::array<std::uint8_t, 128> m_fcb{};
  // Index into m_replies per source address, kNone if no slot yet. Slots are created on the
  // first action frame from an address and reused afterwards (no per-frame allocation).
  std::array<std::uint8_t, 128> m_slot{};
  std::vector<Frame> m_replies;
  Frame m_scratch;
  bool m_initialised = false;
  bool m_shared = false;
};

}  // namespace pbvbus::fdl
