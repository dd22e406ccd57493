#pragma once
// The rig and oracle for the state-RAM Modbus core on arbitrary input (the seeded parser test
// in tests/gateways and the libFuzzer target tests/fuzz/fuzz_state_ram_modbus.cpp): input =
// unit id (first octet) + request PDU, handed to two handlers over the same two state RAMs (one
// Silent, one answering 0x0B for an unknown unit). The oracle's checks are written from the
// Modbus Application Protocol V1.1b3 §6/§7, not from the handler:
//  - an answer is at most 253 octets; its function code is the request's (bit 7 aside);
//  - unknown unit: Silent answers nothing, the gateway variant answers FC|80 0B;
//  - a request the decoder refuses gets FC|80 + the decoder's exception;
//  - a normal read answer has 2 + byte count octets (bits: ceil(q/8), registers: 2q);
//  - no Modbus request ever changes 1x or 3x.
// Returns an empty string when every check holds, else what failed.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "pbvbus/gateways/state_ram_modbus.hpp"

namespace pbvbus::gateways::test {

struct StateRamModbusRig {
  StateRamModbusRig();
  quantum::StateRam a;  ///< unit 1 and broadcast
  quantum::StateRam b;  ///< unit 129
  std::unique_ptr<StateRamModbusHandler> silent;
  std::unique_ptr<StateRamModbusHandler> gateway;
  std::uint64_t hook_calls = 0;
};

std::string check_state_ram_modbus(StateRamModbusRig& rig, std::span<const std::uint8_t> input);

}  // namespace pbvbus::gateways::test
