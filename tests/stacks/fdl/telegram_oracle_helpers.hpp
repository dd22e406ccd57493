#pragma once
// Round-trip oracles for the FDL telegram codec, shared by the seeded mutation test
// (telegram_mutation_parser_test.cpp) and the libFuzzer target (tests/fuzz). No gtest, no heap:
// each returns nullptr when the property holds, else a static description of what broke.
//
// decode_oracle(bytes): if decode() accepts the bytes, then
//   - the fields are in range (DA <= 127, SA <= 126, SAPs and segments <= 63, a segment only
//     with its SAP, data inside the input, SD4/SC without FC);
//   - reencode() succeeds and gives the input bytes, after the input's extension chains are put
//     into the encoder's order (segment octet before SAP octet: the one non-canonical form the
//     decoder accepts, see telegram.hpp);
//   - the re-encoded frame decodes to the same fields;
//   - frame_length() gives the input length, and 0 or that length for every proper prefix.
//   Whether accepted or not: frame_length() is -1, 0 or 1..kMaxFrame.
// encode_oracle(bytes): builds a FrameSpec from the bytes (see the .cpp for the layout) and
//   encodes it with encode() or encode_as(); if that succeeds the frame must decode to the same
//   fields, encode() must have chosen the frame type by §B.1, and frame_length() must agree.

#include <cstdint>
#include <span>

#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::test {

const char* decode_oracle(std::span<const std::uint8_t> bytes);
const char* encode_oracle(std::span<const std::uint8_t> bytes);

/// Copies `in` (a frame decode() accepted as `t`) into `out` with its extension chains in the
/// encoder's order; returns the length (in.size()).
std::size_t canonical_chain_order(std::span<const std::uint8_t> in, const fdl::Telegram& t,
                                  std::uint8_t* out);

}  // namespace pbvbus::test
