#pragma once
// The memory areas of an S7 CPU model as Read Var / Write Var address them (protocol-facts.md
// §H.4 area codes; docs/s7cpu.md): data blocks (DB), flags (M), the process images of the inputs
// (I/E) and outputs (Q/A), counters (Z/C) and timers (T).
//
// The owner (a CPU model) sets the sizes, creates the DBs and reads/writes the areas from its
// user program; S7Server serves the same memory to clients.
//
// Consistency rule: the owner's thread is the only thread. The owner calls S7Server::handle()
// between two of its cycles; one Read Var item is copied out of the memory in that one call
// (one snapshot, never torn), one Write Var item is copied in in that call, and the owner sees it
// on its next cycle. Nothing here locks.
//
// Storage: by default the memory owns every area (sizes from CpuMemorySizes, DBs from
// create_db). An owner that keeps the bytes elsewhere (an H CPU's process images and work
// memory, controllers/s7h) binds areas, counters, timers and DBs to its own storage instead
// (bind, bind_counters, bind_timers, bind_db): the memory is then a view, and the owner keeps
// the storage alive and rebinds after it reallocates. Binding changes sizes() accordingly.
//
// Byte order: the CPU's, big-endian (S7 words and double words are stored high octet first).
// Counters and timers are 16-bit cells; a client reads or writes each as 2 octets, big-endian.
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <vector>

namespace pbvbus::s7cpu {

/// Sizes of the fixed areas, chosen by the CPU model (octets; cells for counters and timers).
struct CpuMemorySizes {
  std::size_t inputs = 128;
  std::size_t outputs = 128;
  std::size_t flags = 256;
  std::size_t counters = 256;
  std::size_t timers = 256;
};

/// The byte areas other than data blocks.
enum class Area : std::uint8_t { Inputs, Outputs, Flags };

class CpuMemory {
 public:
  explicit CpuMemory(const CpuMemorySizes& sizes = {});
  // The views point into the owned vectors: no copies (a move keeps the vectors' buffers).
  CpuMemory(const CpuMemory&) = delete;
  CpuMemory& operator=(const CpuMemory&) = delete;
  CpuMemory(CpuMemory&&) = default;
  CpuMemory& operator=(CpuMemory&&) = default;

  const CpuMemorySizes& sizes() const { return sizes_; }

  /// A DB of `size` octets, zero-filled; an existing DB of that number is replaced. Spans of a
  /// DB stay valid until it is replaced or deleted.
  void create_db(std::uint16_t number, std::size_t size);
  /// False if there was no such DB.
  bool delete_db(std::uint16_t number);
  /// A missing DB is a case of its own (Read/Write Var answer "object does not exist", 0x0A),
  /// distinct from an address past the end of an existing DB (0x05).
  bool has_db(std::uint16_t number) const;
  /// The DB's octets; nullopt for a missing DB.
  std::optional<std::span<std::uint8_t>> db(std::uint16_t number);
  std::optional<std::span<const std::uint8_t>> db(std::uint16_t number) const;

  std::span<std::uint8_t> area(Area a);
  std::span<const std::uint8_t> area(Area a) const;
  std::span<std::uint16_t> counters() { return counters_view_; }
  std::span<const std::uint16_t> counters() const { return counters_view_; }
  std::span<std::uint16_t> timers() { return timers_view_; }
  std::span<const std::uint16_t> timers() const { return timers_view_; }

  // ---- views of the owner's storage (the header comment) ----
  /// The area is `storage` from now on (its own octets are no longer used).
  void bind(Area a, std::span<std::uint8_t> storage);
  void bind_counters(std::span<std::uint16_t> storage);
  void bind_timers(std::span<std::uint16_t> storage);
  /// DB `number` is `storage` (replaces an owned or bound DB of that number).
  void bind_db(std::uint16_t number, std::span<std::uint8_t> storage);
  /// Removes every DB, owned and bound.
  void clear_dbs();

 private:
  struct Db {
    std::vector<std::uint8_t> owned;
    std::span<std::uint8_t> view;  ///< owned, or the owner's storage
  };
  CpuMemorySizes sizes_;
  std::vector<std::uint8_t> inputs_;
  std::vector<std::uint8_t> outputs_;
  std::vector<std::uint8_t> flags_;
  std::vector<std::uint16_t> counters_;
  std::vector<std::uint16_t> timers_;
  std::span<std::uint8_t> inputs_view_;
  std::span<std::uint8_t> outputs_view_;
  std::span<std::uint8_t> flags_view_;
  std::span<std::uint16_t> counters_view_;
  std::span<std::uint16_t> timers_view_;
  std::map<std::uint16_t, Db> dbs_;
};

// Byte and bit access for the owner's user program, on any area or DB span. Readers give
// nullopt and writers false when the address is outside the span (or bit > 7); nothing throws.
std::optional<bool> get_bit(std::span<const std::uint8_t> bytes, std::size_t byte,
                            unsigned bit);
bool set_bit(std::span<std::uint8_t> bytes, std::size_t byte, unsigned bit, bool value);
std::optional<std::uint8_t> get_byte(std::span<const std::uint8_t> bytes, std::size_t byte);
bool set_byte(std::span<std::uint8_t> bytes, std::size_t byte, std::uint8_t value);
/// WORD at `byte` (big-endian).
std::optional<std::uint16_t> get_word(std::span<const std::uint8_t> bytes, std::size_t byte);
bool set_word(std::span<std::uint8_t> bytes, std::size_t byte, std::uint16_t value);
/// DWORD at `byte` (big-endian; a REAL is its IEEE 754 bit pattern).
std::optional<std::uint32_t> get_dword(std::span<const std::uint8_t> bytes, std::size_t byte);
bool set_dword(std::span<std::uint8_t> bytes, std::size_t byte, std::uint32_t value);

}  // namespace pbvbus::s7cpu
