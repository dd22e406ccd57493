// libFuzzer target for the Quantum state-RAM Modbus core (state_ram_modbus.hpp): input = unit
// id (first octet) + request PDU, through a Silent and a 0x0B-answering handler over two state
// RAMs; the oracle (tests/gateways/state_ram_modbus_oracle.hpp, shared with the seeded parser
// test) checks the answer's shape, the decoder's exceptions and that 1x/3x never change.
//   build-fuzz/bin/fuzz_state_ram_modbus -max_total_time=60 <scratch dir>
//   tests/fuzz/corpus/state_ram_modbus
#include <cstddef>
#include <cstdint>
#include <span>

#include "state_ram_modbus_oracle.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static pbvbus::gateways::test::StateRamModbusRig rig;
  if (!pbvbus::gateways::test::check_state_ram_modbus(rig, std::span(data, size)).empty())
    __builtin_trap();
  return 0;
}
