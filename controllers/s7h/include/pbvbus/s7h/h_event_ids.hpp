#pragma once
// S7 event IDs of the I/O error OBs as the H model raises them ("System Software for S7-300/400",
// the OBs' local data): EV_CLASS 39 = incoming, 38 = outgoing; OB 82 FLT_ID 42; OB 83 FLT_ID 61
// (module removed / inserted, type OK); OB 122 EV_CLASS 29, SW_FLT 42 read / 43 write.
// One place for every source file of the model that raises them.
#include <cstdint>

namespace pbvbus::devices::h_event {

inline constexpr std::uint16_t kOb82Incoming = 0x3942;
inline constexpr std::uint16_t kOb82Outgoing = 0x3842;
inline constexpr std::uint16_t kOb83Removed = 0x3961;
inline constexpr std::uint16_t kOb83Inserted = 0x3861;
inline constexpr std::uint16_t kOb122Read = 0x2942;
inline constexpr std::uint16_t kOb122Write = 0x2943;

}  // namespace pbvbus::devices::h_event
