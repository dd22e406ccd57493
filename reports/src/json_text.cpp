#include "pbvbus/reports/json_text.hpp"

#include <cstdint>
#include <cstdio>

namespace pbvbus::tools {

std::string json_quote(std::string_view s) {
  std::string o = "\"";
  o.reserve(s.size() + 2);
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      case '\r': o += "\\r"; break;
      case '\t': o += "\\t"; break;
      default:
        if (u < 0x20 || u == 0x7F) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04X", static_cast<unsigned>(u));
          o += buf;
        } else {
          o += c;
        }
    }
  }
  return o + "\"";
}

std::string format_us(bus::Ticks t) {
  const std::int64_t ns = bus::ticks_to_ns(t);
  char buf[40];
  std::snprintf(buf, sizeof buf, "%lld.%03lld", static_cast<long long>(ns / 1000),
                static_cast<long long>(ns % 1000));
  return buf;
}

std::string hex_octets(std::span<const std::uint8_t> v) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s;
  s.reserve(v.size() * 3);
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) s += ' ';
    s += kDigits[v[i] >> 4];
    s += kDigits[v[i] & 0x0F];
  }
  return s;
}

}  // namespace pbvbus::tools
