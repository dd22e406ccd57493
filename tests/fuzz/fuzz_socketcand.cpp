// libFuzzer target for the socketcand parser and session (gateways/socketcand.hpp): any byte
// stream, fed in two pieces, must give only well-formed reply elements (`< ... >` with no
// delimiter inside), and every frame accepted from the client must be a valid CAN frame that a
// `send` element written from it parses back to unchanged.
//   build-fuzz/bin/fuzz_socketcand -max_total_time=60 <scratch corpus dir> \
//     tests/fuzz/corpus/socketcand
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/gateways/socketcand.hpp"

using namespace pbvbus::gateways;

static void check_frame(const CanFrame& f) {
  if (f.dlc > 8 || f.rtr) __builtin_trap();
  if (f.id > (f.extended ? 0x1FFFFFFFu : 0x7FFu)) __builtin_trap();
  char buf[32];
  std::snprintf(buf, sizeof buf, f.extended ? " send %08X %u" : " send %X %u",
                static_cast<unsigned>(f.id), static_cast<unsigned>(f.dlc));
  std::string text = buf;
  for (unsigned i = 0; i < f.dlc; ++i) {
    std::snprintf(buf, sizeof buf, " %x", f.data[i]);
    text += buf;
  }
  const socketcand::Parsed p = socketcand::parse_element(text + " ");
  if (!p.command || !(p.command->frame == f)) __builtin_trap();
}

static void check_element(const std::string& e) {
  if (e.size() < 4 || e.compare(0, 2, "< ") != 0 || e.compare(e.size() - 2, 2, " >") != 0)
    __builtin_trap();
  for (std::size_t i = 1; i + 1 < e.size(); ++i)
    if (e[i] == '<' || e[i] == '>') __builtin_trap();
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  const socketcand::Parsed whole = socketcand::parse_element(all);
  if (whole.command.has_value() == !whole.error.empty()) __builtin_trap();
  if (whole.command && whole.command->op == socketcand::Op::Send) check_frame(whole.command->frame);

  socketcand::SocketcandSession s;
  std::vector<std::string> replies;
  std::vector<CanFrame> to_bus;
  const std::size_t cut = size == 0 ? 0 : data[0] % (size + 1);
  s.feed(all.substr(0, cut), replies, to_bus);
  s.feed(all.substr(cut), replies, to_bus);
  for (const std::string& r : replies) check_element(r);
  if (to_bus.size() != s.stats().frames_in) __builtin_trap();
  for (const CanFrame& f : to_bus) check_frame(f);
  // A pushed frame is one space, then the element (python-can 4.1 eats that character).
  if (auto t = s.frame_to_client(CanFrame{}, 0)) {
    if (t->empty() || (*t)[0] != ' ') __builtin_trap();
    check_element(t->substr(1));
  }
  return 0;
}
