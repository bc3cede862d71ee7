#include "link/byte_pipe.hpp"

#include <asio/error.hpp>

namespace hil::link {

std::error_code end_of_stream() {
  return asio::error::make_error_code(asio::error::eof);
}

}  // namespace hil::link
