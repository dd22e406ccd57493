#include "pbvbus/gateways/modbus_device_id.hpp"

namespace pbvbus::gateways {

std::size_t modbus_device_id_response(const ModbusRequest& rq, std::array<std::string, 3> objects,
                                      std::span<std::uint8_t, kModbusMaxPdu> rsp) {
  for (auto& o : objects)
    if (o.size() > 64) o.resize(64);  // 3 objects of ≤ 66 octets always fit one PDU
  std::uint8_t first = rq.object_id;
  std::uint8_t last = 2;
  if (rq.read_device_id_code == 4) {
    if (first > 2) {
      rsp[0] = kFcEncapsulatedInterface | 0x80;
      rsp[1] = kExIllegalDataAddress;
      return 2;
    }
    last = first;
  } else if (first > 2) {
    first = 0;  // stream access with an unknown object id restarts at the beginning
  }
  std::size_t n = 0;
  rsp[n++] = kFcEncapsulatedInterface;
  rsp[n++] = kMeiReadDeviceId;
  rsp[n++] = rq.read_device_id_code;
  rsp[n++] = 0x81;  // conformity: basic identification, stream and individual access
  rsp[n++] = 0x00;  // more follows: no
  rsp[n++] = 0x00;  // next object id
  rsp[n++] = static_cast<std::uint8_t>(last - first + 1);
  for (std::uint8_t id = first; id <= last; ++id) {
    rsp[n++] = id;
    rsp[n++] = static_cast<std::uint8_t>(objects[id].size());
    for (char c : objects[id]) rsp[n++] = static_cast<std::uint8_t>(c);
  }
  return n;
}

}  // namespace pbvbus::gateways
