"""FDL telegrams for the outside PG: encoding, checking, splitting a byte stream.

Written from protocol-facts.md §B.1-§B.3 (not from pbvbus's C++ codec):

  SD1  10 DA SA FC FCS 16                  6 octets, no DU
  SD2  68 LE LEr 68 DA SA FC DU.. FCS 16   LE + 6 octets; LE counts DA..last DU octet, 4..249
  SD3  A2 DA SA FC <8 DU octets> FCS 16    14 octets
  SD4  DC DA SA                            token: no FC, no FCS, no ED
  SC   E5                                  short acknowledge

FCS = sum of DA..last DU octet mod 256. The DSAP/SSAP extension octets belong to the DU (they
count for LE and for the SD3 choice): a DU of exactly 8 octets goes out as SD3, none as SD1,
anything else as SD2 (§B.1). Addresses carry the EXT bit 0x80 when a SAP octet follows (§B.2).
"""

from dataclasses import dataclass

SD1, SD2, SD3, SD4, SC, ED = 0x10, 0x68, 0xA2, 0xDC, 0xE5, 0x16
EXT = 0x80
BROADCAST = 127
LE_MAX = 249
MAX_DU = 246  # §B.1: DU including the SAP octets

# FC octet, request frames (§B.3)
FC_REQUEST = 0x40
FCB, FCV = 0x20, 0x10
FN_SDA_LOW, FN_SDN_LOW, FN_SDA_HIGH, FN_SDN_HIGH = 0x3, 0x4, 0x5, 0x6
FN_MSRD, FN_FDL_STATUS, FN_SRD_LOW, FN_SRD_HIGH = 0x7, 0x9, 0xC, 0xD
FN_IDENT, FN_LSAP_STATUS = 0xE, 0xF
EXPECTS_REPLY = {FN_SDA_LOW, FN_SDA_HIGH, FN_MSRD, FN_FDL_STATUS, FN_SRD_LOW, FN_SRD_HIGH,
                 FN_IDENT, FN_LSAP_STATUS}
USES_FCB = {FN_SDA_LOW, FN_SDA_HIGH, FN_SRD_LOW, FN_SRD_HIGH, FN_MSRD}

# FC octet, response frames: station type (bits 5..4) and status (bits 3..0)
TYPE_SLAVE, TYPE_NOT_READY, TYPE_READY, TYPE_IN_RING = 0x00, 0x10, 0x20, 0x30
ST_OK, ST_UE, ST_RR, ST_RS, ST_DL, ST_NR, ST_DH = 0x0, 0x1, 0x2, 0x3, 0x8, 0x9, 0xA


def fcs(octets) -> int:
    """Frame check sequence: arithmetic sum mod 256 (§B.1)."""
    return sum(octets) & 0xFF


def encode(da: int, sa: int, fc: int, dsap=None, ssap=None, data=b"") -> bytes:
    """A telegram with FC. With SAPs both addresses get the EXT bit and DSAP, SSAP lead the DU."""
    du = bytes(data)
    if dsap is not None or ssap is not None:
        if dsap is None or ssap is None:
            raise ValueError("both SAPs or none")
        da |= EXT
        sa |= EXT
        du = bytes([dsap & 0x3F, ssap & 0x3F]) + du
    if len(du) > MAX_DU:
        raise ValueError("DU of %d octets is longer than %d" % (len(du), MAX_DU))
    body = bytes([da & 0xFF, sa & 0xFF, fc & 0xFF]) + du
    if not du:
        return bytes([SD1]) + body + bytes([fcs(body), ED])
    if len(du) == 8:
        return bytes([SD3]) + body + bytes([fcs(body), ED])
    return bytes([SD2, len(body), len(body), SD2]) + body + bytes([fcs(body), ED])


def encode_token(da: int, sa: int) -> bytes:
    """SD4: DC DA SA."""
    return bytes([SD4, da & 0x7F, sa & 0x7F])


def request_fc(fn: int, fcv: bool = False, fcb: bool = False) -> int:
    return FC_REQUEST | (FCB if fcb else 0) | (FCV if fcv else 0) | (fn & 0x0F)


@dataclass
class Telegram:
    """One complete, checked telegram. Addresses without the EXT bit; SAPs None when absent."""
    kind: str            # "SD1", "SD2", "SD3", "SD4", "SC"
    raw: bytes
    da: int = -1
    sa: int = -1
    fc: int = -1
    dsap: object = None
    ssap: object = None
    data: bytes = b""

    @property
    def is_token(self) -> bool:
        return self.kind == "SD4"

    @property
    def is_request(self) -> bool:
        return self.kind in ("SD1", "SD2", "SD3") and bool(self.fc & FC_REQUEST)

    @property
    def is_response(self) -> bool:
        return self.kind == "SC" or (self.kind in ("SD1", "SD2", "SD3") and
                                     not self.fc & FC_REQUEST)

    @property
    def fn(self) -> int:
        return self.fc & 0x0F

    @property
    def fcv(self) -> bool:
        return bool(self.fc & FCV)

    @property
    def fcb(self) -> bool:
        return bool(self.fc & FCB)

    @property
    def status(self) -> int:
        """A response's status (bits 3..0); SC counts as OK."""
        return ST_OK if self.kind == "SC" else self.fc & 0x0F

    @property
    def station_type(self) -> int:
        return 0 if self.kind == "SC" else self.fc & 0x30


def telegram_length(buf) -> int:
    """Length of the telegram that starts buf; 0 = need more octets; -1 = no start here."""
    if not buf:
        return 0
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
        if buf[2] != le or buf[3] != SD2 or le < 3 or le > LE_MAX:
            return -1
        return le + 6
    return -1


def decode(raw: bytes):
    """A whole telegram -> Telegram, or None when it is not valid (delimiters, LE, FCS, SAPs)."""
    raw = bytes(raw)
    n = telegram_length(raw)
    if n <= 0 or n != len(raw):
        return None
    sd = raw[0]
    if sd == SC:
        return Telegram("SC", raw)
    if sd == SD4:
        return Telegram("SD4", raw, da=raw[1] & 0x7F, sa=raw[2] & 0x7F)
    if sd == SD2:
        body, kind = raw[4:-2], "SD2"
    else:
        body, kind = raw[1:-2], ("SD1" if sd == SD1 else "SD3")
    if raw[-1] != ED or fcs(body) != raw[-2]:
        return None
    da, sa, fc = body[0], body[1], body[2]
    du = body[3:]
    dsap = ssap = None
    # §B.2: read extension octets while bit 7 is set; the SAP is the one with bit 6 clear.
    # A region/segment octet (bit 6 set) is not for us: such telegrams are refused.
    if da & EXT:
        if not du or du[0] & 0xC0:
            return None
        dsap, du = du[0] & 0x3F, du[1:]
    if sa & EXT:
        if not du or du[0] & 0xC0:
            return None
        ssap, du = du[0] & 0x3F, du[1:]
    return Telegram(kind, raw, da & 0x7F, sa & 0x7F, fc, dsap, ssap, bytes(du))


class Deframer:
    """Splits a byte stream into telegrams; octets that cannot start one are dropped, counted."""

    def __init__(self):
        self.buf = bytearray()
        self.garbage = 0

    def feed(self, octets):
        self.buf.extend(octets)

    def clear(self):
        self.buf.clear()

    def next(self):
        """The next complete telegram's octets (not yet checked), or None."""
        while self.buf:
            n = telegram_length(self.buf)
            if n < 0:
                del self.buf[0]
                self.garbage += 1
                continue
            if n and len(self.buf) >= n:
                out = bytes(self.buf[:n])
                del self.buf[:n]
                return out
            return None
        return None
