#pragma once
// How the masters (class 1 and class 2) read an FDL confirmation: shared by master.cpp and
// class2_master.cpp so that both judge a slave's answer the same way.

#include "pbvbus/fdl/station.hpp"

namespace pbvbus::dp {

/// A response with data (DL or DH): what Data_Exchange, Slave_Diag, Get_Cfg and the reads expect.
inline bool is_data(const fdl::Confirmation& con) {
  return !con.short_ack &&
         (con.status == fdl::ResponseStatus::DL || con.status == fdl::ResponseStatus::DH);
}
/// SC, or a response without data and a positive status: what Set_Prm/Chk_Cfg expect.
inline bool is_empty_ack(const fdl::Confirmation& con) {
  return con.short_ack ||
         ((con.status == fdl::ResponseStatus::OK || con.status == fdl::ResponseStatus::DL) &&
          con.data.empty());
}
}  // namespace pbvbus::dp
