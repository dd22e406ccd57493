// libFuzzer target for the FDL telegram codec (protocol-facts.md §B).
//
// Every input is decoded; if decode() accepts it, the accepted frame must be valid and
// canonical: reencode() in the same frame type gives the same bytes (after the one documented
// non-canonical form, a segment octet after the SAP in an extension chain, is put into the
// encoder's order), the re-encoded frame decodes to the same fields, and frame_length() agrees.
// The same bytes are also read as a FrameSpec for the encoder: whatever encode()/encode_as()
// produces must decode to the same fields. Any violation traps, so libFuzzer reports it with
// the input. The oracle is in tests/stacks/fdl/telegram_oracle_helpers.cpp.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>

#include "telegram_oracle_helpers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  if (const char* why = pbvbus::test::decode_oracle(in)) {
    std::fprintf(stderr, "decode oracle: %s\n", why);
    __builtin_trap();
  }
  if (const char* why = pbvbus::test::encode_oracle(in)) {
    std::fprintf(stderr, "encode oracle: %s\n", why);
    __builtin_trap();
  }
  return 0;
}
