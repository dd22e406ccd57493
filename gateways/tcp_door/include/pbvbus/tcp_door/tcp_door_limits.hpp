#pragma once
// What every TCP door (Modbus TCP, SLCAN over TCP, socketcand) shares in its options: the
// default client limit and the sink for the lines a door logs when it is under pressure.
//
// Decisions (docs/gateway-modbus-doors.md, docs/gateway-can-doors.md):
//  - Every TCP door has a client limit, 32 by default: each client costs a descriptor, and a
//    door without a limit let ~1020 idle connections exhaust a process limited to 1024, after
//    which no door (nor the pty of a serial attachment) could accept anything.
//  - A door logs what a user must know about (descriptor exhaustion, clients refused or
//    evicted) through DoorLog, never to a stream of its own choice: the program decides where
//    such lines go. An empty DoorLog logs nothing (the counters still count).

#include <cstddef>
#include <functional>
#include <string>

namespace pbvbus::gateways {

/// Receives one line (without a newline) per logged event.
using DoorLog = std::function<void(const std::string&)>;

/// Clients a TCP door serves at once unless its options say otherwise.
inline constexpr std::size_t kDefaultMaxClients = 32;

}  // namespace pbvbus::gateways
