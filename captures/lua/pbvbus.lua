-- pbvbus.lua: Wireshark dissector for pbvbus captures (design.md "Captures").
--
--   tshark -X lua_script:captures/lua/pbvbus.lua -r capture.pcapng
--   wireshark -X lua_script:captures/lua/pbvbus.lua -k -i - < <(pbvbus run --capture -)
--   permanent: copy to ~/.local/lib/wireshark/plugins/
--
-- Decodes, on pcapng interfaces with link type USER0 (147):
--   FDL telegrams (IEC 61158-4-3; protocol-facts.md §B): SD1/SD2/SD3/SD4/SC, LE/LEr, DA/SA with
--   extension bits, DSAP/SSAP and segment octets, FC, FCS (checked), ED.        fields pbfdl.*
--   DP-V0 services chosen by SAP (§D): Set_Prm, Chk_Cfg, Get_Cfg, Slave_Diag, Global_Control,
--   Data_Exchange, Rd_Inp, Rd_Outp, Set_Slave_Add.                               fields pbdp.*
--   DP-V1 (§E): MSAC_C1 read/write/Alarm_Ack, MSAC_C2 initiate/abort/idle/data transport,
--   resource manager, negative responses.                                       fields pbdpv1.*
--   Slave redundancy (PI 2.212, §G.2/G.3): the PrmCmd block in Set_Prm        fields pbdp.prmcmd.*
--   and the Prm_Cmd_Ack/Red_Status status blocks in Slave_Diag.                fields pbdp.red.*
--   MPI connection layer (§H.2/§H.3, docs/mpi.md): connect request/confirm, connection and
--   data acks, data messages with their numbers, disconnect; the S7 PDU of a data message is
--   handed to Wireshark's own s7comm (§H.4).                                    fields pbmpi.*
-- and on USER1 (148) pbvbus event records (captures/include/pbvbus/captures/event_record.hpp).
-- S7 PDUs that the writer stores as upper-PDU records (link type 252) need no script: tshark's
-- exported_pdu dissector hands them to s7comm by the heuristic name in their tags.
--                                                                               fields pbevent.*
--
-- Decisions where the wire alone cannot tell:
--   * The service of a response is the SAP it comes from (its SSAP mirrors the request's DSAP).
--   * Set_Prm octets 8..10 are shown as DPV1_Status_1..3 whenever the request is that long;
--     for a DP-V0 slave they are really its first User_Prm_Data octets (the GSD would tell).
--   * A device-related diagnosis block whose second octet is a known DP-V1 alarm or status type
--     and which is at least 4 octets long is decoded as a DP-V1 alarm/status block.
--   * Redundancy: a Set_Prm with PrmCmd but without Prm_Structure is still read as structured
--     blocks (with a warning); a pure PrmCmd is a Set_Prm of exactly 7 + 3 + 8 octets with one
--     PrmCmd block (§G.2 [I]). The Specifier octet is read as Seq_Nr in bits 7..3 and the
--     specifier in bits 1..0, the PrmCmd Properties bits in the AUMA order (both [U]).
--   * SAPs 0..48 with the class-2 master SAP 50 on the other side are MSAC_C2 connections.
--   * MPI is detected by the rule in the MPI section below (captures/README.md "MPI and S7");
--     other SAP pairs are shown as FDL data and not decoded further.

local fdl = Proto("pbfdl", "PROFIBUS FDL")
local dp = Proto("pbdp", "PROFIBUS DP")
local dpv1 = Proto("pbdpv1", "PROFIBUS DP-V1")
local ev = Proto("pbevent", "pbvbus event")

------------------------------------------------------------------------------------------------
-- Names
local sd_names = { [0x10] = "SD1", [0x68] = "SD2", [0xA2] = "SD3", [0xDC] = "SD4", [0xE5] = "SC" }
local fn_names = {
  [0x0] = "TE", [0x3] = "SDA_low", [0x4] = "SDN_low", [0x5] = "SDA_high", [0x6] = "SDN_high",
  [0x7] = "MSRD", [0x9] = "FDL_Status", [0xC] = "SRD_low", [0xD] = "SRD_high", [0xE] = "Ident",
  [0xF] = "LSAP_Status",
}
local status_names = {
  [0x0] = "OK", [0x1] = "UE", [0x2] = "RR", [0x3] = "RS", [0x8] = "DL", [0x9] = "NR",
  [0xA] = "DH", [0xC] = "RDL", [0xD] = "RDH",
}
local status_long = {
  [0x0] = "positive acknowledgement", [0x1] = "user error", [0x2] = "no resources",
  [0x3] = "SAP not activated", [0x8] = "response data low", [0x9] = "no response data",
  [0xA] = "response data high", [0xC] = "data not received, response data low",
  [0xD] = "data not received, response data high",
}
local station_types = {
  [0] = "slave", [1] = "master not ready", [2] = "master ready for the ring",
  [3] = "master in the ring",
}
local sap_services = {
  [49] = "MSAC_C2 RM", [50] = "Alarm", [51] = "MSAC_C1", [53] = "Ext_User_Prm",
  [55] = "Set_Slave_Add", [56] = "Rd_Inp", [57] = "Rd_Outp", [58] = "Global_Control",
  [59] = "Get_Cfg", [60] = "Slave_Diag", [61] = "Set_Prm", [62] = "Chk_Cfg",
}
local dpv1_fn_names = {
  [0x5E] = "Read", [0x5F] = "Write", [0x5C] = "Alarm_Ack", [0x57] = "Initiate", [0x58] = "Abort",
  [0x51] = "Data_Transport", [0x48] = "Idle", [0x56] = "RM", [0x08] = "Call",
}
local error_decode_names = { [0x80] = "DP-V1", [0xFE] = "FMS", [0xFF] = "HART" }
local error_class_names = { [0xA] = "application", [0xB] = "access", [0xC] = "resource" }
local error_code_names = {
  [0xA] = { [0] = "read error", [1] = "write error", [2] = "module failure",
            [8] = "version conflict", [9] = "feature not supported" },
  [0xB] = { [0] = "invalid index", [1] = "write length error", [2] = "invalid slot",
            [3] = "type conflict", [4] = "invalid area", [5] = "state conflict",
            [6] = "access denied", [7] = "invalid range", [8] = "invalid parameter",
            [9] = "invalid type" },
  [0xC] = { [0] = "read constraint conflict", [1] = "write constraint conflict",
            [2] = "resource busy", [3] = "resource unavailable" },
}
local alarm_types = {
  [1] = "Diagnostic_Alarm", [2] = "Process_Alarm", [3] = "Pull_Alarm", [4] = "Plug_Alarm",
  [5] = "Status_Alarm", [6] = "Update_Alarm",
}
local alarm_spec_names = {
  [0] = "no further differentiation", [1] = "error appears", [2] = "error disappears",
  [3] = "error disappears, slot still disturbed",
}
local status_types = {
  [0x81] = "Status_Message", [0x82] = "Module_Status", [0x83] = "DXB_Link_Status",
  [0x9E] = "Prm_Cmd_Ack", [0x9F] = "Red_Status",
}
local status_spec_names = { [0] = "none", [1] = "status appears", [2] = "status disappears", [3] = "reserved" }
local channel_errors = {
  [1] = "short circuit", [2] = "undervoltage", [3] = "overvoltage", [4] = "overload",
  [5] = "overtemperature", [6] = "line break", [7] = "upper limit exceeded",
  [8] = "lower limit undershot", [9] = "error",
}
local channel_types = {
  [0] = "unspecified", [1] = "bit", [2] = "2 bits", [3] = "4 bits", [4] = "byte", [5] = "word",
  [6] = "2 words", [7] = "reserved",
}
local channel_dirs = { [0] = "reserved", [1] = "input", [2] = "output", [3] = "input/output" }
local prm_block_types = {
  [0x02] = "PrmCmd", [0x03] = "DXB link table", [0x04] = "Isochronous mode",
  [0x07] = "DXB subscriber table", [0x08] = "Time AR", [0x81] = "User prm data",
}
-- Slave redundancy (PI 2.212 as pieced together in protocol-facts.md §G.2/G.3; the AUMA layout).
-- Red_State_1/2 bits: { mask, name, field suffix, short name for the info column }.
local red_state_bits = {
  { 0x01, "Backup", "backup", "Backup" },
  { 0x02, "Primary", "primary", "Primary" },
  { 0x04, "Hardware_defective", "hardware_defective", "HWdefect" },
  { 0x08, "Data_Exchange", "data_exchange", "DX" },
  { 0x10, "Master_State_Clear", "master_state_clear", "MSC" },
  { 0x20, "Baudrate_found", "baudrate_found", "Baud" },
  { 0x40, "Output_Hold_Time_started", "output_hold_time_started", "OHT" },
}
-- PrmCmd Function octet (block octet 5); echoed in Prm_Cmd_Ack/Red_Status octet 5.
local red_function_bits = {
  { 0x02, "Primary_Request", "primary_request" }, { 0x04, "Stop_MSAC1S", "stop_msac1s" },
  { 0x08, "Start_MSAC1S", "start_msac1s" }, { 0x10, "Check_Properties", "check_properties" },
  { 0x40, "Master_State_Clear", "master_state_clear" },
}
-- PrmCmd Properties octet (block octet 6) [U: AUMA column order, bit positions probable].
local prmcmd_property_bits = {
  { 0x01, "Primary_Req_MS0_MS1_used", "primary_req_ms0_ms1_used" },
  { 0x02, "Start_Stop_MSAC1S_used", "start_stop_msac1s_used" },
  { 0x04, "Address_Change", "address_change" }, { 0x08, "Address_Offset64", "address_offset64" },
}
local abort_subnets = { [0] = "none", [1] = "local", [2] = "remote" }
local abort_instances = { [0] = "FDL", [1] = "MSAC_C2", [2] = "user" }
local abort_reasons = {
  [1] = "sequence error", [2] = "invalid request PDU", [3] = "connection timeout",
  [4] = "invalid response PDU", [5] = "invalid service from user", [6] = "Send_Timeout too small",
  [7] = "invalid additional address info", [8] = "waiting for FDL_DATA_REPLY.con",
  [0xF] = "resource error",
}
local event_categories = {
  [1] = "line", [2] = "station", [3] = "master", [4] = "redundancy", [5] = "cpu", [6] = "note",
  [7] = "hsby",
}
local line_event_codes = {
  [0] = "cable cut", [1] = "cable repaired", [2] = "short circuit", [3] = "short circuit repaired",
  [4] = "noise on", [5] = "noise off", [6] = "power off", [7] = "power on",
  [8] = "transceiver failed", [9] = "transceiver repaired", [10] = "babbling transmitter",
  [11] = "babbling stopped",
}
-- Redundancy events (simulation/include/pbvbus/simulation/redundancy_system.hpp): code =
-- redundancy::SystemEvent::Kind, value = the S7 event id (0 for a switchover record).
-- H-system CPU pair events (captures/include/pbvbus/captures/cpu_event.hpp): code = kind,
-- a = rack, b = role after the event, value = event ID (bits 0..15) | OB << 16 | reason << 24 |
-- to << 32 | from << 40 (state, role or system mode by kind).
local cpu_event_kinds = { [0] = "state change", [1] = "role change", [2] = "system mode change", [3] = "OB" }
local cpu_roles = { [0] = "none", [1] = "master", [2] = "standby" }
local cpu_states = {
  [0] = "OFF", [1] = "STOP", [2] = "STARTUP", [3] = "RUN", [4] = "LINK-UP", [5] = "UPDATE",
  [6] = "HOLD", [7] = "ERROR-SEARCH", [8] = "DEFECTIVE", [9] = "SYNCUP",
}
local cpu_modes = {
  [0] = "Stop", [1] = "Startup", [2] = "Solo", [3] = "Link-up", [4] = "Update", [5] = "Redundant",
  [6] = "Hold", [7] = "SYNCUP",
}
local cpu_reasons = {
  [0] = "none", [1] = "master CPU lost", [2] = "master CPU in STOP", [3] = "standby CPU lost",
  [4] = "standby CPU in STOP", [5] = "redundant link lost", [6] = "comparison error",
  [7] = "one-sided OB 121", [8] = "master/standby swap",
}
-- Quantum Hot Standby pair events (captures/include/pbvbus/captures/hsby_event.hpp): code =
-- kind (quantum::PairEventKind), a = rack (-1 the pair or the fibre), b = the rack's state after
-- the event (-1 none), value = a switchover's takeover time in ns.
local hsby_event_kinds = {
  [0] = "power", [1] = "key", [2] = "state", [3] = "switchover", [4] = "transfer lost",
  [5] = "logic mismatch", [6] = "duplicate designation", [7] = "fibre", [8] = "update",
  [9] = "override", [10] = "cpu", [11] = "ignored",
}
local hsby_states = { [-1] = "none", [0] = "off", [1] = "offline", [2] = "primary", [3] = "standby" }
local redundancy_event_codes = {
  [0] = "redundancy loss", [1] = "redundancy restored", [2] = "station failure",
  [3] = "station return", [4] = "master system failure", [5] = "master system return",
  [6] = "switchover",
}

------------------------------------------------------------------------------------------------
-- FDL fields
local F = {
  sd = ProtoField.uint8("pbfdl.sd", "Start delimiter", base.HEX, sd_names),
  type = ProtoField.string("pbfdl.type", "Frame type"),
  le = ProtoField.uint8("pbfdl.le", "LE", base.DEC),
  ler = ProtoField.uint8("pbfdl.ler", "LEr", base.DEC),
  sd2 = ProtoField.uint8("pbfdl.sd_repeat", "Start delimiter (repeated)", base.HEX),
  da = ProtoField.uint8("pbfdl.da", "Destination address", base.DEC, nil, 0x7F),
  da_ext = ProtoField.bool("pbfdl.da_ext", "DA extension (DAE follows)", 8, nil, 0x80),
  sa = ProtoField.uint8("pbfdl.sa", "Source address", base.DEC, nil, 0x7F),
  sa_ext = ProtoField.bool("pbfdl.sa_ext", "SA extension (SAE follows)", 8, nil, 0x80),
  fc = ProtoField.uint8("pbfdl.fc", "Function code", base.HEX),
  fc_request = ProtoField.bool("pbfdl.fc.request", "Request", 8, nil, 0x40),
  fc_fcb = ProtoField.bool("pbfdl.fc.fcb", "FCB (frame count bit)", 8, nil, 0x20),
  fc_fcv = ProtoField.bool("pbfdl.fc.fcv", "FCV (frame count bit valid)", 8, nil, 0x10),
  fc_function = ProtoField.uint8("pbfdl.fc.function", "Function", base.HEX, fn_names, 0x0F),
  fc_cv = ProtoField.bool("pbfdl.fc.clock_value", "Clock value", 8, nil, 0x80),
  fc_station = ProtoField.uint8("pbfdl.fc.station_type", "Station type", base.DEC, station_types, 0x30),
  fc_status = ProtoField.uint8("pbfdl.fc.status", "Status", base.HEX, status_names, 0x0F),
  fc_name = ProtoField.string("pbfdl.fc.name", "Function/status name"),
  dae = ProtoField.uint8("pbfdl.dae", "Destination address extension", base.HEX),
  sae = ProtoField.uint8("pbfdl.sae", "Source address extension", base.HEX),
  dsap = ProtoField.uint8("pbfdl.dsap", "DSAP", base.DEC, nil, 0x3F),
  ssap = ProtoField.uint8("pbfdl.ssap", "SSAP", base.DEC, nil, 0x3F),
  da_segment = ProtoField.uint8("pbfdl.da_segment", "Destination segment", base.DEC, nil, 0x3F),
  sa_segment = ProtoField.uint8("pbfdl.sa_segment", "Source segment", base.DEC, nil, 0x3F),
  service = ProtoField.string("pbfdl.service", "DP service"),
  data = ProtoField.bytes("pbfdl.data", "Data unit"),
  fcs = ProtoField.uint8("pbfdl.fcs", "FCS", base.HEX),
  fcs_ok = ProtoField.bool("pbfdl.fcs_ok", "FCS correct"),
  fcs_calc = ProtoField.uint8("pbfdl.fcs_calc", "FCS computed", base.HEX),
  ed = ProtoField.uint8("pbfdl.ed", "End delimiter", base.HEX),
}
fdl.fields = {}
for _, f in pairs(F) do table.insert(fdl.fields, f) end

local E = {
  fcs = ProtoExpert.new("pbfdl.fcs_bad", "FCS mismatch", expert.group.CHECKSUM, expert.severity.ERROR),
  truncated = ProtoExpert.new("pbfdl.truncated", "Frame truncated", expert.group.MALFORMED, expert.severity.ERROR),
  trailing = ProtoExpert.new("pbfdl.trailing", "Octets after the end of the frame", expert.group.MALFORMED, expert.severity.ERROR),
  le = ProtoExpert.new("pbfdl.le_bad", "LE invalid", expert.group.MALFORMED, expert.severity.ERROR),
  ed = ProtoExpert.new("pbfdl.ed_bad", "End delimiter is not 0x16", expert.group.MALFORMED, expert.severity.ERROR),
  sd = ProtoExpert.new("pbfdl.sd_bad", "Unknown start delimiter", expert.group.MALFORMED, expert.severity.ERROR),
  fc = ProtoExpert.new("pbfdl.fc_reserved", "Reserved function or status code", expert.group.PROTOCOL, expert.severity.WARN),
  ext = ProtoExpert.new("pbfdl.ext_bad", "Bad address extension chain", expert.group.MALFORMED, expert.severity.ERROR),
  addr = ProtoExpert.new("pbfdl.addr_bad", "Invalid address", expert.group.PROTOCOL, expert.severity.WARN),
  dp = ProtoExpert.new("pbdp.malformed", "DP PDU shorter than its service requires", expert.group.MALFORMED, expert.severity.WARN),
  prmcmd = ProtoExpert.new("pbdp.prmcmd.malformed", "PrmCmd block malformed", expert.group.MALFORMED, expert.severity.WARN),
  prmcmd_bits = ProtoExpert.new("pbdp.prmcmd.inconsistent", "PrmCmd and DPV1_Status_3 disagree", expert.group.PROTOCOL, expert.severity.WARN),
  red = ProtoExpert.new("pbdp.red.malformed", "Redundancy status block malformed", expert.group.MALFORMED, expert.severity.WARN),
  dpv1_neg = ProtoExpert.new("pbdpv1.negative", "DP-V1 negative response", expert.group.RESPONSE_CODE, expert.severity.NOTE),
  event = ProtoExpert.new("pbevent.malformed", "Event record malformed", expert.group.MALFORMED, expert.severity.ERROR),
}
fdl.experts = { E.fcs, E.truncated, E.trailing, E.le, E.ed, E.sd, E.fc, E.ext, E.addr }
dp.experts = { E.dp, E.prmcmd, E.prmcmd_bits, E.red }
dpv1.experts = { E.dpv1_neg }
ev.experts = { E.event }

------------------------------------------------------------------------------------------------
-- DP fields
local D = {
  service = ProtoField.string("pbdp.service", "Service"),
  -- Set_Prm
  station_status = ProtoField.uint8("pbdp.prm.station_status", "Station_Status", base.HEX),
  lock_req = ProtoField.bool("pbdp.prm.lock_req", "Lock_Req", 8, nil, 0x80),
  unlock_req = ProtoField.bool("pbdp.prm.unlock_req", "Unlock_Req", 8, nil, 0x40),
  sync_req = ProtoField.bool("pbdp.prm.sync_req", "Sync_Req", 8, nil, 0x20),
  freeze_req = ProtoField.bool("pbdp.prm.freeze_req", "Freeze_Req", 8, nil, 0x10),
  wd_on = ProtoField.bool("pbdp.prm.wd_on", "WD_On", 8, nil, 0x08),
  wd_fact_1 = ProtoField.uint8("pbdp.prm.wd_fact_1", "WD_Fact_1", base.DEC),
  wd_fact_2 = ProtoField.uint8("pbdp.prm.wd_fact_2", "WD_Fact_2", base.DEC),
  wd_ms = ProtoField.uint32("pbdp.prm.watchdog_ms", "Watchdog time (ms)", base.DEC),
  min_tsdr = ProtoField.uint8("pbdp.prm.min_tsdr", "min TSDR (bit times)", base.DEC),
  ident = ProtoField.uint16("pbdp.ident", "Ident_Number", base.HEX),
  group_ident = ProtoField.uint8("pbdp.prm.group_ident", "Group_Ident", base.HEX),
  dpv1_status_1 = ProtoField.uint8("pbdp.prm.dpv1_status_1", "DPV1_Status_1", base.HEX),
  dpv1_enable = ProtoField.bool("pbdp.prm.dpv1_enable", "DPV1_Enable", 8, nil, 0x80),
  fail_safe = ProtoField.bool("pbdp.prm.fail_safe", "Fail_Safe", 8, nil, 0x40),
  publisher_enable = ProtoField.bool("pbdp.prm.publisher_enable", "Publisher_Enable", 8, nil, 0x20),
  wd_base_1ms = ProtoField.bool("pbdp.prm.wd_base_1ms", "WD_Base_1ms", 8, nil, 0x04),
  dis_stop = ProtoField.bool("pbdp.prm.dis_stop_control", "Dis_Stop_Control", 8, nil, 0x02),
  dis_start = ProtoField.bool("pbdp.prm.dis_start_control", "Dis_Start_Control", 8, nil, 0x01),
  dpv1_status_2 = ProtoField.uint8("pbdp.prm.dpv1_status_2", "DPV1_Status_2", base.HEX),
  en_pull_plug = ProtoField.bool("pbdp.prm.enable_pull_plug_alarm", "Enable_Pull_Plug_Alarm", 8, nil, 0x80),
  en_process = ProtoField.bool("pbdp.prm.enable_process_alarm", "Enable_Process_Alarm", 8, nil, 0x40),
  en_diag = ProtoField.bool("pbdp.prm.enable_diagnostic_alarm", "Enable_Diagnostic_Alarm", 8, nil, 0x20),
  en_manuf = ProtoField.bool("pbdp.prm.enable_manufacturer_alarm", "Enable_Manufacturer_Specific_Alarm", 8, nil, 0x10),
  en_status = ProtoField.bool("pbdp.prm.enable_status_alarm", "Enable_Status_Alarm", 8, nil, 0x08),
  en_update = ProtoField.bool("pbdp.prm.enable_update_alarm", "Enable_Update_Alarm", 8, nil, 0x04),
  chk_cfg_mode = ProtoField.bool("pbdp.prm.check_cfg_mode", "Check_Cfg_Mode", 8, nil, 0x01),
  dpv1_status_3 = ProtoField.uint8("pbdp.prm.dpv1_status_3", "DPV1_Status_3", base.HEX),
  prm_cmd = ProtoField.bool("pbdp.prm.prmcmd", "PrmCmd", 8, nil, 0x80),
  isom_req = ProtoField.bool("pbdp.prm.isom_req", "IsoM_Req", 8, nil, 0x10),
  prm_structure = ProtoField.bool("pbdp.prm.prm_structure", "Prm_Structure", 8, nil, 0x08),
  alarm_mode = ProtoField.uint8("pbdp.prm.alarm_mode", "Alarm_Mode", base.DEC, nil, 0x07),
  user_prm_data = ProtoField.bytes("pbdp.prm.user_prm_data", "User_Prm_Data"),
  blk_len = ProtoField.uint8("pbdp.prm.block_length", "Structure_Length", base.DEC),
  blk_type = ProtoField.uint8("pbdp.prm.block_type", "Structure_Type", base.HEX, prm_block_types),
  blk_slot = ProtoField.uint8("pbdp.prm.block_slot", "Slot_Number", base.DEC),
  blk_spec = ProtoField.uint8("pbdp.prm.block_specifier", "Index/Specifier", base.HEX),
  blk_data = ProtoField.bytes("pbdp.prm.block_data", "Structure data"),
  -- Slave redundancy: the PrmCmd block in Set_Prm (§G.2) ...
  prmcmd = ProtoField.bytes("pbdp.prmcmd", "PrmCmd block"),
  prmcmd_len = ProtoField.uint8("pbdp.prmcmd.structure_length", "Structure_Length", base.DEC),
  prmcmd_type = ProtoField.uint8("pbdp.prmcmd.structure_type", "Structure_Type", base.HEX, prm_block_types),
  prmcmd_slot = ProtoField.uint8("pbdp.prmcmd.slot", "Slot_Number", base.DEC),
  prmcmd_spec = ProtoField.uint8("pbdp.prmcmd.specifier", "Specifier/Seq_Nr", base.HEX),
  prmcmd_seq = ProtoField.uint8("pbdp.prmcmd.seq_nr", "Seq_Nr", base.DEC, nil, 0xF8),
  prmcmd_spec_bits = ProtoField.uint8("pbdp.prmcmd.specifier_bits", "Specifier", base.DEC, nil, 0x03),
  prmcmd_function = ProtoField.uint8("pbdp.prmcmd.function", "Function", base.HEX),
  prmcmd_functions = ProtoField.string("pbdp.prmcmd.functions", "Functions requested"),
  prmcmd_properties = ProtoField.uint8("pbdp.prmcmd.properties", "Properties", base.HEX),
  prmcmd_hold = ProtoField.uint16("pbdp.prmcmd.output_hold_time", "Output_Hold_Time (10 ms)", base.DEC),
  prmcmd_hold_ms = ProtoField.uint32("pbdp.prmcmd.output_hold_time_ms", "Output_Hold_Time (ms)", base.DEC),
  prmcmd_pure = ProtoField.bool("pbdp.prmcmd.pure", "Pure PrmCmd (Set_Prm = header, DPV1_Status, PrmCmd block only)"),
  -- ... and the Prm_Cmd_Ack (0x9E) / Red_Status (0x9F) status blocks in the diagnosis (§G.3).
  red_status_type = ProtoField.uint8("pbdp.red.status_type", "Status_Type", base.HEX, status_types),
  red_slot = ProtoField.uint8("pbdp.red.slot", "Slot_Number", base.DEC),
  red_spec = ProtoField.uint8("pbdp.red.specifier", "Specifier/Seq_Nr", base.HEX),
  red_seq = ProtoField.uint8("pbdp.red.seq_nr", "Seq_Nr", base.DEC, nil, 0xF8),
  red_spec_bits = ProtoField.uint8("pbdp.red.specifier_bits", "Status_Specifier", base.DEC, status_spec_names, 0x03),
  red_function = ProtoField.uint8("pbdp.red.function", "Function (echo)", base.HEX),
  red_functions = ProtoField.string("pbdp.red.functions", "Functions echoed"),
  red_state_1 = ProtoField.uint8("pbdp.red.state_1", "Red_State_1 (this interface)", base.HEX),
  red_state_2 = ProtoField.uint8("pbdp.red.state_2", "Red_State_2 (partner)", base.HEX),
  red_state_3 = ProtoField.uint8("pbdp.red.state_3", "Red_State_3", base.HEX),
  red_own = ProtoField.string("pbdp.red.own", "This interface"),
  red_partner = ProtoField.string("pbdp.red.partner", "Partner interface"),
  red_state_text = ProtoField.string("pbdp.red.state", "Redundancy state"),
  -- Chk_Cfg / Get_Cfg
  cfg_id = ProtoField.uint8("pbdp.cfg.id", "Identifier", base.HEX),
  cfg_format = ProtoField.string("pbdp.cfg.format", "Format"),
  cfg_dir = ProtoField.string("pbdp.cfg.direction", "Direction"),
  cfg_len = ProtoField.uint8("pbdp.cfg.length", "Length (units)", base.DEC),
  cfg_unit = ProtoField.string("pbdp.cfg.unit", "Unit"),
  cfg_consistent = ProtoField.bool("pbdp.cfg.consistent", "Consistent over the whole length"),
  cfg_out_len = ProtoField.uint8("pbdp.cfg.output_length_octet", "Output length octet", base.HEX),
  cfg_in_len = ProtoField.uint8("pbdp.cfg.input_length_octet", "Input length octet", base.HEX),
  cfg_manuf = ProtoField.bytes("pbdp.cfg.manufacturer_data", "Manufacturer-specific data"),
  cfg_text = ProtoField.string("pbdp.cfg.text", "Module"),
  -- Slave_Diag
  status_1 = ProtoField.uint8("pbdp.diag.station_status_1", "Station_Status_1", base.HEX),
  s1_non_existent = ProtoField.bool("pbdp.diag.station_non_existent", "Station_Non_Existent", 8, nil, 0x01),
  s1_not_ready = ProtoField.bool("pbdp.diag.station_not_ready", "Station_Not_Ready", 8, nil, 0x02),
  s1_cfg_fault = ProtoField.bool("pbdp.diag.cfg_fault", "Cfg_Fault", 8, nil, 0x04),
  s1_ext_diag = ProtoField.bool("pbdp.diag.ext_diag", "Ext_Diag", 8, nil, 0x08),
  s1_not_supported = ProtoField.bool("pbdp.diag.not_supported", "Not_Supported", 8, nil, 0x10),
  s1_invalid = ProtoField.bool("pbdp.diag.invalid_slave_response", "Invalid_Slave_Response", 8, nil, 0x20),
  s1_prm_fault = ProtoField.bool("pbdp.diag.prm_fault", "Prm_Fault", 8, nil, 0x40),
  s1_master_lock = ProtoField.bool("pbdp.diag.master_lock", "Master_Lock", 8, nil, 0x80),
  status_2 = ProtoField.uint8("pbdp.diag.station_status_2", "Station_Status_2", base.HEX),
  s2_prm_req = ProtoField.bool("pbdp.diag.prm_req", "Prm_Req", 8, nil, 0x01),
  s2_stat_diag = ProtoField.bool("pbdp.diag.stat_diag", "Stat_Diag", 8, nil, 0x02),
  s2_one = ProtoField.bool("pbdp.diag.always_one", "Always 1", 8, nil, 0x04),
  s2_wd_on = ProtoField.bool("pbdp.diag.wd_on", "WD_On", 8, nil, 0x08),
  s2_freeze = ProtoField.bool("pbdp.diag.freeze_mode", "Freeze_Mode", 8, nil, 0x10),
  s2_sync = ProtoField.bool("pbdp.diag.sync_mode", "Sync_Mode", 8, nil, 0x20),
  s2_deactivated = ProtoField.bool("pbdp.diag.deactivated", "Deactivated", 8, nil, 0x80),
  status_3 = ProtoField.uint8("pbdp.diag.station_status_3", "Station_Status_3", base.HEX),
  s3_overflow = ProtoField.bool("pbdp.diag.ext_diag_overflow", "Ext_Diag_Overflow", 8, nil, 0x80),
  master_add = ProtoField.uint8("pbdp.diag.master_add", "Diag.Master_Add", base.DEC),
  status_names = ProtoField.string("pbdp.diag.status", "Status bits set"),
  ext_block = ProtoField.bytes("pbdp.diag.ext_block", "Extended diagnosis block"),
  ext_type = ProtoField.string("pbdp.diag.block_type", "Block type"),
  ext_len = ProtoField.uint8("pbdp.diag.block_length", "Block length", base.DEC),
  id_modules = ProtoField.string("pbdp.diag.faulty_modules", "Faulty modules"),
  ch_module = ProtoField.uint8("pbdp.diag.channel.module", "Module", base.DEC, nil, 0x3F),
  ch_number = ProtoField.uint8("pbdp.diag.channel.number", "Channel", base.DEC, nil, 0x3F),
  ch_dir = ProtoField.uint8("pbdp.diag.channel.direction", "Direction", base.DEC, channel_dirs, 0xC0),
  ch_type = ProtoField.uint8("pbdp.diag.channel.type", "Channel type", base.DEC, channel_types, 0xE0),
  ch_error = ProtoField.uint8("pbdp.diag.channel.error", "Error type", base.DEC, channel_errors, 0x1F),
  dev_data = ProtoField.bytes("pbdp.diag.device_data", "Device-related data"),
  -- Global_Control
  gc_command = ProtoField.uint8("pbdp.gc.control_command", "Control_Command", base.HEX),
  gc_clear = ProtoField.bool("pbdp.gc.clear_data", "Clear_Data", 8, nil, 0x02),
  gc_unfreeze = ProtoField.bool("pbdp.gc.unfreeze", "Unfreeze", 8, nil, 0x04),
  gc_freeze = ProtoField.bool("pbdp.gc.freeze", "Freeze", 8, nil, 0x08),
  gc_unsync = ProtoField.bool("pbdp.gc.unsync", "Unsync", 8, nil, 0x10),
  gc_sync = ProtoField.bool("pbdp.gc.sync", "Sync", 8, nil, 0x20),
  gc_group = ProtoField.uint8("pbdp.gc.group_select", "Group_Select", base.HEX),
  -- Data
  outputs = ProtoField.bytes("pbdp.outputs", "Outputs"),
  data = ProtoField.bytes("pbdp.data", "Service data"),
  inputs = ProtoField.bytes("pbdp.inputs", "Inputs"),
  -- Set_Slave_Add
  new_address = ProtoField.uint8("pbdp.ssa.new_address", "New_Slave_Address", base.DEC),
  no_add_chg = ProtoField.uint8("pbdp.ssa.no_add_chg", "No_Add_Chg", base.HEX),
  rem_data = ProtoField.bytes("pbdp.ssa.rem_slave_data", "Rem_Slave_Data"),
}
-- Bit fields of the redundancy octets: pbdp.prmcmd.<bit>, pbdp.prmcmd.properties.<bit>,
-- pbdp.red.function.<bit>, pbdp.red.state_1.<bit>, pbdp.red.state_2.<bit>.
local function bit_fields(prefix, bits)
  local out = {}
  for _, b in ipairs(bits) do
    local f = ProtoField.bool(prefix .. "." .. b[3], b[2], 8, nil, b[1])
    table.insert(out, f)
    D[prefix .. "." .. b[3]] = f
  end
  return out
end
local RB = {
  prmcmd_function = bit_fields("pbdp.prmcmd", red_function_bits),
  prmcmd_properties = bit_fields("pbdp.prmcmd.properties", prmcmd_property_bits),
  red_function = bit_fields("pbdp.red.function", red_function_bits),
  red_state_1 = bit_fields("pbdp.red.state_1", red_state_bits),
  red_state_2 = bit_fields("pbdp.red.state_2", red_state_bits),
}
dp.fields = {}
for _, f in pairs(D) do table.insert(dp.fields, f) end

------------------------------------------------------------------------------------------------
-- DP-V1 fields
local V = {
  fn = ProtoField.uint8("pbdpv1.function_num", "Function_Num", base.HEX),
  fn_name = ProtoField.string("pbdpv1.service", "Service"),
  error_bit = ProtoField.bool("pbdpv1.error", "Negative response", 8, nil, 0x80),
  slot = ProtoField.uint8("pbdpv1.slot", "Slot_Number", base.DEC),
  index = ProtoField.uint8("pbdpv1.index", "Index", base.DEC),
  length = ProtoField.uint8("pbdpv1.length", "Length", base.DEC),
  data = ProtoField.bytes("pbdpv1.data", "Data"),
  error_decode = ProtoField.uint8("pbdpv1.error_decode", "Error_Decode", base.HEX, error_decode_names),
  error_code_1 = ProtoField.uint8("pbdpv1.error_code_1", "Error_Code_1", base.HEX),
  error_class = ProtoField.uint8("pbdpv1.error_class", "Error class", base.HEX, error_class_names, 0xF0),
  error_code = ProtoField.uint8("pbdpv1.error_code", "Error code", base.HEX, nil, 0x0F),
  error_text = ProtoField.string("pbdpv1.error_text", "Error"),
  error_code_2 = ProtoField.uint8("pbdpv1.error_code_2", "Error_Code_2", base.HEX),
  alarm_type = ProtoField.uint8("pbdpv1.alarm_type", "Alarm_Type", base.DEC, alarm_types, 0x7F),
  alarm_spec = ProtoField.uint8("pbdpv1.alarm_specifier", "Alarm_Specifier", base.HEX),
  seq_nr = ProtoField.uint8("pbdpv1.seq_nr", "Seq_Nr", base.DEC, nil, 0xF8),
  add_ack = ProtoField.bool("pbdpv1.add_ack", "Add_Ack", 8, nil, 0x04),
  spec = ProtoField.uint8("pbdpv1.specifier", "Specifier", base.DEC, alarm_spec_names, 0x03),
  status_type = ProtoField.uint8("pbdpv1.status_type", "Status_Type", base.HEX, status_types),
  status_spec = ProtoField.uint8("pbdpv1.status_specifier", "Status_Specifier", base.DEC, status_spec_names, 0x03),
  diag_data = ProtoField.bytes("pbdpv1.diagnostic_user_data", "Diagnostic_User_Data"),
  send_timeout = ProtoField.uint16("pbdpv1.send_timeout", "Send_Timeout (10 ms)", base.DEC),
  server_sap = ProtoField.uint8("pbdpv1.server_sap", "Server_SAP", base.DEC),
  max_len = ProtoField.uint8("pbdpv1.max_len_data_unit", "Max_Len_Data_Unit", base.DEC),
  features_1 = ProtoField.uint8("pbdpv1.features_supported_1", "Features_Supported_1", base.HEX),
  features_2 = ProtoField.uint8("pbdpv1.features_supported_2", "Features_Supported_2", base.HEX),
  pfeatures_1 = ProtoField.uint8("pbdpv1.profile_features_1", "Profile_Features_Supported_1", base.HEX),
  pfeatures_2 = ProtoField.uint8("pbdpv1.profile_features_2", "Profile_Features_Supported_2", base.HEX),
  profile_ident = ProtoField.uint16("pbdpv1.profile_ident", "Profile_Ident_Number", base.HEX),
  s_type = ProtoField.uint8("pbdpv1.s_type", "S_Type", base.HEX),
  s_len = ProtoField.uint8("pbdpv1.s_len", "S_Len", base.DEC),
  d_type = ProtoField.uint8("pbdpv1.d_type", "D_Type", base.HEX),
  d_len = ProtoField.uint8("pbdpv1.d_len", "D_Len", base.DEC),
  addr_data = ProtoField.bytes("pbdpv1.addr_data", "Addr_Data"),
  subnet = ProtoField.uint8("pbdpv1.abort.subnet", "Subnet", base.DEC, abort_subnets),
  instance = ProtoField.uint8("pbdpv1.abort.instance", "Instance", base.DEC, abort_instances, 0xF0),
  reason = ProtoField.uint8("pbdpv1.abort.reason", "Reason_Code", base.DEC, abort_reasons, 0x0F),
}
dpv1.fields = {}
for _, f in pairs(V) do table.insert(dpv1.fields, f) end

------------------------------------------------------------------------------------------------
-- Event fields
local EV = {
  version = ProtoField.uint8("pbevent.version", "Version", base.DEC),
  category = ProtoField.uint8("pbevent.category", "Category", base.DEC, event_categories),
  code = ProtoField.uint16("pbevent.code", "Code", base.DEC),
  code_name = ProtoField.string("pbevent.code_name", "Event"),
  line = ProtoField.int32("pbevent.line", "Line", base.DEC),
  a = ProtoField.int32("pbevent.a", "Station/attachment a", base.DEC),
  b = ProtoField.int32("pbevent.b", "Station/attachment b", base.DEC),
  value = ProtoField.uint64("pbevent.value", "Value", base.HEX),
  text = ProtoField.string("pbevent.text", "Text", base.UNICODE),
  s7 = ProtoField.string("pbevent.s7", "S7 event id"),
  cpu_kind = ProtoField.uint16("pbevent.cpu.kind", "CPU event", base.DEC, cpu_event_kinds),
  cpu_rack = ProtoField.int32("pbevent.cpu.rack", "Rack", base.DEC),
  cpu_role = ProtoField.int32("pbevent.cpu.role", "Role", base.DEC, cpu_roles),
  cpu_ob = ProtoField.uint8("pbevent.cpu.ob", "OB number", base.DEC),
  cpu_ob_name = ProtoField.string("pbevent.cpu.ob_name", "OB"),
  cpu_reason = ProtoField.uint8("pbevent.cpu.reason", "Reason", base.DEC, cpu_reasons),
  cpu_event_id = ProtoField.uint16("pbevent.cpu.event_id", "Event ID", base.HEX),
  cpu_from = ProtoField.string("pbevent.cpu.from", "From"),
  cpu_to = ProtoField.string("pbevent.cpu.to", "To"),
  hsby_kind = ProtoField.uint16("pbevent.hsby.kind", "Hot Standby event", base.DEC, hsby_event_kinds),
  hsby_rack = ProtoField.int32("pbevent.hsby.rack", "Rack", base.DEC),
  hsby_state = ProtoField.int32("pbevent.hsby.state", "State after", base.DEC, hsby_states),
  hsby_kind_name = ProtoField.string("pbevent.hsby.kind_name", "Event"),
  hsby_state_name = ProtoField.string("pbevent.hsby.state_name", "State after"),
  hsby_takeover = ProtoField.uint64("pbevent.hsby.takeover_ns", "Takeover time (ns)", base.DEC),
  hsby_takeover_ms = ProtoField.string("pbevent.hsby.takeover", "Takeover time"),
}
ev.fields = {}
for _, f in pairs(EV) do table.insert(ev.fields, f) end

------------------------------------------------------------------------------------------------
-- Helpers
local function bits_set(v, names)
  local out = {}
  for _, e in ipairs(names) do
    if bit.band(v, e[1]) ~= 0 then table.insert(out, e[2]) end
  end
  return table.concat(out, ", ")
end

local function hexbytes(tvb, off, len)
  local t = {}
  for i = 0, len - 1 do t[#t + 1] = string.format("%02X", tvb(off + i, 1):uint()) end
  return table.concat(t, " ")
end

-- A DP/DP-V1 payload: tvb range [off, off+len) inside the FDL frame.
local function short(tree, need, have)
  if have < need then
    tree:add_proto_expert_info(E.dp, string.format("needs %d octets, has %d", need, have))
    return true
  end
  return false
end

------------------------------------------------------------------------------------------------
-- Slave redundancy (§G.2/G.3)

-- Names of the bits set in v, joined with sep; `col` picks the name column (2 = full name).
local prmcmd_block, red_status_block

local function bit_names(v, bits, sep, col)
  local out = {}
  for _, b in ipairs(bits) do
    if bit.band(v, b[1]) ~= 0 then table.insert(out, b[col or 2]) end
  end
  return table.concat(out, sep)
end

local function add_bits(item, fields, range)
  for _, f in ipairs(fields) do item:add(f, range) end
end

-- The PrmCmd structured block in Set_Prm (§G.2), `blen` octets declared at `pos`, `have`
-- present. Returns the info text, e.g. "PrmCmd Primary_Request".
function prmcmd_block(tvb, pos, blen, have, tree)
  local b = tree:add(D.prmcmd, tvb(pos, have))
  b:add(D.prmcmd_len, tvb(pos, 1))
  b:add(D.prmcmd_type, tvb(pos + 1, 1))
  local fn = ""
  if have >= 3 then
    b:add(D.prmcmd_slot, tvb(pos + 2, 1))
    local slot = tvb(pos + 2, 1):uint()
    if slot ~= 0 then b:add_proto_expert_info(E.prmcmd, string.format("Slot_Number %d, a PrmCmd has slot 0", slot)) end
  end
  if have >= 4 then
    local sp = b:add(D.prmcmd_spec, tvb(pos + 3, 1))
    sp:add(D.prmcmd_seq, tvb(pos + 3, 1))
    sp:add(D.prmcmd_spec_bits, tvb(pos + 3, 1))
  end
  if have >= 5 then
    local v = tvb(pos + 4, 1):uint()
    local fi = b:add(D.prmcmd_function, tvb(pos + 4, 1))
    add_bits(fi, RB.prmcmd_function, tvb(pos + 4, 1))
    fn = bit_names(v, red_function_bits, "+")
    b:add(D.prmcmd_functions, tvb(pos + 4, 1), fn ~= "" and fn or "none")
  end
  if have >= 6 then
    local pr = b:add(D.prmcmd_properties, tvb(pos + 5, 1))
    add_bits(pr, RB.prmcmd_properties, tvb(pos + 5, 1))
  end
  local hold_ms
  if have >= 8 then
    b:add(D.prmcmd_hold, tvb(pos + 6, 2))
    hold_ms = tvb(pos + 6, 2):uint() * 10
    b:add(D.prmcmd_hold_ms, tvb(pos + 6, 2), hold_ms):set_generated()
  end
  if blen ~= 8 then
    b:add_proto_expert_info(E.prmcmd, string.format("Structure_Length %d, a PrmCmd block has 8 octets", blen))
  end
  if have < blen then
    b:add_proto_expert_info(E.prmcmd, string.format("PrmCmd block cut short: %d of %d octets", have, blen))
  elseif have > 8 then
    b:add(D.blk_data, tvb(pos + 8, have - 8))
  end
  b:set_text(string.format("PrmCmd block: %s%s", fn ~= "" and fn or "no function",
    hold_ms and string.format(", Output_Hold_Time %d ms", hold_ms) or ""))
  return "PrmCmd" .. (fn ~= "" and (" " .. fn) or "")
end

-- One Red_State octet: its field with the bit subfields, and the short names ("Primary+DX").
local function red_state(tree, field, bitfields, range)
  local it = tree:add(field, range)
  add_bits(it, bitfields, range)
  local short = bit_names(range:uint(), red_state_bits, "+", 4)
  it:append_text(" (" .. (short ~= "" and short or "none") .. ")")
  return short ~= "" and short or "none", bit_names(range:uint(), red_state_bits, ", ")
end

-- A Prm_Cmd_Ack (0x9E) or Red_Status (0x9F) status block in the diagnosis (§G.3): `blen`
-- octets declared at `off` (the header), `have` present. Returns the info text.
function red_status_block(tvb, off, blen, have, tree)
  local t = tvb(off + 1, 1):uint()
  local name = status_types[t]
  tree:add(D.red_status_type, tvb(off + 1, 1))
  if have >= 3 then tree:add(D.red_slot, tvb(off + 2, 1)) end
  if have >= 4 then
    local sp = tree:add(D.red_spec, tvb(off + 3, 1))
    sp:add(D.red_seq, tvb(off + 3, 1))
    sp:add(D.red_spec_bits, tvb(off + 3, 1))
  end
  local fn = ""
  if have >= 5 then
    local fi = tree:add(D.red_function, tvb(off + 4, 1))
    add_bits(fi, RB.red_function, tvb(off + 4, 1))
    fn = bit_names(tvb(off + 4, 1):uint(), red_function_bits, "+")
    tree:add(D.red_functions, tvb(off + 4, 1), fn ~= "" and fn or "none")
  end
  local own, partner, own_long, partner_long
  if have >= 6 then
    own, own_long = red_state(tree, D.red_state_1, RB.red_state_1, tvb(off + 5, 1))
    tree:add(D.red_own, tvb(off + 5, 1), own_long ~= "" and own_long or "none")
  end
  if have >= 7 then
    partner, partner_long = red_state(tree, D.red_state_2, RB.red_state_2, tvb(off + 6, 1))
    tree:add(D.red_partner, tvb(off + 6, 1), partner_long ~= "" and partner_long or "none")
  end
  if have >= 8 then tree:add(D.red_state_3, tvb(off + 7, 1)) end
  if have > 8 then tree:add(V.diag_data, tvb(off + 8, have - 8)) end
  if blen ~= 8 then
    tree:add_proto_expert_info(E.red, string.format("%s block of %d octets, expected 8", name, blen))
  end
  if have < math.min(blen, 8) then
    tree:add_proto_expert_info(E.red, string.format("%s block cut short: %d of %d octets", name, have, blen))
  end
  local text = name
  if t == 0x9E and fn ~= "" then text = text .. " " .. fn end
  if own then
    text = text .. " own " .. own
    if partner then text = text .. ", partner " .. partner end
    tree:add(D.red_state_text, tvb(off + 5, partner and 2 or 1),
      "own " .. (own_long ~= "" and own_long or "none") ..
      (partner and ("; partner " .. (partner_long ~= "" and partner_long or "none")) or ""))
  else
    text = text .. " (cut short)"
  end
  return text
end

------------------------------------------------------------------------------------------------
-- DP decoders; each returns a short text for the info column (may be "").
local function dp_set_prm(tvb, off, len, tree)
  if short(tree, 7, len) then return "" end
  local st = tree:add(D.station_status, tvb(off, 1))
  for _, f in ipairs({ D.lock_req, D.unlock_req, D.sync_req, D.freeze_req, D.wd_on }) do st:add(f, tvb(off, 1)) end
  tree:add(D.wd_fact_1, tvb(off + 1, 1))
  tree:add(D.wd_fact_2, tvb(off + 2, 1))
  local base_ms = 10
  if len >= 8 and bit.band(tvb(off + 7, 1):uint(), 0x04) ~= 0 then base_ms = 1 end
  local wd = base_ms * tvb(off + 1, 1):uint() * tvb(off + 2, 1):uint()
  tree:add(D.wd_ms, tvb(off + 1, 2), wd):set_generated()
  tree:add(D.min_tsdr, tvb(off + 3, 1))
  tree:add(D.ident, tvb(off + 4, 2))
  tree:add(D.group_ident, tvb(off + 6, 1))
  local user = off + 7
  if len >= 10 then
    local s1 = tree:add(D.dpv1_status_1, tvb(off + 7, 1))
    for _, f in ipairs({ D.dpv1_enable, D.fail_safe, D.publisher_enable, D.wd_base_1ms, D.dis_stop, D.dis_start }) do
      s1:add(f, tvb(off + 7, 1))
    end
    local s2 = tree:add(D.dpv1_status_2, tvb(off + 8, 1))
    for _, f in ipairs({ D.en_pull_plug, D.en_process, D.en_diag, D.en_manuf, D.en_status, D.en_update, D.chk_cfg_mode }) do
      s2:add(f, tvb(off + 8, 1))
    end
    local s3 = tree:add(D.dpv1_status_3, tvb(off + 9, 1))
    for _, f in ipairs({ D.prm_cmd, D.isom_req, D.prm_structure, D.alarm_mode }) do s3:add(f, tvb(off + 9, 1)) end
    user = off + 10
  end
  local extra = ""
  local s3 = (len >= 10) and tvb(off + 9, 1):uint() or 0
  local prmcmd_bit = bit.band(s3, 0x80) ~= 0
  local structured = bit.band(s3, 0x08) ~= 0
  if len >= 10 and (structured or prmcmd_bit) then
    -- Prm_Structure: the rest is a sequence of structured blocks (§D.2, §G.2). PrmCmd without
    -- Prm_Structure still means a PrmCmd block follows: decoded, with a warning.
    if prmcmd_bit and not structured then
      tree:add_proto_expert_info(E.prmcmd_bits, "DPV1_Status_3 has PrmCmd but not Prm_Structure; blocks decoded anyway")
    end
    local pos, stop = user, off + len
    local nblocks, prmcmds = 0, 0
    while pos < stop do
      local remain = stop - pos
      local blen = tvb(pos, 1):uint()
      local btype = (remain >= 2) and tvb(pos + 1, 1):uint() or -1
      nblocks = nblocks + 1
      if btype == 0x02 and blen >= 2 then
        prmcmds = prmcmds + 1
        extra = extra .. " " .. prmcmd_block(tvb, pos, blen, math.min(blen, remain), tree)
        if blen > remain then break end
        pos = pos + blen
      elseif blen < 4 or blen > remain then
        tree:add_proto_expert_info(E.dp, string.format("structured block of length %d at octet %d does not fit", blen, pos - off + 1))
        tree:add(D.user_prm_data, tvb(pos, remain))
        break
      else
        local b = tree:add(D.blk_type, tvb(pos + 1, 1))
        b:set_text(string.format("Structured block: %s, %d octets", prm_block_types[btype] or string.format("type 0x%02X", btype), blen))
        b:add(D.blk_len, tvb(pos, 1))
        b:add(D.blk_slot, tvb(pos + 2, 1))
        b:add(D.blk_spec, tvb(pos + 3, 1))
        if blen > 4 then b:add(D.blk_data, tvb(pos + 4, blen - 4)) end
        pos = pos + blen
      end
    end
    if prmcmd_bit and prmcmds == 0 then
      tree:add_proto_expert_info(E.prmcmd_bits, "DPV1_Status_3 has PrmCmd but no PrmCmd block (type 0x02) follows")
    elseif prmcmds > 0 and not prmcmd_bit then
      tree:add_proto_expert_info(E.prmcmd_bits, "PrmCmd block without the PrmCmd bit in DPV1_Status_3")
    end
    -- A pure PrmCmd: nothing but the DP header, the DPV1_Status octets and one 8-octet block
    -- (§G.2: 7 + 3 + 8 = 18 octets; the VPC3 skips its normal parameter check for it).
    if prmcmds == 1 and nblocks == 1 and len == 18 and tvb(user, 1):uint() == 8 then
      tree:add(D.prmcmd_pure, tvb(off, len), true):set_generated()
      extra = " pure" .. extra
    end
  elseif off + len > user then
    tree:add(D.user_prm_data, tvb(user, off + len - user))
  end
  return string.format("ident 0x%04X WD %d ms", tvb(off + 4, 2):uint(), wd) .. extra
end

local function cfg_describe(dir, n, words, consistent)
  local unit = words and (n == 1 and "word" or "words") or (n == 1 and "byte" or "bytes")
  return string.format("%d %s %s%s", n, unit, dir, consistent and " consistent" or "")
end

-- Chk_Cfg request / Get_Cfg response: identifiers in general or special format (§D.3).
local function dp_cfg(tvb, off, len, tree)
  local pos, stop, count = off, off + len, 0
  while pos < stop do
    local id = tvb(pos, 1):uint()
    local start = pos
    pos = pos + 1
    count = count + 1
    local item = tree:add(D.cfg_id, tvb(start, 1))
    if bit.band(id, 0x30) ~= 0 then
      local dirs = { [1] = "in", [2] = "out", [3] = "in/out" }
      local dir = dirs[bit.rshift(bit.band(id, 0x30), 4)]
      local n = bit.band(id, 0x0F) + 1
      local words = bit.band(id, 0x40) ~= 0
      local cons = bit.band(id, 0x80) ~= 0
      local text = cfg_describe(dir, n, words, cons)
      item:add(D.cfg_format, tvb(start, 1), "general")
      item:add(D.cfg_dir, tvb(start, 1), dir)
      item:add(D.cfg_len, tvb(start, 1), n)
      item:add(D.cfg_unit, tvb(start, 1), words and "words" or "bytes")
      item:add(D.cfg_consistent, tvb(start, 1), cons)
      item:add(D.cfg_text, tvb(start, 1), text)
      item:append_text(" (" .. text .. ")")
    else
      local kind = bit.rshift(id, 6)
      local manuf = bit.band(id, 0x0F)
      item:add(D.cfg_format, tvb(start, 1), "special")
      local parts = {}
      local function len_octet(field, dir)
        if pos >= stop then
          item:add_proto_expert_info(E.dp, "length octet missing")
          return
        end
        local lo = tvb(pos, 1):uint()
        local n = bit.band(lo, 0x3F) + 1
        local words = bit.band(lo, 0x40) ~= 0
        local cons = bit.band(lo, 0x80) ~= 0
        local l = item:add(field, tvb(pos, 1))
        l:add(D.cfg_dir, tvb(pos, 1), dir)
        l:add(D.cfg_len, tvb(pos, 1), n)
        l:add(D.cfg_unit, tvb(pos, 1), words and "words" or "bytes")
        l:add(D.cfg_consistent, tvb(pos, 1), cons)
        table.insert(parts, cfg_describe(dir, n, words, cons))
        pos = pos + 1
      end
      if kind == 0 then
        table.insert(parts, "empty slot")
      elseif kind == 1 then
        len_octet(D.cfg_in_len, "in")
      elseif kind == 2 then
        len_octet(D.cfg_out_len, "out")
      else
        len_octet(D.cfg_out_len, "out")
        len_octet(D.cfg_in_len, "in")
      end
      -- 15 in Chk_Cfg means: no octets follow, skip their check.
      if manuf > 0 and manuf < 15 then
        local n = math.min(manuf, stop - pos)
        if n < manuf then item:add_proto_expert_info(E.dp, "manufacturer data cut short") end
        if n > 0 then item:add(D.cfg_manuf, tvb(pos, n)) end
        pos = pos + n
        table.insert(parts, string.format("%d manufacturer octets", manuf))
      end
      local text = table.concat(parts, ", ")
      item:set_len(pos - start)
      item:add(D.cfg_text, tvb(start, pos - start), text)
      item:append_text(" (special: " .. text .. ")")
    end
  end
  return string.format("%d identifiers", count)
end

local s1_bits = {
  { 0x01, "Station_Non_Existent" }, { 0x02, "Station_Not_Ready" }, { 0x04, "Cfg_Fault" },
  { 0x08, "Ext_Diag" }, { 0x10, "Not_Supported" }, { 0x20, "Invalid_Slave_Response" },
  { 0x40, "Prm_Fault" }, { 0x80, "Master_Lock" },
}
local s2_bits = {
  { 0x01, "Prm_Req" }, { 0x02, "Stat_Diag" }, { 0x08, "WD_On" }, { 0x10, "Freeze_Mode" },
  { 0x20, "Sync_Mode" }, { 0x80, "Deactivated" },
}

-- DP-V1 alarm or status PDU inside a device-related block (§D.5, §E.5).
local function dpv1_diag_block(tvb, off, blen, tree, declared)
  local t = tvb(off + 1, 1):uint()
  local sub = tree:add(dpv1, tvb(off, blen))
  if bit.band(t, 0x80) == 0 then
    sub:set_text(string.format("DP-V1 alarm: %s, slot %d", alarm_types[t] or ("type " .. t), tvb(off + 2, 1):uint()))
    sub:add(V.alarm_type, tvb(off + 1, 1))
    sub:add(V.slot, tvb(off + 2, 1))
    local sp = sub:add(V.alarm_spec, tvb(off + 3, 1))
    sp:add(V.seq_nr, tvb(off + 3, 1))
    sp:add(V.add_ack, tvb(off + 3, 1))
    sp:add(V.spec, tvb(off + 3, 1))
    if blen > 4 then sub:add(V.diag_data, tvb(off + 4, blen - 4)) end
    return "alarm " .. (alarm_types[t] or tostring(t))
  elseif t == 0x9E or t == 0x9F then
    -- Slave redundancy status (§G.3).
    local what = red_status_block(tvb, off, declared or blen, blen, sub)
    sub:set_text("DP-V1 status (slave redundancy): " .. what)
    return what
  else
    sub:set_text(string.format("DP-V1 status: %s, slot %d", status_types[t] or string.format("0x%02X", t), tvb(off + 2, 1):uint()))
    sub:add(V.status_type, tvb(off + 1, 1))
    sub:add(V.slot, tvb(off + 2, 1))
    sub:add(V.status_spec, tvb(off + 3, 1))
    if blen > 4 then sub:add(V.diag_data, tvb(off + 4, blen - 4)) end
    return "status " .. (status_types[t] or string.format("0x%02X", t))
  end
end

local function is_dpv1_type(t)
  if bit.band(t, 0x80) == 0 then return (t >= 1 and t <= 6) or (t >= 32 and t <= 126) end
  return status_types[t] ~= nil or (t >= 0xA0 and t <= 0xFE)
end

local function dp_ext_diag(tvb, off, len, tree)
  local pos, stop = off, off + len
  local notes = {}
  while pos < stop do
    local h = tvb(pos, 1):uint()
    local kind = bit.rshift(h, 6)
    local blen = (kind == 2) and 3 or bit.band(h, 0x3F)
    if kind == 3 then blen = 1 end
    if blen < 1 then blen = 1 end
    local have = math.min(blen, stop - pos)
    local b = tree:add(D.ext_block, tvb(pos, have))
    if have < blen then b:add_proto_expert_info(E.dp, "diagnosis block cut short") end
    if kind == 0 then
      b:add(D.ext_type, tvb(pos, 1), "device-related")
      b:add(D.ext_len, tvb(pos, 1), blen)
      local t2 = (have >= 2) and tvb(pos + 1, 1):uint() or 0
      if (have >= 4 and is_dpv1_type(t2)) or (have >= 2 and (t2 == 0x9E or t2 == 0x9F)) then
        local what = dpv1_diag_block(tvb, pos, have, b, blen)
        b:set_text("Device-related block: " .. what)
        table.insert(notes, what)
      else
        if have > 1 then b:add(D.dev_data, tvb(pos + 1, have - 1)) end
        b:set_text(string.format("Device-related block, %d octets", blen))
      end
    elseif kind == 1 then
      b:add(D.ext_type, tvb(pos, 1), "identifier-related")
      b:add(D.ext_len, tvb(pos, 1), blen)
      local mods = {}
      for i = 1, have - 1 do
        local o = tvb(pos + i, 1):uint()
        for k = 0, 7 do
          if bit.band(o, bit.lshift(1, k)) ~= 0 then table.insert(mods, tostring((i - 1) * 8 + k)) end
        end
      end
      local list = table.concat(mods, ",")
      b:add(D.id_modules, tvb(pos, have), list)
      b:set_text("Identifier-related block: faulty modules " .. (list == "" and "none" or list))
      if list ~= "" then table.insert(notes, "modules " .. list) end
    elseif kind == 2 then
      b:add(D.ext_type, tvb(pos, 1), "channel-related")
      b:add(D.ch_module, tvb(pos, 1))
      if have == 3 then
        b:add(D.ch_dir, tvb(pos + 1, 1))
        b:add(D.ch_number, tvb(pos + 1, 1))
        b:add(D.ch_type, tvb(pos + 2, 1))
        b:add(D.ch_error, tvb(pos + 2, 1))
        local err = bit.band(tvb(pos + 2, 1):uint(), 0x1F)
        local name = channel_errors[err] or (err >= 16 and "manufacturer-specific " .. err or "reserved " .. err)
        b:set_text(string.format("Channel-related block: module %d channel %d %s: %s", bit.band(h, 0x3F),
          bit.band(tvb(pos + 1, 1):uint(), 0x3F), channel_dirs[bit.rshift(tvb(pos + 1, 1):uint(), 6)], name))
        table.insert(notes, name)
      end
    else
      b:add(D.ext_type, tvb(pos, 1), "reserved")
    end
    pos = pos + have
  end
  return table.concat(notes, ", ")
end

local function dp_slave_diag_res(tvb, off, len, tree)
  if short(tree, 6, len) then return "" end
  local s1 = tvb(off, 1):uint()
  local s2 = tvb(off + 1, 1):uint()
  local i1 = tree:add(D.status_1, tvb(off, 1))
  for _, f in ipairs({ D.s1_non_existent, D.s1_not_ready, D.s1_cfg_fault, D.s1_ext_diag, D.s1_not_supported,
    D.s1_invalid, D.s1_prm_fault, D.s1_master_lock }) do i1:add(f, tvb(off, 1)) end
  local i2 = tree:add(D.status_2, tvb(off + 1, 1))
  for _, f in ipairs({ D.s2_prm_req, D.s2_stat_diag, D.s2_one, D.s2_wd_on, D.s2_freeze, D.s2_sync,
    D.s2_deactivated }) do i2:add(f, tvb(off + 1, 1)) end
  local i3 = tree:add(D.status_3, tvb(off + 2, 1))
  i3:add(D.s3_overflow, tvb(off + 2, 1))
  tree:add(D.master_add, tvb(off + 3, 1))
  tree:add(D.ident, tvb(off + 4, 2))
  local names = bits_set(s1, s1_bits)
  local n2 = bits_set(s2, s2_bits)
  if n2 ~= "" then names = (names == "" and n2) or (names .. ", " .. n2) end
  if bit.band(tvb(off + 2, 1):uint(), 0x80) ~= 0 then
    names = (names == "" and "Ext_Diag_Overflow") or (names .. ", Ext_Diag_Overflow")
  end
  tree:add(D.status_names, tvb(off, 3), names)
  local master = tvb(off + 3, 1):uint()
  local text = string.format("ident 0x%04X master %s", tvb(off + 4, 2):uint(),
    master == 0xFF and "none" or tostring(master))
  if names ~= "" then text = text .. " [" .. names .. "]" end
  if len > 6 then
    local ext = dp_ext_diag(tvb, off + 6, len - 6, tree)
    if ext ~= "" then text = text .. " ext: " .. ext end
  end
  return text
end

local function dp_global_control(tvb, off, len, tree)
  if short(tree, 2, len) then return "" end
  local c = tvb(off, 1):uint()
  local it = tree:add(D.gc_command, tvb(off, 1))
  for _, f in ipairs({ D.gc_clear, D.gc_unfreeze, D.gc_freeze, D.gc_unsync, D.gc_sync }) do it:add(f, tvb(off, 1)) end
  tree:add(D.gc_group, tvb(off + 1, 1))
  local names = bits_set(c, { { 0x02, "Clear" }, { 0x04, "Unfreeze" }, { 0x08, "Freeze" }, { 0x10, "Unsync" }, { 0x20, "Sync" } })
  if names == "" then names = "Operate" end
  return string.format("%s group 0x%02X", names, tvb(off + 1, 1):uint())
end

local function dp_set_slave_add(tvb, off, len, tree)
  if short(tree, 4, len) then return "" end
  tree:add(D.new_address, tvb(off, 1))
  tree:add(D.ident, tvb(off + 1, 2))
  tree:add(D.no_add_chg, tvb(off + 3, 1))
  if len > 4 then tree:add(D.rem_data, tvb(off + 4, len - 4)) end
  return string.format("new address %d ident 0x%04X", tvb(off, 1):uint(), tvb(off + 1, 2):uint())
end

------------------------------------------------------------------------------------------------
-- DP-V1 PDUs (§E.2, E.3, E.5, E.6)
local function dpv1_error(tvb, off, len, tree)
  if len < 4 then
    tree:add_proto_expert_info(E.dp, "negative response shorter than 4 octets")
    return "negative"
  end
  tree:add(V.error_decode, tvb(off + 1, 1))
  local e1 = tvb(off + 2, 1):uint()
  local it = tree:add(V.error_code_1, tvb(off + 2, 1))
  it:add(V.error_class, tvb(off + 2, 1))
  it:add(V.error_code, tvb(off + 2, 1))
  tree:add(V.error_code_2, tvb(off + 3, 1))
  local cls, code = bit.rshift(e1, 4), bit.band(e1, 0x0F)
  local text
  if tvb(off + 1, 1):uint() == 0x80 then
    local cname = error_class_names[cls] or ((cls >= 0xD) and "user-specific" or string.format("class 0x%X", cls))
    local names = error_code_names[cls]
    local ename = (names and names[code]) or ((code >= 0xA or (cls == 0xC and code >= 8)) and "user-specific" or
      string.format("code 0x%X", code))
    text = cname .. ": " .. ename
  else
    text = string.format("%s error 0x%02X 0x%02X",
      error_decode_names[tvb(off + 1, 1):uint()] or string.format("decode 0x%02X", tvb(off + 1, 1):uint()), e1,
      tvb(off + 3, 1):uint())
  end
  tree:add(V.error_text, tvb(off + 1, 3), text)
  tree:add_proto_expert_info(E.dpv1_neg, text)
  return text
end

-- Returns the info text ("Read.req slot 0 index 0 len 64") or nil if this is no DP-V1 PDU.
local function dissect_dpv1(tvb, off, len, tree, is_req, c2)
  if len == 0 then
    -- E.4: a C1 poll from the master, or "not ready yet" from the slave.
    return is_req and "poll" or "not ready"
  end
  local fnum = tvb(off, 1):uint()
  local base_fn = bit.band(fnum, 0x7F)
  local name = dpv1_fn_names[base_fn] or string.format("Function 0x%02X", base_fn)
  local t = tree:add(dpv1, tvb(off, len))
  t:set_text("PROFIBUS DP-V1, " .. name)
  local fi = t:add(V.fn, tvb(off, 1))
  fi:add(V.error_bit, tvb(off, 1))
  local neg = bit.band(fnum, 0x80) ~= 0
  local dir = is_req and ".req" or (neg and ".res-" or ".res")
  t:add(V.fn_name, tvb(off, 1), name .. dir)
  if neg and not is_req then
    return name .. dir .. " " .. dpv1_error(tvb, off, len, t)
  end
  if base_fn == 0x5E or base_fn == 0x5F or base_fn == 0x51 then
    if len < 4 then
      t:add_proto_expert_info(E.dp, "read/write PDU shorter than 4 octets")
      return name .. dir
    end
    t:add(V.slot, tvb(off + 1, 1))
    t:add(V.index, tvb(off + 2, 1))
    t:add(V.length, tvb(off + 3, 1))
    local text = string.format("%s%s slot %d index %d len %d", name, dir, tvb(off + 1, 1):uint(),
      tvb(off + 2, 1):uint(), tvb(off + 3, 1):uint())
    if len > 4 then t:add(V.data, tvb(off + 4, len - 4)) end
    return text
  elseif base_fn == 0x5C then
    if len < 4 then
      t:add_proto_expert_info(E.dp, "Alarm_Ack shorter than 4 octets")
      return name .. dir
    end
    t:add(V.slot, tvb(off + 1, 1))
    t:add(V.alarm_type, tvb(off + 2, 1))
    local sp = t:add(V.alarm_spec, tvb(off + 3, 1))
    sp:add(V.seq_nr, tvb(off + 3, 1))
    sp:add(V.add_ack, tvb(off + 3, 1))
    sp:add(V.spec, tvb(off + 3, 1))
    return string.format("%s%s slot %d %s seq %d", name, dir, tvb(off + 1, 1):uint(),
      alarm_types[bit.band(tvb(off + 2, 1):uint(), 0x7F)] or ("type " .. tvb(off + 2, 1):uint()),
      bit.rshift(tvb(off + 3, 1):uint(), 3))
  elseif base_fn == 0x56 then
    if len >= 4 then
      t:add(V.server_sap, tvb(off + 1, 1))
      t:add(V.send_timeout, tvb(off + 2, 2))
      return string.format("%s%s server SAP %d", name, dir, tvb(off + 1, 1):uint())
    end
    return name .. dir
  elseif base_fn == 0x57 then
    local p = off + 1
    if is_req then
      if len < 16 then t:add_proto_expert_info(E.dp, "Initiate.req shorter than 16 octets"); return name .. dir end
      p = p + 3  -- reserved
      t:add(V.send_timeout, tvb(p, 2)); p = p + 2
    else
      if len < 12 then t:add_proto_expert_info(E.dp, "Initiate.res shorter than 12 octets"); return name .. dir end
      t:add(V.max_len, tvb(p, 1)); p = p + 1
    end
    t:add(V.features_1, tvb(p, 1)); t:add(V.features_2, tvb(p + 1, 1))
    t:add(V.pfeatures_1, tvb(p + 2, 1)); t:add(V.pfeatures_2, tvb(p + 3, 1))
    t:add(V.profile_ident, tvb(p + 4, 2))
    t:add(V.s_type, tvb(p + 6, 1)); t:add(V.s_len, tvb(p + 7, 1))
    t:add(V.d_type, tvb(p + 8, 1)); t:add(V.d_len, tvb(p + 9, 1))
    p = p + 10
    if off + len > p then t:add(V.addr_data, tvb(p, off + len - p)) end
    return name .. dir
  elseif base_fn == 0x58 then
    if len >= 3 then
      t:add(V.subnet, tvb(off + 1, 1))
      t:add(V.instance, tvb(off + 2, 1))
      t:add(V.reason, tvb(off + 2, 1))
      local r = bit.band(tvb(off + 2, 1):uint(), 0x0F)
      return string.format("%s%s %s", name, dir, abort_reasons[r] or ("reason " .. r))
    end
    return name .. dir
  elseif base_fn == 0x48 then
    return name .. dir
  end
  if len > 1 then t:add(V.data, tvb(off + 1, len - 1)) end
  return name .. dir
end

------------------------------------------------------------------------------------------------
-- The DP layer: decides the service from SAPs and the FC. Returns protocol, info text.
local function dissect_dp(tvb, off, len, tree, fr)
  local is_req = fr.request
  local sap = is_req and fr.dsap or fr.ssap        -- the slave-side (service) SAP
  local other = is_req and fr.ssap or fr.dsap
  local suffix = is_req and ".req" or ".res"
  if sap == nil then
    -- Default SAP: Data_Exchange for SRD requests and for data responses.
    if is_req then
      if fr.fn ~= 0xC and fr.fn ~= 0xD then return nil end
    elseif fr.sd ~= 0xE5 and not (fr.status == 0x8 or fr.status == 0xA or fr.status == 0xC or fr.status == 0xD) then
      return nil
    end
    local t = tree:add(dp, tvb(off, len))
    t:set_text("PROFIBUS DP, Data_Exchange" .. suffix)
    t:add(D.service, tvb(off, len), "Data_Exchange" .. suffix)
    if len > 0 then t:add(is_req and D.outputs or D.inputs, tvb(off, len)) end
    return "DP", "Data_Exchange" .. suffix .. string.format(" %d B", len)
  end
  local c2 = sap <= 48 and other == 50
  if sap == 51 or sap == 50 or sap == 49 or c2 then
    local which = (sap == 51 and "MSAC_C1") or (sap == 50 and "MSAC_C1 alarm") or "MSAC_C2"
    local text = dissect_dpv1(tvb, off, len, tree, is_req, c2)
    return "DP-V1", which .. " " .. text
  end
  local service = sap_services[sap]
  if service == nil then return nil end
  local t = tree:add(dp, tvb(off, len))
  t:set_text("PROFIBUS DP, " .. service .. suffix)
  t:add(D.service, tvb(off, len), service .. suffix)
  local extra = ""
  if sap == 61 and is_req then
    extra = dp_set_prm(tvb, off, len, t)
  elseif (sap == 62 and is_req) or (sap == 59 and not is_req) then
    if len > 0 then extra = dp_cfg(tvb, off, len, t) end
  elseif sap == 60 and not is_req then
    extra = dp_slave_diag_res(tvb, off, len, t)
  elseif sap == 58 and is_req then
    extra = dp_global_control(tvb, off, len, t)
  elseif sap == 55 and is_req then
    extra = dp_set_slave_add(tvb, off, len, t)
  elseif sap == 56 and not is_req then
    if len > 0 then t:add(D.inputs, tvb(off, len)) end
    extra = string.format("%d B", len)
  elseif sap == 57 and not is_req then
    if len > 0 then t:add(D.outputs, tvb(off, len)) end
    extra = string.format("%d B", len)
  elseif len > 0 then
    t:add(D.data, tvb(off, len))
  end
  local info = service .. suffix
  if extra ~= "" then info = info .. " " .. extra end
  return "DP", info
end

------------------------------------------------------------------------------------------------
-- MPI connection layer (protocol-facts.md §H.2/§H.3, docs/mpi.md) on FDL SRD requests with SAP
-- extensions, and the S7 PDU of its data messages handed to Wireshark's own s7comm (§H.4).
--
-- Detection rule (captures/README.md "MPI and S7"): a frame is MPI when
--   * it is an intact SD2 or SD3 request with FC SRD_low or SRD_high, both DA and SA carry an
--     extension with a SAP (DSAP and SSAP present), and
--   * its DU (after the SAP octets) is a whole MPI PDU as stacks/mpi/pdu.hpp decodes it:
--     E0 + 11 connect parameters sent to DSAP 0; D0 + 11; 05 01; F1 nr + at least one octet;
--     B0 01 nr; 80 — each with exactly that length (a data message up to 244 octets), and
--   * either the interface is marked MPI (its if_description starts with "MPI", as the pbvbus
--     writer writes it for an MPI line: "MPI 187.5 kbit/s, probe at ..."), or neither SAP is a
--     DP SAP (49..63: the DP-V0 and DP-V1 service SAPs, the class-2 master's SAP 50 that every
--     MSAC_C2 frame carries, the global SAP 63).
-- Every DP frame with SAPs has one SAP in 49..62 (§D SAP table; MSAC_C2 frames carry 50 on the
-- master's side) and Data_Exchange has no SAPs, so outside an interface marked MPI no DP frame
-- is taken for MPI. On a marked interface MPI is tried first (a CPU hands out connection SAPs
-- up to 63, docs/mpi.md decision 5), and a frame that is no MPI PDU still goes to DP.
local mpi = Proto("pbmpi", "MPI connection layer")
local mpi_pdu_names = {
  [0xE0] = "Connect request", [0xD0] = "Connect confirm", [0x05] = "Connection ack",
  [0xF1] = "Data", [0xB0] = "Data ack", [0x80] = "Disconnect request",
}
local M = {
  pdu = ProtoField.uint8("pbmpi.pdu", "PDU type", base.HEX, mpi_pdu_names),
  pdu_name = ProtoField.string("pbmpi.pdu_name", "PDU"),
  subcode = ProtoField.uint8("pbmpi.subcode", "Ack subcode", base.HEX),
  msg_nr = ProtoField.uint8("pbmpi.msg_nr", "Message number", base.DEC),
  ack_nr = ProtoField.uint8("pbmpi.ack_nr", "Acknowledged message number", base.DEC),
  connect_params = ProtoField.bytes("pbmpi.connect_params", "Connect parameters (not decoded)"),
  s7 = ProtoField.bytes("pbmpi.s7_pdu", "S7 PDU"),
  s7_len = ProtoField.uint16("pbmpi.s7_len", "S7 PDU length", base.DEC),
  src = ProtoField.string("pbmpi.src", "Sender (address:SAP)"),
  dst = ProtoField.string("pbmpi.dst", "Receiver (address:SAP)"),
  marked = ProtoField.bool("pbmpi.line_marked", "Interface marked MPI"),
}
mpi.fields = {}
for _, f in pairs(M) do table.insert(mpi.fields, f) end
local E_mpi_s7 = ProtoExpert.new("pbmpi.s7_undecoded", "Data message not decoded by s7comm",
  expert.group.UNDECODED, expert.severity.NOTE)
mpi.experts = { E_mpi_s7 }
local f_if_desc = Field.new("frame.interface_description")
local cotp_heuristics_ok = true  -- set false if try_heuristics is missing (older Wireshark)

local function interface_is_mpi()
  local d = f_if_desc()
  if d == nil then return false end
  local s = tostring(d.value)
  return s:sub(1, 3) == "MPI"
end

-- The MPI PDU type of `len` octets at `off`, or nil when they are no whole MPI PDU.
local function mpi_pdu_type(tvb, off, len, dsap)
  if len < 1 then return nil end
  local t = tvb(off, 1):uint()
  if t == 0xE0 then return (len == 12 and dsap == 0) and t or nil end
  if t == 0xD0 then return len == 12 and t or nil end
  if t == 0x05 then return (len == 2 and tvb(off + 1, 1):uint() == 0x01) and t or nil end
  if t == 0xF1 then return (len >= 3 and len <= 244) and t or nil end
  if t == 0xB0 then return (len == 3 and tvb(off + 1, 1):uint() == 0x01) and t or nil end
  if t == 0x80 then return len == 1 and t or nil end
  return nil
end

-- Whether the frame is MPI by the rule above; returns the PDU type and whether the interface
-- is marked MPI.
local function mpi_detect(tvb, off, len, fr)
  if not fr.request or (fr.fn ~= 0xC and fr.fn ~= 0xD) then return nil end
  if fr.sd ~= 0x68 and fr.sd ~= 0xA2 then return nil end
  if fr.dsap == nil or fr.ssap == nil then return nil end
  local t = mpi_pdu_type(tvb, off, len, fr.dsap)
  if t == nil then return nil end
  local marked = interface_is_mpi()
  if not marked and (fr.dsap >= 49 or fr.ssap >= 49) then return nil end
  return t, marked
end

-- Decodes the MPI PDU (type `t`) at [off, off+len) into the tree; returns the info text.
local function dissect_mpi(tvb, pinfo, tree, off, len, fr, t, marked)
  local m = tree:add(mpi, tvb(off, len))
  local name = mpi_pdu_names[t]
  m:set_text("MPI connection layer, " .. name)
  m:add(M.pdu, tvb(off, 1))
  m:add(M.pdu_name, tvb(off, 1), name)
  m:add(M.src, tvb(off, len), string.format("%d:%d", fr.sa, fr.ssap)):set_generated()
  m:add(M.dst, tvb(off, len), string.format("%d:%d", fr.da, fr.dsap)):set_generated()
  m:add(M.marked, tvb(off, len), marked):set_generated()
  local info = "MPI " .. name
  if t == 0xE0 or t == 0xD0 then
    m:add(M.connect_params, tvb(off + 1, 11))
    info = string.format("%s SAP %d→%d", info, fr.ssap, fr.dsap)
  elseif t == 0x05 then
    m:add(M.subcode, tvb(off + 1, 1))
  elseif t == 0xB0 then
    m:add(M.subcode, tvb(off + 1, 1))
    m:add(M.ack_nr, tvb(off + 2, 1))
    info = string.format("%s nr %d", info, tvb(off + 2, 1):uint())
  elseif t == 0xF1 then
    m:add(M.msg_nr, tvb(off + 1, 1))
    local s7off, s7len = off + 2, len - 2
    m:add(M.s7, tvb(s7off, s7len))
    m:add(M.s7_len, tvb(s7off, s7len), s7len):set_generated()
    info = string.format("%s nr %d", info, tvb(off + 1, 1):uint())
    -- Hand the S7 PDU to s7comm, a heuristic dissector of COTP (tools-and-formats.md §3.4,
    -- §4.2: DissectorTable.try_heuristics("cotp", ...) works from Lua in tshark 4.0).
    local s7info = nil
    if cotp_heuristics_ok then
      local ok, taken = pcall(DissectorTable.try_heuristics, "cotp", tvb(s7off, s7len):tvb(), pinfo, tree)
      if not ok then cotp_heuristics_ok = false end
      if ok and taken then
        s7info = tostring(pinfo.cols.info)
        -- s7comm fences the info column; the FDL line below replaces it as a whole.
        pcall(function() pinfo.cols.info:clear_fence() end)
      end
    end
    if s7info then
      info = info .. ": S7 " .. s7info
    else
      m:add_proto_expert_info(E_mpi_s7)
    end
  end
  return info
end

------------------------------------------------------------------------------------------------
-- FDL
local function fcs_of(tvb, off, len)
  local s = 0
  for i = 0, len - 1 do s = s + tvb(off + i, 1):uint() end
  return s % 256
end

-- Address extension chain (§B.2): octets while bit 7 is set; bit 6 = segment, else SAP.
local function ext_chain(tvb, pos, stop, tree, f_raw, f_sap, f_seg, truncated)
  local sap, seg
  while true do
    if pos >= stop then
      -- In a frame cut short the chain simply is not there: the truncation is the error.
      if not truncated then tree:add_proto_expert_info(E.ext, "extension chain runs past the data") end
      return pos, sap, seg, false
    end
    local o = tvb(pos, 1):uint()
    local it = tree:add(f_raw, tvb(pos, 1))
    if bit.band(o, 0x40) ~= 0 then
      it:add(f_seg, tvb(pos, 1))
      seg = bit.band(o, 0x3F)
    else
      it:add(f_sap, tvb(pos, 1))
      if sap ~= nil then tree:add_proto_expert_info(E.ext, "two SAPs in one chain") end
      sap = bit.band(o, 0x3F)
    end
    pos = pos + 1
    if bit.band(o, 0x80) == 0 then break end
  end
  if sap == nil then tree:add_proto_expert_info(E.ext, "extension chain without a SAP") end
  return pos, sap, seg, sap ~= nil
end

function fdl.dissector(tvb, pinfo, tree)
  local n = tvb:len()
  pinfo.cols.protocol = "FDL"
  local t = tree:add(fdl, tvb())
  if n == 0 then
    t:add_proto_expert_info(E.truncated, "empty frame")
    pinfo.cols.info = "empty"
    return
  end
  local sd = tvb(0, 1):uint()
  t:add(F.sd, tvb(0, 1))
  local tname = sd_names[sd]
  if tname == nil then
    t:add_proto_expert_info(E.sd, string.format("start delimiter 0x%02X", sd))
    t:add(F.data, tvb(0, n))
    pinfo.cols.info = string.format("garbage (%d octets, first 0x%02X)", n, sd)
    return
  end
  t:add(F.type, tvb(0, 1), tname)
  t:set_text("PROFIBUS FDL, " .. tname)
  if sd == 0xE5 then
    if n > 1 then t:add_proto_expert_info(E.trailing, string.format("%d octets after SC", n - 1)) end
    pinfo.cols.info = "SC"
    return
  end
  if sd == 0xDC then
    if n < 3 then
      t:add_proto_expert_info(E.truncated, string.format("token needs 3 octets, has %d", n))
      pinfo.cols.info = "Token (truncated)"
      return
    end
    t:add(F.da, tvb(1, 1)); t:add(F.sa, tvb(2, 1))
    if n > 3 then t:add_proto_expert_info(E.trailing, string.format("%d octets after the token", n - 3)) end
    local da, sa = bit.band(tvb(1, 1):uint(), 0x7F), bit.band(tvb(2, 1):uint(), 0x7F)
    pinfo.cols.src = tostring(sa); pinfo.cols.dst = tostring(da)
    pinfo.cols.info = string.format("Token %d→%d", sa, da)
    return
  end
  -- SD1, SD2, SD3: header, then DA SA FC [ext] [DU] FCS ED.
  local body, blen  -- offset of DA, octets DA..last DU
  if sd == 0x10 then
    body, blen = 1, 3
  elseif sd == 0xA2 then
    body, blen = 1, 11
  else
    if n < 4 then
      t:add_proto_expert_info(E.truncated, "SD2 header cut short")
      pinfo.cols.info = "SD2 (truncated)"
      return
    end
    local le, ler = tvb(1, 1):uint(), tvb(2, 1):uint()
    t:add(F.le, tvb(1, 1)); t:add(F.ler, tvb(2, 1)); t:add(F.sd2, tvb(3, 1))
    if le ~= ler then t:add_proto_expert_info(E.le, string.format("LE %d differs from LEr %d", le, ler)) end
    if le < 4 or le > 249 then t:add_proto_expert_info(E.le, string.format("LE %d outside 4..249", le)) end
    if tvb(3, 1):uint() ~= 0x68 then t:add_proto_expert_info(E.sd, "second SD2 delimiter is not 0x68") end
    body, blen = 4, le
  end
  local full = body + blen + 2
  local truncated = n < full
  local avail = math.min(blen, n - body)  -- octets of DA..DU present
  if truncated then
    t:add_proto_expert_info(E.truncated, string.format("%d of %d octets", n, full))
  elseif n > full then
    t:add_proto_expert_info(E.trailing, string.format("%d octets after the end delimiter", n - full))
  end
  if avail < 3 then
    if avail >= 1 then t:add(F.da, tvb(body, 1)) end
    if avail >= 2 then t:add(F.sa, tvb(body + 1, 1)) end
    pinfo.cols.info = tname .. " (truncated)"
    return
  end
  local da_o, sa_o, fc = tvb(body, 1):uint(), tvb(body + 1, 1):uint(), tvb(body + 2, 1):uint()
  local da, sa = bit.band(da_o, 0x7F), bit.band(sa_o, 0x7F)
  t:add(F.da, tvb(body, 1)); t:add(F.da_ext, tvb(body, 1))
  t:add(F.sa, tvb(body + 1, 1)); t:add(F.sa_ext, tvb(body + 1, 1))
  if sa == 127 then t:add_proto_expert_info(E.addr, "source address 127") end
  local fci = t:add(F.fc, tvb(body + 2, 1))
  local fr = { sd = sd, request = bit.band(fc, 0x40) ~= 0 }
  local fcname
  if fr.request then
    fr.fn = bit.band(fc, 0x0F)
    fci:add(F.fc_cv, tvb(body + 2, 1)); fci:add(F.fc_request, tvb(body + 2, 1))
    fci:add(F.fc_fcb, tvb(body + 2, 1)); fci:add(F.fc_fcv, tvb(body + 2, 1))
    fci:add(F.fc_function, tvb(body + 2, 1))
    fcname = fn_names[fr.fn]
    if fc == 0xC0 then fcname = "CV" end
    if fcname == nil or (bit.band(fc, 0x80) ~= 0 and fc ~= 0xC0) then
      t:add_proto_expert_info(E.fc, string.format("reserved request function 0x%X", fr.fn))
      fcname = fcname or string.format("fn 0x%X", fr.fn)
    end
    fci:append_text(string.format(" (%s, FCB=%d, FCV=%d)", fcname, bit.band(fc, 0x20) ~= 0 and 1 or 0,
      bit.band(fc, 0x10) ~= 0 and 1 or 0))
  else
    fr.status = bit.band(fc, 0x0F)
    fci:add(F.fc_request, tvb(body + 2, 1))
    fci:add(F.fc_station, tvb(body + 2, 1))
    fci:add(F.fc_status, tvb(body + 2, 1))
    fcname = status_names[fr.status]
    if fcname == nil or bit.band(fc, 0x80) ~= 0 then
      t:add_proto_expert_info(E.fc, string.format("reserved response status 0x%X", fr.status))
      fcname = fcname or string.format("status 0x%X", fr.status)
    end
    fci:append_text(string.format(" (%s: %s, %s)", fcname, status_long[fr.status] or "reserved",
      station_types[bit.rshift(bit.band(fc, 0x30), 4)]))
  end
  t:add(F.fc_name, tvb(body + 2, 1), fcname)
  -- Extensions and DU
  local pos, stop = body + 3, body + avail
  local ok_ext = true
  if bit.band(da_o, 0x80) ~= 0 then
    local ok
    pos, fr.dsap, fr.da_seg, ok = ext_chain(tvb, pos, stop, t, F.dae, F.dsap, F.da_segment, truncated)
    ok_ext = ok_ext and ok
  end
  if bit.band(sa_o, 0x80) ~= 0 then
    local ok
    pos, fr.ssap, fr.sa_seg, ok = ext_chain(tvb, pos, stop, t, F.sae, F.ssap, F.sa_segment, truncated)
    ok_ext = ok_ext and ok
  end
  local du_off, du_len = pos, stop - pos
  if du_len > 0 then t:add(F.data, tvb(du_off, du_len)) end
  -- FCS and ED
  local fcs_ok = nil
  if not truncated then
    local calc = fcs_of(tvb, body, blen)
    local got = tvb(body + blen, 1):uint()
    local fi = t:add(F.fcs, tvb(body + blen, 1))
    fcs_ok = (calc == got)
    t:add(F.fcs_ok, tvb(body + blen, 1), fcs_ok):set_generated()
    if not fcs_ok then
      t:add(F.fcs_calc, tvb(body + blen, 1), calc):set_generated()
      fi:add_proto_expert_info(E.fcs, string.format("FCS mismatch: 0x%02X in the frame, 0x%02X computed", got, calc))
    end
    local edi = t:add(F.ed, tvb(body + blen + 1, 1))
    if tvb(body + blen + 1, 1):uint() ~= 0x16 then edi:add_proto_expert_info(E.ed) end
  elseif n > body + blen then
    t:add(F.fcs, tvb(body + blen, 1))
  end
  pinfo.cols.src = tostring(sa)
  pinfo.cols.dst = tostring(da)
  -- DP on top (only for frames whose extension chains make sense)
  local proto, dptext
  fr.da, fr.sa = da, sa
  if ok_ext and not truncated and fcs_ok then
    local mt, marked = mpi_detect(tvb, du_off, du_len, fr)
    if mt ~= nil then
      proto, dptext = "MPI", dissect_mpi(tvb, pinfo, tree, du_off, du_len, fr, mt, marked)
    end
  end
  if ok_ext and dptext == nil then
    proto, dptext = dissect_dp(tvb, du_off, du_len, tree, fr)
  end
  if dptext ~= nil and proto == "MPI" then
    -- decoded in the MPI subtree (pbmpi.*); pbfdl.service stays the DP service
  elseif dptext ~= nil then
    t:add(F.service, tvb(du_off, du_len), dptext)
  elseif fr.dsap ~= nil or fr.ssap ~= nil then
    dptext = string.format("SAP %s→%s", fr.ssap ~= nil and tostring(fr.ssap) or "-",
      fr.dsap ~= nil and tostring(fr.dsap) or "-")
    if du_len > 0 then dptext = dptext .. string.format(" %d B", du_len) end
  end
  if proto then pinfo.cols.protocol = proto end
  local info
  if fr.request then
    info = string.format("%s %d→%d", fcname, sa, da)
    if dptext then info = info .. " " .. dptext end
    if fr.fn == 0xC or fr.fn == 0xD or fr.fn == 0x3 or fr.fn == 0x5 or fr.fn == 0x7 or bit.band(fc, 0x30) ~= 0 then
      info = info .. string.format(" FCB=%d FCV=%d", bit.band(fc, 0x20) ~= 0 and 1 or 0, bit.band(fc, 0x10) ~= 0 and 1 or 0)
    end
  else
    info = string.format("%d→%d %s", sa, da, fcname)
    if fr.status == 0 and fc ~= 0 then info = info .. " (" .. station_types[bit.rshift(bit.band(fc, 0x30), 4)] .. ")" end
    if dptext then info = info .. " " .. dptext end
  end
  if truncated then info = info .. " [truncated]" end
  if fcs_ok == false then info = info .. " [FCS mismatch]" end
  pinfo.cols.info = info
end

------------------------------------------------------------------------------------------------
-- Event records (event_record.hpp): little-endian, 24-octet header, then UTF-8 text.
function ev.dissector(tvb, pinfo, tree)
  pinfo.cols.protocol = "Event"
  local n = tvb:len()
  local t = tree:add(ev, tvb())
  if n < 1 or tvb(0, 1):uint() ~= 1 then
    t:add_proto_expert_info(E.event, "unknown event record version")
    pinfo.cols.info = "event record of an unknown version"
    return
  end
  if n < 24 then
    t:add_proto_expert_info(E.event, string.format("%d octets, the header needs 24", n))
    pinfo.cols.info = "event record (truncated)"
    return
  end
  t:add(EV.version, tvb(0, 1))
  local cat = tvb(1, 1):uint()
  t:add(EV.category, tvb(1, 1))
  local code = tvb(2, 2):le_uint()
  t:add_le(EV.code, tvb(2, 2))
  local cname
  if cat == 1 then cname = line_event_codes[code] end
  if cat == 4 then cname = redundancy_event_codes[code] end
  if cat == 5 then cname = cpu_event_kinds[code] end
  if cat == 7 then cname = hsby_event_kinds[code] end
  if cname then t:add(EV.code_name, tvb(2, 2), cname) end
  t:add_le(EV.line, tvb(4, 4))
  t:add_le(EV.a, tvb(8, 4))
  t:add_le(EV.b, tvb(12, 4))
  t:add_le(EV.value, tvb(16, 8))
  -- Redundancy and CPU events carry the S7 event id (W#16#73A3 ...) in the value (CPU: its low
  -- 16 bits; the rest is the OB, reason and from/to, cpu_event.hpp).
  if cat == 4 and tvb(16, 4):le_uint() ~= 0 then
    t:add(EV.s7, tvb(16, 2), string.format("W#16#%04X", tvb(16, 4):le_uint()))
  end
  if cat == 5 then
    if tvb(16, 2):le_uint() ~= 0 then
      t:add(EV.s7, tvb(16, 2), string.format("W#16#%04X", tvb(16, 2):le_uint()))
    end
    local c = t:add(ev, tvb(2, 22), "CPU event")
    c:set_text("CPU event: " .. (cpu_event_kinds[code] or ("kind " .. code)))
    c:add_le(EV.cpu_kind, tvb(2, 2))
    c:add_le(EV.cpu_rack, tvb(8, 4))
    c:add_le(EV.cpu_role, tvb(12, 4))
    c:add_le(EV.cpu_event_id, tvb(16, 2))
    local names = nil
    if code == 0 then names = cpu_states elseif code == 1 then names = cpu_roles elseif code == 2 then names = cpu_modes end
    if code == 3 then
      local ob = tvb(18, 1):uint()
      c:add(EV.cpu_ob, tvb(18, 1))
      c:add(EV.cpu_ob_name, tvb(18, 1), "OB " .. ob)
      c:add(EV.cpu_reason, tvb(19, 1))
    elseif names then
      local to, from = tvb(20, 1):uint(), tvb(21, 1):uint()
      c:add(EV.cpu_from, tvb(21, 1), names[from] or tostring(from))
      c:add(EV.cpu_to, tvb(20, 1), names[to] or tostring(to))
    end
  end
  if cat == 7 then
    local c = t:add(ev, tvb(2, 22), "Hot Standby event")
    c:set_text("Hot Standby event: " .. (hsby_event_kinds[code] or ("kind " .. code)))
    c:add_le(EV.hsby_kind, tvb(2, 2))
    c:add_le(EV.hsby_rack, tvb(8, 4))
    c:add_le(EV.hsby_state, tvb(12, 4))
    c:add(EV.hsby_kind_name, tvb(2, 2), hsby_event_kinds[code] or ("kind " .. code))
    local st = tvb(12, 4):le_int()
    c:add(EV.hsby_state_name, tvb(12, 4), hsby_states[st] or ("state " .. st))
    -- Only a switchover carries a takeover time (0 when the pair filed no switchover record).
    if code == 3 then
      local ns = tvb(16, 8):le_uint64()
      c:add_le(EV.hsby_takeover, tvb(16, 8))
      -- ms with 6 decimals, from the integer ns (no floating point on 64-bit values).
      local ms, rest = ns / 1000000, ns % 1000000
      c:add(EV.hsby_takeover_ms, tvb(16, 8), tostring(ms) .. "." .. string.format("%06d", rest:tonumber()) .. " ms")
    end
  end
  local text = ""
  if n > 24 then
    text = tvb(24, n - 24):string(ENC_UTF_8)
    t:add(EV.text, tvb(24, n - 24), text)
  end
  local catname = event_categories[cat] or ("category " .. cat)
  t:set_text("pbvbus event, " .. catname .. ": " .. text)
  pinfo.cols.info = "[" .. catname .. "] " .. (text ~= "" and text or (cname or ("code " .. code)))
end

local wtap_table = DissectorTable.get("wtap_encap")
wtap_table:add(wtap.USER0, fdl)
wtap_table:add(wtap.USER1, ev)
