// Input behaviours of simulated DP slave modules (io_behaviour.hpp).
#include "pbvbus/slaves/io_behaviour.hpp"

namespace pbvbus::devices {

namespace {
__extension__ typedef __int128 Int128;  // NOLINT: ramp products exceed 64 bits
}  // namespace

std::string check_behaviour(const IoBehaviour& b, std::size_t modules) {
  switch (b.kind) {
    case IoBehaviour::Kind::Constant: return {};
    case IoBehaviour::Kind::Counter:
      if (b.period < 0) return "counter period must not be negative";
      return {};
    case IoBehaviour::Kind::Echo:
      if (b.source_module && *b.source_module >= modules)
        return "echo source module " + std::to_string(*b.source_module) + " does not exist (" +
               std::to_string(modules) + " modules)";
      return {};
    case IoBehaviour::Kind::Ramp:
      if (b.period <= 0) return "ramp period must be positive";
      if (b.max < b.min) return "ramp max is below min";
      return {};
    case IoBehaviour::Kind::Table:
      if (b.rows.empty()) return "table has no rows";
      for (std::size_t i = 0; i < b.rows.size(); ++i) {
        if (b.rows[i].first < 0) return "table row " + std::to_string(i) + ": negative time";
        if (i > 0 && b.rows[i].first < b.rows[i - 1].first)
          return "table row " + std::to_string(i) + ": times must ascend";
      }
      if (b.repeat && b.period <= b.rows.back().first)
        return "repeating table needs a period longer than its last row time";
      return {};
  }
  return "unknown behaviour";
}

std::int64_t behaviour_value(const IoBehaviour& b, bus::Ticks now, std::uint64_t cycles) {
  switch (b.kind) {
    case IoBehaviour::Kind::Counter: {
      const std::uint64_t n =
          b.period > 0 ? static_cast<std::uint64_t>((now < 0 ? 0 : now) / b.period) : cycles;
      // Unsigned arithmetic wraps; the writer keeps the low octets.
      return static_cast<std::int64_t>(b.start + b.step * n);
    }
    case IoBehaviour::Kind::Ramp: {
      const bus::Ticks phase = (now < 0 ? 0 : now) % b.period;
      // span × phase may exceed 64 bits for long periods at tick resolution: use 128 bits.
      const Int128 span = static_cast<Int128>(b.max) - b.min;
      return b.min + static_cast<std::int64_t>(span * phase / b.period);
    }
    case IoBehaviour::Kind::Table: {
      bus::Ticks t = now < 0 ? 0 : now;
      if (b.repeat) t %= b.period;
      std::int64_t v = b.rows.front().second;
      for (const auto& r : b.rows) {
        if (r.first > t) break;
        v = r.second;
      }
      return v;
    }
    default: return 0;
  }
}

void put_big_endian(std::int64_t value, std::vector<std::uint8_t>::iterator out, std::size_t width) {
  auto u = static_cast<std::uint64_t>(value);
  for (std::size_t i = width; i-- > 0;) {
    out[static_cast<std::ptrdiff_t>(i)] = static_cast<std::uint8_t>(u & 0xFF);
    u >>= 8;
  }
}

}  // namespace pbvbus::devices
