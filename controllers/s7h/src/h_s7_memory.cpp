// The S7 memory layout of an H CPU (h_s7_memory.hpp).
#include "pbvbus/s7h/h_s7_memory.hpp"

#include <algorithm>
#include <set>

namespace pbvbus::devices {

std::vector<std::string> validate(const HS7MemoryConfig& c) {
  std::vector<std::string> out;
  std::set<std::uint16_t> seen;
  std::size_t total = c.flags;
  for (const HS7Db& d : c.dbs) {
    if (d.number == 0) out.push_back("DB 0 is not a data block (numbers start at 1)");
    if (!seen.insert(d.number).second)
      out.push_back("DB " + std::to_string(d.number) + " is configured twice");
    total += std::min(d.size, kMaxS7Memory + 1);
  }
  if (total > kMaxS7Memory)
    out.push_back("flags and DBs need " + std::to_string(total) + " octets, more than " +
                  std::to_string(kMaxS7Memory));
  if (c.counters > 0xFFFF || c.timers > 0xFFFF)
    out.push_back("counters and timers are numbered with 16 bits (at most 65535)");
  if (c.order_number.size() > 20) out.push_back("the order number has more than 20 characters");
  return out;
}

HS7Layout layout(const HS7MemoryConfig& c, std::size_t program_memory) {
  HS7Layout l;
  l.flags = std::max(c.flags, program_memory);
  std::size_t at = l.flags;
  for (const HS7Db& d : c.dbs) {
    l.dbs.push_back({d.number, at, d.size});
    at += d.size;
  }
  l.total = at;
  return l;
}

}  // namespace pbvbus::devices
