#!/usr/bin/python3
"""A DP-V0 slave behind a serial port (a pty), written for pbvbus's conformance battery.

`pbvbus conformance --pty PATH --speed N/M` creates a pty at the device under test's address and
runs the battery against whatever program has PATH open. This is such a program: a small but
real DP-V0 slave for a compact station described by a GSD (default examples/gsd/PBVB0A01.gsd:
ident 0x0A01, one module `0x11,0x21` = 2 octets in, 2 octets out, User_Prm_Data_Len 1).
tests/integration/outside_slave_test.cpp runs it honest and with one rule broken on purpose.

    outside_slave.py --port /tmp/dut --address 5 --speed 1/1000 --baud 1.5M [--break ident]

What it implements (protocol-facts.md §B, §C.6, §D; behaviour as pbvbus's own slave engine,
stacks/dp/include/pbvbus/dp/slave_engine.hpp, where the standard leaves a choice):
  FDL  SD1/SD2/SD3 requests (SD4 tokens and SC are not for a slave), FCS and end delimiter
       checked, LE = LEr, the FDL length rule to split the byte stream; DA = own address or 127.
       Address extensions: DSAP/SSAP (a region/segment octet: the telegram is ignored).
       FDL_Status (FC 0x49) answered `10 SA DA 00 FCS 16` (station type slave, status OK).
       FCB/FCV per source address (§C.6): the first frame (FCV=0, FCB=1) and every new action
       frame (FCV=1, FCB toggled) store the FCB and the reply; FCV=1 with the stored FCB is a
       repeat: the stored reply goes out again and the request is not executed (and, as at a
       real ASIC, the DP layer never sees it: no watchdog restart).
       Responses mirror the request's SAPs (response DSAP = request SSAP and vice versa); a
       refusal is `10 SA DA 03 FCS 16` (RS, SD1); the frame type is SD1 without DU, SD3 for
       exactly 8 octets of DU (SAPs included), SD2 otherwise.
  DP   Power_On (address 126 only) / Wait_Prm / Wait_Cfg / Data_Exch.
       Set_Prm (SAP 61): always SC (RS at address 126); from another master while locked: SC
       without effect. Lock=0/Unlock=0 changes only min TSDR; Unlock from the owner releases
       (Wait_Prm). Checked: 7 + User_Prm_Data_Len octets, Ident_Number, WD factors not 0 with
       WD_On, Sync_Req/Freeze_Req against the GSD (Not_Supported). A fault sets Prm_Fault in the
       next diagnosis and leaves the slave in Wait_Prm, unlocked. PBVB0A01's three parameters
       (Bit(1), BitArea(4-5), Bit(0)) accept every value their bits can hold, so there is no
       content check to make; this program makes none.
       Chk_Cfg (SAP 62): RS before a Set_Prm; identifiers compared by meaning (general and
       special format, §D.3); a mismatch sets Cfg_Fault with an identifier-related block naming
       the faulty module, back to Wait_Prm.
       Slave_Diag (SAP 60): 6 octets (bits per §D.4: Station_Not_Ready, Cfg_Fault, Ext_Diag,
       Not_Supported, Prm_Fault; Prm_Req, always-1, WD_On, Freeze_Mode, Sync_Mode; Master_Add,
       ident), plus the identifier block after a Cfg_Fault. To anyone, in any state.
       Get_Cfg (SAP 59): the GSD module's identifiers, to anyone, in any state.
       Data_Exchange (default SAP, SRD): only the owner in Data_Exch (else RS); outputs of the
       configured length, or none at all (Fail_Safe=1 in the GSD: outputs safe); any other
       length: Wait_Prm and RS. Inputs: a big-endian counter of the Data_Exchanges executed.
       Rd_Inp (56) / Rd_Outp (57): in Data_Exch, to anyone (else RS).
       Global_Control (SAP 58): from the owner in Data_Exch, broadcast or unicast, group select
       against Group_Ident: Clear_Data (outputs safe until a telegram without it), Sync/Unsync
       and Freeze/Unfreeze where Set_Prm enabled them (the "un" wins in one telegram).
       Set_Slave_Add (SAP 55): refused (RS), see "Decisions".
       Every other SAP (the DP-V1 SAPs 0..51 included): RS.
  Watchdog: with WD_On the response monitoring runs TWD = 10 ms x WD_Fact_1 x WD_Fact_2 of
       VIRTUAL time and is restarted by every frame from the owner; on expiry the outputs go
       safe and the slave returns to Wait_Prm, unlocked.

Decisions (a program behind a pty has no virtual clock):
  - Time. The battery runs paced: virtual time follows the wall clock at the ratio --speed N/M
    (1/1000: one virtual millisecond lasts one wall second). The program converts every
    duration of the standard the same way: wall = virtual x M / N. So the watchdog is kept in
    wall time scaled by --speed, and TWD = 10 ms virtual is 10 s of wall time at 1/1000.
    Virtual time of a paced run follows the wall clock only roughly (the pty and the operating
    system add delays), so a check against the watchdog within a few virtual milliseconds of
    its expiry is not meaningful for this program.
  - Min TSDR. A slave must not answer earlier than min TSDR bit times (11, or what Set_Prm
    octet 4 set; §C.1, §D.2) after the request. This program reads the request a moment after
    its last octet and waits until min TSDR bit times (at --baud, scaled by --speed) have
    passed since then, then writes the reply at once; what the pty, Python and the scheduler
    add on top must stay below max TSDR - min TSDR (at 1.5 Mbit/s and 1/1000: 139 bit times =
    93 ms of wall time). A new min TSDR applies from the next request on.
  - Set_Slave_Add. The GSD says Set_Slave_Add_supp = 1, but a pty attachment stands at one
    fixed FDL address: after taking a new address the program would hear nothing addressed to
    it. It refuses Set_Slave_Add (RS); `--set-slave-add accept` takes the new address anyway
    (to see what the battery makes of that).
  - Garbage on the line (octets that cannot start a telegram, a bad FCS or end delimiter, LE
    and LEr that differ) is dropped and counted: the splitter drops ONE octet and looks for a
    telegram again from the next one, so a stray start delimiter cannot swallow a request; an
    incomplete telegram whose rest does not come within --resync seconds loses its first octet
    the same way. The program never exits on
    bad input; it ends on SIGINT/SIGTERM, after --max-time seconds, or when the pty's other
    side is gone, and then prints a summary (JSON) on stdout.
  - SIGHUP (a pty hanging up) ends it like SIGTERM.
  - Opening the port: pending input is flushed (requests written before the program was
    there are stale; their replies would come far too late).

Deliberately broken behaviours (for the suite's own test; one at a time):
  --break ident   Set_Prm with another Ident_Number is accepted (the rule of §D.2/§D.8 that a
                  wrong ident is a parameterisation fault is broken).
  --break fcb     a repeat (FCV=1, same FCB) is executed again instead of answered from the
                  stored reply (§C.6).
"""

import argparse
import json
import os
import select
import signal
import sys
import time

import serial

# --- FDL constants (protocol-facts.md §B) -------------------------------------------------------
SD1, SD2, SD3, SD4, SC, ED = 0x10, 0x68, 0xA2, 0xDC, 0xE5, 0x16
BROADCAST, DEFAULT_ADDRESS, NO_MASTER = 127, 126, 0xFF
EXT = 0x80
# Request functions (FC bits 3..0 with bit 6 set).
FN_SDA_LOW, FN_SDN_LOW, FN_SDA_HIGH, FN_SDN_HIGH, FN_MSRD = 0x3, 0x4, 0x5, 0x6, 0x7
FN_FDL_STATUS, FN_SRD_LOW, FN_SRD_HIGH = 0x9, 0xC, 0xD
FN_RESERVED = (0x1, 0x2, 0x8, 0xA, 0xB)
FN_USES_FCB = (FN_SDA_LOW, FN_SDA_HIGH, FN_SRD_LOW, FN_SRD_HIGH, FN_MSRD)
FN_NO_REPLY = (0x0, FN_SDN_LOW, FN_SDN_HIGH)
FCB, FCV = 0x20, 0x10
# Response status (slave: station type bits 00).
ST_OK, ST_RS, ST_DL, ST_DH = 0x00, 0x03, 0x08, 0x0A

# --- DP constants (§D.1, §D.2, §D.4) -------------------------------------------------------------
SAP_SET_SLAVE_ADD, SAP_RD_INP, SAP_RD_OUTP, SAP_GLOBAL_CONTROL = 55, 56, 57, 58
SAP_GET_CFG, SAP_SLAVE_DIAG, SAP_SET_PRM, SAP_CHK_CFG = 59, 60, 61, 62
LOCK_REQ, UNLOCK_REQ, SYNC_REQ, FREEZE_REQ, WD_ON = 0x80, 0x40, 0x20, 0x10, 0x08
GC_CLEAR, GC_UNFREEZE, GC_FREEZE, GC_UNSYNC, GC_SYNC = 0x02, 0x04, 0x08, 0x10, 0x20
# Station_Status_1 / _2.
D1_NOT_READY, D1_CFG_FAULT, D1_EXT_DIAG, D1_NOT_SUPPORTED, D1_PRM_FAULT = 0x02, 0x04, 0x08, 0x10, 0x40
D2_PRM_REQ, D2_ALWAYS_1, D2_WD_ON, D2_FREEZE, D2_SYNC = 0x01, 0x04, 0x08, 0x10, 0x20
POWER_ON, WAIT_PRM, WAIT_CFG, DATA_EXCH = "Power_On", "Wait_Prm", "Wait_Cfg", "Data_Exch"
MIN_TSDR_DEFAULT = 11  # bit times (§C.1)

BAUDS = {"9.6k": 9600, "19.2k": 19200, "45.45k": 45450, "93.75k": 93750, "187.5k": 187500,
         "500k": 500000, "1.5M": 1500000, "3M": 3000000, "6M": 6000000, "12M": 12000000}


# --- GSD (the few keywords a compact DP-V0 station needs; PI 2.122, protocol-facts.md §I) -------
class GsdError(Exception):
    pass


def read_gsd(path):
    """Ident, User_Prm_Data_Len, features and the first module's identifiers of a compact GSD."""
    try:
        with open(path, encoding="latin-1") as f:
            raw = f.read().splitlines()
    except OSError as e:
        raise GsdError(f"{path}: {e.strerror}") from e
    lines, cont = [], ""
    for line in raw:
        out, quoted = "", False
        for ch in line:  # ';' starts a comment outside "..."
            if ch == '"':
                quoted = not quoted
            if ch == ";" and not quoted:
                break
            out += ch
        out = out.strip()
        if out.endswith("\\"):
            cont += out[:-1] + " "
            continue
        lines.append(cont + out)
        cont = ""
    kv, module = {}, None
    for line in lines:
        if "=" not in line:
            continue
        key, value = (s.strip() for s in line.split("=", 1))
        if key.lower() == "module" and module is None:
            rest = value.split('"')
            if len(rest) < 3:
                raise GsdError(f"{path}: bad Module line: {line}")
            module = (rest[1], [int(x, 0) for x in rest[2].replace(" ", "").split(",") if x])
        else:
            kv.setdefault(key.lower(), value)

    def num(key, default=None):
        if key.lower() not in kv:
            if default is None:
                raise GsdError(f"{path}: {key} is missing")
            return default
        try:
            return int(kv[key.lower()], 0)
        except ValueError as e:
            raise GsdError(f"{path}: {key} = {kv[key.lower()]} is not a number") from e

    if num("Modular_Station", 0) != 0:
        raise GsdError(f"{path}: a modular station; this program is a compact station only")
    if num("DPV1_Slave", 0) != 0:
        raise GsdError(f"{path}: DPV1_Slave = 1; this program is a DP-V0 slave only")
    if module is None:
        raise GsdError(f"{path}: no Module")
    return {
        "ident": num("Ident_Number"),
        "user_prm_len": num("User_Prm_Data_Len", 0),
        "sync": num("Sync_Mode_supp", 0) != 0,
        "freeze": num("Freeze_Mode_supp", 0) != 0,
        "fail_safe": num("Fail_Safe", 0) != 0,
        "set_slave_add": num("Set_Slave_Add_supp", 0) != 0,
        "max_diag_len": max(6, min(244, num("Max_Diag_Data_Len", 6))),
        "module": module[0],
        "cfg": bytes(module[1]),
    }


# --- configuration identifiers (§D.3) ------------------------------------------------------------
def parse_cfg(octets, allow_skip):
    """[(input, output, mfr)] with input/output = (units, words, consistent) or None; None if bad.
    Special format: identifier, [output length octet], [input length octet], [mfr octets]."""
    ids, i = [], 0

    def length(o):
        return ((o & 0x3F) + 1, bool(o & 0x40), bool(o & 0x80))

    while i < len(octets):
        b = octets[i]
        i += 1
        if b & 0x30:
            io = ((b & 0x0F) + 1, bool(b & 0x40), bool(b & 0x80))
            ids.append((io if b & 0x10 else None, io if b & 0x20 else None, b""))
            continue
        out_io = in_io = None
        if b & 0x80:
            if i >= len(octets):
                return None
            out_io = length(octets[i])
            i += 1
        if b & 0x40:
            if i >= len(octets):
                return None
            in_io = length(octets[i])
            i += 1
        n = b & 0x0F
        if n == 15:
            if not allow_skip:
                return None
            mfr = None  # not checked
        else:
            if len(octets) - i < n:
                return None
            mfr = bytes(octets[i:i + n])
            i += n
        ids.append((in_io, out_io, mfr))
    return ids


def io_bytes(io):
    return 0 if io is None else io[0] * (2 if io[1] else 1)


def cfg_matches(configured, real):
    if configured[0] != real[0] or configured[1] != real[1]:
        return False
    return configured[2] is None or configured[2] == real[2]


# --- FDL telegrams (§B) ---------------------------------------------------------------------------
def frame_length(buf):
    """Length of the telegram at buf[0] by the FDL length rule; 0 = need more octets; -1 = no
    telegram starts here (drop one octet and look again)."""
    sd = buf[0]
    if sd == SC:
        return 1
    if sd == SD4:
        return 3
    if sd == SD1:
        return 6
    if sd == SD3:
        return 14
    if sd == SD2:
        if len(buf) < 4:
            return 0
        le = buf[1]
        if buf[2] != le or buf[3] != SD2 or le < 3 or le > 249:
            return -1
        return le + 6
    return -1


class Telegram:
    __slots__ = ("da", "sa", "fc", "dsap", "ssap", "data")


def frame_error(frame):
    """The framing checks of a receiver (§B.1): "" if the octets are one intact telegram."""
    sd = frame[0]
    if sd in (SC, SD4):
        return ""
    body = frame[4:-2] if sd == SD2 else frame[1:-2]
    if frame[-1] != ED:
        return "end delimiter"
    if sum(body) & 0xFF != frame[-2]:
        return "FCS"
    if sd == SD2 and len(body) < 4:
        return "LE below 4"
    return ""


def decode(frame):
    """A request telegram from an intact frame, or why it is none for a slave (§B)."""
    sd = frame[0]
    if sd in (SC, SD4):
        return "not a request"  # acknowledgement or token: no business of a slave
    body = frame[4:-2] if sd == SD2 else frame[1:-2]
    t = Telegram()
    da, sa, fc = body[0], body[1], body[2]
    t.da, t.sa, t.fc = da & 0x7F, sa & 0x7F, fc
    if t.sa == BROADCAST:
        return "source address 127"
    if not fc & 0x40:
        return "not a request"  # a response from someone else's exchange
    fn = fc & 0x0F
    if (fc & 0x80 and fc != 0xC0) or fn in FN_RESERVED:
        return "reserved function"
    if t.da == BROADCAST and fn not in FN_NO_REPLY:
        return "broadcast with a reply expected"
    pos = 3
    t.dsap = t.ssap = None
    for ext, name in ((da, "dsap"), (sa, "ssap")):
        if not ext & EXT:
            continue
        if pos >= len(body):
            return "address extension missing"
        o = body[pos]
        pos += 1
        if o & 0xC0:  # a chained or region/segment octet: not used on DP lines
            return "segment address"
        setattr(t, name, o & 0x3F)
    t.data = bytes(body[pos:])
    return t


def encode(da, sa, fc, dsap=None, ssap=None, data=b""):
    d, s, ext = da, sa, b""
    if dsap is not None:  # DAE first, then SAE (§B.2)
        d |= EXT
        ext += bytes([dsap])
    if ssap is not None:
        s |= EXT
        ext += bytes([ssap])
    du = ext + bytes(data)
    body = bytes([d, s, fc]) + du
    fcs = sum(body) & 0xFF
    if not du:
        return bytes([SD1]) + body + bytes([fcs, ED])
    if len(du) == 8:
        return bytes([SD3]) + body + bytes([fcs, ED])
    return bytes([SD2, len(body), len(body), SD2]) + body + bytes([fcs, ED])


# A DP layer's answer: ("sc",), ("status", st), ("data", st, du) or None (no reply).
def short_ack():
    return ("sc",)


def refuse():
    return ("status", ST_RS)


def data_reply(du, st=ST_DL):
    return ("data", st, bytes(du))


# --- the DP slave (§D) ----------------------------------------------------------------------------
class DpSlave:
    def __init__(self, gsd, address, clock, breaks, set_slave_add):
        self.gsd = gsd
        self.address = address
        self.clock = clock  # virtual seconds -> wall seconds
        self.breaks = breaks
        self.accept_set_slave_add = set_slave_add == "accept"
        ids = parse_cfg(gsd["cfg"], False)
        if ids is None:
            raise GsdError(f"module {gsd['module']}: bad identifiers {gsd['cfg'].hex()}")
        self.real_ids = ids
        self.n_in = sum(io_bytes(i[0]) for i in ids)
        self.n_out = sum(io_bytes(i[1]) for i in ids)
        self.min_tsdr = MIN_TSDR_DEFAULT
        self.count = 0  # Data_Exchanges executed: the inputs
        self.stats = {"set_prm": 0, "chk_cfg": 0, "slave_diag": 0, "data_exchange": 0,
                      "global_control": 0, "get_cfg": 0, "rd_inp": 0, "rd_outp": 0,
                      "set_slave_add": 0, "other": 0, "refused": 0, "prm_faults": 0,
                      "cfg_faults": 0, "data_exch_entries": 0, "watchdog_expiries": 0}
        self.prm_fault = self.cfg_fault = self.not_supported = False
        self.cfg_fault_modules, self.cfg_fault_span = [], 1
        self.state = WAIT_PRM
        self.master = NO_MASTER
        self.outputs = bytes(self.n_out)   # received (Rd_Outp)
        self.applied = bytes(self.n_out)   # on the device's terminals
        self.frozen = bytes(self.n_in)
        self._reset_params()

    def _reset_params(self):
        self.wd_on, self.wd_deadline, self.wd_time = False, None, 0.0
        self.sync_enabled = self.freeze_enabled = False
        self.group = 0

    def inputs(self):
        return (self.count % (1 << (8 * self.n_in))).to_bytes(self.n_in, "big") if self.n_in else b""

    # state helpers
    def leave_operation(self):
        self.applied = bytes(self.n_out)  # outputs safe
        self.outputs = bytes(self.n_out)
        self.sync_mode = self.freeze_mode = self.clear = self.fail_safe_zero = False

    def go_wait_prm(self):
        self.leave_operation()
        self.state = WAIT_PRM
        self.master = NO_MASTER
        self._reset_params()

    sync_mode = freeze_mode = clear = fail_safe_zero = False

    def check_watchdog(self, now):
        if self.wd_on and self.wd_deadline is not None and now >= self.wd_deadline:
            self.stats["watchdog_expiries"] += 1
            self.go_wait_prm()

    def next_deadline(self):
        return self.wd_deadline if self.wd_on else None

    # dispatch
    def on_request(self, t, now):
        """Returns the DP answer (see short_ack etc.) or None; may change min_tsdr/address."""
        self.check_watchdog(now)
        fn = t.fc & 0x0F
        if self.master != NO_MASTER and t.sa == self.master and self.wd_on:
            self.wd_deadline = now + self.wd_time
        if t.da == BROADCAST:
            if t.dsap == SAP_GLOBAL_CONTROL:
                self.stats["global_control"] += 1
                self.global_control(t)
            else:
                self.stats["other"] += 1
            return None
        if t.da == DEFAULT_ADDRESS and self.state == WAIT_PRM:
            self.state = POWER_ON
        if t.da != DEFAULT_ADDRESS and self.state == POWER_ON:
            self.state = WAIT_PRM
        answer = refuse()
        if t.dsap is None:
            if fn in (FN_SRD_LOW, FN_SRD_HIGH):
                self.stats["data_exchange"] += 1
                answer = self.data_exchange(t)
            else:
                self.stats["other"] += 1
        else:
            handler = {
                SAP_SET_PRM: ("set_prm", self.set_prm),
                SAP_CHK_CFG: ("chk_cfg", self.chk_cfg),
                SAP_SLAVE_DIAG: ("slave_diag", lambda _t: data_reply(self.diag())),
                SAP_GET_CFG: ("get_cfg", lambda _t: data_reply(self.gsd["cfg"])),
                SAP_GLOBAL_CONTROL: ("global_control", self.global_control),
                SAP_SET_SLAVE_ADD: ("set_slave_add", self.set_slave_add),
                SAP_RD_INP: ("rd_inp", self.rd_inp),
                SAP_RD_OUTP: ("rd_outp", self.rd_outp),
            }.get(t.dsap)
            if handler is None:
                self.stats["other"] += 1
            else:
                self.stats[handler[0]] += 1
                answer = handler[1](t)
        if fn in FN_NO_REPLY:
            return None
        if answer == refuse():
            self.stats["refused"] += 1
        return answer

    # Set_Prm (§D.2)
    def set_prm(self, t):
        if self.state == POWER_ON:
            return refuse()
        if self.master != NO_MASTER and t.sa != self.master:
            return short_ack()  # locked by another master: no effect
        d = t.data
        if len(d) < 7:
            self.stats["prm_faults"] += 1
            self.go_wait_prm()
            self.prm_fault = True
            return short_ack()
        status, wd1, wd2, min_tsdr = d[0], d[1], d[2], d[3]
        ident = (d[4] << 8) | d[5]
        lock, unlock = bool(status & LOCK_REQ), bool(status & UNLOCK_REQ)
        if min_tsdr != 0 and not lock:
            self.new_min_tsdr = min_tsdr
        if not lock and not unlock:
            return short_ack()  # only min TSDR may change
        if unlock:
            if self.master != NO_MASTER:
                self.go_wait_prm()  # released for other masters
            return short_ack()
        fault = False
        if ident != self.gsd["ident"] and "ident" not in self.breaks:
            fault = True
        if status & WD_ON and (wd1 == 0 or wd2 == 0):
            fault = True
        not_supported = bool(status & SYNC_REQ and not self.gsd["sync"] or
                             status & FREEZE_REQ and not self.gsd["freeze"])
        if len(d) - 7 != self.gsd["user_prm_len"]:
            fault = True
        if fault or not_supported:
            self.stats["prm_faults"] += 1
            self.go_wait_prm()
            self.prm_fault, self.not_supported = fault, not_supported
            return short_ack()
        if self.state in (DATA_EXCH, WAIT_CFG):
            self.leave_operation()
        self.prm_fault = self.not_supported = self.cfg_fault = False
        self.cfg_fault_modules = []
        self.master = t.sa
        self.group = d[6]
        self.sync_enabled = bool(status & SYNC_REQ)
        self.freeze_enabled = bool(status & FREEZE_REQ)
        self.wd_on = bool(status & WD_ON)
        self.wd_time = self.clock(0.010 * wd1 * wd2) if self.wd_on else 0.0
        self.wd_deadline = time.monotonic() + self.wd_time if self.wd_on else None
        if min_tsdr != 0:
            self.new_min_tsdr = min_tsdr
        self.state = WAIT_CFG
        return short_ack()

    # Chk_Cfg (§D.3)
    def chk_cfg(self, t):
        if self.state not in (WAIT_CFG, DATA_EXCH):
            return refuse()
        if t.sa != self.master:
            return short_ack()  # locked by another master
        ids = parse_cfg(t.data, True)
        self.cfg_fault_modules, self.cfg_fault_span = [], 1
        ok = ids is not None
        if ok:
            for j in range(max(len(ids), len(self.real_ids))):
                if j < len(ids) and j < len(self.real_ids) and cfg_matches(ids[j], self.real_ids[j]):
                    continue
                ok = False
                module = 0 if j < len(self.real_ids) else 1 + (j - len(self.real_ids))
                if not self.cfg_fault_modules or self.cfg_fault_modules[-1] != module:
                    self.cfg_fault_modules.append(module)
                self.cfg_fault_span = max(self.cfg_fault_span, module + 1)
        if not ok:
            self.stats["cfg_faults"] += 1
            modules, span = self.cfg_fault_modules, self.cfg_fault_span
            self.go_wait_prm()
            self.cfg_fault, self.cfg_fault_modules, self.cfg_fault_span = True, modules, span
            return short_ack()
        self.cfg_fault = False
        if self.state == WAIT_CFG:
            self.state = DATA_EXCH
            self.stats["data_exch_entries"] += 1
        return short_ack()

    # Slave_Diag (§D.4, §D.5)
    def diag(self):
        s1 = s2 = 0
        s2 |= D2_ALWAYS_1
        if self.state != DATA_EXCH:
            s1 |= D1_NOT_READY
        if self.cfg_fault:
            s1 |= D1_CFG_FAULT
        if self.not_supported:
            s1 |= D1_NOT_SUPPORTED
        if self.prm_fault:
            s1 |= D1_PRM_FAULT
        if self.state in (POWER_ON, WAIT_PRM):
            s2 |= D2_PRM_REQ
        if self.wd_on:
            s2 |= D2_WD_ON
        if self.freeze_mode:
            s2 |= D2_FREEZE
        if self.sync_mode:
            s2 |= D2_SYNC
        s3, ext = 0, b""
        if self.cfg_fault_modules:
            # Identifier-related block: header 01LLLLLL (length incl. header), one bit per module.
            octets = min((self.cfg_fault_span + 7) // 8, 62)
            bits = bytearray(octets)
            for m in self.cfg_fault_modules:
                if m // 8 < octets:
                    bits[m // 8] |= 1 << (m % 8)
            block = bytes([0x40 | (octets + 1)]) + bytes(bits)
            if 6 + len(block) <= self.gsd["max_diag_len"]:
                ext = block
            else:
                s3 |= 0x80  # Ext_Diag_Overflow: the block does not fit Max_Diag_Data_Len
            s1 |= D1_EXT_DIAG
        ident = self.gsd["ident"]
        return bytes([s1, s2, s3, self.master, ident >> 8, ident & 0xFF]) + ext

    # Data_Exchange (§D.7)
    def data_exchange(self, t):
        if self.state != DATA_EXCH or t.sa != self.master:
            return refuse()
        if len(t.data) == self.n_out:
            self.outputs = t.data
            self.fail_safe_zero = False
            if not self.sync_mode and not self.clear:
                self.applied = t.data
        elif not t.data and self.gsd["fail_safe"]:
            self.fail_safe_zero = True  # the master in Clear sends no output data at all
            if not self.sync_mode:
                self.applied = bytes(self.n_out)
        else:
            self.go_wait_prm()
            return refuse()
        self.count += 1
        du = self.frozen if self.freeze_mode else self.inputs()
        return data_reply(du) if self.n_in else short_ack()

    def rd_inp(self, _t):
        if self.state != DATA_EXCH:
            return refuse()
        return data_reply(self.frozen if self.freeze_mode else self.inputs()) if self.n_in else short_ack()

    def rd_outp(self, _t):
        if self.state != DATA_EXCH:
            return refuse()
        return data_reply(self.outputs) if self.n_out else short_ack()

    # Global_Control (§D.6)
    def global_control(self, t):
        if self.state != DATA_EXCH or t.sa != self.master or len(t.data) != 2:
            return refuse()
        cmd, groups = t.data[0], t.data[1]
        if groups != 0 and groups & self.group == 0:
            return short_ack()  # not for our groups
        clear = bool(cmd & GC_CLEAR)
        if clear and not self.clear:
            self.applied = bytes(self.n_out)
        self.clear = clear
        if self.sync_enabled:
            if cmd & GC_UNSYNC:  # Unsync wins over Sync in the same telegram
                self.sync_mode = False
                if not self.clear and not self.fail_safe_zero:
                    self.applied = self.outputs
            elif cmd & GC_SYNC:
                self.sync_mode = True
                if not self.clear and not self.fail_safe_zero:
                    self.applied = self.outputs  # latch the latest outputs
        if self.freeze_enabled:
            if cmd & GC_UNFREEZE:  # Unfreeze wins over Freeze
                self.freeze_mode = False
            elif cmd & GC_FREEZE:
                self.frozen = self.inputs()
                self.freeze_mode = True
        return short_ack()

    # Set_Slave_Add (§D.7)
    def set_slave_add(self, t):
        if not self.accept_set_slave_add or not self.gsd["set_slave_add"]:
            return refuse()  # see "Decisions": a pty attachment has a fixed address
        if self.state not in (POWER_ON, WAIT_PRM) or len(t.data) < 4:
            return refuse()
        new, ident = t.data[0], (t.data[1] << 8) | t.data[2]
        if ident != self.gsd["ident"] or new > 125:
            return refuse()
        self.new_address = new
        self.state = WAIT_PRM
        return short_ack()

    # Taken after the reply has gone out (the reply itself keeps the old values).
    new_address = None
    new_min_tsdr = None


# --- the station: FDL on top of the byte stream ---------------------------------------------------
class Station:
    def __init__(self, slave, address, breaks, log):
        self.slave = slave
        self.address = address
        self.breaks = breaks
        self.log = log
        self.fcb = {}       # SA -> FCB of its last action frame (§C.6)
        self.stored = {}    # SA -> the reply sent to it
        self.counts = {"telegrams": 0, "replies": 0, "repeats": 0, "fdl_status": 0,
                       "garbage_octets": 0, "bad_telegrams": 0, "abandoned": 0,
                       "not_for_us": 0}

    def handle(self, frame, now):
        """The reply octets for one complete telegram (b"" for none)."""
        t = decode(frame)
        if isinstance(t, str):
            if t != "not a request":
                self.counts["bad_telegrams"] += 1
                self.log(f"dropped ({t}): {frame.hex(' ')}")
            return b""
        if t.da != self.address and t.da != BROADCAST:
            self.counts["not_for_us"] += 1
            return b""
        self.counts["telegrams"] += 1
        fn = t.fc & 0x0F
        if fn == FN_FDL_STATUS:
            self.counts["fdl_status"] += 1
            return encode(t.sa, self.address, ST_OK)
        expects = fn not in FN_NO_REPLY and t.da != BROADCAST
        uses_fcb = fn in FN_USES_FCB
        fcb = 1 if t.fc & FCB else 0
        if (expects and uses_fcb and t.fc & FCV and self.fcb.get(t.sa) == fcb
                and "fcb" not in self.breaks):
            self.counts["repeats"] += 1
            return self.stored.get(t.sa, b"")  # a repeat: the stored reply, not executed again
        answer = self.slave.on_request(t, now)
        if not expects or answer is None:
            return b""
        if answer[0] == "sc":
            reply = bytes([SC])
        elif answer[0] == "status":
            reply = encode(t.sa, self.address, answer[1])
        else:
            reply = encode(t.sa, self.address, answer[1], t.ssap, t.dsap, answer[2])
        if uses_fcb and t.fc & (FCV | FCB):
            self.fcb[t.sa] = fcb
            self.stored[t.sa] = reply
        return reply


def take_new_values(slave, station):
    """A new min TSDR or address counts from the end of the reply that carried it on."""
    if slave.new_min_tsdr is not None:
        slave.min_tsdr, slave.new_min_tsdr = slave.new_min_tsdr, None
    if slave.new_address is not None:
        station.address = slave.address = slave.new_address
        slave.new_address = None


def parse_speed(text):
    try:
        n, m = (int(x) for x in text.split("/")) if "/" in text else (int(text), 1)
    except ValueError:
        n = m = 0
    if n <= 0 or m <= 0:
        raise argparse.ArgumentTypeError(f"--speed {text}: expected N/M with N, M > 0")
    return n, m


def parse_baud(text):
    if text not in BAUDS:
        raise argparse.ArgumentTypeError(f"--baud {text}: one of {', '.join(BAUDS)}")
    return BAUDS[text]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description="A DP-V0 slave behind a pty for pbvbus conformance.")
    ap.add_argument("--port", required=True, help="the pty (or its symlink) to open")
    ap.add_argument("--address", type=int, required=True, help="own FDL address 0..126")
    ap.add_argument("--gsd", default=os.path.join(here, "..", "..", "examples", "gsd", "PBVB0A01.gsd"))
    ap.add_argument("--speed", type=parse_speed, default=(1, 1000),
                    help="the battery's speed ratio N/M (virtual time = wall time x N/M)")
    ap.add_argument("--baud", type=parse_baud, default=BAUDS["1.5M"], help="the line's baud rate")
    ap.add_argument("--break", dest="breaks", action="append", default=[], choices=["ident", "fcb"],
                    help="break one rule on purpose")
    ap.add_argument("--set-slave-add", choices=["refuse", "accept"], default="refuse")
    ap.add_argument("--resync", type=float, default=1.0,
                    help="wall seconds after which an incomplete telegram is dropped")
    ap.add_argument("--max-time", type=float, default=0.0, help="wall seconds to run (0 = until killed)")
    ap.add_argument("--wait-port", type=float, default=30.0, help="wall seconds to wait for --port")
    ap.add_argument("-v", "--verbose", action="store_true", help="log every telegram on stderr")
    args = ap.parse_args()
    if not 0 <= args.address <= 126:
        ap.error("--address must be 0..126")
    try:
        gsd = read_gsd(args.gsd)
    except GsdError as e:
        print(f"outside_slave: {e}", file=sys.stderr)
        return 2
    n, m = args.speed
    clock = lambda virtual_s: virtual_s * m / n  # noqa: E731  virtual seconds -> wall seconds
    bit_wall = clock(1.0 / args.baud)
    t0 = time.monotonic()

    def log(msg):
        if args.verbose:
            print(f"[{time.monotonic() - t0:9.3f}] {msg}", file=sys.stderr, flush=True)

    slave = DpSlave(gsd, args.address, clock, args.breaks, args.set_slave_add)
    station = Station(slave, args.address, args.breaks, log)

    stop = []
    # SIGHUP too: a pty whose other side goes away may hang up on whoever has it open.
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, lambda *_: stop.append(1))

    deadline = t0 + args.wait_port
    while not os.path.exists(args.port):
        if time.monotonic() > deadline or stop:
            print(f"outside_slave: {args.port} did not appear", file=sys.stderr)
            return 2
        time.sleep(0.01)
    try:
        port = serial.Serial(args.port, baudrate=19200, timeout=0)
    except (serial.SerialException, OSError) as e:
        print(f"outside_slave: cannot open {args.port}: {e}", file=sys.stderr)
        return 2
    port.reset_input_buffer()
    fd = port.fileno()
    log(f"open {args.port}: address {args.address}, ident 0x{gsd['ident']:04X}, cfg "
        f"{gsd['cfg'].hex(' ')}, speed {n}/{m}, 1 bit = {bit_wall * 1e3:.3f} ms wall, "
        f"breaks {args.breaks or 'none'}")

    buf = bytearray()
    first_at = None  # when the oldest octet of an incomplete telegram arrived
    ended = "killed"
    while not stop:
        now = time.monotonic()
        if args.max_time and now - t0 > args.max_time:
            ended = "max-time"
            break
        slave.check_watchdog(now)
        try:
            ready, _, _ = select.select([fd], [], [], 0.005)
        except InterruptedError:
            continue
        if ready:
            try:
                chunk = os.read(fd, 4096)
            except OSError:
                chunk = b""
            if not chunk:
                ended = "port closed"
                break
            buf += chunk
        now = time.monotonic()
        if buf and first_at is not None and now - first_at > args.resync:
            station.counts["abandoned"] += 1
            log(f"abandoned incomplete {bytes(buf[:16]).hex(' ')}")
            del buf[0]
            first_at = now if buf else None
        while buf:
            n_len = frame_length(buf)
            if n_len < 0:
                station.counts["garbage_octets"] += 1
                del buf[0]
                continue
            if n_len == 0 or len(buf) < n_len:
                if first_at is None:
                    first_at = now
                break
            frame = bytes(buf[:n_len])
            why = frame_error(frame)
            if why:
                # Not a telegram after all: drop its first octet only and look again, so a
                # request that a stray start delimiter swallowed is still found.
                station.counts["bad_telegrams"] += 1
                log(f"dropped ({why}): {frame.hex(' ')}")
                del buf[0]
                continue
            del buf[:n_len]
            first_at = None
            log(f"rx {frame.hex(' ')}")
            reply = station.handle(frame, now)
            if not reply:
                take_new_values(slave, station)
                continue
            # Not before min TSDR bit times after the request (it arrived just before `now`).
            wait = now + slave.min_tsdr * bit_wall - time.monotonic()
            if wait > 0:
                time.sleep(wait)
            try:
                port.write(reply)
            except (serial.SerialException, OSError):
                ended = "port closed"
                stop.append(1)
                break
            station.counts["replies"] += 1
            log(f"tx {reply.hex(' ')}")
            take_new_values(slave, station)
    summary = {"ended": ended, "state": slave.state, "master": slave.master,
               "address": station.address, "breaks": args.breaks,
               "inputs": slave.inputs().hex(), "outputs": slave.outputs.hex(),
               "fdl": station.counts, "dp": slave.stats}
    print(json.dumps(summary), flush=True)
    # Done: a SIGTERM from whoever stops us may still come (the battery closing the pty ends the
    # loop first). Ignore it from here: Python's finalization puts Python-level handlers back to
    # SIG_DFL (not SIG_IGN ones), so a late SIGTERM would otherwise end a clean exit as 143.
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_IGN)
    return 0


if __name__ == "__main__":
    sys.exit(main())
