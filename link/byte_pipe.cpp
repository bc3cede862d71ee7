#include "link/byte_pipe.hpp"

#include <asio/error.hpp>

namespace hil::link {

std::error_code end_of_stream() {
  return asio::error::make_error_code(asio::error::eof);
}

std::error_code closed_here() {
  return std::make_error_code(std::errc::operation_canceled);
}

std::error_code portable_error(std::error_code ec) {
  if (ec.category() == asio::error::get_system_category())
    return {ec.value(), std::system_category()};
  return ec;
}

}  // namespace hil::link
