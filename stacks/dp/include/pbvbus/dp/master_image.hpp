#pragma once
// The class-1 master's process image of one DP slave (design.md "Consistent data";
// protocol-facts.md §F, S7 SFC 14 DPRD_DAT / SFC 15 DPWR_DAT): what the user program, a gateway
// or a test reads and writes from any thread while dp::Master runs on the bus thread.
//
// - Outputs: one ConsistentBuffer (seqlock) per module. The user replaces a module's outputs
//   whole (write_outputs, DPWR_DAT); the bus takes one snapshot per Data_Exchange, module by
//   module, so every module in a telegram comes from one user write.
// - Inputs: one ConsistentBuffer holding the whole input telegram. The bus publishes every
//   Data_Exchange response whole, so read_inputs() of one module (DPRD_DAT) and
//   read_all_inputs() of the slave both see the inputs of one telegram, never a mix.
// - The length given must equal the module's configured length (as DPRD_DAT/DPWR_DAT demand);
//   anything else is refused with ImageAccess::WrongLength and nothing is copied.
//
// Decision: inputs keep their last value when the slave leaves data exchange (as an S7 process
// image does); data_valid() tells whether they are current. Reads and writes never allocate.

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "pbvbus/dp/process_image.hpp"
#include "pbvbus/dp/slave_config.hpp"

namespace pbvbus::dp {

enum class ImageAccess : std::uint8_t {
  Ok,
  NoSuchModule,
  WrongLength,  ///< length ≠ the module's configured length (S7: W#16#808x area length error)
};
std::string_view to_string(ImageAccess a);

class MasterImage {
 public:
  explicit MasterImage(const SlaveLayout& layout);
  MasterImage(const MasterImage&) = delete;
  MasterImage& operator=(const MasterImage&) = delete;

  std::size_t modules() const { return m_layout.size(); }
  const ModuleLayout& module(std::size_t m) const { return m_layout[m]; }
  std::size_t input_length() const { return m_inputs.size(); }
  std::size_t output_length() const { return m_output_len; }

  // --- user side (any thread) ---
  /// DPRD_DAT: copies a module's inputs, all from one Data_Exchange response.
  ImageAccess read_inputs(std::size_t module, std::span<std::uint8_t> out) const;
  /// All inputs of the slave, from one response. `out.size()` must equal input_length().
  ImageAccess read_all_inputs(std::span<std::uint8_t> out) const;
  /// DPWR_DAT: replaces a module's outputs as one unit.
  ImageAccess write_outputs(std::size_t module, std::span<const std::uint8_t> data);
  /// Reads back what the user last wrote to a module's outputs.
  ImageAccess read_outputs(std::size_t module, std::span<std::uint8_t> out) const;
  /// Number of input telegrams published so far (changes with every response).
  std::uint32_t inputs_generation() const { return m_inputs.generation(); }
  /// True while the slave is in data exchange with this master (inputs are current).
  bool data_valid() const { return m_valid.load(std::memory_order_acquire); }

  // --- bus side (the master's thread) ---
  /// Output telegram for one Data_Exchange: each module from one user write.
  void snapshot_outputs(std::span<std::uint8_t> telegram) const;
  /// Publishes one response's inputs whole; ignored unless telegram.size() == input_length().
  void publish_inputs(std::span<const std::uint8_t> telegram);
  void set_valid(bool v) { m_valid.store(v, std::memory_order_release); }

 private:
  std::vector<ModuleLayout> m_layout;
  std::size_t m_output_len = 0;
  std::vector<std::unique_ptr<ConsistentBuffer>> m_out;
  ConsistentBuffer m_inputs;
  std::atomic<bool> m_valid{false};
};

}  // namespace pbvbus::dp
