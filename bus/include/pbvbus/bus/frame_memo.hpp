#pragma once
// A per-frame slot for what a layer above the bus works out from a frame's octets
// (docs/architecture.md "Decode once per frame").
//
// Every frame on a line reaches several readers: the addressed station, every receive-all
// station (masters), the statistics tap and the capture probes. Each of them used to decode the
// same octets again. The line now owns one FrameMemo per transmission and hands a pointer to it
// with every RxFrame and TapFrame of that transmission; the first reader stores its result there
// and the others find it. The bus does not know what is inside (the FDL layer keeps its decoded
// telegram there, fdl/decoded_frame.hpp), so the layering stays as it is: bus below fdl.
//
// What keeps an entry from being taken for another frame:
//  - an entry is keyed by its owner (an address the storing layer picks, one per kind of
//    content) and by the exact view it was made from: the octets' address and length, so a
//    partial view (a frame cut short for some receivers) never matches the whole frame's entry;
//  - the line empties the slot whenever the octets of the transmission change while readers
//    may still look at it (a collision garbles them) and when it reuses the slot for the next
//    transmission.
// The contents must be trivially copyable and destructible (they are overwritten in place) and
// at most kCapacity octets; the storing layer checks this at compile time.

#include <cstddef>
#include <cstdint>
#include <span>

namespace pbvbus::bus {

class FrameMemo {
 public:
  static constexpr std::size_t kCapacity = 64;

  /// The stored entry if `owner` stored it for exactly `bytes`, else nullptr.
  const void* find(const void* owner, std::span<const std::uint8_t> bytes) const {
    return m_owner == owner && m_data == bytes.data() && m_size == bytes.size() ? m_storage
                                                                              : nullptr;
  }
  /// Storage for a new entry of `owner` made from `bytes` (replacing any other entry); the
  /// caller constructs its object there.
  void* store(const void* owner, std::span<const std::uint8_t> bytes) {
    m_owner = owner;
    m_data = bytes.data();
    m_size = bytes.size();
    return m_storage;
  }
  void clear() { m_owner = nullptr; }

 private:
  const void* m_owner = nullptr;
  const std::uint8_t* m_data = nullptr;
  std::size_t m_size = 0;
  alignas(std::max_align_t) std::byte m_storage[kCapacity];
};

}  // namespace pbvbus::bus
