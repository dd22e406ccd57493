// SFC 90 H_CTRL: MODE/SUBMODE decoding, RET_VAL and the jobs (h_sfc90.hpp has the table,
// docs/h-sfc90.md the sources and decisions).
#include "pbvbus/s7h/h_sfc90.hpp"

#include "pbvbus/s7h/h_cpu_pair.hpp"

namespace pbvbus::devices {

std::string_view to_string(HCtrlJob j) {
  switch (j) {
    case HCtrlJob::None: return "none";
    case HCtrlJob::DisableLinkUp: return "disable link-up";
    case HCtrlJob::EnableLinkUp: return "re-enable link-up";
    case HCtrlJob::DisableUpdate: return "disable update";
    case HCtrlJob::EnableUpdate: return "re-enable update";
    case HCtrlJob::RemoveTest: return "remove self-test component";
    case HCtrlJob::AddTest: return "add self-test component";
    case HCtrlJob::StartTest: return "start self-test component";
  }
  return "?";
}

std::string_view to_string(SelfTestComponent c) {
  switch (c) {
    case SelfTestComponent::Ram: return "RAM test";
    case SelfTestComponent::Alu: return "ALU test";
    case SelfTestComponent::OsChecksum: return "operating-system checksum";
    case SelfTestComponent::CodeChecksum: return "code-block checksum";
    case SelfTestComponent::SyncCompare: return "sync-link comparison";
  }
  return "?";
}

HCtrlDecoded decode_h_ctrl(std::uint8_t mode, std::uint8_t submode) {
  HCtrlDecoded d;
  HCtrlJob job = HCtrlJob::None;
  switch (mode) {
    case 0: job = HCtrlJob::DisableLinkUp; break;
    case 1: job = HCtrlJob::EnableLinkUp; break;
    case 3: job = HCtrlJob::DisableUpdate; break;
    case 4: job = HCtrlJob::EnableUpdate; break;
    case 10: job = HCtrlJob::RemoveTest; break;
    case 11: job = HCtrlJob::AddTest; break;
    case 12: job = HCtrlJob::StartTest; break;
    default:
      d.ret_val = kHCtrlBadMode;
      return d;
  }
  if (mode <= 4) {
    if (submode != 0) {
      d.ret_val = kHCtrlBadSubmode;
      return d;
    }
  } else if (submode == kAllComponents) {
    d.component = -1;
  } else if (submode < kSelfTestComponents) {
    d.component = submode;
  } else {
    d.ret_val = kHCtrlBadSubmode;
    return d;
  }
  d.job = job;
  return d;
}

bool HSelfTestControl::set_included(int component, bool in) {
  bool changed = false;
  for (int i = 0; i < kSelfTestComponents; ++i) {
    if (component >= 0 && i != component) continue;
    auto& v = m_in[static_cast<std::size_t>(i)];
    changed = changed || v != in;
    v = in;
  }
  return changed;
}

void HSelfTestControl::start(int component) {
  for (int i = 0; i < kSelfTestComponents; ++i)
    if (component < 0 || i == component) ++m_started[static_cast<std::size_t>(i)];
}

std::uint16_t h_ctrl(HCpuPair& pair, HSelfTestControl& self_test, std::uint8_t mode,
                     std::uint8_t submode, bus::Ticks now) {
  const HCtrlDecoded d = decode_h_ctrl(mode, submode);
  if (d.job == HCtrlJob::None) return d.ret_val;
  if (pair.params().profile == HProfile::S7_1500RH) return kHCtrlNotAvailable;
  bool changed = true;
  switch (d.job) {
    case HCtrlJob::None: break;
    case HCtrlJob::DisableLinkUp: changed = pair.set_link_up_enabled(false, now); break;
    case HCtrlJob::EnableLinkUp: changed = pair.set_link_up_enabled(true, now); break;
    case HCtrlJob::DisableUpdate: changed = pair.set_update_enabled(false, now); break;
    case HCtrlJob::EnableUpdate: changed = pair.set_update_enabled(true, now); break;
    case HCtrlJob::RemoveTest: changed = self_test.set_included(d.component, false); break;
    case HCtrlJob::AddTest: changed = self_test.set_included(d.component, true); break;
    case HCtrlJob::StartTest: self_test.start(d.component); break;
  }
  return changed ? kHCtrlOk : kHCtrlAlready;
}

}  // namespace pbvbus::devices
