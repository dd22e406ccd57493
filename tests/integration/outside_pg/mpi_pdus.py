"""MPI connection-layer PDUs: the FDL DU after DA SA FC DSAP SSAP (protocol-facts.md §H.3).

| PDU                | octets                            | direction                          |
|--------------------|-----------------------------------|------------------------------------|
| connect request    | E0 + 11 connect parameters        | PG -> PLC, DSAP 00, SSAP = PG SAP  |
| connect confirm    | D0 + 11 connect parameters        | PLC -> PG, its SSAP = the PLC SAP  |
| connection ack     | 05 01                             | PG -> PLC, then PLC -> PG          |
| data               | F1 msgNr S7-PDU..                 | either way                         |
| data ack           | B0 01 msgNr                       | receiver -> sender, own SRD frame  |
| disconnect request | 80                                | PG -> PLC                          |

The 11 connect parameters are the trace's `04 00 80 00 02 00 02 01 00 01 00`; their fields are
not decoded (§H.3 [U]). Message numbers: 8 bits per sender, from 0, after 255 comes 1.
"""

CONNECT_REQUEST, CONNECT_CONFIRM = 0xE0, 0xD0
CONN_ACK, DATA, DATA_ACK, DISCONNECT = 0x05, 0xF1, 0xB0, 0x80
TRACE_CONNECT_PARAMS = bytes.fromhex("04 00 80 00 02 00 02 01 00 01 00")
CONNECT_SAP = 0x00    # the PLC's SAP for connect requests (§H.3 step 1)
DEFAULT_PG_SAP = 0x14  # libnodave's connectionNumber (§H.3)
MAX_S7_PDU = 242       # §B.1: 246 DU octets - 2 SAPs - F1 - msgNr


def connect_request(params: bytes = TRACE_CONNECT_PARAMS) -> bytes:
    return bytes([CONNECT_REQUEST]) + bytes(params)


def connection_ack() -> bytes:
    return bytes([CONN_ACK, 0x01])


def data(nr: int, s7_pdu: bytes) -> bytes:
    if len(s7_pdu) > MAX_S7_PDU:
        raise ValueError("S7 PDU of %d octets does not fit one MPI data message" % len(s7_pdu))
    return bytes([DATA, nr & 0xFF]) + bytes(s7_pdu)


def data_ack(nr: int) -> bytes:
    return bytes([DATA_ACK, 0x01, nr & 0xFF])


def disconnect() -> bytes:
    return bytes([DISCONNECT])


def next_message_number(nr: int) -> int:
    """0, 1, .., 255, 1, 2, .. (libnodave skips 0 on the wrap)."""
    return 1 if nr >= 255 else nr + 1


def decode(du: bytes):
    """An MPI PDU -> (kind, fields) or (None, reason).

    kinds: "connect_request" (params), "connect_confirm" (params), "conn_ack" (),
    "data" (nr, s7_pdu), "data_ack" (nr), "disconnect" ()."""
    du = bytes(du)
    if not du:
        return None, "empty"
    t = du[0]
    if t == CONNECT_REQUEST:
        return ("connect_request", du[1:]) if len(du) == 12 else (None, "connect request length")
    if t == CONNECT_CONFIRM:
        return ("connect_confirm", du[1:]) if len(du) == 12 else (None, "connect confirm length")
    if t == CONN_ACK:
        return ("conn_ack",) if du == b"\x05\x01" else (None, "connection ack")
    if t == DATA:
        return ("data", du[1], du[2:]) if len(du) >= 3 else (None, "data too short")
    if t == DATA_ACK:
        return ("data_ack", du[2]) if len(du) == 3 and du[1] == 0x01 else (None, "data ack")
    if t == DISCONNECT:
        return ("disconnect",) if len(du) == 1 else (None, "disconnect length")
    return None, "unknown PDU type 0x%02X" % t
