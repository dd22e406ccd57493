"""DP-V0 slave services and state machine for the GSD PBVB0A01 (Ident 0x0A01, 16 DI / 16 DO).

From protocol-facts.md §D (D.1 SAPs, D.2 Set_Prm, D.3 Chk_Cfg/Get_Cfg, D.4 Slave_Diag,
D.6 Global_Control, D.7 Data_Exchange/Rd_Inp/Rd_Outp/Set_Slave_Add, D.8 state machine) and
the GSD file. Times are VIRTUAL seconds supplied by the caller.
"""

from fdl_layer import Indication, Result

IDENT = 0x0A01
REAL_CFG = bytes([0x11, 0x21])      # 2 octets in, 2 octets out
N_IN, N_OUT = 2, 2
USER_PRM_LEN = 1
USER_PRM_ALLOWED = 0x33             # bit 0 outputs on stop, bit 1 diag L+, bits 4-5 input delay
NO_ADDRESS = 126                    # default "not yet addressed" station address

SAP_SET_SLAVE_ADD = 55
SAP_RD_INP = 56
SAP_RD_OUTP = 57
SAP_GLOBAL_CONTROL = 58
SAP_GET_CFG = 59
SAP_SLAVE_DIAG = 60
SAP_SET_PRM = 61
SAP_CHK_CFG = 62

WAIT_PRM, WAIT_CFG, DATA_EXCH = "Wait_Prm", "Wait_Cfg", "Data_Exch"

# Station_Status octets (§D.2 for Set_Prm octet 1, §D.4 for the diagnosis)
PRM_LOCK, PRM_UNLOCK, PRM_SYNC, PRM_FREEZE, PRM_WD_ON = 0x80, 0x40, 0x20, 0x10, 0x08
S1_NOT_READY, S1_CFG_FAULT, S1_EXT_DIAG, S1_PRM_FAULT = 0x02, 0x04, 0x08, 0x40
S2_PRM_REQ, S2_ALWAYS_1, S2_WD_ON, S2_FREEZE, S2_SYNC = 0x01, 0x04, 0x08, 0x10, 0x20
GC_CLEAR, GC_UNFREEZE, GC_FREEZE, GC_UNSYNC, GC_SYNC = 0x02, 0x04, 0x08, 0x10, 0x20

WD_BASE = 0.010                     # DP-V0: 10 ms per unit of WD_Fact_1 * WD_Fact_2

# Unit diagnosis: one device-related block, header 0x02 (length 2 incl. header), then one
# status octet = GSD Unit_Diag_Bit(8..15) (bit 8 = octet 8 bit 0).
UNIT_L_PLUS_MISSING = 0x01          # Unit_Diag_Bit(8)


class DpSlave:
    def __init__(self, address, bugs=frozenset(), log=None, lplus_missing_after=None):
        self.address = address
        self.bugs = bugs
        self.log = log or (lambda msg: None)
        self.lplus_missing_after = lplus_missing_after  # None: never; N: after N Data_Exchanges
        self.address_locked = False     # No_Add_Chg != 0 received
        self.min_tsdr = 11              # recorded only (a pty keeps no bit timing)
        self.counter = 0                # the inputs: big-endian count of Data_Exchanges
        self.dx_count = 0
        self._reset_to_wait_prm(initial=True)

    # -- helpers -------------------------------------------------------------------------
    def _set_state(self, state, why):
        if state != self.state:
            self.log("state %s -> %s (%s)" % (self.state, state, why))
        self.state = state

    def _reset_to_wait_prm(self, initial=False, why=""):
        """Wait_Prm: unlocked, no watchdog, outputs in the safe state (0)."""
        if initial:
            self.state = WAIT_PRM
        else:
            self._set_state(WAIT_PRM, why)
        self._clear()

    def _clear(self):
        """Forget the parameterisation: unlocked, no watchdog, outputs safe (0)."""
        self.owner = None
        self.prm_fault = False
        self.cfg_fault = False
        self.wd_on = False
        self.wd_time = 0.0
        self.wd_deadline = None
        self.sync_enabled = self.freeze_enabled = False
        self.sync_mode = self.freeze_mode = False
        self.frozen = None
        self.group_ident = 0
        self.user_prm = 0x00
        self.outputs_rx = bytes(N_OUT)   # last received
        self.outputs = bytes(N_OUT)      # applied ("physical")
        self.diag_pending = False
        self.ext_reported = False

    def live_inputs(self):
        return bytes([(self.counter >> 8) & 0xFF, self.counter & 0xFF])

    def input_image(self):
        return self.frozen if self.freeze_mode and self.frozen is not None else self.live_inputs()

    def unit_diag(self):
        """The device-related block, or b'' when there is nothing to report."""
        if self.state == WAIT_PRM or not (self.user_prm & 0x02):
            return b""
        if self.lplus_missing_after is None or self.dx_count < self.lplus_missing_after:
            return b""
        return bytes([0x02, UNIT_L_PLUS_MISSING])

    def diagnosis(self):
        ext = self.unit_diag()
        s1 = 0
        if self.state != DATA_EXCH:
            s1 |= S1_NOT_READY
        if self.cfg_fault:
            s1 |= S1_CFG_FAULT
        if self.prm_fault:
            s1 |= S1_PRM_FAULT
        if ext:
            s1 |= S1_EXT_DIAG
        s2 = S2_ALWAYS_1
        if self.state == WAIT_PRM:
            s2 |= S2_PRM_REQ
            if "diag_always1_wait_prm" in self.bugs:
                s2 &= ~S2_ALWAYS_1          # BUG: the always-1 bit missing in Wait_Prm
        elif self.wd_on:
            s2 |= S2_WD_ON
        if self.freeze_mode:
            s2 |= S2_FREEZE
        if self.sync_mode:
            s2 |= S2_SYNC
        master = 0xFF if self.owner is None else self.owner
        return bytes([s1, s2, 0x00, master, IDENT >> 8, IDENT & 0xFF]) + ext

    # -- timing --------------------------------------------------------------------------
    def heard(self, sa, now):
        """A valid telegram addressed to us (or broadcast) ended at `now`."""
        if self.owner is not None and sa == self.owner and self.wd_deadline is not None:
            self.wd_deadline = now + self.wd_time

    def next_deadline(self):
        return self.wd_deadline

    def check_watchdog(self, now):
        if self.wd_deadline is not None and now >= self.wd_deadline:
            self.log("watchdog expired (TWD %.3f s, owner %s)" % (self.wd_time, self.owner))
            self._reset_to_wait_prm(why="watchdog")
            return True
        return False

    # -- dispatch ------------------------------------------------------------------------
    def service(self, ind: Indication, now) -> Result:
        if not ind.confirmed:
            if ind.dsap == SAP_GLOBAL_CONTROL:
                self._global_control(ind)
            return Result.none()
        if ind.dsap is None:
            return self._data_exchange(ind, now)
        handler = {
            SAP_SET_SLAVE_ADD: self._set_slave_add,
            SAP_RD_INP: self._rd_inp,
            SAP_RD_OUTP: self._rd_outp,
            SAP_GLOBAL_CONTROL: self._global_control_srd,
            SAP_GET_CFG: self._get_cfg,
            SAP_SLAVE_DIAG: self._slave_diag,
            SAP_SET_PRM: self._set_prm,
            SAP_CHK_CFG: self._chk_cfg,
        }.get(ind.dsap)
        if handler is None:
            return Result.rs()               # SAP not activated
        return handler(ind, now)

    def _locked_to_other(self, sa):
        return self.owner is not None and sa != self.owner

    # -- services ------------------------------------------------------------------------
    def _slave_diag(self, ind, now=None):
        if ind.sa == self.owner:
            self.diag_pending = False
        return Result("data", self.diagnosis())

    def _get_cfg(self, ind, now=None):
        return Result("data", REAL_CFG)

    def _rd_inp(self, ind, now=None):
        if self.state != DATA_EXCH:
            return Result.rs()
        return Result("data", self.input_image())

    def _rd_outp(self, ind, now=None):
        if self.state != DATA_EXCH:
            return Result.rs()
        return Result("data", self.outputs)

    def _set_prm(self, ind, now):
        du = ind.du
        if self.address == NO_ADDRESS:
            return Result.rs()
        if self._locked_to_other(ind.sa) and "lock_ignored" not in self.bugs:
            self.log("Set_Prm from %d ignored: locked to %d" % (ind.sa, self.owner))
            return Result.sc()
        if not du:
            self._prm_fault(ind.sa, "empty Set_Prm")
            return Result.sc()
        status = du[0]
        if status & PRM_UNLOCK:                 # 0 1 and 1 1: released
            self._reset_to_wait_prm(why="unlock by %d" % ind.sa)
            return Result.sc()
        if not status & PRM_LOCK:               # 0 0: only min TSDR
            if len(du) >= 4 and du[3]:
                self.min_tsdr = du[3]
                self.log("min TSDR %d (lock 0 unlock 0)" % du[3])
            return Result.sc()
        # Lock_Req = 1: a full parameterisation
        why = None
        if len(du) != 7 + USER_PRM_LEN:
            why = "length %d, expected %d" % (len(du), 7 + USER_PRM_LEN)
        elif (du[4] << 8 | du[5]) != IDENT:
            why = "ident 0x%04X" % (du[4] << 8 | du[5])
        elif status & PRM_WD_ON and (du[1] == 0 or du[2] == 0):
            why = "watchdog factor 0"
        elif du[7] & ~USER_PRM_ALLOWED & 0xFF:
            why = "User_Prm_Data 0x%02X" % du[7]
        if why:
            self._prm_fault(ind.sa, why)
            return Result.sc()
        if du[3]:
            self.min_tsdr = du[3]
        self._clear()                                  # clean slate, then apply
        self.owner = ind.sa
        self.wd_on = bool(status & PRM_WD_ON)
        self.wd_time = du[1] * du[2] * WD_BASE
        self.wd_deadline = now + self.wd_time if self.wd_on else None
        self.sync_enabled = bool(status & PRM_SYNC)
        self.freeze_enabled = bool(status & PRM_FREEZE)
        self.group_ident = du[6]
        self.user_prm = du[7]
        self._set_state(WAIT_CFG, "Set_Prm from %d" % ind.sa)
        self.log("Set_Prm ok: owner %d WD %s %.3f s min TSDR %d group 0x%02X user 0x%02X%s%s"
                 % (ind.sa, "on" if self.wd_on else "off", self.wd_time, self.min_tsdr,
                    self.group_ident, self.user_prm, " sync" if self.sync_enabled else "",
                    " freeze" if self.freeze_enabled else ""))
        return Result.sc()

    def _prm_fault(self, sa, why):
        self._reset_to_wait_prm(why="Prm_Fault: %s" % why)
        self.prm_fault = True
        self.log("Set_Prm from %d rejected: %s" % (sa, why))

    def _chk_cfg(self, ind, now=None):
        if self.address == NO_ADDRESS or self.state == WAIT_PRM:
            return Result.rs()
        if self._locked_to_other(ind.sa):
            self.log("Chk_Cfg from %d ignored: locked to %d" % (ind.sa, self.owner))
            return Result.sc()
        if ind.du == REAL_CFG:
            self.cfg_fault = False
            if self.state == WAIT_CFG:
                self.outputs_rx = self.outputs = bytes(N_OUT)
                self._set_state(DATA_EXCH, "Chk_Cfg ok")
            return Result.sc()
        self._reset_to_wait_prm(why="Cfg_Fault: %s" % ind.du.hex(" "))
        self.cfg_fault = True
        return Result.sc()

    def _data_exchange(self, ind, now=None):
        if self.address == NO_ADDRESS or self.state != DATA_EXCH or ind.sa != self.owner:
            return Result.rs()
        if len(ind.du) == N_OUT:
            received = bytes(ind.du)
        elif len(ind.du) == 0:                    # Fail_Safe: Clear mode, no output data
            received = self.outputs if self.user_prm & 0x01 else bytes(N_OUT)
        else:
            self.log("Data_Exchange with %d output octets refused" % len(ind.du))
            return Result("ue")
        self.outputs_rx = received
        if not self.sync_mode:
            self.outputs = received
        inputs = self.input_image()
        self.counter = (self.counter + 1) & 0xFFFF
        self.dx_count += 1
        reported = bool(self.unit_diag())
        if reported != self.ext_reported:
            self.ext_reported = reported
            self.diag_pending = True
            self.log("unit diagnosis changed: DH until the owner reads Slave_Diag")
        return Result("data", inputs, high=self.diag_pending)

    def _global_control_srd(self, ind, now=None):
        self._global_control(ind)
        return Result.sc()

    def _global_control(self, ind):
        du = ind.du
        if len(du) != 2 or self.state != DATA_EXCH or ind.sa != self.owner:
            return
        cmd, group = du[0], du[1]
        if group != 0 and not (group & self.group_ident) and "group_ignored" not in self.bugs:
            return
        if cmd & GC_CLEAR:
            self.outputs_rx = self.outputs = bytes(N_OUT)
        if self.sync_enabled:
            if cmd & GC_UNSYNC:
                self.sync_mode = False
                self.outputs = self.outputs_rx
            elif cmd & GC_SYNC:
                self.sync_mode = True
                self.outputs = self.outputs_rx
        if self.freeze_enabled:
            if cmd & GC_UNFREEZE:
                self.freeze_mode = False
                self.frozen = None
            elif cmd & GC_FREEZE:
                self.freeze_mode = True
                self.frozen = self.live_inputs()
        if cmd & 0x3C:
            self.log("Global_Control 0x%02X group 0x%02X: sync %s freeze %s outputs %s"
                     % (cmd, group, self.sync_mode, self.freeze_mode, self.outputs.hex()))

    def _set_slave_add(self, ind, now=None):
        du = ind.du
        if len(du) < 4:
            return Result.rs()
        new, ident, no_add_chg = du[0], du[1] << 8 | du[2], du[3]
        why = None
        if self.state != WAIT_PRM:
            why = "state %s" % self.state
        elif self.address_locked:
            why = "address change locked (No_Add_Chg)"
        elif ident != IDENT:
            why = "ident 0x%04X" % ident
        elif new > 125:
            why = "address %d" % new
        if why:
            self.log("Set_Slave_Add from %d refused: %s" % (ind.sa, why))
            return Result.rs()
        self.log("Set_Slave_Add: address %d -> %d%s" % (self.address, new,
                 ", no further change" if no_add_chg else ""))
        self.address = new                 # the reply still goes out from the old address
        if no_add_chg:
            self.address_locked = True
        return Result.sc()
