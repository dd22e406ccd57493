// The node and PDO map of the CANopen gateway (canopen_gateway.hpp): which slave is which node,
// how many PDOs carry its octets, and what cannot be mapped.
#include <algorithm>
#include <cstdio>
#include <string>

#include "pbvbus/gateways/canopen_gateway.hpp"

namespace pbvbus::gateways {

namespace {

std::string fmt(const char* f, unsigned a, unsigned b = 0, unsigned c = 0, unsigned d = 0) {
  char buf[200];
  int n = std::snprintf(buf, sizeof buf, f, a, b, c, d);
  return std::string(buf, n > 0 ? static_cast<std::size_t>(std::min(n, 199)) : 0);
}

std::size_t pdos_for(std::size_t octets) {
  return std::min(canopen::kPdoCount, (octets + canopen::kPdoOctets - 1) / canopen::kPdoOctets);
}

}  // namespace

CanopenMap build_canopen_map(std::span<const SourceSlave> slaves, const CanopenOptions& opt) {
  CanopenMap m;
  // node id → address that holds it. Explicit entries are placed first so that a remapped
  // slave keeps its node even when another slave's address equals it (that one is unmapped).
  std::array<int, 128> owner;
  owner.fill(-1);
  std::vector<int> node_of(slaves.size(), -1);
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 0; i < slaves.size(); ++i) {
      const auto& s = slaves[i];
      const auto it = opt.node_ids.find(s.address);
      const bool explicit_entry = it != opt.node_ids.end();
      if (explicit_entry != (pass == 0)) continue;
      const unsigned node = explicit_entry ? it->second : s.address;
      if (node < canopen::kMinNode || node > canopen::kMaxNode) {
        m.warnings.push_back(fmt("slave %u: node id %u is outside 1..127; the slave is not mapped",
                                 s.address, node));
        continue;
      }
      if (owner[node] >= 0) {
        m.warnings.push_back(fmt("slave %u: node id %u is already slave %u's; the slave is not mapped",
                                 s.address, node, static_cast<unsigned>(owner[node])));
        continue;
      }
      owner[node] = s.address;
      node_of[i] = static_cast<int>(node);
    }
  }
  for (const auto& [addr, node] : opt.node_ids) {
    const bool known = std::any_of(slaves.begin(), slaves.end(),
                                   [a = addr](const SourceSlave& s) { return s.address == a; });
    if (!known)
      m.warnings.push_back(fmt("node map: address %u is not a slave of this master system (node %u "
                               "ignored)", addr, node));
  }
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    if (node_of[i] < 0) continue;
    const auto& s = slaves[i];
    CanopenNode n;
    n.address = s.address;
    n.node = static_cast<std::uint8_t>(node_of[i]);
    n.name = s.name;
    n.input_len = s.input_len;
    n.output_len = s.output_len;
    n.tpdos = pdos_for(s.input_len);
    n.rpdos = pdos_for(s.output_len);
    n.outputs_writable = s.outputs_writable;
    if (s.input_len > canopen::kMappedOctets)
      m.warnings.push_back(fmt("slave %u (node %u): input octets 32..%u are not mapped (TPDO1..4 "
                               "carry 32 octets)", s.address, n.node,
                               static_cast<unsigned>(s.input_len - 1)));
    if (s.output_len > canopen::kMappedOctets)
      m.warnings.push_back(fmt("slave %u (node %u): output octets 32..%u are not mapped (RPDO1..4 "
                               "carry 32 octets)", s.address, n.node,
                               static_cast<unsigned>(s.output_len - 1)));
    m.nodes.push_back(std::move(n));
  }
  return m;
}

std::string to_text(const CanopenMap& m) {
  std::string out;
  for (const auto& n : m.nodes) {
    out += fmt("node %u = slave %u \"", n.node, n.address) + n.name +
           fmt("\": %u input octets, %u output octets\n", static_cast<unsigned>(n.input_len),
               static_cast<unsigned>(n.output_len));
    if (!n.outputs_writable) out.insert(out.size() - 1, " (outputs read-only)");
    for (std::size_t i = 0; i < n.tpdos; ++i) {
      const std::size_t first = i * 8, last = std::min(n.input_len, first + 8) - 1;
      out += fmt("  TPDO%u %03X  inputs %u..%u\n", static_cast<unsigned>(i + 1),
                 canopen::kCobTpdo[i] + n.node, static_cast<unsigned>(first),
                 static_cast<unsigned>(last));
    }
    for (std::size_t i = 0; i < n.rpdos; ++i) {
      const std::size_t first = i * 8, last = std::min(n.output_len, first + 8) - 1;
      out += fmt("  RPDO%u %03X  outputs %u..%u\n", static_cast<unsigned>(i + 1),
                 canopen::kCobRpdo[i] + n.node, static_cast<unsigned>(first),
                 static_cast<unsigned>(last));
    }
    out += fmt("  EMCY %03X  heartbeat %03X  SDO %03X/%03X\n", canopen::kCobEmcy + n.node,
               canopen::kCobHeartbeat + n.node, canopen::kCobSdoRx + n.node,
               canopen::kCobSdoTx + n.node);
  }
  for (const auto& w : m.warnings) out += "warning: " + w + "\n";
  return out;
}

}  // namespace pbvbus::gateways
