#include "pbvbus/quantum/reference.hpp"

#include <cstdio>

namespace pbvbus::quantum {

std::optional<Reference> parse_reference(std::string_view text) {
  if (text.size() != 5 && text.size() != 6) return std::nullopt;
  for (char c : text)
    if (c < '0' || c > '9') return std::nullopt;
  Reference r;
  switch (text[0]) {
    case '0': r.type = RefType::Coil0x; break;
    case '1': r.type = RefType::Input1x; break;
    case '3': r.type = RefType::Register3x; break;
    case '4': r.type = RefType::Register4x; break;
    default: return std::nullopt;
  }
  std::uint32_t number = 0;
  for (char c : text.substr(1)) number = number * 10 + static_cast<std::uint32_t>(c - '0');
  if (number == 0 || number > 65535) return std::nullopt;
  r.index = number - 1;
  return r;
}

std::string format_reference(const Reference& r) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%u%05u", static_cast<unsigned>(r.type),
                static_cast<unsigned>(r.index + 1));
  return buf;
}

}  // namespace pbvbus::quantum
