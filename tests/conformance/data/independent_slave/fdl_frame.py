"""FDL telegram framing: encoding, FCS, and a resynchronising byte-stream deframer.

Written from protocol-facts.md §B.1 only:

  SD1  10 DA SA FC FCS 16                          (6 octets, no DU)
  SD2  68 LE LEr 68 DA SA FC DU... FCS 16          (LE + 6 octets; LE = DA..last DU octet)
  SD3  A2 DA SA FC <8 DU octets> FCS 16            (14 octets)
  SD4  DC DA SA                                    (token: no FC, FCS, ED)
  SC   E5                                          (short acknowledge)

FCS = sum mod 256 of DA..last DU octet. "DU" here means everything after FC, i.e. the address
extension octets (DSAP/SSAP) are part of it, as §B.1 counts them for LE and for the SD3 choice.
"""

from dataclasses import dataclass, field

SD1 = 0x10
SD2 = 0x68
SD3 = 0xA2
SD4 = 0xDC
SC = 0xE5
ED = 0x16

LE_MIN = 3     # §B.1: S1/S2 accept 3..249 on receive (the spec range is 4..249)
LE_MAX = 249
MAX_BUFFER = 1024  # a stream that never yields a telegram is trimmed to this


def fcs(octets) -> int:
    """Frame check sequence: arithmetic sum modulo 256."""
    return sum(octets) & 0xFF


def encode(da: int, sa: int, fc: int, du: bytes = b"") -> bytes:
    """Build a telegram with FC, choosing SD1 / SD3 / SD2 as §B.1 says.

    du includes any DSAP/SSAP extension octets."""
    du = bytes(du)
    body = bytes([da & 0xFF, sa & 0xFF, fc & 0xFF]) + du
    if not du:
        return bytes([SD1]) + body + bytes([fcs(body), ED])
    if len(du) == 8:
        return bytes([SD3]) + body + bytes([fcs(body), ED])
    le = len(body)
    if le > LE_MAX:
        raise ValueError("DU too long for SD2: LE %d" % le)
    return bytes([SD2, le, le, SD2]) + body + bytes([fcs(body), ED])


def encode_token(da: int, sa: int) -> bytes:
    return bytes([SD4, da & 0x7F, sa & 0x7F])


@dataclass
class Telegram:
    """One complete, checked telegram."""
    kind: str                 # 'SD1', 'SD2', 'SD3', 'SD4', 'SC'
    raw: bytes
    da: int = -1              # raw octets (incl. EXT bit); -1 for SC
    sa: int = -1
    fc: int = -1              # -1 for SD4 and SC
    data: bytes = field(default=b"")  # octets after FC (extensions + DU)

    def __repr__(self):
        return "Telegram(%s %s)" % (self.kind, self.raw.hex(" "))


# results of _check_at
OK, BAD, INCOMPLETE = "ok", "bad", "incomplete"


def _check_at(buf, i):
    """Try to read one telegram starting at buf[i]. Returns (status, length, telegram)."""
    n = len(buf) - i
    if n <= 0:
        return INCOMPLETE, 0, None
    b = buf[i]
    if b == SC:
        return OK, 1, Telegram("SC", bytes([SC]))
    if b == SD4:
        if n < 3:
            return INCOMPLETE, 0, None
        da, sa = buf[i + 1], buf[i + 2]
        if da & 0x80 or sa & 0x80:
            return BAD, 0, None
        return OK, 3, Telegram("SD4", bytes(buf[i:i + 3]), da, sa)
    if b == SD1:
        if n < 6:
            return INCOMPLETE, 0, None
        if buf[i + 5] != ED or fcs(buf[i + 1:i + 4]) != buf[i + 4]:
            return BAD, 0, None
        raw = bytes(buf[i:i + 6])
        return OK, 6, Telegram("SD1", raw, raw[1], raw[2], raw[3], b"")
    if b == SD3:
        if n < 14:
            return INCOMPLETE, 0, None
        if buf[i + 13] != ED or fcs(buf[i + 1:i + 12]) != buf[i + 12]:
            return BAD, 0, None
        raw = bytes(buf[i:i + 14])
        return OK, 14, Telegram("SD3", raw, raw[1], raw[2], raw[3], raw[4:12])
    if b == SD2:
        # header checks as soon as the octets are there, so junk is dropped early
        if n >= 2 and not (LE_MIN <= buf[i + 1] <= LE_MAX):
            return BAD, 0, None
        if n >= 3 and buf[i + 2] != buf[i + 1]:
            return BAD, 0, None
        if n >= 4 and buf[i + 3] != SD2:
            return BAD, 0, None
        if n < 4:
            return INCOMPLETE, 0, None
        le = buf[i + 1]
        total = le + 6
        if n < total:
            return INCOMPLETE, 0, None
        body = buf[i + 4:i + 4 + le]
        if buf[i + total - 1] != ED or fcs(body) != buf[i + 4 + le]:
            return BAD, 0, None
        raw = bytes(buf[i:i + total])
        return OK, total, Telegram("SD2", raw, raw[4], raw[5], raw[6], raw[7:4 + le])
    return BAD, 0, None


_CHECKED = (SD1, SD2, SD3)


class Deframer:
    """Splits a byte stream into telegrams; never raises on bad input.

    Resynchronisation rules (a pty gives no idle-time boundaries):
      * an octet that cannot start a telegram, or a candidate that fails its header,
        FCS or ED check, costs one octet: the scan restarts at the next octet;
      * while a candidate is incomplete, if a later FCS-checked telegram ends exactly at
        the end of the received bytes, the candidate was junk and is dropped;
      * a token candidate (no FCS) loses to an FCS-checked telegram starting 1 or 2 octets
        later;
      * flush_stale() (the caller's inter-byte gap timer) drops an incomplete tail, while
        still extracting any complete telegram inside it.
    """

    def __init__(self):
        self.buf = bytearray()
        self.junk = 0       # octets discarded
        self.frames = 0     # telegrams delivered

    def pending(self) -> bool:
        return len(self.buf) > 0

    def feed(self, data) -> list:
        self.buf += data
        if len(self.buf) > MAX_BUFFER:
            cut = len(self.buf) - MAX_BUFFER
            del self.buf[:cut]
            self.junk += cut
        return self._parse(stale=False)

    def flush_stale(self) -> list:
        return self._parse(stale=True)

    def _later_complete(self):
        buf = self.buf
        for j in range(1, len(buf)):
            if buf[j] in _CHECKED:
                st, ln, _ = _check_at(buf, j)
                if st == OK and j + ln == len(buf):
                    return j
        return None

    def _parse(self, stale: bool) -> list:
        out = []
        buf = self.buf
        while buf:
            st, ln, tel = _check_at(buf, 0)
            if st == OK:
                if tel.kind == "SD4":
                    skip = None
                    for j in (1, 2):
                        if j < len(buf) and buf[j] in _CHECKED and _check_at(buf, j)[0] == OK:
                            skip = j
                            break
                    if skip is not None:
                        del buf[:skip]
                        self.junk += skip
                        continue
                del buf[:ln]
                self.frames += 1
                out.append(tel)
            elif st == BAD:
                del buf[:1]
                self.junk += 1
            else:
                j = self._later_complete()
                if j is not None:
                    del buf[:j]
                    self.junk += j
                elif stale:
                    del buf[:1]
                    self.junk += 1
                else:
                    break
        return out
