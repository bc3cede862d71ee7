#include "client/common/pipe_binding.hpp"

#include <utility>

namespace hil::client {

PipeBinding::PipeBinding(link::TransportContext& context, link::Endpoint endpoint,
                         Handlers handlers)
    : context_(context),
      endpoint_(std::move(endpoint)),
      handlers_(std::move(handlers)),
      timer_(context.executor, [this] {
        if (handlers_.timer) handlers_.timer();
      }) {}

PipeBinding::~PipeBinding() {
  *alive_ = false;
  close();
}

void PipeBinding::open() {
  close();
  const std::uint64_t generation = generation_;
  link::connect(context_, endpoint_,
                [this, alive = alive_, generation](std::error_code ec, link::BytePipePtr pipe) {
                  if (!*alive || generation != generation_) {
                    if (pipe) pipe->close();
                    return;
                  }
                  if (ec || !pipe) {
                    if (handlers_.connect_failed)
                      handlers_.connect_failed(ec ? ec : std::make_error_code(std::errc::io_error));
                    return;
                  }
                  pipe_ = pipe;
                  pipe->start({[this, alive, generation](protocol::ByteView bytes) {
                                 if (!*alive || generation != generation_) return;
                                 if (handlers_.bytes) handlers_.bytes(bytes);
                               },
                               [this, alive, generation](std::error_code) {
                                 if (!*alive || generation != generation_) return;
                                 pipe_.reset();
                                 if (handlers_.closed) handlers_.closed();
                               }});
                  if (handlers_.connected) handlers_.connected();
                });
}

void PipeBinding::close() {
  ++generation_;
  if (pipe_) std::exchange(pipe_, nullptr)->close();
}

bool PipeBinding::write(protocol::ByteView bytes) {
  if (!pipe_) return false;
  pipe_->write(bytes);
  return true;
}

}  // namespace hil::client
