// The DP section of the `pbvbus run` report, text and JSON (schema in report.hpp).
#include "pbvbus/reports/dp_report.hpp"

#include <cstdio>
#include <optional>
#include <ostream>
#include <string>

#include "pbvbus/reports/json_text.hpp"

namespace pbvbus::tools {

namespace {

// Equidistance (docs/dp-equidistance.md): only for a master that has it, so that every other
// report stays as it was.
void write_equidistance_text(const DpMasterReport& m, std::ostream& os) {
  const auto& e = m.equidistance;
  if (e.period <= 0) return;
  const auto bit = bus::ticks_per_bit(m.baud);
  os << "  equidistance: T_DP " << format_us(e.period) << " us = " << e.period / bit << " bit times, cycles "
     << e.cycles << ", overruns " << e.overruns << " (due times passed over " << e.missed << "), max lateness "
     << format_us(e.max_lateness) << " us = " << e.max_lateness / bit << " bit times, cycle start jitter "
     << e.jitter / bit << " bit times over " << e.intervals << " on-time cycles\n";
}

void write_equidistance_json(const DpMasterReport& m, std::ostream& os) {
  const auto& e = m.equidistance;
  if (e.period <= 0) return;
  const auto bit = bus::ticks_per_bit(m.baud);
  os << ",\"equidistance\":{\"t_dp_ns\":" << bus::ticks_to_ns(e.period) << ",\"t_dp_bits\":" << e.period / bit
     << ",\"cycles\":" << e.cycles << ",\"overruns\":" << e.overruns << ",\"missed\":" << e.missed
     << ",\"max_lateness_ns\":" << bus::ticks_to_ns(e.max_lateness)
     << ",\"max_lateness_bits\":" << e.max_lateness / bit << ",\"jitter_bits\":" << e.jitter / bit
     << ",\"on_time_intervals\":" << e.intervals << "}";
}

}  // namespace

void write_dp_text(const std::vector<DpMasterReport>& r, std::ostream& os) {
  for (const auto& m : r) {
    const auto bit = bus::ticks_per_bit(m.baud);
    os << "\ndp master " << static_cast<int>(m.address) << " on line " << m.line << ": "
       << m.mode << ", Global_Control sent " << m.global_controls << ", Data_Control_Time "
       << m.data_control_time * 10 << " ms\n";
    write_equidistance_text(m, os);
    for (const auto& s : m.slaves) {
      os << "  dp slave " << static_cast<int>(s.address) << " \"" << s.model << "\" [";
      for (std::size_t i = 0; i < s.modules.size(); ++i) os << (i ? ", " : "") << s.modules[i];
      os << "]: " << s.state << " (slave: " << s.slave_state << ")\n";
      os << "    diagnosis " << hex_octets(s.diag);
      if (!s.diag_bits.empty()) {
        os << " (";
        for (std::size_t i = 0; i < s.diag_bits.size(); ++i) os << (i ? ", " : "") << s.diag_bits[i];
        os << ")";
      }
      os << "\n    inputs " << s.input_len << " octets: " << (s.inputs.empty() ? "-" : hex_octets(s.inputs))
         << "\n    outputs " << s.output_len << " octets: " << (s.outputs.empty() ? "-" : hex_octets(s.outputs))
         << "\n";
      const auto& st = s.stats;
      if (st.cycle_count > 0) {
        os << "    DP cycle (" << st.cycle_count << "): min " << format_us(st.cycle_min) << " / median "
           << format_us(s.cycle_median) << " / max " << format_us(st.cycle_max) << " us = " << st.cycle_min / bit
           << " / " << s.cycle_median / bit << " / " << st.cycle_max / bit << " bit times\n";
      }
      os << "    data exchanges " << st.data_exchanges << ", start-ups " << st.startups
         << ", diagnosis reads " << st.diag_reads << ", failures " << st.failures << ", returns "
         << st.returns << ", no response " << st.no_response << ", retries " << st.retries << "\n";
    }
  }
}

void write_dp_json(const std::vector<DpMasterReport>& r, std::ostream& os) {
  os << ",\n\"dp_masters\":[";
  for (std::size_t mi = 0; mi < r.size(); ++mi) {
    const auto& m = r[mi];
    const auto bit = bus::ticks_per_bit(m.baud);
    os << (mi ? ",\n" : "\n") << "{\"address\":" << static_cast<int>(m.address)
       << ",\"line\":" << json_quote(m.line) << ",\"mode\":" << json_quote(m.mode)
       << ",\"global_controls\":" << m.global_controls
       << ",\"data_control_time_ms\":" << m.data_control_time * 10;
    write_equidistance_json(m, os);
    os << ",\"slaves\":[";
    for (std::size_t i = 0; i < m.slaves.size(); ++i) {
      const auto& s = m.slaves[i];
      const auto& st = s.stats;
      os << (i ? ",\n  " : "\n  ") << "{\"address\":" << static_cast<int>(s.address)
         << ",\"model\":" << json_quote(s.model) << ",\"modules\":[";
      for (std::size_t k = 0; k < s.modules.size(); ++k) os << (k ? "," : "") << json_quote(s.modules[k]);
      os << "],\"state\":" << json_quote(s.state) << ",\"slave_state\":" << json_quote(s.slave_state)
         << ",\"diag\":" << json_quote(hex_octets(s.diag)) << ",\"diag_bits\":[";
      for (std::size_t k = 0; k < s.diag_bits.size(); ++k) os << (k ? "," : "") << json_quote(s.diag_bits[k]);
      os << "],\"input_len\":" << s.input_len << ",\"output_len\":" << s.output_len
         << ",\"inputs\":" << json_quote(hex_octets(s.inputs)) << ",\"outputs\":" << json_quote(hex_octets(s.outputs))
         << ",\"cycle\":{\"count\":" << st.cycle_count << ",\"min_ns\":" << bus::ticks_to_ns(st.cycle_min)
         << ",\"median_ns\":" << bus::ticks_to_ns(s.cycle_median)
         << ",\"max_ns\":" << bus::ticks_to_ns(st.cycle_max) << ",\"min_bits\":" << st.cycle_min / bit
         << ",\"median_bits\":" << s.cycle_median / bit << ",\"max_bits\":" << st.cycle_max / bit
         << "},\"data_exchanges\":" << st.data_exchanges << ",\"startups\":" << st.startups
         << ",\"diag_reads\":" << st.diag_reads << ",\"failures\":" << st.failures
         << ",\"returns\":" << st.returns << ",\"no_response\":" << st.no_response
         << ",\"retries\":" << st.retries << "}";
    }
    os << "]}";
  }
  os << "]";
}

namespace {

template <class T>
std::string opt_json(const std::optional<T>& v) {
  return v ? std::to_string(static_cast<long long>(*v)) : std::string("null");
}

}  // namespace

void write_dp_slaves_text(const std::vector<DpSlaveView>& r, std::ostream& os) {
  for (const auto& v : r) {
    os << "\ndp slave " << static_cast<int>(v.address) << " on line " << v.line << " \"" << v.model
       << "\" [";
    for (std::size_t i = 0; i < v.modules.size(); ++i) os << (i ? ", " : "") << v.modules[i];
    os << "], its own view: " << v.state << ", owner "
       << (v.owner ? std::to_string(*v.owner) : std::string("none")) << " ("
       << (v.master ? "dp master " + std::to_string(*v.master) + " in the scenario"
                    : std::string("no pbvbus master"))
       << "), watchdog "
       << (v.watchdog ? std::to_string(*v.watchdog / bus::kTicksPerMs) + " ms" : std::string("off")) << "\n";
    os << "    diagnosis " << hex_octets(v.diag);
    if (!v.diag_bits.empty()) {
      os << " (";
      for (std::size_t i = 0; i < v.diag_bits.size(); ++i) os << (i ? ", " : "") << v.diag_bits[i];
      os << ")";
    }
    os << "\n    inputs " << v.input_len << " octets: " << (v.inputs.empty() ? "-" : hex_octets(v.inputs))
       << " (sent last), outputs " << v.output_len
       << " octets: " << (v.outputs.empty() ? "-" : hex_octets(v.outputs)) << " (received last)\n";
    const auto& s = v.stats;
    os << "    answered: Set_Prm " << s.set_prm << ", Chk_Cfg " << s.chk_cfg << ", Slave_Diag "
       << s.slave_diag << ", Data_Exchange " << s.data_exchange << ", Global_Control "
       << s.global_control << ", Get_Cfg " << s.get_cfg << ", Rd_Inp " << s.rd_inp << ", Rd_Outp "
       << s.rd_outp << ", Set_Slave_Add " << s.set_slave_add << ", DP-V1 " << s.dpv1 << ", other "
       << s.other << "; refused (RS) " << s.refused << "\n";
    os << "    Prm faults " << s.prm_faults << ", Cfg faults " << s.cfg_faults
       << ", Data_Exch entered " << s.data_exch_entries << " times, watchdog expiries "
       << s.watchdog_expiries << "; FDL: " << v.fdl.requests << " requests, " << v.fdl.replies
       << " replies, " << v.fdl.repeats << " repeats, " << v.fdl.dropped_tsyn
       << " dropped for too short an idle time (TSYN), " << v.fdl.dropped_errors
       << " dropped damaged\n";
  }
}

void write_dp_slaves_json(const std::vector<DpSlaveView>& r, std::ostream& os) {
  os << ",\n\"dp_slaves\":[";
  for (std::size_t i = 0; i < r.size(); ++i) {
    const auto& v = r[i];
    const auto& s = v.stats;
    os << (i ? ",\n" : "\n") << "{\"line\":" << json_quote(v.line)
       << ",\"address\":" << static_cast<int>(v.address) << ",\"model\":" << json_quote(v.model)
       << ",\"gsd\":" << json_quote(v.gsd) << ",\"modules\":[";
    for (std::size_t k = 0; k < v.modules.size(); ++k) os << (k ? "," : "") << json_quote(v.modules[k]);
    os << "],\"master\":" << opt_json(v.master) << ",\"state\":" << json_quote(v.state)
       << ",\"owner\":" << opt_json(v.owner) << ",\"watchdog_ns\":"
       << (v.watchdog ? std::to_string(bus::ticks_to_ns(*v.watchdog)) : std::string("null"))
       << ",\"diag\":" << json_quote(hex_octets(v.diag)) << ",\"diag_bits\":[";
    for (std::size_t k = 0; k < v.diag_bits.size(); ++k) os << (k ? "," : "") << json_quote(v.diag_bits[k]);
    os << "],\"input_len\":" << v.input_len << ",\"output_len\":" << v.output_len
       << ",\"inputs\":" << json_quote(hex_octets(v.inputs)) << ",\"outputs\":" << json_quote(hex_octets(v.outputs))
       << ",\n \"requests\":{\"set_prm\":" << s.set_prm << ",\"chk_cfg\":" << s.chk_cfg
       << ",\"slave_diag\":" << s.slave_diag << ",\"data_exchange\":" << s.data_exchange
       << ",\"global_control\":" << s.global_control << ",\"get_cfg\":" << s.get_cfg
       << ",\"rd_inp\":" << s.rd_inp << ",\"rd_outp\":" << s.rd_outp
       << ",\"set_slave_add\":" << s.set_slave_add << ",\"dpv1\":" << s.dpv1
       << ",\"other\":" << s.other << "},\"refused\":" << s.refused
       << ",\"prm_faults\":" << s.prm_faults << ",\"cfg_faults\":" << s.cfg_faults
       << ",\"data_exch_entries\":" << s.data_exch_entries
       << ",\"watchdog_expiries\":" << s.watchdog_expiries << ",\n \"fdl\":{\"requests\":"
       << v.fdl.requests << ",\"replies\":" << v.fdl.replies << ",\"repeats\":" << v.fdl.repeats
       << ",\"fdl_status\":" << v.fdl.fdl_status << ",\"dropped_errors\":" << v.fdl.dropped_errors
       << ",\"dropped_tsyn\":" << v.fdl.dropped_tsyn << "}}";
  }
  os << "]";
}

}  // namespace pbvbus::tools
