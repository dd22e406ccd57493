// HCpuPair: checksum errors found by the self-tests (001 §5.4 "Ошибка контрольной суммы",
// L4023-4065, Table 5-6) and log_entry() for the parts built on the pair (docs/h-changes.md).
#include <stdexcept>
#include <string>

#include "pbvbus/s7h/h_cpu_pair.hpp"

namespace pbvbus::devices {

void HCpuPair::log_entry(int rack, bus::Ticks now, std::string text, std::uint16_t code) {
  if (rack != 0 && rack != 1) throw std::out_of_range("HCpuPair: rack must be 0 or 1");
  run_due(now);
  diag(rack, now, std::move(text), code);
  after_step(now);
}

// Table 5-6 (first checksum error since the last unbuffered power-on):
//   start-up test after power-on      -> the CPU goes DEFECTIVE, the system Solo;
//   cyclic self-test (STOP or Solo)   -> the error is corrected, the CPU stays in STOP/Solo;
//   cyclic self-test (Redundant)      -> corrected, that CPU goes ERROR-SEARCH, Solo;
//   in ERROR-SEARCH                   -> DEFECTIVE.
// "The cause is entered in the diagnostic buffer"; "repeated within 7 days -> DEFECTIVE"
// (001 L4063). The seeds give no event ID: code 0. Decisions (docs/h-changes.md): the partner
// of a CPU that leaves Redundant becomes master if needed (as item 2 of 001 L3910-3913 says)
// and runs OB 72 ChecksumError; the 7-day window is defective_window, as for F17.
bool HCpuPair::checksum_error(int r, HChecksumContext where, bus::Ticks now) {
  if (r != 0 && r != 1) throw std::out_of_range("HCpuPair: rack must be 0 or 1");
  run_due(now);
  Cpu& c = m_cpu[r];
  if (is_1500() || !powered(r) || c.state == CpuState::Defective) return false;
  const bool repeated = c.last_checksum && now - *c.last_checksum <= m_p.defective_window;
  c.last_checksum = now;
  const bool redundant = system_mode() == SystemMode::Redundant &&
                         (c.state == CpuState::Run) && linked(r);
  const int p = partner(r);
  const bool was_master = c.role == CpuRole::Master;
  if (where == HChecksumContext::PowerOnTest || c.state == CpuState::ErrorSearch || repeated) {
    const std::string why = where == HChecksumContext::PowerOnTest
                                ? "checksum error in the power-on self-test"
                            : repeated ? "checksum error repeated within 7 days"
                                       : "checksum error in ERROR-SEARCH";
    diag(r, now, why);
    make_defective(r, now, why);
    if (redundant) {
      // The system leaves Redundant: the partner continues Solo (as master) with OB 72.
      ob(p, 72, HReason::ChecksumError, now);
    }
    after_step(now);
    return true;
  }
  if (!redundant) {
    diag(r, now, "checksum error in the cyclic self-test: corrected");
    after_step(now);
    return true;
  }
  diag(r, now, "checksum error in the cyclic self-test: corrected, ERROR-SEARCH");
  if (was_master) {
    set_role(r, CpuRole::Standby, now, "checksum error");
    set_role(p, CpuRole::Master, now, "partner: checksum error");
  }
  set_state(r, CpuState::ErrorSearch, now, "checksum error");
  c.deadline = now + m_p.self_test_time;
  ob(p, 72, HReason::ChecksumError, now);
  after_step(now);
  return true;
}

}  // namespace pbvbus::devices
