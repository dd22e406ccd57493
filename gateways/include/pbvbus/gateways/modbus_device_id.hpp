#pragma once
// The FC43/14 Read Device Identification answer (Modbus Application Protocol V1.1b3 §6.21) for
// the basic objects, shared by the Modbus cores of this layer (docs/gateway-modbus.md):
// VendorName (0), ProductCode (1), MajorMinorRevision (2). Conformity level 0x81 (basic,
// stream and individual access); codes 1..3 answer the basic objects from `object_id` on (an
// unknown object id restarts at 0 for stream access), code 4 (individual access) answers one
// object and an unknown object id is 0x02. Each object is cut to 64 octets, so 3 objects of
// ≤ 66 octets always fit one PDU.

#include <array>
#include <cstddef>
#include <span>
#include <string>

#include "pbvbus/gateways/modbus_handler.hpp"
#include "pbvbus/gateways/modbus_pdu.hpp"

namespace pbvbus::gateways {

/// `rq` is a decoded FC43/14 request (read_device_id_code 1..4). Returns the response length.
std::size_t modbus_device_id_response(const ModbusRequest& rq, std::array<std::string, 3> objects,
                                      std::span<std::uint8_t, kModbusMaxPdu> rsp);

}  // namespace pbvbus::gateways
