#pragma once
// 128-bit nanosecond arithmetic, saturated to int64: capture timestamps from any resolution and
// offset (pcapng if_tsresol, if_tsoffset) and frame durations at any if_speed never overflow.

#include <cstdint>
#include <limits>

namespace pbvbus::captures {

__extension__ typedef __int128 i128;

inline std::int64_t saturate(i128 v) {
  if (v > std::numeric_limits<std::int64_t>::max()) return std::numeric_limits<std::int64_t>::max();
  if (v < std::numeric_limits<std::int64_t>::min()) return std::numeric_limits<std::int64_t>::min();
  return static_cast<std::int64_t>(v);
}

}  // namespace pbvbus::captures
