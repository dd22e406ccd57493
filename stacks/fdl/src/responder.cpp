#include "pbvbus/fdl/responder.hpp"

namespace pbvbus::fdl {

namespace {
const Frame kEmptyFrame{};
}  // namespace

void Responder::reset() {
  m_fcb.fill(kNone);
  m_slot.fill(kNone);
  for (auto& f : m_replies) f.len = 0;
  m_initialised = true;
}

Responder::Check Responder::check(const Telegram& req) {
  if (!m_initialised) reset();
  const RequestFn fn = fc_request_fn(req.fc);
  if (!fn_uses_fcb(fn) || !fc_fcv(req.fc)) return Check::Execute;
  const std::uint8_t fcb = fc_fcb(req.fc) ? 1 : 0;
  if (m_fcb[key(req.sa)] == fcb) return Check::Repeat;
  return Check::Execute;
}

const Frame& Responder::stored_reply(std::uint8_t sa) const {
  if (!m_initialised || sa >= 128 || m_slot[key(sa)] == kNone) return kEmptyFrame;
  return m_replies[m_slot[key(sa)]];
}

void Responder::clear(Reply& reply) {
  reply.kind = Reply::Kind::Status;
  reply.status = ResponseStatus::RS;
  reply.data.clear();
  reply.new_address.reset();
  reply.new_min_tsdr.reset();
}

Frame Responder::fdl_status_reply(const Telegram& req, std::uint8_t own, StationType type) {
  Frame f;
  FrameSpec spec;
  spec.da = req.sa;
  spec.sa = own;
  spec.fc = make_response_fc(type, ResponseStatus::OK);
  encode_as(FrameType::SD1, spec, f);
  return f;
}

const Frame& Responder::finish(const Telegram& req, std::uint8_t own, StationType type, const Reply& reply) {
  if (!m_initialised) reset();
  const RequestFn fn = fc_request_fn(req.fc);
  const bool store = fn_uses_fcb(fn) && (fc_fcv(req.fc) || fc_fcb(req.fc));
  if (store) {
    // First frame (FCV=0, FCB=1) or a new action frame: remember its FCB, and encode the
    // answer straight into the SA's slot (no copy per frame).
    const std::uint8_t k = key(req.sa);
    m_fcb[k] = fc_fcb(req.fc) ? 1 : 0;
    if (m_slot[k] == kNone) {
      m_slot[k] = static_cast<std::uint8_t>(m_replies.size());
      m_replies.emplace_back();
    }
  }
  Frame& out = store ? m_replies[m_slot[key(req.sa)]] : m_scratch;
  out.len = 0;
  FrameSpec spec;
  spec.da = req.sa;
  spec.sa = own;
  switch (reply.kind) {
    case Reply::Kind::None: break;
    case Reply::Kind::ShortAck:
      out.buf[0] = kSC;
      out.len = 1;
      break;
    case Reply::Kind::Data:
      spec.fc = make_response_fc(type, reply.status);
      // Mirror the request's extensions: its source SAP/segment becomes our destination's.
      spec.dsap = req.ssap;
      spec.ssap = req.dsap;
      if (reply.saps_not_mirrored) [[unlikely]] {  // mutant slave only
        spec.dsap = req.dsap;
        spec.ssap = req.ssap;
      }
      if (req.ssap) spec.da_segment = req.sa_segment;
      if (req.dsap) spec.sa_segment = req.da_segment;
      spec.data = reply.data;
      if (encode(spec, out) == EncodeError::None) break;
      [[fallthrough]];  // too long: tell the requester it was a user error
    case Reply::Kind::Status: {
      FrameSpec s;
      s.da = req.sa;
      s.sa = own;
      const ResponseStatus st = reply.kind == Reply::Kind::Status ? reply.status : ResponseStatus::UE;
      s.fc = make_response_fc(type, st);
      if (encode_as(FrameType::SD1, s, out) != EncodeError::None) out.len = 0;
      break;
    }
  }
  return out;
}

}  // namespace pbvbus::fdl
