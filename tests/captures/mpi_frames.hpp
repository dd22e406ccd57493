#pragma once
// MPI frames and S7 PDUs for the captures tests, written by hand (never produced by the code
// under test): the frames of docs/mpi.md "Whole frames" (the §H.3 trace, PG 0, PLC 2, both SAPs
// 0x14) and the §H.4 Read Var job and answer (DB1.DBB0, 10 bytes). FCS = sum of DA .. last DU
// octet mod 256 (protocol-facts.md §B.1), summed in the comments.

#include "capture_fixture.hpp"

namespace pbvbus::captures::test {

// docs/mpi.md steps 1..7 (1 and 2 are the §H.3 trace verbatim).
inline const Bytes kMpiConnectRequest = {0x68, 0x11, 0x11, 0x68, 0x82, 0x80, 0x6D, 0x00,
                                         0x14, 0xE0, 0x04, 0x00, 0x80, 0x00, 0x02, 0x00,
                                         0x02, 0x01, 0x00, 0x01, 0x00, 0xED, 0x16};
inline const Bytes kMpiConnectConfirm = {0x68, 0x11, 0x11, 0x68, 0x80, 0x82, 0x6C, 0x14,
                                         0x14, 0xD0, 0x04, 0x00, 0x80, 0x00, 0x02, 0x00,
                                         0x02, 0x01, 0x00, 0x01, 0x00, 0xF0, 0x16};
inline const Bytes kMpiAckPg = {0x68, 0x07, 0x07, 0x68, 0x82, 0x80, 0x5D,
                                0x14, 0x14, 0x05, 0x01, 0x8D, 0x16};
inline const Bytes kMpiAckPlc = {0x68, 0x07, 0x07, 0x68, 0x80, 0x82, 0x5C,
                                 0x14, 0x14, 0x05, 0x01, 0x8C, 0x16};
/// Data 0 PG -> PLC carrying the §H.4 Read Var job.
inline const Bytes kMpiDataJob = {0x68, 0x1F, 0x1F, 0x68, 0x82, 0x80, 0x7D, 0x14, 0x14, 0xF1,
                                  0x00, 0x32, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x0E, 0x00,
                                  0x00, 0x04, 0x01, 0x12, 0x0A, 0x10, 0x02, 0x00, 0x0A, 0x00,
                                  0x01, 0x84, 0x00, 0x00, 0x00, 0x9C, 0x16};
inline const Bytes kMpiDataAckPlc = {0x68, 0x08, 0x08, 0x68, 0x80, 0x82, 0x7C,
                                     0x14, 0x14, 0xB0, 0x01, 0x00, 0x57, 0x16};
inline const Bytes kMpiDisconnect = {0x68, 0x06, 0x06, 0x68, 0x82, 0x80,
                                     0x5D, 0x14, 0x14, 0x80, 0x07, 0x16};
/// Data 0 PLC -> PG (SRD_low, FCB toggled: 0x5C) carrying the §H.4 answer with the data octets
/// 01..0A. LE = 3 + 2 SAPs + F1 00 + 28 = 35 (0x23). FCS: 80+82+5C+14+14+F1+00 = 0x277; the
/// answer header and item 32 03 00 00 00 01 00 02 00 0E 00 00 04 01 FF 04 00 50 = 0x19E; the
/// data 1+..+10 = 0x37; 0x277 + 0x19E + 0x37 = 0x44C -> 0x4C.
inline const Bytes kMpiDataAnswer = {
    0x68, 0x23, 0x23, 0x68, 0x80, 0x82, 0x5C, 0x14, 0x14, 0xF1, 0x00, 0x32, 0x03,
    0x00, 0x00, 0x00, 0x01, 0x00, 0x02, 0x00, 0x0E, 0x00, 0x00, 0x04, 0x01, 0xFF,
    0x04, 0x00, 0x50, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A,
    0x4C, 0x16};
/// Data ack 0 PG -> PLC (SRD_high, FCB toggled: 0x5D). FCS: 82+80+5D+14+14+B0+01+00 = 0x238.
inline const Bytes kMpiDataAckPg = {0x68, 0x08, 0x08, 0x68, 0x82, 0x80, 0x5D,
                                    0x14, 0x14, 0xB0, 0x01, 0x00, 0x38, 0x16};
/// Data 1 from PG SAP 0x14 to a CPU connection SAP 50 (0x32), which is also a DP SAP: MPI only
/// on an interface marked MPI. FCS: 82+80+5D+32+14+F1+01+AA = 0x341 -> 0x41.
inline const Bytes kMpiDataHighSap = {0x68, 0x08, 0x08, 0x68, 0x82, 0x80, 0x5D,
                                      0x32, 0x14, 0xF1, 0x01, 0xAA, 0x41, 0x16};

// §H.4 "Example read, DB1.DBB0, 10 bytes": the job and the answer (data 01..0A).
inline const Bytes kS7ReadJob = {0x32, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x0E,
                                 0x00, 0x00, 0x04, 0x01, 0x12, 0x0A, 0x10, 0x02,
                                 0x00, 0x0A, 0x00, 0x01, 0x84, 0x00, 0x00, 0x00};
inline const Bytes kS7ReadAnswer = {0x32, 0x03, 0x00, 0x00, 0x00, 0x01, 0x00, 0x02, 0x00, 0x0E,
                                    0x00, 0x00, 0x04, 0x01, 0xFF, 0x04, 0x00, 0x50, 0x01, 0x02,
                                    0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A};

/// The whole MPI exchange in wire order: set-up, the job, its ack, the answer, its ack,
/// disconnect.
inline const std::vector<Bytes>& mpi_exchange() {
  static const std::vector<Bytes> v = {kMpiConnectRequest, kMpiConnectConfirm, kMpiAckPg,
                                       kMpiAckPlc,         kMpiDataJob,        kMpiDataAckPlc,
                                       kMpiDataAnswer,     kMpiDataAckPg,      kMpiDisconnect};
  return v;
}

/// Seeded mutations of the MPI exchange for robustness tests: the DU after DSAP/SSAP is cut,
/// overwritten or grown (also the PDU type octet and the S7 PDU inside data messages), and the
/// SAP octets and addresses sometimes changed; LE and the FCS are set right again so that every
/// frame reaches the MPI decoders. Not a golden: only "no crash, no Lua error" is checked.
class MpiMutator {
 public:
  explicit MpiMutator(std::uint64_t seed) : m_rng(seed) {}
  Bytes next_frame() {
    const auto& ex = mpi_exchange();
    Bytes b = ex[next() % ex.size()];
    const std::size_t du = 9, end = b.size() - 2;
    switch (next() % 5) {
      case 0:
        b.erase(b.begin() + static_cast<std::ptrdiff_t>(du + next() % (end - du)),
                b.begin() + static_cast<std::ptrdiff_t>(end));
        break;
      case 1:
        for (int k = 0; k < 3; ++k) b[du + next() % (end - du)] = static_cast<std::uint8_t>(next());
        break;
      case 2:
        b.insert(b.begin() + static_cast<std::ptrdiff_t>(end), static_cast<std::uint8_t>(next()));
        break;
      case 3:  // another PDU type octet, the rest kept
        b[du] = kTypes[next() % sizeof kTypes];
        break;
      default:  // other SAPs (with the extension bits kept) or addresses
        b[7] = static_cast<std::uint8_t>(next() % 64);
        b[8] = static_cast<std::uint8_t>(next() % 64);
        if (next() % 2) b[4] = static_cast<std::uint8_t>(0x80 | (next() % 8));
        break;
    }
    b[1] = b[2] = static_cast<std::uint8_t>(b.size() - 6);
    unsigned sum = 0;
    for (std::size_t k = 4; k + 2 < b.size(); ++k) sum += b[k];
    b[b.size() - 2] = static_cast<std::uint8_t>(sum);
    return b;
  }

 private:
  static constexpr std::uint8_t kTypes[] = {0xE0, 0xD0, 0x05, 0xF1, 0xB0, 0x80, 0x32, 0x00};
  std::uint64_t next() {
    m_rng ^= m_rng << 13;
    m_rng ^= m_rng >> 7;
    m_rng ^= m_rng << 17;
    return m_rng;
  }
  std::uint64_t m_rng;
};

}  // namespace pbvbus::captures::test
