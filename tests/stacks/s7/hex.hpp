#pragma once
// Octets from the hex text of the reference notes ("03 00 00 16 ..."; spaces and '|' ignored),
// so the golden sequences in the tests read as they are printed in tools-and-formats.md §3.4
// and protocol-facts.md §H.4.
#include <cstdint>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace pbvbus::s7::test {

inline std::vector<std::uint8_t> hex(std::string_view text) {
  std::vector<std::uint8_t> out;
  int hi = -1;
  for (const char c : text) {
    int v = -1;
    if (c >= '0' && c <= '9')
      v = c - '0';
    else if (c >= 'a' && c <= 'f')
      v = c - 'a' + 10;
    else if (c >= 'A' && c <= 'F')
      v = c - 'A' + 10;
    else if (c == ' ' || c == '|' || c == '\n')
      continue;
    else
      throw std::invalid_argument("hex: bad character");
    if (hi < 0) {
      hi = v;
    } else {
      out.push_back(static_cast<std::uint8_t>(hi * 16 + v));
      hi = -1;
    }
  }
  if (hi >= 0) throw std::invalid_argument("hex: odd number of digits");
  return out;
}

}  // namespace pbvbus::s7::test
