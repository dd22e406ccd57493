#include "pbvbus/gateways/canopen_objects.hpp"

#include "pbvbus/dp/diagnosis.hpp"

namespace pbvbus::gateways::canopen {

std::uint8_t dp_state_code(dp::SlaveStatusState s) {
  // The enum's order is the status block's order, starting at 1 (0 is left free so that a
  // zeroed register never looks like a state).
  return static_cast<std::uint8_t>(static_cast<std::uint8_t>(s) + 1);
}

bool has_ext_diag(const SlaveStatus& st) {
  return !st.diag.empty() && (st.diag[0] & dp::kDiagExtDiag) != 0;
}

std::uint8_t dp_status_flags(const SourceSlave& slave, const SlaveStatus& st) {
  const std::uint8_t s1 = st.diag.empty() ? 0 : st.diag[0];
  std::uint8_t f = 0;
  if (st.data_valid) f |= kFlagDataValid;
  if (s1 & dp::kDiagExtDiag) f |= kFlagExtDiag;
  if (st.state == dp::SlaveStatusState::NotPresent || (s1 & dp::kDiagStationNonExistent))
    f |= kFlagStationFailure;
  if (s1 & dp::kDiagPrmFault) f |= kFlagPrmFault;
  if (s1 & dp::kDiagCfgFault) f |= kFlagCfgFault;
  if (slave.switched) f |= kFlagSwitched;
  if (st.redundancy_lost) f |= kFlagRedundancyLost;
  if (st.active_channel == 1) f |= kFlagChannelB;
  return f;
}

std::optional<std::uint8_t> heartbeat_state(dp::SlaveStatusState s, dp::MasterMode mode) {
  using S = dp::SlaveStatusState;
  switch (s) {
    case S::NotPresent:
    case S::Locked: return std::nullopt;
    default: break;
  }
  if (mode == dp::MasterMode::Stop) return kStateStopped;
  switch (s) {
    case S::DataExchange:
      return mode == dp::MasterMode::Operate ? kStateOperational : kStatePreOperational;
    case S::Diag:
    case S::Prm:
    case S::Cfg:
    case S::CheckDiag: return kStatePreOperational;
    default: return std::nullopt;  // Inactive: deactivated, or the master is offline
  }
}

namespace {

ObjectAccess ok(std::uint32_t v, std::uint8_t size) { return {0, v, size}; }
ObjectAccess fail(std::uint32_t code) { return {code, 0, 0}; }

// Highest sub-index of an existing object, nullopt if the object does not exist.
std::optional<unsigned> last_sub(const NodeObjects& n, std::uint16_t index) {
  switch (index) {
    case kObjDeviceType:
    case kObjErrorRegister:
    case kObjProducerHeartbeat: return 0u;
    case kObjIdentity: return 4u;
    case kObjDpStatus: return kDpStatusSubs;
    case kObjDpDiagnosis: return static_cast<unsigned>(n.status.diag.size());
    default: return std::nullopt;
  }
}

}  // namespace

ObjectAccess read_object(const NodeObjects& n, std::uint16_t index, std::uint8_t sub) {
  const auto last = last_sub(n, index);
  if (!last) return fail(kAbortNoObject);
  if (sub > *last) return fail(kAbortNoSubIndex);
  const SlaveStatus& st = n.status;
  switch (index) {
    case kObjDeviceType: return ok(0, 4);  // no CiA device profile
    case kObjErrorRegister: return ok(n.error_register, 1);
    case kObjProducerHeartbeat: return ok(n.heartbeat_ms, 2);
    case kObjIdentity:
      switch (sub) {
        case 0: return ok(4, 1);
        case 1: return ok(0, 4);  // vendor id: none assigned
        case 2: return ok(n.slave ? n.slave->ident : 0u, 4);
        case 3: return ok(0, 4);
        default: return ok(n.slave ? n.slave->address : 0u, 4);
      }
    case kObjDpStatus:
      switch (sub) {
        case 0: return ok(kDpStatusSubs, 1);
        case 1: return ok(dp_state_code(st.state), 1);
        case 2: return ok(n.slave ? dp_status_flags(*n.slave, st) : 0u, 1);
        case 3: return ok(static_cast<std::uint32_t>(st.data_exchanges), 4);  // mod 2^32
        case 4: return ok(n.slave ? n.slave->ident : 0u, 2);
        case 5:
          return ok(st.active_channel < 0 ? 0xFFu : static_cast<std::uint32_t>(st.active_channel),
                    1);
        case 6: return ok(static_cast<std::uint32_t>(st.failures), 4);
        default: return ok(static_cast<std::uint32_t>(st.diag.size() & 0xFF), 1);
      }
    default:  // kObjDpDiagnosis
      if (sub == 0) return ok(static_cast<std::uint32_t>(st.diag.size() & 0xFF), 1);
      return ok(st.diag[sub - 1u], 1);
  }
}

ObjectAccess check_write(const NodeObjects& n, std::uint16_t index, std::uint8_t sub,
                         std::uint8_t size, std::uint32_t value) {
  const auto last = last_sub(n, index);
  if (!last) return fail(kAbortNoObject);
  if (sub > *last) return fail(kAbortNoSubIndex);
  if (index != kObjProducerHeartbeat) return fail(kAbortReadOnly);
  if (size != 0 && size != 2) return fail(kAbortLength);
  return ok(value & 0xFFFFu, 2);
}

std::string_view abort_text(std::uint32_t code) {
  switch (code) {
    case kAbortCommandSpecifier: return "command specifier not valid or unknown";
    case kAbortReadOnly: return "attempt to write a read only object";
    case kAbortNoObject: return "object does not exist in the object dictionary";
    case kAbortLength: return "data type does not match, length of service parameter does not match";
    case kAbortNoSubIndex: return "sub-index does not exist";
    default: return "unknown abort code";
  }
}

}  // namespace pbvbus::gateways::canopen
