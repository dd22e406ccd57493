"""S7 communication PDUs the PG needs: Setup Communication and Read Var (protocol-facts.md §H.4).

Header (big-endian): 32 ROSCTR 00 00 ref(2) parlen(2) datalen(2) [errclass errcode in ack and
ack-data], 10 or 12 octets. ROSCTR 1 job, 2 ack, 3 ack-data.
Setup Communication job: F0 00 MaxAmQ_calling(2) MaxAmQ_called(2) PDU_length(2); the answer
has the same layout with the CPU's PDU size; the smaller of the two is used.
Read Var job: 04 count, items 12 0A 10 TS len(2) db(2) area addr(3) (addr = byte * 8 for byte
access). Answer data per item: return code, TS, length (in bits for TS 0x04), data.
"""

import struct

PROTO = 0x32
JOB, ACK, ACK_DATA = 1, 2, 3
FN_SETUP, FN_READ = 0xF0, 0x04
AREA_DB = 0x84
TS_BYTE = 0x02
RC_OK = 0xFF
RETURN_CODES = {0x01: "hardware fault", 0x03: "accessing the object not allowed",
                0x05: "address out of range", 0x06: "data type not supported",
                0x07: "data type inconsistent", 0x0A: "object does not exist"}
PG_PDU_SIZE = 240  # what the PG asks for: the largest S7 PDU that fits one MPI data message
READ_OVERHEAD = 12 + 2 + 4  # ack-data header, 04 count, one item's RC TS len(2)


class S7Error(Exception):
    pass


def header(rosctr: int, ref: int, param: bytes, data: bytes = b"") -> bytes:
    return struct.pack(">BBHHHH", PROTO, rosctr, 0, ref & 0xFFFF, len(param), len(data))


def setup_request(ref: int, pdu_size: int = PG_PDU_SIZE) -> bytes:
    param = struct.pack(">BBHHH", FN_SETUP, 0, 1, 1, pdu_size)
    return header(JOB, ref, param) + param


def read_db_bytes_request(ref: int, db: int, start: int, length: int) -> bytes:
    item = struct.pack(">BBBBHHB", 0x12, 0x0A, 0x10, TS_BYTE, length, db, AREA_DB)
    item += (start * 8).to_bytes(3, "big")
    param = bytes([FN_READ, 1]) + item
    return header(JOB, ref, param) + param


def parse_answer(pdu: bytes, ref: int, fn: int):
    """Checks an ack-data answer to job `ref` with function `fn`; returns (param, data)."""
    pdu = bytes(pdu)
    if len(pdu) < 12 or pdu[0] != PROTO:
        raise S7Error("not an S7 PDU: %s" % pdu.hex(" "))
    rosctr, pref, plen, dlen = pdu[1], struct.unpack(">H", pdu[4:6])[0], \
        struct.unpack(">H", pdu[6:8])[0], struct.unpack(">H", pdu[8:10])[0]
    if rosctr not in (ACK, ACK_DATA):
        raise S7Error("answer ROSCTR %d, expected ack-data" % rosctr)
    if pref != ref:
        raise S7Error("answer to PDU reference %d, expected %d" % (pref, ref))
    if pdu[10] or pdu[11]:
        raise S7Error("error class 0x%02X code 0x%02X" % (pdu[10], pdu[11]))
    if rosctr != ACK_DATA:
        raise S7Error("ack without data")
    if len(pdu) != 12 + plen + dlen:
        raise S7Error("lengths %d + %d do not match the PDU's %d octets" % (plen, dlen, len(pdu)))
    param, data = pdu[12:12 + plen], pdu[12 + plen:]
    if not param or param[0] != fn:
        raise S7Error("answer function 0x%02X, expected 0x%02X" % (param[0] if param else -1, fn))
    return param, data


def parse_setup_answer(pdu: bytes, ref: int) -> int:
    """The CPU's PDU size from a Setup Communication answer."""
    param, _ = parse_answer(pdu, ref, FN_SETUP)
    if len(param) != 8:
        raise S7Error("setup answer parameters of %d octets" % len(param))
    return struct.unpack(">H", param[6:8])[0]


def parse_read_answer(pdu: bytes, ref: int, length: int) -> bytes:
    """The data of a one-item Read Var answer; S7Error with the return code otherwise."""
    param, data = parse_answer(pdu, ref, FN_READ)
    if len(param) != 2 or param[1] != 1:
        raise S7Error("read answer with %s items" % (param[1] if len(param) > 1 else "no"))
    if len(data) < 4:
        raise S7Error("read answer item of %d octets" % len(data))
    rc, ts, n = data[0], data[1], struct.unpack(">H", data[2:4])[0]
    if rc != RC_OK:
        raise S7Error("return code 0x%02X (%s)" % (rc, RETURN_CODES.get(rc, "unknown")))
    nbytes = n // 8 if ts in (0x03, 0x04, 0x05) else n
    if nbytes != length or len(data) < 4 + nbytes:
        raise S7Error("read answer carries %d octets, asked for %d" % (nbytes, length))
    return bytes(data[4:4 + nbytes])


def max_read_length(pdu_size: int) -> int:
    """Octets one Read Var of one item can return within the negotiated PDU size."""
    return pdu_size - READ_OVERHEAD
