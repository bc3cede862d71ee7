#pragma once
// The WR8 client's communication log: the common one of client/common/,
// one entry per frame sent or received, per parse error and per note.

#include "client/common/comm_log.hpp"

namespace hil::client::wr8 {

using client::CommLog;
using client::LogEntry;
using client::LogKind;
using client::to_string;

}  // namespace hil::client::wr8
