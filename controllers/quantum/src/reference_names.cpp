#include "pbvbus/quantum/reference_names.hpp"

#include <cstdio>

namespace pbvbus::quantum {

std::string reference_name(RefType type, std::uint32_t index) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%u%05lu", static_cast<unsigned>(type),
                static_cast<unsigned long>(index) + 1UL);
  return buf;
}

}  // namespace pbvbus::quantum
