// The H-system model running the real user program (h_program.hpp) on both CPUs through
// RedundantExecution: the sync point, the comparison (F16) and the sync error (F18) acting on
// the pair, the program's events (7960) in events(). h_system.hpp has the decisions.
#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

void HSystemModel::set_program(const ProgramSpec& given) {
  // SFC 14/15 look LADDR up in the I/O map's modules (h_dp_sfc.hpp).
  ProgramSpec spec = given;
  spec.io_modules.clear();
  for (const HIoEntry& e : m_map.entries())
    spec.io_modules.push_back({static_cast<std::uint32_t>(e.in_addr), static_cast<std::uint32_t>(e.in_len),
                               static_cast<std::uint32_t>(e.out_addr), static_cast<std::uint32_t>(e.out_len),
                               !e.central});
  const auto errors = validate(spec, m_map.pii_size(), m_map.piq_size());
  if (!errors.empty()) throw std::invalid_argument("program: " + errors.front());
  // The memory area holds the program's state, the flags and the DBs (h_s7_memory.hpp).
  const devices::Program probe(spec, m_map.pii_size(), m_map.piq_size());
  HS7Layout lay = layout(m_s7_cfg, probe.memory_size());
  m_exec = std::make_unique<RedundantExecution>(spec, m_map.pii_size(), m_map.piq_size(),
                                                lay.total);
  m_s7_layout = std::move(lay);
  m_s7_spec = std::make_unique<ProgramSpec>(spec);
  m_program = nullptr;
  m_scan_time = spec.scan_time;  // > 0: validate() checked it
  m_direct = spec.copies;        // OB 122 checks those with `direct` (h_system_diag.cpp)
  if (!m_scan_armed && program_runs() && !m_pair.io_frozen()) arm_scan(m_sched.now());
}

bool HSystemModel::inject_divergence(int rack, Area area, std::uint32_t offset,
                                     std::uint8_t xor_mask) {
  return m_exec && m_exec->inject_divergence(rack, area, offset, xor_mask);
}

void HSystemModel::scan_execution(bus::Ticks now) {
  // The sync point: the master's reading of the I/O goes into both PIIs.
  m_map.read_inputs(m_systems, m_pii);
  red_io_in(now);  // FB 450 RED_IN (h_system_redundant_io.cpp)
  const std::array<bool, 2> running{m_pair.dp_master_operate(0), m_pair.dp_master_operate(1)};
  if (running[0] || running[1]) {
    // Direct access (L PIB / T PQB): OB 122 for unreachable modules, their bytes read 0.
    m_direct_pii = m_pii;
    direct_access(now, m_direct_pii);
    m_exec->set_inputs(m_direct_pii);
  } else {
    m_exec->set_inputs(m_pii);
  }
  if (!running[0] && !running[1]) return;
  ++m_scans;
  std::optional<int> out;
  m_split_outputs = m_pair.master_count() >= 2;
  if (m_split_outputs) {
    // F6/F7: two masters, no longer redundant: each CPU runs alone as its own master, no
    // comparison, and drives its own side: its PIQ goes into line r's master images only (a
    // switched station takes the outputs of the line it has as primary). Both run on the same
    // PII (the inputs of the active channels). piq() shows rack 0's (rack 1's when 0 does not
    // run).
    for (int r = 1; r >= 0; --r) {
      if (!running[static_cast<std::size_t>(r)]) continue;
      std::array<bool, 2> one{r == 0, r == 1};
      ScanResult res = m_exec->scan(now, one, r);
      for (const auto& e : res.events) on_program_event(e, one);
      m_map.write_outputs(m_systems, red_io_out(m_exec->image(r).piq()), r);
      if (res.output_rack) out = res.output_rack;
    }
  } else {
    const int master = m_pair.master();
    ScanResult res = m_exec->scan(now, running, master);
    for (const auto& e : res.events) on_program_event(e, res.ran);
    out = res.output_rack;
    // A sync error happens during the run, the comparison at its end: F18 first.
    if (res.sync_error && master >= 0) {
      // F18: the CPUs asked for different sync points.
      sync_error_reaction(1 - master, now, "the CPUs took different paths");
      after_op();
    } else if (res.comparison_error) {
      // F16 found by the comparison itself: the pair's reaction (standby ERROR-SEARCH or STOP,
      // OB 72 on the master); the outputs of this scan are the master's (sent below).
      const ImageDifference& d = *res.comparison_error;
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s offset %u: %02X (rack 0) / %02X (rack 1)",
                    std::string(area_name(d.area)).c_str(), static_cast<unsigned>(d.offset),
                    static_cast<unsigned>(d.value[0]), static_cast<unsigned>(d.value[1]));
      m_ob72_note = buf;
      m_pair.inject_comparison_error(now);
      m_ob72_note.clear();
      after_op();
    }
  }
  if (out && !m_split_outputs)
    m_map.write_outputs(m_systems, red_io_out(m_exec->image(*out).piq()));
  const auto piq = m_exec->image(out.value_or(m_pair.master() >= 0 ? m_pair.master() : 0)).piq();
  std::copy(piq.begin(), piq.end(), m_piq.begin());
}

void HSystemModel::on_program_event(const ProgramEvent& e, std::array<bool, 2> ran) {
  HSystemEvent h;
  h.time = e.time;
  h.original_time = e.time;
  h.rack = ran[0] && ran[1] ? -1 : (ran[0] ? 0 : 1);
  h.role = h.rack < 0 ? CpuRole::Master : m_pair.role(h.rack);
  h.ob = 0;  // error 7960 is the program's own message, no OB (digest §6 codes table)
  h.code = e.code;
  h.incoming = e.incoming;
  char buf[128];
  std::snprintf(buf, sizeof buf, "W#16#%04X %s: discrepancy IB %u / IB %u (%u octets), monitor %u",
                static_cast<unsigned>(e.code), e.incoming ? "incoming" : "outgoing",
                static_cast<unsigned>(e.input_a), static_cast<unsigned>(e.input_b),
                static_cast<unsigned>(e.length), static_cast<unsigned>(e.network));
  h.text = buf;
  h.source = HSystemEvent::Source::Program;
  add_event(std::move(h));
}

}  // namespace pbvbus::devices
