#pragma once
// Consistent process data hand-over between the bus and a device model or gateway running in
// another thread (design.md "Consistent data"; protocol-facts.md §F): a module's bytes are never
// observed half old, half new.
//
// ConsistentBuffer is a sequence lock over atomic 64-bit words: writers (any number, serialised
// by the sequence word) never wait for readers; a reader retries while a write is in progress
// and never blocks the bus thread. Memory order without fences (which ThreadSanitizer cannot
// model): the writer takes the odd sequence with an acquire RMW, stores data words with release;
// the reader loads data words with acquire, so a reader that saw any new word also sees the
// sequence move and retries. On x86 these are plain moves. The data words are atomics, so the
// scheme is free of data races in the C++ memory model. Reads and writes never allocate.

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "pbvbus/dp/slave_config.hpp"

namespace pbvbus::dp {

class ConsistentBuffer {
 public:
  explicit ConsistentBuffer(std::size_t len = 0);
  ConsistentBuffer(const ConsistentBuffer&) = delete;
  ConsistentBuffer& operator=(const ConsistentBuffer&) = delete;

  std::size_t size() const { return m_len; }
  /// Replaces the whole content. `data.size()` must equal size() (else nothing happens and false
  /// is returned).
  bool write(std::span<const std::uint8_t> data);
  /// Sets every byte to `value`.
  void fill(std::uint8_t value);
  /// Copies the whole content, from one write. `out.size()` must equal size().
  bool read(std::span<std::uint8_t> out) const;
  /// Like read(), but gives up (returns false, `out` undefined) after `attempts` tries that met
  /// a write in progress: for a reader that must not wait for a writer thread that may have
  /// been preempted in the middle of its copy.
  bool try_read(std::span<std::uint8_t> out, int attempts) const;
  /// Number of completed writes (changes whenever the content was replaced).
  std::uint32_t generation() const { return m_seq.load(std::memory_order_acquire) / 2; }

 private:
  std::uint32_t begin_write();
  void end_write(std::uint32_t s);

  std::size_t m_len = 0;
  std::size_t m_words = 0;
  std::unique_ptr<std::atomic<std::uint64_t>[]> m_data;
  std::atomic<std::uint32_t> m_seq{0};  ///< odd while a write is in progress
};

/// Inputs and outputs of every module of a slave, one ConsistentBuffer per module and
/// direction, laid out as in the Data_Exchange telegrams.
class ProcessImage {
 public:
  explicit ProcessImage(const SlaveLayout& layout);

  std::size_t modules() const { return m_layout.size(); }
  const ModuleLayout& module(std::size_t m) const { return m_layout[m]; }
  ConsistentBuffer& inputs(std::size_t m) { return *m_in[m]; }
  ConsistentBuffer& outputs(std::size_t m) { return *m_out[m]; }
  const ConsistentBuffer& inputs(std::size_t m) const { return *m_in[m]; }
  const ConsistentBuffer& outputs(std::size_t m) const { return *m_out[m]; }

  /// Bus side: assembles the input telegram, every module from one write of that module. Never
  /// waits for a device thread: a module whose writer is busy right now (e.g. preempted in the
  /// middle of its copy) contributes the complete value the bus read last time. Bus thread only.
  void read_all_inputs(std::span<std::uint8_t> telegram);
  /// Bus side: hands the output telegram to the device, module by module.
  void write_all_outputs(std::span<const std::uint8_t> telegram);
  /// Bus side: outputs to the safe state (all zero).
  void clear_outputs();

 private:
  std::vector<ModuleLayout> m_layout;
  std::vector<std::uint8_t> m_last_inputs;  ///< last complete input telegram (bus thread)
  std::vector<std::unique_ptr<ConsistentBuffer>> m_in;
  std::vector<std::unique_ptr<ConsistentBuffer>> m_out;
};

}  // namespace pbvbus::dp
