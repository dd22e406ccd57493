#pragma once
// Private to fdl_traffic: the octets counting up from any start, as one table. The `n` octets
// fill_counting() writes from `first` are kCounting[first .. first + n) for n <= kCountingMax,
// so a request or reply can be copied from here in one go instead of zero-filled and then
// filled (the same octets).

#include <array>
#include <cstddef>
#include <cstdint>

namespace pbvbus::devices::detail {

inline constexpr std::size_t kCountingMax = 256;

inline constexpr std::array<std::uint8_t, 2 * kCountingMax> kCounting = [] {
  std::array<std::uint8_t, 2 * kCountingMax> t{};
  for (std::size_t j = 0; j < t.size(); ++j) t[j] = static_cast<std::uint8_t>(j);
  return t;
}();

}  // namespace pbvbus::devices::detail
