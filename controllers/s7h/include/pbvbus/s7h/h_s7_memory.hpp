#pragma once
// How an H CPU's memory appears over S7 communication (docs/h-system.md "S7 communication";
// protocol-facts.md §H.4 areas). Part of the pair's configuration: both CPUs have the same
// layout, as they run the same program on the same memory (seeds-digest.md §5 "identical
// values").
//
//   I (area 81)   = the CPU's PII (process-image input table, ProcessImage::pii)
//   Q (area 82)   = the CPU's PIQ (ProcessImage::piq)
//   M (area 83)   = the first flags_size() octets of ProcessImage::memory: the user program's
//                   state from MB 0 up (docs/h-programs.md: counters, then monitors), the rest
//                   free flags. So "what the program writes is what a client reads": a
//                   counter's state is MB <its offset>.
//   DB n (84)     = the configured DBs, in configuration order, after the flags in the same
//                   memory area.
//   C, T (1C, 1D) = counters and timers, 16-bit cells per CPU (not in the memory area).
//
// The memory area therefore holds flags and DBs: the redundant comparison (PIQ + memory,
// h_redundant_execution.hpp) covers what clients write, and the update copies it (digest §4
// step 9: "outputs and re-modified DBs ..., then timers, counters, memory bits, inputs").
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pbvbus::devices {

struct HS7Db {
  std::uint16_t number = 1;  ///< 1..65535, unique
  std::size_t size = 0;      ///< octets (0 allowed: it exists, every address is out of range)
};

struct HS7MemoryConfig {
  /// M area octets; grows to the program's memory size if that is larger.
  std::size_t flags = 256;
  std::size_t counters = 256;
  std::size_t timers = 256;
  std::vector<HS7Db> dbs;
  /// SZL 0011 order number (MLFB); empty = the profile's default (h_system.hpp
  /// s7_order_number).
  std::string order_number;
};

/// Messages for a bad configuration (DB 0, duplicate numbers, a total memory area above
/// kMaxS7Memory); empty when fine.
std::vector<std::string> validate(const HS7MemoryConfig& c);

/// Largest memory area (flags + DBs), octets: the work memory of a CPU 417-5H is far larger;
/// this bound keeps a typo from allocating gigabytes.
inline constexpr std::size_t kMaxS7Memory = 16 * 1024 * 1024;

/// Where the areas lie in ProcessImage::memory for a program needing `program_memory` octets.
struct HS7Layout {
  std::size_t flags = 0;  ///< M octets: max(config flags, program memory)
  struct Db {
    std::uint16_t number = 0;
    std::size_t offset = 0;
    std::size_t size = 0;
  };
  std::vector<Db> dbs;
  std::size_t total = 0;  ///< flags + every DB
};
HS7Layout layout(const HS7MemoryConfig& c, std::size_t program_memory);

}  // namespace pbvbus::devices
