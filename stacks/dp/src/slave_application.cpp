// Device side of the DP slave (protocol-facts.md §D.5, §E.5, §F).
#include "pbvbus/dp/slave_application.hpp"

#include "pbvbus/dp/prm.hpp"
#include "record_key.hpp"

#include <algorithm>

namespace pbvbus::dp {

std::string_view to_string(SlaveState s) {
  switch (s) {
    case SlaveState::PowerOn: return "Power_On";
    case SlaveState::WaitPrm: return "Wait_Prm";
    case SlaveState::WaitCfg: return "Wait_Cfg";
    case SlaveState::DataExch: return "Data_Exch";
  }
  return "?";
}

SlaveApplication::SlaveApplication(const SlaveLayout& layout)
    : m_image(layout), m_module_states(layout.modules.size(), ModuleState::Ok) {
  m_alarms.reserve(32);
}

bool SlaveApplication::write_inputs(std::size_t module, std::span<const std::uint8_t> data) {
  if (module >= m_image.modules()) return false;
  return m_image.inputs(module).write(data);
}

bool SlaveApplication::read_outputs(std::size_t module, std::span<std::uint8_t> out) const {
  if (module >= m_image.modules()) return false;
  return m_image.outputs(module).read(out);
}

std::uint32_t SlaveApplication::outputs_generation(std::size_t module) const {
  return module < m_image.modules() ? m_image.outputs(module).generation() : 0;
}

void SlaveApplication::set_ext_diag(bool on) {
  std::lock_guard lk(m_mu);
  if (m_ext_diag == on) return;
  m_ext_diag = on;
  diag_changed();
}

void SlaveApplication::set_stat_diag(bool on) {
  std::lock_guard lk(m_mu);
  if (m_stat_diag == on) return;
  m_stat_diag = on;
  diag_changed();
}

void SlaveApplication::set_device_diag(std::span<const std::uint8_t> data) {
  std::lock_guard lk(m_mu);
  m_device_diag.assign(data.begin(), data.end());
  diag_changed();
}

void SlaveApplication::add_channel_diag(const ChannelDiag& c) {
  std::lock_guard lk(m_mu);
  if (std::find(m_channels.begin(), m_channels.end(), c) != m_channels.end()) return;
  m_channels.push_back(c);
  diag_changed();
}

void SlaveApplication::remove_channel_diag(const ChannelDiag& c) {
  std::lock_guard lk(m_mu);
  const auto it = std::find(m_channels.begin(), m_channels.end(), c);
  if (it == m_channels.end()) return;
  m_channels.erase(it);
  diag_changed();
}

void SlaveApplication::clear_channel_diags() {
  std::lock_guard lk(m_mu);
  if (m_channels.empty()) return;
  m_channels.clear();
  diag_changed();
}

void SlaveApplication::set_module_state(std::size_t module, ModuleState s) {
  std::lock_guard lk(m_mu);
  if (module >= m_module_states.size() || m_module_states[module] == s) return;
  m_module_states[module] = s;
  diag_changed();
}

bool SlaveApplication::set_status(std::uint8_t status_type, std::uint8_t slot,
                                  std::uint8_t specifier, std::span<const std::uint8_t> data) {
  if ((status_type & 0x80) == 0 || status_type == kModuleStatus || status_type == 0xFF ||
      data.size() > 59)
    return false;
  Alarm st;
  st.type = status_type;
  st.slot = slot;
  st.specifier = specifier;
  st.len = static_cast<std::uint8_t>(data.size());
  std::copy(data.begin(), data.end(), st.data.begin());
  std::lock_guard lk(m_mu);
  const auto it = std::find_if(m_status.begin(), m_status.end(), [&](const Alarm& a) {
    return a.type == status_type && a.slot == slot;
  });
  if (it != m_status.end())
    *it = st;
  else
    m_status.push_back(st);
  diag_changed();
  return true;
}

void SlaveApplication::clear_status(std::uint8_t status_type, std::uint8_t slot) {
  std::lock_guard lk(m_mu);
  const auto it = std::find_if(m_status.begin(), m_status.end(), [&](const Alarm& a) {
    return a.type == status_type && a.slot == slot;
  });
  if (it == m_status.end()) return;
  m_status.erase(it);
  diag_changed();
}

AlarmResult SlaveApplication::raise_alarm(std::uint8_t type, std::uint8_t slot, AlarmSpec spec,
                                          bool add_ack, std::span<const std::uint8_t> data,
                                          std::uint8_t* seq_nr) {
  const std::uint8_t enable = alarm_enable_bit(type);
  if (enable == 0 || data.size() > 59) return AlarmResult::BadArgument;
  std::lock_guard lk(m_mu);
  if (!m_alarms_open) return AlarmResult::Closed;
  if ((m_alarm_enables & enable) == 0) return AlarmResult::TypeNotEnabled;
  if (m_alarm_mode == 0) {
    // Alarm_Mode 0: one outstanding alarm of each type.
    for (const auto& a : m_alarms)
      if (a.type == type) return AlarmResult::LimitExpired;
  } else if (m_alarms.size() >= alarm_mode_limit(m_alarm_mode)) {
    return AlarmResult::LimitExpired;
  }
  // Seq_Nr runs 0..31; skip numbers still outstanding so that an Alarm_Ack is unambiguous.
  std::uint8_t seq = m_next_seq;
  for (int tries = 0; tries < 32; ++tries) {
    const bool used = std::any_of(m_alarms.begin(), m_alarms.end(),
                                  [&](const Alarm& a) { return alarm_seq_nr(a.specifier) == seq; });
    if (!used) break;
    seq = static_cast<std::uint8_t>((seq + 1) & 0x1F);
  }
  m_next_seq = static_cast<std::uint8_t>((seq + 1) & 0x1F);
  Alarm a;
  a.type = type;
  a.slot = slot;
  a.specifier = alarm_specifier(seq, add_ack, spec);
  a.len = static_cast<std::uint8_t>(data.size());
  std::copy(data.begin(), data.end(), a.data.begin());
  m_alarms.push_back(a);
  if (seq_nr) *seq_nr = seq;
  diag_changed();
  return AlarmResult::Ok;
}

std::size_t SlaveApplication::alarms_outstanding() const {
  std::lock_guard lk(m_mu);
  return m_alarms.size();
}

void SlaveApplication::on_alarm_ack(
    std::function<void(std::uint8_t type, std::uint8_t slot, std::uint8_t seq)> cb) {
  std::lock_guard lk(m_mu);
  m_alarm_ack_cb = std::move(cb);
}

void SlaveApplication::on_read(std::uint8_t slot, std::uint8_t index, RecordReadHandler h) {
  std::lock_guard lk(m_mu);
  m_read_handlers[record_key(slot, index)] = std::move(h);
}

void SlaveApplication::on_write(std::uint8_t slot, std::uint8_t index, RecordWriteHandler h) {
  std::lock_guard lk(m_mu);
  m_write_handlers[record_key(slot, index)] = std::move(h);
}

void SlaveApplication::on_write_any(RecordWriteHandler h) {
  std::lock_guard lk(m_mu);
  m_write_any = std::move(h);
}

void SlaveApplication::complete_read(std::uint32_t id, std::span<const std::uint8_t> data) {
  std::lock_guard lk(m_mu);
  m_completions[id] = Completion{false, {}, {data.begin(), data.end()}};
}

void SlaveApplication::complete_write(std::uint32_t id) {
  std::lock_guard lk(m_mu);
  m_completions[id] = Completion{false, {}, {}};
}

void SlaveApplication::complete_error(std::uint32_t id, Dpv1Error e) {
  std::lock_guard lk(m_mu);
  m_completions[id] = Completion{true, e, {}};
}

}  // namespace pbvbus::dp
