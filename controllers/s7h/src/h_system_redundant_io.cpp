// The H-system model running redundant two-channel I/O (h_redundant_io.hpp) on its process
// images: RED_IN after the inputs are read, RED_OUT on the outputs, RED_DIAG on OB 82/85 of a
// paired module, depassivation on OB 100, on entering Redundant and by FC 451. h_system.hpp
// (block "redundant I/O") and docs/h-redundant-io.md have the decisions.
#include <algorithm>
#include <stdexcept>

#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

void HSystemModel::set_redundant_io(const std::vector<RedIoPair>& pairs) {
  std::vector<RedIoPairSpec> specs;
  specs.reserve(pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const auto& p = pairs[i];
    const std::string n = "redundant I/O: pair " + std::to_string(i) + ": ";
    std::size_t addr[2] = {0, 0}, len[2] = {0, 0};
    const RedIoModule* ref[2] = {&p.a, &p.b};
    for (int k = 0; k < 2; ++k) {
      const HIoEntry* e = m_map.find(ref[k]->system, ref[k]->station, ref[k]->module);
      if (!e)
        throw std::invalid_argument(n + "no module " + std::to_string(ref[k]->module) +
                                    " at station " + std::to_string(ref[k]->station) +
                                    " of DP master system " + std::to_string(ref[k]->system + 1));
      const bool in = is_input(p.spec.kind);
      addr[k] = in ? e->in_addr : e->out_addr;
      len[k] = in ? e->in_len : e->out_len;
      if (len[k] == 0)
        throw std::invalid_argument(n + "module " + std::to_string(ref[k]->module) +
                                    " at station " + std::to_string(ref[k]->station) + " has no " +
                                    (in ? "inputs" : "outputs"));
    }
    if (len[0] != len[1])
      throw std::invalid_argument(n + "the modules differ in length (" + std::to_string(len[0]) +
                                  " / " + std::to_string(len[1]) + " octets)");
    RedIoPairSpec s = p.spec;
    // The valid value lives at the lower address (001 L5819-5822): that module is module_L.
    const int lo = addr[0] <= addr[1] ? 0 : 1;
    s.address_low = static_cast<std::uint32_t>(addr[lo]);
    s.address_high = static_cast<std::uint32_t>(addr[1 - lo]);
    s.length = static_cast<std::uint32_t>(len[0]);
    specs.push_back(s);
  }
  if (auto e = RedundantIo::validate(specs); !e.empty())
    throw std::invalid_argument("redundant I/O: " + e);
  m_red_io = specs.empty() ? nullptr : std::make_unique<RedundantIo>(std::move(specs));
  m_red_io_seen = 0;
}

bool HSystemModel::red_depa() {
  if (!m_red_io) return false;
  return m_red_io->request_depassivation(m_sched.now(), DepassivationTrigger::Fc451);
}

void HSystemModel::red_io_in(bus::Ticks now) {
  if (!m_red_io) return;
  // RED_IN is a block of the user program: it runs when OB 1 runs on some CPU.
  if (!m_pair.dp_master_operate(0) && !m_pair.dp_master_operate(1)) return;
  m_red_io->red_in(now, m_pii);
  red_io_flush();
}

std::span<const std::uint8_t> HSystemModel::red_io_out(std::span<const std::uint8_t> piq) {
  if (!m_red_io) return piq;
  m_red_io_out = m_red_io->red_out(piq);
  return m_red_io_out;
}

void HSystemModel::red_io_on_event(const HSystemEvent& e) {
  // RED_DIAG, called in OB 82 and OB 85 (001 Table 7-4 bits 3-4): a diagnostic interrupt of a
  // paired module (OB 82 W#16#3942/3842; a station-level one, MDL_STOP, concerns every module
  // of the station), or the process-image transfer error of its station (OB 85 39B1/38B1).
  RedIoCause cause = RedIoCause::None;
  if (e.ob == 82 && (e.code == 0x3942 || e.code == 0x3842)) cause = RedIoCause::Ob82;
  if (e.ob == 85 && e.source == HSystemEvent::Source::Image && e.system >= 0)
    cause = RedIoCause::Ob85;
  if (cause == RedIoCause::None) return;
  bool any = false;
  for (std::size_t i = 0; i < m_red_io->size(); ++i) {
    const auto& s = m_red_io->spec(i);
    for (std::uint32_t addr : {s.address_low, s.address_high}) {
      // The I/O map entry behind this address.
      for (const HIoEntry& x : m_map.entries()) {
        if (x.central || x.system != e.system || x.address != e.station) continue;
        if (cause == RedIoCause::Ob82 && e.module >= 0 &&
            x.module != static_cast<std::size_t>(e.module))
          continue;
        const bool in = is_input(s.kind);
        if ((in ? x.in_addr : x.out_addr) != addr || (in ? x.in_len : x.out_len) == 0) continue;
        m_red_io->module_fault(e.time, i, addr == s.address_low ? RedModule::L : RedModule::H,
                               cause, e.incoming);
        any = true;
      }
    }
  }
  if (any) red_io_flush();
}

void HSystemModel::red_io_on_pair_event(const HEvent& e) {
  // Depassivation "at the start-up of the H system" and "on the transition to Redundant mode"
  // (001 L6585-6589); it is carried out at the next RED_IN.
  const bus::Ticks now = e.at;
  if (e.kind == HEvent::Kind::State && e.to_state == CpuState::Startup)
    m_red_io->request_depassivation(now, DepassivationTrigger::Startup);
  else if (e.kind == HEvent::Kind::SystemMode && e.to_mode == SystemMode::Redundant)
    m_red_io->request_depassivation(now, DepassivationTrigger::Redundant);
}

void HSystemModel::red_io_flush() {
  const auto& ev = m_red_io->events();
  for (; m_red_io_seen < ev.size(); ++m_red_io_seen) {
    const RedIoEvent& r = ev[m_red_io_seen];
    HSystemEvent h;
    h.time = r.time;
    h.original_time = r.time;
    h.ob = 0;  // a diagnostic-buffer entry of the block library, no OB of its own
    h.code = r.code;
    h.text = describe(r);
    h.source = HSystemEvent::Source::Program;
    // Which station the module is in (the pair's module for a module entry).
    if (r.module >= 0) {
      const auto& s = m_red_io->spec(r.pair);
      const bool in = is_input(s.kind);
      for (const HIoEntry& x : m_map.entries())
        if (!x.central && (in ? x.in_len : x.out_len) > 0 &&
            (in ? x.in_addr : x.out_addr) == r.address) {
          h.system = x.system;
          h.station = x.address;
          h.module = static_cast<int>(x.module);
          h.mdl_addr = static_cast<std::uint16_t>(r.address);
        }
    }
    log_on_powered(r.time, r.code, h.text);
    const bool run0 = m_pair.dp_master_operate(0), run1 = m_pair.dp_master_operate(1);
    h.rack = run0 && run1 ? -1 : (run0 ? 0 : (run1 ? 1 : -1));
    h.role = h.rack < 0 ? CpuRole::Master : m_pair.role(h.rack);
    add_event(std::move(h));
  }
}

}  // namespace pbvbus::devices
