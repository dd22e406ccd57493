// libFuzzer target for the capture reader as replay's input (docs/replay.md: truncated
// blocks, wrong lengths, unknown block types, huge captured lengths): the bytes go through
// captures::read_pcapng AND through the whole path `pbvbus replay` takes with them
// (build_replay_input, replay_plan, the report's field names). Either a clear error or results
// that agree with the input: every record inside the file, every frame's octets and DU inside
// it, pairing both ways, and the replay input's frames the reader's records of that line.
//   build-fuzz/bin/fuzz_pcapng -max_total_time=60 <scratch corpus dir> tests/fuzz/corpus/pcapng
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/conformance/replay.hpp"
#include "pbvbus/conformance/replay_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pbvbus;
  const std::span<const std::uint8_t> in(data, size);
  captures::PcapngError perr;
  const auto cap = captures::read_pcapng(in, perr);
  if (!cap) {
    if (perr.message.empty() || perr.offset > size) __builtin_trap();
  } else {
    for (const auto& r : cap->records) {
      if (r.offset >= size || r.interface >= cap->interfaces.size()) __builtin_trap();
      if (r.bytes.size() > size) __builtin_trap();
    }
  }
  std::string err;
  const auto ri = conformance::build_replay_input(in, {}, err);
  if (!ri) {
    if (err.empty()) __builtin_trap();
    return 0;
  }
  // A whole file the reader accepts gives the replay input exactly its records of that line.
  if (cap) {
    std::size_t n = 0;
    for (const auto& r : cap->records) n += r.interface == ri->interface;
    if (n != ri->frames.size() || !ri->read_error.empty()) __builtin_trap();
  }
  for (std::size_t k = 0; k < ri->frames.size(); ++k) {
    const auto& f = ri->frames[k];
    if (f.offset >= size || f.bytes.size() > size || f.end < f.start) __builtin_trap();
    if ((f.role == conformance::ReplayRole::Unusable) == f.unusable_reason.empty()) __builtin_trap();
    if (f.role != conformance::ReplayRole::Unusable && f.du_offset + f.du_len > f.bytes.size())
      __builtin_trap();
    if (f.reply >= 0 && (static_cast<std::size_t>(f.reply) >= ri->frames.size() ||
                         ri->frames[static_cast<std::size_t>(f.reply)].request != static_cast<int>(k)))
      __builtin_trap();
    if (conformance::frame_field_names(f.bytes).size() != f.bytes.size()) __builtin_trap();
    (void)conformance::replay_service_name(f);
  }
  for (std::size_t i : conformance::replay_plan(*ri, {}))
    if (i >= ri->frames.size()) __builtin_trap();
  return 0;
}
