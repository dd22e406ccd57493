// Decode once per frame (decoded_frame.hpp; docs/architecture.md "Decode once per frame").
#include "pbvbus/fdl/decoded_frame.hpp"

#include <new>
#include <type_traits>

namespace pbvbus::fdl {

// The memo's storage is overwritten in place and never destroyed.
static_assert(std::is_trivially_copyable_v<DecodedFrame>);
static_assert(std::is_trivially_destructible_v<DecodedFrame>);
static_assert(sizeof(DecodedFrame) <= bus::FrameMemo::kCapacity);
static_assert(alignof(DecodedFrame) <= alignof(std::max_align_t));

const DecodedFrame& decode_into(std::span<const std::uint8_t> bytes, bus::FrameMemo* memo,
                                DecodedFrame& scratch) {
  DecodedFrame* d =
      memo != nullptr ? ::new (memo->store(&kDecodedFrameMemoOwner, bytes)) DecodedFrame : &scratch;
  d->error = decode(bytes, d->telegram);
  return *d;
}

}  // namespace pbvbus::fdl
