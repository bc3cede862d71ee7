#include "protocol/wr8/svgui_receiver.hpp"

#include <algorithm>

namespace hil::protocol::wr8::svgui {

bool ProgramReceiver::on_arrival(ByteView arrived, ReadEvent& event) {
  unread_.insert(unread_.end(), arrived.begin(), arrived.end());
  if (unread_.empty()) return false;
  event = ReadEvent{};
  event.length_byte = unread_.front();
  const auto after_length = unread_.begin() + 1;
  if (version_ == Version::v2019) {
    event.packet.assign(after_length, unread_.end());
    event.length_mismatch = event.packet.size() != event.length_byte;
    unread_.clear();
    return true;
  }
  const auto declared = static_cast<std::int8_t>(event.length_byte);
  if (declared <= 0) {
    event.unreadable_length = true;
    unread_.erase(unread_.begin());
    return true;
  }
  const auto available = static_cast<std::size_t>(unread_.end() - after_length);
  const std::size_t take = std::min<std::size_t>(static_cast<std::size_t>(declared), available);
  event.packet.assign(after_length, after_length + static_cast<std::ptrdiff_t>(take));
  event.length_mismatch = take != static_cast<std::size_t>(declared);
  unread_.erase(unread_.begin(), after_length + static_cast<std::ptrdiff_t>(take));
  return true;
}

}  // namespace hil::protocol::wr8::svgui
