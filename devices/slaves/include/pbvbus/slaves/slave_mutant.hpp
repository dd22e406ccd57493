#pragma once
// Mutant slaves (docs/mutants.md): a SlaveModel option that breaks exactly ONE rule of the standard, so
// that the conformance battery (conformance/) and the replayer can be shown to catch it. They
// exist for the suite's own tests and for a developer who wants to see what a failure looks
// like; a scenario names one with `dp_slave { mutant: "ignore_fcb" }`.
//
// Each mutant changes only the behaviour its rule describes; everything else stays conformant
// (so a mutant fails the tests aimed at its rule and, ideally, nothing else). Where a rule can
// only be seen from the device side (outputs applied to the process), the battery looks at the
// model's application (white box) — see docs/conformance.md.

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace pbvbus::devices {

enum class SlaveMutant : std::uint8_t {
  TsdrTooLate,           ///< answers 20 bit times after the GSD's MaxTsdr at the line's baud
  IgnoreMinTsdr,         ///< answers at its own delay even when Set_Prm asked for a larger min TSDR
  IgnoreFcb,             ///< a repeated request (same FCB, FCV = 1) is processed as a new one
  NoPrmReqBit,           ///< Slave_Diag in Wait_Prm lacks Prm_Req (octet 2 bit 0)
  AcceptWrongIdent,      ///< Set_Prm with another Ident_Number is accepted
  IgnoreWatchdog,        ///< the response monitoring never expires
  TearConsistent,        ///< a module consistent over its whole length is handed over in halves
  WrongGetCfg,           ///< Get_Cfg answers the real configuration with its last octet altered
  IgnoreClearData,       ///< Global_Control Clear_Data does not set the outputs safe
  IgnoreLock,            ///< a Set_Prm from another master is accepted while locked
  AcceptWrongCfg,        ///< a Chk_Cfg that does not match is accepted
  IgnoreFreeze,          ///< Freeze does not freeze the inputs
  IgnoreSync,            ///< Sync does not hold the outputs (applied at once)
  SlowSlaveInterval,     ///< needs 10 × its GSD Min_Slave_Intervall between polls (else no answer)
  KeepStateOnPowerCycle, ///< power off/on keeps the parameterisation (stays in Data_Exch)
  Dpv1BadIndexAccepted,  ///< MSAC_C1 Read of an unknown index answers data instead of an error
  RejectFailSafe,        ///< a zero-length Data_Exchange in Clear is refused despite Fail_Safe=1
  WrongDiagIdent,        ///< Slave_Diag octets 5..6 carry the ident + 1
  GetCfgSapsNotSwapped,  ///< the Get_Cfg reply carries DSAP 59, SSAP 62 (not mirrored)
  DataExchangeInWaitCfg, ///< Data_Exchange answered after Set_Prm, before a good Chk_Cfg
  FcbGlobal,             ///< one frame count bit (and stored reply) for all masters
};

struct MutantInfo {
  SlaveMutant mutant;
  std::string_view name;  ///< as in scenarios and on the command line, e.g. "ignore_fcb"
  std::string_view rule;  ///< the rule it breaks, in words
};

/// Every mutant, in enum order.
std::span<const MutantInfo> slave_mutants();
/// By name; nullopt if there is no such mutant.
std::optional<SlaveMutant> parse_slave_mutant(std::string_view name);
std::string_view slave_mutant_name(SlaveMutant m);

}  // namespace pbvbus::devices
