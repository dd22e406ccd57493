"""FDL responder layer of a passive station (DP slave): address filter, FC decoding, SAP
extensions, FCB/FCV memory per requesting station, and reply building.

From protocol-facts.md §B.2 (addresses, extensions, mirrored replies), §B.3 (FC octet),
§C.6 (FCB/FCV responder rules). The DP layer (dp_state.DpSlave) sees only Indications and
answers with Results; it never touches octets of the FDL header.
"""

from dataclasses import dataclass
from typing import Optional

import fdl_frame
from fdl_frame import Telegram, encode

EXT = 0x80          # address octet / extension octet: an extension follows
EXT_SEGMENT = 0x40  # extension octet is a region/segment address, not a SAP
BROADCAST = 127

# request functions (FC bits 3..0 with bit 6 set)
F_TE = 0x0
F_SDA_LOW, F_SDN_LOW, F_SDA_HIGH, F_SDN_HIGH = 0x3, 0x4, 0x5, 0x6
F_MSRD = 0x7
F_FDL_STATUS = 0x9
F_SRD_LOW, F_SRD_HIGH = 0xC, 0xD
F_IDENT, F_LSAP_STATUS = 0xE, 0xF

# response FC octets of a slave (station type bits 5..4 = 00)
R_OK, R_UE, R_RR, R_RS, R_DL, R_NR, R_DH = 0x00, 0x01, 0x02, 0x03, 0x08, 0x09, 0x0A

SC_OCTET = bytes([fdl_frame.SC])


@dataclass
class Request:
    """A decoded request telegram."""
    da: int                  # 0..127
    sa: int                  # 0..127
    da_ext: bool
    sa_ext: bool
    fc: int
    dsap: Optional[int]      # None = default (NIL) SAP
    ssap: Optional[int]
    du: bytes                # DU after the extension octets

    @property
    def function(self):
        return self.fc & 0x0F

    @property
    def fcb(self):
        return bool(self.fc & 0x20)

    @property
    def fcv(self):
        return bool(self.fc & 0x10)

    @property
    def high(self):
        return self.function in (F_SDA_HIGH, F_SDN_HIGH, F_SRD_HIGH)


def _read_ext(data: bytes, pos: int):
    """Read one chain of extension octets (§B.2 parsing rule). Returns (sap, new_pos) or
    (None, -1) if the chain runs past the end or holds no SAP octet."""
    sap = None
    while True:
        if pos >= len(data):
            return None, -1
        o = data[pos]
        pos += 1
        if not (o & EXT_SEGMENT) and sap is None:
            sap = o & 0x3F
        if not (o & EXT):
            break
    if sap is None:
        return None, -1
    return sap, pos


def decode_request(tel: Telegram) -> Optional[Request]:
    """Decode an SD1/SD2/SD3 request; None for anything else or a malformed one."""
    if tel.kind not in ("SD1", "SD2", "SD3"):
        return None
    if not (tel.fc & 0x40):          # bit 6 = 0: a response, not a request
        return None
    da_ext = bool(tel.da & EXT)
    sa_ext = bool(tel.sa & EXT)
    pos = 0
    dsap = ssap = None
    if da_ext:
        dsap, pos = _read_ext(tel.data, pos)
        if dsap is None:
            return None
    if sa_ext:
        ssap, pos = _read_ext(tel.data, pos)
        if ssap is None:
            return None
    return Request(tel.da & 0x7F, tel.sa & 0x7F, da_ext, sa_ext, tel.fc, dsap, ssap,
                   bytes(tel.data[pos:]))


@dataclass
class Indication:
    """What the DP layer sees of a request."""
    sa: int
    dsap: Optional[int]
    ssap: Optional[int]
    du: bytes
    confirmed: bool          # SRD (a reply goes back) vs SDN
    broadcast: bool


@dataclass
class Result:
    """The DP layer's answer: 'data' (DL/DH with du), 'sc', 'rs', 'ue', or 'none'."""
    kind: str
    data: bytes = b""
    high: bool = False       # 'data': answer DH instead of DL

    @staticmethod
    def sc():
        return Result("sc")

    @staticmethod
    def rs():
        return Result("rs")

    @staticmethod
    def none():
        return Result("none")


class FcbMemory:
    """§C.6 responder side: per source address, the FCB of its last action frame and the reply
    sent to it. With bug 'fcb_global' one entry is shared by all stations."""

    def __init__(self, per_station=True):
        self.per_station = per_station
        self.table = {}

    def _key(self, sa):
        return sa if self.per_station else 0

    def lookup(self, sa):
        return self.table.get(self._key(sa))

    def store(self, sa, fcb, reply):
        self.table[self._key(sa)] = (fcb, reply)


class FdlResponder:
    """Turns received telegrams into replies (bytes) or None. `station` is the DP layer:
    it has .address, heard(sa, now), service(ind, now) -> Result."""

    def __init__(self, station, bugs=frozenset(), log=None):
        self.station = station
        self.bugs = bugs
        self.log = log or (lambda msg: None)
        self.fcb = FcbMemory(per_station="fcb_global" not in bugs)
        self.repeats = 0

    # -- reply building ------------------------------------------------------------------
    def _reply(self, req: Request, my: int, fc: int, du: bytes = b"") -> bytes:
        """A data reply mirroring the request's addressing (§B.2): DA = request SA,
        SA = own address, DSAP = request SSAP, SSAP = request DSAP."""
        da = req.sa | (EXT if req.sa_ext else 0)
        sa = my | (EXT if req.da_ext else 0)
        ext = b""
        if "get_cfg_saps_unswapped" in self.bugs and req.dsap == 59:
            # BUG: the Get_Cfg reply carries the request's SAPs in the request's order
            if req.da_ext:
                ext += bytes([req.dsap])
            if req.sa_ext:
                ext += bytes([req.ssap])
        else:
            if req.sa_ext:
                ext += bytes([req.ssap])     # reply DAE
            if req.da_ext:
                ext += bytes([req.dsap])     # reply SAE
        return encode(da, sa, fc, ext + du)

    def _status(self, req: Request, my: int, status: int) -> bytes:
        """A reply without data (FDL status, RS, UE): SD1, no address extensions."""
        return encode(req.sa, my, status)

    # -- main entry ----------------------------------------------------------------------
    def handle(self, tel: Telegram, now: float) -> Optional[bytes]:
        req = decode_request(tel)
        if req is None:
            return None                       # SC, token, response, malformed
        my = self.station.address
        if req.da != my and req.da != BROADCAST:
            return None                       # not for us
        broadcast = req.da == BROADCAST
        self.station.heard(req.sa, now)       # watchdog: any valid frame from the owner
        if req.fc & 0x80:
            return None                       # clock value (CV); ignored by a slave
        f = req.function
        if f in (F_SDN_LOW, F_SDN_HIGH):
            ind = Indication(req.sa, req.dsap, req.ssap, req.du, False, broadcast)
            self.station.service(ind, now)
            return None
        if broadcast:
            return None                       # only SDN may be broadcast (§B.2)
        if f == F_FDL_STATUS:
            return self._status(req, my, R_OK)
        if f in (F_SRD_LOW, F_SRD_HIGH, F_SDA_LOW, F_SDA_HIGH):
            return self._confirmed(req, my, now)
        if f in (F_MSRD, F_IDENT, F_LSAP_STATUS):
            return self._status(req, my, R_RS)
        return None                           # TE, reserved functions

    def _confirmed(self, req: Request, my: int, now: float) -> bytes:
        uses_fcb = req.fcv or req.fcb         # FCV=0/FCB=0: a frame without FCB
        if req.fcv:
            last = self.fcb.lookup(req.sa)
            if last is not None and last[0] == req.fcb:
                self.repeats += 1
                if "fcb_reexecute" not in self.bugs:
                    self.log("FCB repeat from %d: stored reply resent" % req.sa)
                    return last[1]
                self.log("FCB repeat from %d: executed again (bug fcb_reexecute)" % req.sa)
        reply = self._execute(req, my, now)
        if uses_fcb:
            self.fcb.store(req.sa, req.fcb, reply)
        return reply

    def _execute(self, req: Request, my: int, now: float) -> bytes:
        if req.function in (F_SDA_LOW, F_SDA_HIGH):
            return self._status(req, my, R_RS)    # no DP service uses SDA
        ind = Indication(req.sa, req.dsap, req.ssap, req.du, True, False)
        res = self.station.service(ind, now)
        if res.kind == "data":
            return self._reply(req, my, R_DH if res.high else R_DL, res.data)
        if res.kind == "sc":
            return SC_OCTET
        if res.kind == "ue":
            return self._status(req, my, R_UE)
        return self._status(req, my, R_RS)
