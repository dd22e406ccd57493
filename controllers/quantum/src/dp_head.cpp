// One rack's DP master module (dp_head.hpp).
#include "pbvbus/quantum/dp_head.hpp"

#include <algorithm>

namespace pbvbus::quantum {

DpHead::DpHead(const dp::MasterParams& master, std::vector<dp::SlaveParams> slaves,
               const fdl::BusParams& params, std::vector<DpIoMap> map, bus::Ticks silence_bound)
    : m_master(master, std::move(slaves)), m_map(std::move(map)), m_bound(silence_bound),
      m_tbit(bus::ticks_per_bit(params.baud)) {
  m_station = std::make_unique<fdl::ActiveStation>(master.address, params, *this);
  for (const DpIoMap& e : m_map) {
    const dp::MasterImage& img = m_master.image(e.slave);
    m_buf.reserve(std::max({m_buf.capacity(), img.input_length(), img.output_length()}));
  }
}

void DpHead::attach(bus::Line& line, std::string label) {
  m_line = &line;
  m_att = line.attach(*m_station, std::move(label));
}

void DpHead::set_role(bus::Ticks now, HeadRole role) {
  if (role == m_role) return;
  const HeadRole was = m_role;
  m_role = role;
  switch (role) {
    case HeadRole::Off:
      if (m_line != nullptr) m_line->set_power(m_att, false);
      return;
    case HeadRole::Passive:
      // Listen first, then power (a module that comes up passive never sends anything).
      m_master.set_standby(true);
      m_station->set_passive(true, now);
      m_last_heard = bus::kNever;
      m_last_start = bus::kNever;
      if (was == HeadRole::Off && m_line != nullptr) m_line->set_power(m_att, true);
      return;
    case HeadRole::Active:
      if (was == HeadRole::Passive) {
        // docs/quantum-hsby-dp.md: the shadow's slaves resume without Set_Prm, then the station
        // claims the token after TTO of silence.
        m_master.take_over(now);
        m_station->set_passive(false, now);
        return;
      }
      // From Off: a module that powers up as the only primary starts its slaves normally.
      m_master.set_standby(false);
      m_station->set_passive(false, now);
      if (m_line != nullptr) m_line->set_power(m_att, true);
      return;
  }
}

void DpHead::read_inputs(StateRam& ram) {
  for (const DpIoMap& e : m_map) {
    const dp::MasterImage& img = m_master.image(e.slave);
    const std::size_t n = img.input_length();
    if (n == 0) continue;
    m_buf.resize(n);
    (void)img.read_all_inputs(m_buf);
    if (e.inputs.type == RefType::Input1x) {
      for (std::size_t i = 0; i < n * 8; ++i) {
        const auto at = static_cast<std::uint32_t>(e.inputs.index + i);
        if (at >= ram.count(RefType::Input1x)) break;
        ram.set_input(at, ((m_buf[i / 8] >> (i % 8)) & 1) != 0);
      }
    } else {
      for (std::size_t i = 0; i < n; i += 2) {
        const auto at = static_cast<std::uint32_t>(e.inputs.index + i / 2);
        if (at >= ram.count(RefType::Register3x)) break;
        const std::uint16_t lo = i + 1 < n ? m_buf[i + 1] : 0;
        ram.set_input_reg(at, static_cast<std::uint16_t>((m_buf[i] << 8) | lo));
      }
    }
  }
}

void DpHead::write_outputs(const StateRam& ram) {
  for (const DpIoMap& e : m_map) {
    dp::MasterImage& img = m_master.image(e.slave);
    const std::size_t n = img.output_length();
    if (n == 0) continue;
    m_buf.assign(n, 0);
    if (e.outputs.type == RefType::Coil0x) {
      for (std::size_t i = 0; i < n * 8; ++i) {
        const auto at = static_cast<std::uint32_t>(e.outputs.index + i);
        if (at >= ram.count(RefType::Coil0x)) break;
        if (ram.coil(at)) m_buf[i / 8] = static_cast<std::uint8_t>(m_buf[i / 8] | (1u << (i % 8)));
      }
    } else {
      for (std::size_t i = 0; i < n; i += 2) {
        const auto at = static_cast<std::uint32_t>(e.outputs.index + i / 2);
        if (at >= ram.count(RefType::Register4x)) break;
        const std::uint16_t w = ram.holding(at);
        m_buf[i] = static_cast<std::uint8_t>(w >> 8);
        if (i + 1 < n) m_buf[i + 1] = static_cast<std::uint8_t>(w & 0xFF);
      }
    }
    std::size_t off = 0;
    for (std::size_t m = 0; m < img.modules(); ++m) {
      const std::size_t len = img.module(m).out_len;
      if (len == 0) continue;
      (void)img.write_outputs(m, std::span<const std::uint8_t>(m_buf).subspan(off, len));
      off += len;
    }
  }
}

bool DpHead::hears_active_master(bus::Ticks now) const {
  return m_role == HeadRole::Passive && m_last_heard != bus::kNever && now - m_last_heard <= m_bound;
}

bool DpHead::heard_since(bus::Ticks since, bus::Ticks now) const {
  (void)now;
  return m_role == HeadRole::Passive && m_last_start != bus::kNever && m_last_start >= since;
}

namespace {

/// Octets of a telegram on the wire (IEC 61158-4-3 frame formats): SC 1, SD4 3, SD1 6, SD3 14,
/// SD2 LE + 6 with LE = DA SA FC + the address extension octets + the DU.
std::size_t dph_octets(const fdl::Telegram& t) {
  switch (t.type) {
    case fdl::FrameType::SC: return 1;
    case fdl::FrameType::SD4: return 3;
    case fdl::FrameType::SD1: return 6;
    case fdl::FrameType::SD3: return 14;
    case fdl::FrameType::SD2: break;
  }
  const std::size_t ext = (t.dsap ? 1 : 0) + (t.ssap ? 1 : 0) + (t.da_segment ? 1 : 0) +
                          (t.sa_segment ? 1 : 0);
  return 3 + ext + t.data.size() + 6;
}

}  // namespace

void DpHead::on_power_on(bus::Ticks now) {
  m_last_heard = bus::kNever;
  m_last_start = bus::kNever;
  m_master.on_power_on(now);
}

bool DpHead::next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) {
  return m_master.next_request(prio, now, out);
}

void DpHead::on_confirmation(const fdl::Confirmation& con) { m_master.on_confirmation(con); }

void DpHead::on_request(const fdl::Indication& ind, fdl::Reply& reply) {
  m_master.on_request(ind, reply);
}

void DpHead::on_token(bus::Ticks now, bus::Ticks trr) { m_master.on_token(now, trr); }

void DpHead::on_observed(bus::Ticks now, const fdl::Telegram& t) {
  if (t.sa == m_station->address()) {
    m_last_heard = now;
    m_last_start = now - static_cast<bus::Ticks>(dph_octets(t) * 11) * m_tbit;
  }
  m_master.on_observed(now, t);
}

}  // namespace pbvbus::quantum
