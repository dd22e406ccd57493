#pragma once
// TPKT framing, RFC 1006 (tools-and-formats.md §3.4): `03 00 LL LL` then the COTP TPDU, LL
// the total length including these 4 octets. TCP delivers a byte stream, so a door feeds
// whatever recv() returned into a TpktReassembler and takes whole TPKTs out of it.
//
// Decisions (docs/s7.md "TPKT"):
// - A length below 7 (header + the 3-octet DT header, snap7's CheckPDU bound) or above the
//   reassembler's maximum is an error; so is a version other than 3. The reserved octet is not
//   checked (RFC 1006 gives it no meaning a receiver could act on).
// - Errors are sticky: a stream whose framing is lost cannot be resynchronised (there is no
//   delimiter), so after an error nothing more is consumed and the door closes the connection.
// - The buffer never holds more than one TPKT of at most max_length octets: garbage cannot make
//   the reassembler allocate more than that.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/s7/error.hpp"

namespace pbvbus::s7 {

inline constexpr std::uint8_t kTpktVersion = 3;
inline constexpr std::size_t kTpktHeaderLength = 4;
inline constexpr std::size_t kTpktMinLength = 7;
inline constexpr std::size_t kTpktMaxLength = 65535;
/// Bound before the TPDU size is negotiated: the largest class 0 TPDU (2048, ISO 8073) + header.
inline constexpr std::size_t kTpktDefaultMaxLength = 2048 + kTpktHeaderLength;

/// Appends `03 00 LL LL payload`. TpktLengthTooSmall for a payload under 3 octets (no COTP TPDU
/// is that short), TpktPayloadTooLarge above 65531; `out` is unchanged on an error.
Error append_tpkt(std::vector<std::uint8_t>& out, std::span<const std::uint8_t> payload);

class TpktReassembler {
 public:
  explicit TpktReassembler(std::size_t max_length = kTpktDefaultMaxLength);

  /// The largest TPKT accepted from now on (e.g. 4 + the negotiated TPDU size), clamped to
  /// [7, 65535]. A TPKT already being received is checked against the new bound only if its
  /// length field has not been read yet.
  void set_max_length(std::size_t max_length);
  std::size_t max_length() const { return max_; }

  /// Consumes octets of `in` up to the end of the current TPKT and returns how many it took.
  /// Takes nothing while a whole TPKT is ready (call pop() first) or after an error.
  std::size_t feed(std::span<const std::uint8_t> in);

  bool ready() const { return ready_; }
  /// The whole TPKT (header included) / its payload (the COTP TPDU); valid until pop().
  std::span<const std::uint8_t> tpkt() const;
  std::span<const std::uint8_t> payload() const;
  void pop();

  Error error() const { return error_; }
  /// Stream offset (octets fed since construction) of the octet that caused the error.
  std::size_t error_offset() const { return error_offset_; }
  /// Octets of an unfinished TPKT held now (0 between TPKTs).
  std::size_t pending() const { return ready_ ? 0 : buf_.size(); }

 private:
  void fail(Error e, std::size_t at);

  std::size_t max_;
  std::vector<std::uint8_t> buf_;
  std::size_t expected_ = 0;  ///< length field, once the header is in
  bool ready_ = false;
  Error error_ = Error::None;
  std::size_t error_offset_ = 0;
  std::size_t stream_offset_ = 0;
};

}  // namespace pbvbus::s7
