// Names of the MPI connection layer's input and output values.
#include "pbvbus/mpi/io.hpp"

namespace pbvbus::mpi {

std::string_view to_string(FdlReply r) {
  switch (r) {
    case FdlReply::Ack: return "SC";
    case FdlReply::NoResources: return "RR";
    case FdlReply::SapNotActivated: return "RS";
    case FdlReply::UserError: return "UE";
  }
  return "?";
}

std::string_view to_string(EventKind k) {
  switch (k) {
    case EventKind::ConnectIndication: return "connect indication";
    case EventKind::Connected: return "connected";
    case EventKind::ConnectRefused: return "connect refused";
    case EventKind::DataIndication: return "data indication";
    case EventKind::DataConfirm: return "data confirm";
    case EventKind::Disconnected: return "disconnected";
    case EventKind::Broken: return "broken";
  }
  return "?";
}

std::string_view to_string(Reason r) {
  switch (r) {
    case Reason::None: return "none";
    case Reason::Local: return "local";
    case Reason::ByPeer: return "by peer";
    case Reason::PeerReconnected: return "peer reconnected";
    case Reason::ConnectTimeout: return "connect timeout";
    case Reason::AckTimeout: return "ack timeout";
    case Reason::PeerGone: return "peer gone";
    case Reason::PeerRefused: return "peer refused";
    case Reason::SequenceError: return "sequence error";
  }
  return "?";
}

}  // namespace pbvbus::mpi
