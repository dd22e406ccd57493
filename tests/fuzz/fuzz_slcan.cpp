// libFuzzer target for the SLCAN parser and session (gateways/slcan.hpp): any byte stream, fed
// in two pieces, must be answered line by line (exactly one '\r' or '\a' per line handled),
// every frame accepted from the host must be a valid CAN frame that the encoder writes and the
// parser reads back unchanged, and parse_line on the whole input gives a command or an error.
//   build-fuzz/bin/fuzz_slcan -max_total_time=60 <scratch corpus dir> tests/fuzz/corpus/slcan
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/gateways/slcan.hpp"

using namespace pbvbus::gateways;

static void check_frame(const CanFrame& f) {
  if (f.dlc > 8) __builtin_trap();
  if (f.id > (f.extended ? 0x1FFFFFFFu : 0x7FFu)) __builtin_trap();
  std::string line = slcan::encode_frame(f);
  if (line.empty() || line.back() != '\r') __builtin_trap();
  line.pop_back();
  const slcan::Parsed p = slcan::parse_line(line);
  if (!p.command || !(p.command->frame == f)) __builtin_trap();
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  const slcan::Parsed whole = slcan::parse_line(all);
  if (whole.command.has_value() == !whole.error.empty()) __builtin_trap();
  if (whole.command && whole.command->op == slcan::Op::Send) check_frame(whole.command->frame);

  slcan::SlcanSession s;
  std::string reply;
  std::vector<CanFrame> to_bus;
  const std::size_t cut = size == 0 ? 0 : data[0] % (size + 1);
  s.feed(all.substr(0, cut), reply, to_bus);
  s.feed(all.substr(cut), reply, to_bus);
  const auto terminators = static_cast<std::uint64_t>(
      std::count(reply.begin(), reply.end(), '\r') + std::count(reply.begin(), reply.end(), '\a'));
  if (terminators != s.stats().lines) __builtin_trap();
  if (to_bus.size() != s.stats().frames_in) __builtin_trap();
  for (const CanFrame& f : to_bus) check_frame(f);
  (void)s.frame_to_host(CanFrame{}, 0);
  return 0;
}
