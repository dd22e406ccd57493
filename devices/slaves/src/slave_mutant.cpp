// The mutant catalogue (slave_mutant.hpp; docs/mutants.md): names as in scenarios and the rule
// of IEC 61158-6 / protocol-facts.md each mutant breaks. The hooks live in fdl::PassiveStation
// (PassiveMutation) and dp::SlaveEngine (dp::EngineMutation); SlaveModel maps between them.
#include "pbvbus/slaves/slave_mutant.hpp"

#include <array>

namespace pbvbus::devices {

namespace {

using M = SlaveMutant;

constexpr std::array<MutantInfo, 21> kMutants{{
    {M::TsdrTooLate, "tsdr_too_late",
     "a responder answers no later than max TSDR (the GSD's MaxTsdr at the line's baud) after "
     "the request's last stop bit (IEC 61158-4-3 station delay; protocol-facts.md §C.2)"},
    {M::IgnoreMinTsdr, "ignore_min_tsdr",
     "a slave answers no earlier than the min TSDR the master sets in Set_Prm octet 4 "
     "(protocol-facts.md §D.2, §C.2)"},
    {M::IgnoreFcb, "ignore_fcb",
     "a request repeated with FCV = 1 and the same FCB is answered from the stored reply, not "
     "executed again (IEC 61158-4-3 frame count bit; protocol-facts.md §C.6)"},
    {M::NoPrmReqBit, "no_prm_req_bit",
     "a slave waiting for parameters sets Prm_Req (Slave_Diag octet 2 bit 0) "
     "(protocol-facts.md §D.4, §D.8)"},
    {M::AcceptWrongIdent, "accept_wrong_ident",
     "a Set_Prm whose Ident_Number (octets 5..6) is not the slave's is a parameterisation error "
     "(Prm_Fault, stays in Wait_Prm) (protocol-facts.md §D.2, §D.8)"},
    {M::IgnoreWatchdog, "ignore_watchdog",
     "with WD_On the slave leaves data exchange (outputs safe, Wait_Prm) when no frame from its "
     "master arrives within WD_Fact_1 x WD_Fact_2 x 10 ms (protocol-facts.md §D.2, §D.8)"},
    {M::TearConsistent, "tear_consistent",
     "a module consistent over its whole length is handed over as one unit, never half old and "
     "half new (protocol-facts.md §F, §D.3)"},
    {M::WrongGetCfg, "wrong_get_cfg",
     "Get_Cfg answers the slave's real configuration, identifier by identifier "
     "(protocol-facts.md §D.3)"},
    {M::IgnoreClearData, "ignore_clear_data",
     "Global_Control with Clear_Data sets the outputs to the safe state "
     "(protocol-facts.md §D.6)"},
    {M::IgnoreLock, "ignore_lock",
     "a slave locked by one master ignores Set_Prm from any other master "
     "(protocol-facts.md §D.2 Lock_Req, §D.8)"},
    {M::AcceptWrongCfg, "accept_wrong_cfg",
     "a Chk_Cfg that does not match the real configuration is a configuration error (Cfg_Fault, "
     "back to Wait_Prm) (protocol-facts.md §D.3, §D.8)"},
    {M::IgnoreFreeze, "ignore_freeze",
     "after Global_Control Freeze the inputs stay frozen until the next Freeze or Unfreeze "
     "(protocol-facts.md §D.6)"},
    {M::IgnoreSync, "ignore_sync",
     "in Sync mode outputs of Data_Exchange are held and applied only at the next Sync "
     "(protocol-facts.md §D.6)"},
    {M::SlowSlaveInterval, "slow_slave_interval",
     "a slave answers every poll that comes at least its GSD Min_Slave_Intervall (100 us units) "
     "after the previous one (protocol-facts.md §C.2, §D.9, §I.2)"},
    {M::KeepStateOnPowerCycle, "keep_state_on_power_cycle",
     "after power off/on a slave starts in Wait_Prm, unparameterised (protocol-facts.md §D.8)"},
    {M::Dpv1BadIndexAccepted, "dpv1_bad_index_accepted",
     "an MSAC_C1 Read of an index the slot does not have is answered with the error "
     "80 B0 00 (invalid index) (protocol-facts.md §E.2, §E.3)"},
    {M::RejectFailSafe, "reject_fail_safe",
     "a Fail_Safe slave accepts a Data_Exchange without output data in Clear and sets its "
     "outputs safe (protocol-facts.md §D.8 Fail_Safe, §D.2)"},
    {M::WrongDiagIdent, "wrong_diag_ident",
     "Slave_Diag octets 5..6 carry the slave's Ident_Number (protocol-facts.md §D.4)"},
    {M::GetCfgSapsNotSwapped, "get_cfg_saps_not_swapped",
     "a response mirrors its request: DSAP = the request's SSAP, SSAP = the request's DSAP "
     "(Get_Cfg: DSAP 62, SSAP 59) (protocol-facts.md §B.2)"},
    {M::DataExchangeInWaitCfg, "dx_in_wait_cfg",
     "after Set_Prm the slave waits for a good Chk_Cfg (Wait_Cfg) and refuses Data_Exchange "
     "until then (protocol-facts.md §D.8)"},
    {M::FcbGlobal, "fcb_global",
     "the responder keeps the frame count bit and the stored reply per requesting station "
     "(IEC 61158-4-3; protocol-facts.md §C.6)"},
}};

constexpr bool table_in_enum_order() {
  for (std::size_t i = 0; i < kMutants.size(); ++i)
    if (static_cast<std::size_t>(kMutants[i].mutant) != i) return false;
  return true;
}
static_assert(table_in_enum_order(), "slave_mutants(): one row per enum value, in enum order");
static_assert(static_cast<std::size_t>(M::FcbGlobal) + 1 == kMutants.size(),
              "a new SlaveMutant needs its row");

}  // namespace

std::span<const MutantInfo> slave_mutants() { return kMutants; }

std::optional<SlaveMutant> parse_slave_mutant(std::string_view name) {
  for (const MutantInfo& i : kMutants)
    if (i.name == name) return i.mutant;
  return std::nullopt;
}

std::string_view slave_mutant_name(SlaveMutant m) {
  const auto i = static_cast<std::size_t>(m);
  return i < kMutants.size() ? kMutants[i].name : std::string_view("unknown");
}

}  // namespace pbvbus::devices
