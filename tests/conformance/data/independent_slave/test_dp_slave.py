"""FDL responder + DP state machine tests, telegram in -> telegram out.

Golden frames: the facts' Appendix 1 examples, re-worked by hand for Ident 0x0A01 / cfg 11 21.
Master 1 (SA 0x81 with EXT), slave 10 (DA 0x8A with EXT) unless stated otherwise.
"""

import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import dp_state                                   # noqa: E402
from dp_state import DATA_EXCH, WAIT_CFG, WAIT_PRM, DpSlave  # noqa: E402
from fdl_frame import Deframer, encode            # noqa: E402
from fdl_layer import FdlResponder                # noqa: E402


def h(s):
    return bytes.fromhex(s)


SC = h("E5")
# Slave_Diag request, first frame (S11 trace)
DIAG_6D = h("68 05 05 68 8A 81 6D 3C 3E F2 16")
# Diag reply before parameterisation: 02 05 00 FF 0A 01 in SD3;
# FCS = 81+8A+08+3E+3C+02+05+00+FF+0A+01 = 0x29E -> 9E
DIAG_WAIT_PRM = h("A2 81 8A 08 3E 3C 02 05 00 FF 0A 01 9E 16")
# Set_Prm lock+WD 10x10x10 ms, min TSDR 11, ident 0A01, group 0, user prm 00, FCV=1 FCB=0;
# facts' frame had 12 34 and no user octet (FCS D0): D0 - 0x46 + 0x0B = 0x95
SET_PRM_5D = h("68 0D 0D 68 8A 81 5D 3D 3E 88 0A 0A 0B 0A 01 00 00 95 16")
# Chk_Cfg 11 21, FCV=1 FCB=1: facts' 10 20 frame FCS 34 + 2 = 36
CHK_CFG_7D = h("68 07 07 68 8A 81 7D 3E 3E 11 21 36 16")
# Diag in Data_Exch: 00 0C 00 01 0A 01 -> FCS 81+8A+08+3E+3C+00+0C+00+01+0A+01 = 0x1A5 -> A5
DIAG_5D = h("68 05 05 68 8A 81 5D 3C 3E E2 16")
DIAG_DXCH = h("A2 81 8A 08 3E 3C 00 0C 00 01 0A 01 A5 16")
# Data_Exchange AA 55 (facts' frame), reply inputs 00 00: FCS 01+0A+08 = 13
DX_5D = h("68 05 05 68 0A 01 5D AA 55 67 16")
DX_7D = h("68 05 05 68 0A 01 7D AA 55 87 16")
DX_REPLY_0 = h("68 05 05 68 01 0A 08 00 00 13 16")
DX_REPLY_1 = h("68 05 05 68 01 0A 08 00 01 14 16")
RS_TO_1 = h("10 01 0A 03 0E 16")


def set_prm(sa=1, da=10, fc=0x5D, status=0x88, f1=10, f2=10, tsdr=11, ident=0x0A01, group=0,
            user=b"\x00"):
    du = bytes([0x3D, 0x3E, status, f1, f2, tsdr, ident >> 8, ident & 0xFF, group]) + user
    return encode(da | 0x80, sa | 0x80, fc, du)


def sap_req(dsap, sa=1, da=10, fc=0x5D, du=b""):
    return encode(da | 0x80, sa | 0x80, fc, bytes([dsap, 0x3E]) + du)


def dx(sa=1, da=10, fc=0x5D, out=b"\x00\x00"):
    return encode(da, sa, fc, out)


def gc(cmd, group=0, sa=1, da=127):
    return encode(da | 0x80, sa | 0x80, 0x46, bytes([0x3A, 0x3E, cmd, group]))


class Harness:
    def __init__(self, address=10, bugs=(), **kw):
        self.dp = DpSlave(address, bugs=frozenset(bugs), **kw)
        self.fdl = FdlResponder(self.dp, bugs=frozenset(bugs))
        self.now = 0.0

    def send(self, frame, dt=0.001):
        """One telegram in; the reply octets (or None)."""
        self.now += dt
        self.dp.check_watchdog(self.now)
        tels = Deframer().feed(frame)
        assert len(tels) == 1, frame.hex(" ")
        return self.fdl.handle(tels[0], self.now)

    def diag(self, sa=1):
        r = self.send(sap_req(0x3C, sa=sa, fc=0x4D))     # FCV=0 FCB=0: no FCB bookkeeping
        tel = Deframer().feed(r)[0]
        return tel.data[2:]                               # skip the swapped SAPs

    def startup(self, status=0x88, group=0, user=b"\x00"):
        assert self.send(DIAG_6D) == DIAG_WAIT_PRM
        assert self.send(set_prm(status=status, group=group, user=user)) == SC
        assert self.send(CHK_CFG_7D) == SC
        assert self.dp.state == DATA_EXCH


class Fdl(unittest.TestCase):
    def test_fdl_status(self):
        t = Harness(address=3)
        self.assertEqual(t.send(h("10 03 01 49 4D 16")), h("10 01 03 00 04 16"))

    def test_not_addressed_to_us(self):
        t = Harness(address=3)
        self.assertIsNone(t.send(h("10 05 02 49 50 16")))          # to station 5
        self.assertIsNone(t.send(h("10 01 05 30 36 16")))          # someone's reply
        self.assertIsNone(t.send(h("DC 03 02")))                   # a token
        self.assertIsNone(t.send(h("E5")))

    def test_broadcast_srd_not_answered(self):
        t = Harness()
        self.assertIsNone(t.send(sap_req(0x3C, da=127)))

    def test_unknown_sap_and_unsupported_functions(self):
        t = Harness()
        self.assertEqual(t.send(sap_req(0x33)), RS_TO_1)           # DP-V1 C1 SAP: RS
        self.assertEqual(t.send(encode(10, 1, 0x4E)), RS_TO_1)     # Request Ident
        self.assertEqual(t.send(encode(0x8A, 0x81, 0x53, h("3C 3E"))), RS_TO_1)  # SDA

    def test_diag_reply_sd3_swapped(self):
        t = Harness()
        self.assertEqual(t.send(DIAG_6D), DIAG_WAIT_PRM)

    def test_get_cfg_reply(self):
        t = Harness()
        # request FCS 8A+81+6D+3B+3E = 0x1F1 -> F1; reply 81+8A+08+3E+3B+11+21 = 0x1BE -> BE
        req = h("68 05 05 68 8A 81 6D 3B 3E F1 16")
        self.assertEqual(t.send(req), h("68 07 07 68 81 8A 08 3E 3B 11 21 BE 16"))

    def test_fcb_repeat_resends_stored_reply(self):
        t = Harness()
        t.startup()
        self.assertEqual(t.send(DIAG_5D), DIAG_DXCH)
        self.assertEqual(t.send(DX_7D), DX_REPLY_0)
        self.assertEqual(t.send(DX_7D), DX_REPLY_0)               # repeat: same reply
        self.assertEqual(t.dp.dx_count, 1)                        # not executed twice
        self.assertEqual(t.send(DX_5D), DX_REPLY_1)

    def test_first_frame_restarts_fcb(self):
        t = Harness()
        t.startup()
        t.send(DIAG_5D)
        t.send(dx(fc=0x7D))
        self.assertEqual(t.send(dx(fc=0x6D)), DX_REPLY_1)          # FCV=0 FCB=1: new
        self.assertEqual(t.send(dx(fc=0x7D)), DX_REPLY_1)          # FCB same as first: repeat

    def test_fcb_per_station(self):
        t = Harness()
        t.startup()                        # master 1's last frame: Chk_Cfg FCB=1
        # master 2 reads the diag with FCV=1, FCB=1: a new frame for station 2
        r = t.send(sap_req(0x3C, sa=2, fc=0x7D))
        self.assertEqual(Deframer().feed(r)[0].data[2:], h("00 0C 00 01 0A 01"))

    def test_sap_mirroring_without_ssap(self):
        # DA with EXT (DSAP 60), SA without EXT (default SSAP): reply DA plain, SA with EXT,
        # only an SAE (= 60): 01 8A 08 3C + diag
        t = Harness()
        r = t.send(encode(0x8A, 0x01, 0x6D, h("3C")))
        self.assertEqual(r, encode(0x01, 0x8A, 0x08, h("3C 02 05 00 FF 0A 01")))


class DpStates(unittest.TestCase):
    def test_startup_and_diag_per_state(self):
        t = Harness()
        # the FCB alternates 1, 0, 1, ... as a master's would
        self.assertEqual(t.diag(), h("02 05 00 FF 0A 01"))
        self.assertEqual(t.send(DX_7D), RS_TO_1)                   # Wait_Prm: RS
        self.assertEqual(t.send(SET_PRM_5D), SC)
        self.assertEqual(t.dp.state, WAIT_CFG)
        self.assertEqual(t.diag(), h("02 0C 00 01 0A 01"))
        self.assertEqual(t.send(DX_7D), RS_TO_1)                   # Wait_Cfg: RS
        self.assertEqual(t.send(sap_req(0x3E, fc=0x5D, du=h("11 21"))), SC)
        self.assertEqual(t.diag(), h("00 0C 00 01 0A 01"))
        self.assertEqual(t.send(DX_7D), DX_REPLY_0)
        self.assertEqual(t.dp.outputs, h("AA 55"))

    def test_prm_fault_wrong_ident(self):
        t = Harness()
        # the facts' Set_Prm frame (ident 0x1234, no user octet)
        self.assertEqual(t.send(h("68 0C 0C 68 8A 81 5D 3D 3E 88 0A 0A 0B 12 34 00 D0 16")), SC)
        self.assertEqual(t.diag(), h("42 05 00 FF 0A 01"))
        # each a first frame (FCV=0 FCB=1), so none is a repeat
        t.send(set_prm(ident=0x0A01, user=b"", fc=0x6D))         # length 7: fault too
        self.assertEqual(t.diag(), h("42 05 00 FF 0A 01"))
        t.send(set_prm(user=b"\x04", fc=0x6D))                    # reserved user bit
        self.assertEqual(t.diag(), h("42 05 00 FF 0A 01"))
        t.send(set_prm(status=0x88, f1=0, fc=0x6D))               # WD factor 0
        self.assertEqual(t.diag(), h("42 05 00 FF 0A 01"))
        t.send(set_prm(status=0x80, user=b"\x33", fc=0x6D))       # good, no WD
        self.assertEqual(t.diag(), h("02 04 00 01 0A 01"))

    def test_cfg_fault(self):
        t = Harness()
        t.send(SET_PRM_5D)
        self.assertEqual(t.send(h("68 07 07 68 8A 81 7D 3E 3E 10 20 34 16")), SC)
        self.assertEqual(t.dp.state, WAIT_PRM)
        self.assertEqual(t.diag(), h("06 05 00 FF 0A 01"))
        self.assertEqual(t.send(sap_req(0x3E, fc=0x5D, du=h("11 21"))), RS_TO_1)  # Wait_Prm

    def test_chk_cfg_other_config_in_data_exch(self):
        t = Harness()
        t.startup()
        t.send(sap_req(0x3E, fc=0x5D, du=h("31")))
        self.assertEqual(t.dp.state, WAIT_PRM)
        self.assertEqual(t.diag(), h("06 05 00 FF 0A 01"))

    def test_watchdog(self):
        t = Harness()
        t.startup()                                               # WD 1 s
        t.send(DX_5D, dt=0.9)
        t.send(DX_7D, dt=0.9)                                     # restarted: still alive
        self.assertEqual(t.dp.state, DATA_EXCH)
        t.send(sap_req(0x3C, sa=2, fc=0x4D), dt=0.9)              # other master: no restart
        t.now += 0.2
        self.assertTrue(t.dp.check_watchdog(t.now))
        self.assertEqual(t.dp.outputs, h("00 00"))
        self.assertEqual(t.diag(), h("02 05 00 FF 0A 01"))

    def test_no_watchdog_without_wd_on(self):
        t = Harness()
        t.startup(status=0x80)
        t.now += 1000
        self.assertFalse(t.dp.check_watchdog(t.now))
        self.assertEqual(t.diag(), h("00 04 00 01 0A 01"))

    def test_lock(self):
        t = Harness()
        t.startup()
        self.assertEqual(t.send(set_prm(sa=2, fc=0x6D)), SC)      # ignored
        self.assertEqual(t.dp.owner, 1)
        self.assertEqual(t.dp.state, DATA_EXCH)
        self.assertEqual(t.send(dx(sa=2, fc=0x6D)), h("10 02 0A 03 0F 16"))  # not the owner
        # unlock by the owner
        self.assertEqual(t.send(set_prm(status=0x40, fc=0x5D)), SC)
        self.assertEqual(t.diag(), h("02 05 00 FF 0A 01"))
        self.assertEqual(t.send(set_prm(sa=2, fc=0x5D)), SC)      # now master 2 may
        self.assertEqual(t.dp.owner, 2)

    def test_prm_lock0_unlock0_only_min_tsdr(self):
        t = Harness()
        t.startup()
        t.send(set_prm(status=0x00, tsdr=40, ident=0x9999))
        self.assertEqual(t.dp.min_tsdr, 40)
        self.assertEqual(t.dp.state, DATA_EXCH)

    def test_fail_safe_zero_length(self):
        t = Harness()
        t.startup()
        t.send(DX_5D)
        self.assertEqual(t.send(dx(fc=0x7D, out=b"")), DX_REPLY_1)
        self.assertEqual(t.dp.outputs, h("00 00"))
        # keep-last-value parameter (user prm bit 0)
        t2 = Harness()
        t2.startup(user=b"\x01")
        t2.send(DX_5D)
        t2.send(dx(fc=0x7D, out=b""))
        self.assertEqual(t2.dp.outputs, h("AA 55"))

    def test_wrong_output_length(self):
        t = Harness()
        t.startup()
        self.assertEqual(t.send(dx(fc=0x5D, out=b"\x01")), h("10 01 0A 01 0C 16"))   # UE

    def test_rd_inp_rd_outp(self):
        t = Harness()
        self.assertEqual(t.send(sap_req(0x38, sa=2, fc=0x4D)), h("10 02 0A 03 0F 16"))
        t.startup()
        t.send(DX_5D)
        r = t.send(sap_req(0x39, sa=2, fc=0x4D))                  # any master may read
        self.assertEqual(r, encode(0x82, 0x8A, 0x08, h("3E 39 AA 55")))
        r = t.send(sap_req(0x38, sa=2, fc=0x4D))
        self.assertEqual(r, encode(0x82, 0x8A, 0x08, h("3E 38 00 01")))

    def test_global_control_clear(self):
        t = Harness()
        t.startup()
        t.send(DX_5D)
        self.assertIsNone(t.send(h("68 07 07 68 FF 81 46 3A 3E 02 00 40 16")))
        self.assertEqual(t.dp.outputs, h("00 00"))

    def test_sync_freeze(self):
        t = Harness()
        t.startup(status=0xB8, group=0x02)                        # sync+freeze enabled
        t.send(dx(fc=0x5D, out=h("01 01")))
        t.send(gc(0x20, 0x02))                                    # Sync, group 2
        self.assertEqual(t.dp.outputs, h("01 01"))
        t.send(dx(fc=0x7D, out=h("02 02")))
        self.assertEqual(t.dp.outputs, h("01 01"))                # held
        t.send(gc(0x20))
        self.assertEqual(t.dp.outputs, h("02 02"))
        t.send(gc(0x08))                                          # Freeze at counter 2
        self.assertEqual(t.diag(), h("00 3C 00 01 0A 01"))
        r1 = t.send(dx(fc=0x5D))
        r2 = t.send(dx(fc=0x7D))
        self.assertEqual(r1, r2)                                  # frozen inputs
        self.assertEqual(Deframer().feed(r1)[0].data, h("00 02"))
        t.send(gc(0x14))                                          # Unsync + Unfreeze
        self.assertEqual(t.diag(), h("00 0C 00 01 0A 01"))
        self.assertEqual(t.dp.outputs, h("00 00"))

    def test_sync_and_unsync_together(self):
        t = Harness()
        t.startup(status=0xA8)
        t.send(gc(0x30))
        self.assertFalse(t.dp.sync_mode)

    def test_group_mismatch_ignored(self):
        t = Harness()
        t.startup(status=0xA8, group=0x01)
        t.send(gc(0x20, 0x04))
        self.assertFalse(t.dp.sync_mode)

    def test_sync_not_enabled_ignored(self):
        t = Harness()
        t.startup(status=0x88)
        t.send(gc(0x28))
        self.assertEqual(t.diag(), h("00 0C 00 01 0A 01"))

    def test_gc_from_other_master_ignored(self):
        t = Harness()
        t.startup()
        t.send(DX_5D)
        t.send(gc(0x02, sa=2))
        self.assertEqual(t.dp.outputs, h("AA 55"))

    def test_set_slave_add(self):
        t = Harness(address=126)
        # facts' frame (ident 0x1234): refused
        self.assertEqual(t.send(h("68 09 09 68 FE 81 6D 37 3E 05 12 34 00 AC 16")),
                         h("10 01 7E 03 82 16"))
        self.assertEqual(t.dp.address, 126)
        # Set_Prm at 126: RS
        self.assertEqual(t.send(set_prm(da=126, fc=0x6D)), h("10 01 7E 03 82 16"))
        # ident 0A01: FCS AC - 0x46 + 0x0B = 0x71
        self.assertEqual(t.send(h("68 09 09 68 FE 81 6D 37 3E 05 0A 01 00 71 16")), SC)
        self.assertEqual(t.dp.address, 5)
        self.assertEqual(t.send(h("10 05 01 49 4F 16")), h("10 01 05 00 06 16"))
        self.assertIsNone(t.send(h("10 7E 01 49 C8 16")))         # old address: silent

    def test_no_add_chg(self):
        t = Harness(address=126)
        t.send(encode(0xFE, 0x81, 0x6D, h("37 3E 07 0A 01 01")))
        self.assertEqual(t.dp.address, 7)
        r = t.send(encode(0x87, 0x81, 0x6D, h("37 3E 08 0A 01 00")))
        self.assertEqual(r, h("10 01 07 03 0B 16"))
        self.assertEqual(t.dp.address, 7)

    def test_set_slave_add_refused_in_data_exch(self):
        t = Harness()
        t.startup()
        t.send(sap_req(0x37, fc=0x5D, du=h("05 0A 01 00")))
        self.assertEqual(t.dp.address, 10)

    def test_unit_diag_and_dh(self):
        t = Harness(lplus_missing_after=2)
        t.startup(user=b"\x02")
        t.send(DIAG_5D)
        self.assertEqual(Deframer().feed(t.send(DX_7D))[0].fc, 0x08)
        self.assertEqual(Deframer().feed(t.send(DX_5D))[0].fc, 0x0A)   # 2nd: DH, new diag
        self.assertEqual(Deframer().feed(t.send(DX_7D))[0].fc, 0x0A)   # until read
        self.assertEqual(t.diag(), h("08 0C 00 01 0A 01 02 01"))
        self.assertEqual(Deframer().feed(t.send(DX_5D))[0].fc, 0x08)   # read: DL again

    def test_unit_diag_disabled_by_parameter(self):
        t = Harness(lplus_missing_after=0)
        t.startup(user=b"\x00")
        self.assertEqual(t.diag(), h("00 0C 00 01 0A 01"))


class Bugs(unittest.TestCase):
    def test_fcb_reexecute(self):
        t = Harness(bugs=["fcb_reexecute"])
        t.startup()
        t.send(DIAG_5D)
        self.assertEqual(t.send(DX_7D), DX_REPLY_0)
        self.assertEqual(t.send(DX_7D), DX_REPLY_1)               # executed again

    def test_fcb_global(self):
        t = Harness(bugs=["fcb_global"])
        t.startup()                                               # master 1's last FCB=1
        r = t.send(sap_req(0x3C, sa=2, fc=0x7D))                  # master 2, FCB=1
        self.assertEqual(r, SC)                                   # master 1's Chk_Cfg reply

    def test_diag_always1_wait_prm(self):
        t = Harness(bugs=["diag_always1_wait_prm"])
        self.assertEqual(t.diag(), h("02 01 00 FF 0A 01"))
        t.startup_ok = t.send(SET_PRM_5D)
        self.assertEqual(t.diag(), h("02 0C 00 01 0A 01"))        # other states honest

    def test_get_cfg_saps_unswapped(self):
        t = Harness(bugs=["get_cfg_saps_unswapped"])
        r = t.send(h("68 05 05 68 8A 81 6D 3B 3E F1 16"))
        self.assertEqual(r, h("68 07 07 68 81 8A 08 3B 3E 11 21 BE 16"))
        self.assertEqual(t.send(DIAG_5D)[4:6], h("3E 3C"))        # others swapped

    def test_lock_ignored(self):
        t = Harness(bugs=["lock_ignored"])
        t.startup()
        t.send(set_prm(sa=2, fc=0x6D))
        self.assertEqual(t.dp.owner, 2)

    def test_group_ignored(self):
        t = Harness(bugs=["group_ignored"])
        t.startup(status=0xA8, group=0x01)
        t.send(gc(0x20, 0x04))
        self.assertTrue(t.dp.sync_mode)


if __name__ == "__main__":
    unittest.main()
