#include "mocks/avr/chip.hpp"

#include "mocks/avr/sketch_build.hpp"

extern "C" {
#include <avr_adc.h>
#include <avr_extint.h>
#include <avr_ioport.h>
#include <avr_uart.h>
#include <sim_avr.h>
#include <sim_core.h>
#include <sim_elf.h>
#include <sim_interrupts.h>
#include <sim_io.h>
#include <sim_irq.h>
}

#include <algorithm>
#include <array>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>

namespace hil::mocks::avr {

namespace {

// ATmega328P data-space addresses (datasheet, "Register Summary").
constexpr std::uint16_t kUcsr0a = 0xC0;
constexpr std::uint16_t kUcsr0b = 0xC1;
constexpr std::uint16_t kUbrr0l = 0xC4;
constexpr std::uint16_t kUbrr0h = 0xC5;
constexpr std::uint16_t kUcsr0c = 0xC2;
constexpr std::uint8_t kU2x0 = 1 << 1;
constexpr std::uint8_t kRxen0 = 1 << 4;
constexpr std::uint8_t kTxen0 = 1 << 3;

// PINx, DDRx, PORTx of ports B, C and D.
struct PortRegs {
  std::uint16_t pin, ddr, port;
};
PortRegs port_regs(char port) {
  switch (port) {
    case 'B':
      return {0x23, 0x24, 0x25};
    case 'C':
      return {0x26, 0x27, 0x28};
    default:
      return {0x29, 0x2A, 0x2B};
  }
}

// A timer's control register A and its two compare registers (low byte),
// and the COMnx1 bit that connects each output.
struct TimerRegs {
  std::uint16_t tccra, ocra, ocrb;
};
constexpr std::array<TimerRegs, 3> kTimers{
    {{0x44, 0x47, 0x48}, {0x80, 0x88, 0x8A}, {0xB0, 0xB3, 0xB4}}};
constexpr std::uint8_t kComA1 = 1 << 7;
constexpr std::uint8_t kComB1 = 1 << 5;

// ELF32 header fields (System V ABI): the AVR machine number, and the
// avr-gcc architecture number in the low bits of e_flags.
constexpr std::uint16_t kEmAvr = 83;
constexpr std::uint32_t kAvr5 = 5;

void quiet_logger(avr_t* avr, int level, const char* format, va_list ap);

// simavr's logger is one function for the process; it hands each message
// to the chip it came from.
void install_logger() {
  static std::once_flag once;
  std::call_once(once, [] { avr_global_logger_set(&quiet_logger); });
}

std::string elf_family(std::uint32_t mach) {
  switch (mach) {
    case 2:
      return "avr2 (ATtiny)";
    case 25:
      return "avr25 (ATtiny)";
    case 4:
      return "avr4 (ATmega8-class)";
    case 51:
      return "avr51 (ATmega128-class)";
    case 6:
      return "avr6 (ATmega2560-class)";
    case 100:
      return "avrtiny";
    default:
      return "avr" + std::to_string(mach);
  }
}

}  // namespace

struct Chip::Impl {
  avr_t* avr = nullptr;
  Chip* chip = nullptr;
  std::uint64_t stop = 0;  // the running run_to()'s next stopping cycle
  std::multimap<std::uint64_t, std::function<void()>> events;
  std::deque<std::uint8_t> rx_waiting;  // beyond the chip's FIFO
  bool rx_full = false;                 // the chip's FIFO said XOFF
  std::function<void(std::uint8_t, std::uint64_t)> on_tx;
  struct Watch {
    std::function<void(bool)> fn;
    int last = -1;
    BoardPin pin;
  };
  std::vector<std::unique_ptr<Watch>> watches;
  std::function<void(int)> on_conversion;
  std::vector<std::string> messages;
  bool driving = false;
  avr_uart_t* uart = nullptr;            // UART0's own state
  avr_cycle_timer_t rx_ready = nullptr;  // simavr's timer that hands a received byte over

  // The line in front of the chip delivers each byte when its stop bit is
  // in, the moment the USART sets RXC; simavr would wait one more byte
  // time before handing it over. The first byte after the FIFO was empty
  // is handed over on the next cycle instead: the timer simavr started for
  // it is found (once, by its parameter: the UART) and brought forward.
  void receive_now(std::uint8_t byte) {
    avr_cycle_timer_pool_t* pool = &avr->cycle_timers;
    std::vector<avr_cycle_timer_t> before;
    for (auto* t = pool->timer; t != nullptr; t = t->next)
      if (t->param == uart) before.push_back(t->timer);
    const bool pumping =
        rx_ready != nullptr && std::find(before.begin(), before.end(), rx_ready) != before.end();
    avr_raise_irq(uart_irq(UART_IRQ_INPUT), byte);
    if (pumping) return;  // bytes are waiting: they follow at the line's pace
    if (rx_ready == nullptr) {
      for (auto* t = pool->timer; t != nullptr; t = t->next)
        if (t->param == uart && std::find(before.begin(), before.end(), t->timer) == before.end())
          rx_ready = t->timer;
      if (rx_ready == nullptr) return;
    }
    if (avr_cycle_timer_status(avr, rx_ready, uart) == 0) return;
    avr_cycle_timer_cancel(avr, rx_ready, uart);
    avr_cycle_timer_register(avr, 1, rx_ready, uart);
  }

  avr_irq_t* uart_irq(int which) const {
    return avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), which);
  }
  avr_irq_t* pin_irq(const BoardPin& pin) const {
    return avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(static_cast<std::uint32_t>(pin.port)),
                         pin.bit);
  }

  void datasheet_reset_values() {
    // simavr turns the transmitter on at reset so that a test program can
    // print without setting the UART up; the chip starts with it off, and
    // a firmware that never calls Serial.begin() must stay silent.
    avr->data[kUcsr0b] = 0;
    // simavr polls an INT0/INT1 pin on every cycle while it is low in the
    // low-level mode (the reset default), enabled or not: an encoder pin
    // held low would slow the chip threefold. Off, a low level interrupts
    // once, on the falling edge (docs/firmware.md, "What is emulated").
    for (std::uint8_t n = 0; n < 2; ++n)
      avr_extint_set_strict_lvl_trig(avr, n, 0);
  }

  // simavr counts a parity bit in every UART frame, parity or not, so its
  // bytes take 11 bit times where the 8N1 line takes 10: each byte would
  // come 10 % late. The byte time is set again from the frame format the
  // firmware chose (UCSR0C, UCSR0B's UCSZ02) whenever it changes.
  // Cycles a bit takes at the baud rate UBRR0 and U2X0 set.
  std::uint32_t bit_cycles() const {
    const std::uint8_t* d = avr->data;
    const std::uint32_t ubrr = (static_cast<std::uint32_t>(d[kUbrr0h] & 0x0F) << 8) | d[kUbrr0l];
    return (ubrr + 1) * ((d[kUcsr0a] & kU2x0) != 0 ? 8U : 16U);
  }

  void fix_byte_time() {
    const std::uint8_t* d = avr->data;
    if ((d[kUcsr0b] & (kRxen0 | kTxen0)) == 0) return;
    const std::uint32_t per_bit = bit_cycles();
    const std::uint8_t c = d[kUcsr0c];
    const std::uint32_t size = ((c >> 1) & 0x3U) | ((d[kUcsr0b] & 0x04U) != 0 ? 4U : 0U);
    const std::uint32_t data_bits = size <= 3 ? 5 + size : size == 7 ? 9 : 8;
    const std::uint32_t parity = (c & 0x20U) != 0 ? 1 : 0;
    const std::uint32_t stop_bits = (c & 0x08U) != 0 ? 2 : 1;
    uart->cycles_per_byte = per_bit * (1 + data_bits + parity + stop_bits);
  }

  void quiet_uart() {
    // Off: printing what the firmware sends to stdout, and sleeping the
    // host thread while the firmware polls an empty receiver.
    std::uint32_t flags = 0;
    avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
    flags &= ~static_cast<std::uint32_t>(AVR_UART_FLAG_POLL_SLEEP | AVR_UART_FLAG_STDIO);
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
  }

  void pump_rx() {
    // The receiver takes bytes only while it is on; the chip drops the rest.
    while (!rx_waiting.empty() && !rx_full) {
      const std::uint8_t byte = rx_waiting.front();
      rx_waiting.pop_front();
      if ((avr->data[kUcsr0b] & kRxen0) == 0) continue;
      receive_now(byte);
    }
  }
};

namespace {

void quiet_logger(avr_t* avr, int level, const char* format, va_list ap) {
  if (avr == nullptr || level > LOG_WARNING || avr->custom.data == nullptr) return;
  auto* impl = static_cast<Chip::Impl*>(avr->custom.data);
  if (impl->messages.size() >= 64) return;
  std::array<char, 256> text{};
  std::vsnprintf(text.data(), text.size(), format, ap);
  std::string line(text.data());
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r'))
    line.pop_back();
  impl->messages.push_back(std::move(line));
}

void on_tx(avr_irq_t* /*irq*/, std::uint32_t value, void* param) {
  auto* impl = static_cast<Chip::Impl*>(param);
  if (impl->on_tx) impl->on_tx(static_cast<std::uint8_t>(value), impl->avr->cycle);
}

// The receive FIFO's flow control: XOFF 1 when it is full (or the
// receiver goes off), XOFF 0 and XON 1 when there is room again.
void on_xoff(avr_irq_t* /*irq*/, std::uint32_t value, void* param) {
  static_cast<Chip::Impl*>(param)->rx_full = value != 0;
}

void on_xon(avr_irq_t* /*irq*/, std::uint32_t value, void* param) {
  auto* impl = static_cast<Chip::Impl*>(param);
  if (value == 0) return;
  impl->rx_full = false;
  impl->pump_rx();
}

void on_pin(avr_irq_t* /*irq*/, std::uint32_t value, void* param) {
  auto* watch = static_cast<Chip::Impl::Watch*>(param);
  const int level = value != 0 ? 1 : 0;
  if (level == watch->last) return;
  watch->last = level;
  watch->fn(level != 0);
}

void on_adc_trigger(avr_irq_t* /*irq*/, std::uint32_t value, void* param) {
  auto* impl = static_cast<Chip::Impl*>(param);
  // simavr raises the mux description (a bit-field struct) as its first
  // 32 bits; the struct itself may be wider.
  static_assert(sizeof(avr_adc_mux_t) <= sizeof(std::uint64_t));
  const std::uint64_t bits = value;
  avr_adc_mux_t mux{};
  std::memcpy(&mux, &bits, sizeof mux);
  if (impl->on_conversion && mux.kind == ADC_MUX_SINGLE) impl->on_conversion(mux.src);
}

void sleep_nowhere(avr_t* /*avr*/, avr_cycle_count_t /*cycles*/) {
  // Virtual time: the clock jumps over a sleep; nothing waits.
}

}  // namespace

namespace {

// An ELF file's sections as simavr reads them, freed when it goes.
struct Image {
  explicit Image(const std::filesystem::path& path) {
    install_logger();
    if (elf_read_firmware(path.string().c_str(), &fw) != 0)
      throw std::invalid_argument(path.string() + ": cannot load the ELF file's sections");
  }
  ~Image() {
    std::free(fw.flash);
    std::free(fw.eeprom);
    std::free(fw.fuse);
    std::free(fw.lockbits);
#if ELF_SYMBOLS
    for (std::uint32_t i = 0; i < fw.symbolcount; ++i)
      std::free(fw.symbol[i]);
    std::free(fw.symbol);
#endif
  }
  Image(const Image&) = delete;
  Image& operator=(const Image&) = delete;
  elf_firmware_t fw{};
};

}  // namespace

ElfInfo check_elf(const std::filesystem::path& path) {
  const std::string name = path.string();
  if (!std::filesystem::is_regular_file(path))
    throw std::invalid_argument(name + ": cannot read the firmware file");
  AvrElfInfo header;
  try {
    header = read_avr_elf(path);
  } catch (const SketchBuildError& e) {
    throw std::invalid_argument(std::string(e.what()) +
                                " (build the sketch with `hil firmware build SKETCH.ino`, or give "
                                "its .elf)");
  }
  if (header.machine != kEmAvr)
    throw std::invalid_argument(name + ": built for another processor (ELF machine " +
                                std::to_string(header.machine) + "), not an AVR");
  if (header.architecture != kAvr5)
    throw std::invalid_argument(name + ": built for the AVR family " +
                                elf_family(header.architecture) +
                                "; hil emulates the ATmega328P (avr5)");

  const Image image(path);
  ElfInfo info{path, image.fw.flashsize, image.fw.mmcu};
  if (!info.mmcu.empty() && info.mmcu != "atmega328p" && info.mmcu != "atmega328")
    throw std::invalid_argument(name + ": built for the " + info.mmcu +
                                "; hil emulates the ATmega328P");
  if (info.flash_bytes > Chip::kFlashBytes)
    throw std::invalid_argument(name + ": " + std::to_string(info.flash_bytes) +
                                " bytes of program, more than the ATmega328P's 32 KiB of flash");
  return info;
}

Chip::Chip(const std::filesystem::path& elf)
    : elf_(check_elf(elf)), impl_(std::make_unique<Impl>()) {
  impl_->chip = this;
  Image image(elf);
  avr_t* avr = avr_make_mcu_by_name("atmega328p");
  if (avr == nullptr) throw std::runtime_error("simavr has no ATmega328P core");
  impl_->avr = avr;
  avr->custom.data = impl_.get();
  avr_init(avr);
  avr->log = LOG_WARNING;
  avr->frequency = kFrequencyHz;
  avr->vcc = avr->avcc = avr->aref = 5000;
  avr->sleep = &sleep_nowhere;
  image.fw.tracecount = 0;  // a VCD trace request in the image writes no file
  avr_load_firmware(avr, &image.fw);
  avr->frequency = kFrequencyHz;
  impl_->quiet_uart();
  impl_->datasheet_reset_values();
  for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
    if (std::strcmp(io->kind, "uart") == 0 && reinterpret_cast<avr_uart_t*>(io)->name == '0')
      impl_->uart = reinterpret_cast<avr_uart_t*>(io);
  }
  if (impl_->uart == nullptr) throw std::runtime_error("simavr's ATmega328P has no UART0");
  avr_irq_register_notify(impl_->uart_irq(UART_IRQ_OUTPUT), &on_tx, impl_.get());
  avr_irq_register_notify(impl_->uart_irq(UART_IRQ_OUT_XOFF), &on_xoff, impl_.get());
  avr_irq_register_notify(impl_->uart_irq(UART_IRQ_OUT_XON), &on_xon, impl_.get());
  avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_OUT_TRIGGER),
                          &on_adc_trigger, impl_.get());
}

Chip::~Chip() {
  if (impl_ && impl_->avr) avr_terminate(impl_->avr);
  if (impl_) std::free(impl_->avr);
}

std::uint64_t Chip::cycle() const {
  return impl_->avr->cycle;
}

Chip::State Chip::state() const {
  switch (impl_->avr->state) {
    case cpu_Done:
      return State::halted;
    case cpu_Crashed:
    case cpu_Stopped:
      return State::crashed;
    default:
      return State::running;
  }
}

void Chip::run_to(std::uint64_t target) {
  avr_t* avr = impl_->avr;
  auto& events = impl_->events;
  for (;;) {
    while (!events.empty() && events.begin()->first <= avr->cycle) {
      auto fn = std::move(events.begin()->second);
      events.erase(events.begin());
      fn();
    }
    if (avr->cycle >= target || state() != State::running) return;
    impl_->stop = events.empty() ? target : std::min(target, events.begin()->first);
    impl_->fix_byte_time();
    // simavr's own loop (avr_run) looks at its timers after every
    // instruction; here only when one is due, which is what makes the
    // emulation fast enough (docs/performance.md).
    avr_cycle_timer_pool_t* timers = &avr->cycle_timers;
    while (avr->cycle < impl_->stop && avr->state == cpu_Running) {
      const avr_flashaddr_t pc = avr_run_one(avr);
      if (timers->timer != nullptr && timers->timer->when <= avr->cycle)
        avr_cycle_timer_process(avr);
      avr->pc = pc;
      if (avr->interrupt_state) avr_service_interrupts(avr);
    }
    // Asleep: simavr's step moves the clock to the next timer (or stops a
    // chip asleep with interrupts off for good).
    if (avr->state == cpu_Sleeping) avr_run(avr);
  }
}

void Chip::reset() {
  avr_t* avr = impl_->avr;
  avr_reset(avr);
  avr->log = LOG_WARNING;
  impl_->quiet_uart();
  impl_->datasheet_reset_values();
  impl_->rx_waiting.clear();
  impl_->rx_full = false;
  for (auto& w : impl_->watches)
    w->last = -1;
}

void Chip::at_cycle(std::uint64_t cycle, std::function<void()> fn) {
  impl_->events.emplace(cycle, std::move(fn));
  impl_->stop = std::min(impl_->stop, cycle);
}

void Chip::uart_receive(std::uint8_t byte) {
  // With the receiver off the byte is never sampled.
  if ((impl_->avr->data[kUcsr0b] & kRxen0) == 0) return;
  if (impl_->rx_waiting.size() >= 4096) {
    ++overruns_;
    return;
  }
  impl_->rx_waiting.push_back(byte);
  impl_->pump_rx();
}

void Chip::on_uart_transmit(std::function<void(std::uint8_t, std::uint64_t)> fn) {
  impl_->on_tx = std::move(fn);
}

bool Chip::uart_enabled() const {
  return (impl_->avr->data[kUcsr0b] & (kRxen0 | kTxen0)) != 0;
}

std::uint32_t Chip::uart_baud() const {
  return uart_enabled() ? kFrequencyHz / impl_->bit_cycles() : 0;
}

bool Chip::output_level(const BoardPin& pin) const {
  const PortRegs r = port_regs(pin.port);
  const std::uint8_t* d = impl_->avr->data;
  const std::uint8_t mask = static_cast<std::uint8_t>(1 << pin.bit);
  return (d[r.ddr] & mask) != 0 && (d[r.port] & mask) != 0;
}

int Chip::pwm_duty(const BoardPin& pin) const {
  if (pin.pwm) {
    const TimerRegs& t = kTimers.at(static_cast<std::size_t>(pin.pwm->timer));
    const std::uint8_t* d = impl_->avr->data;
    const bool a = pin.pwm->channel == 'A';
    if ((d[t.tccra] & (a ? kComA1 : kComB1)) != 0) return d[a ? t.ocra : t.ocrb];
  }
  return output_level(pin) ? 255 : 0;
}

void Chip::drive(const BoardPin& pin, bool level) {
  impl_->driving = true;
  avr_raise_irq(impl_->pin_irq(pin), level ? 1 : 0);
  impl_->driving = false;
}

void Chip::on_output_change(const BoardPin& pin, std::function<void(bool)> fn) {
  auto watch = std::make_unique<Impl::Watch>();
  watch->pin = pin;
  Impl* impl = impl_.get();
  watch->fn = [impl, pin, fn = std::move(fn)](bool level) {
    // A pin the firmware reads is driven from outside; only its outputs count.
    if (impl->driving) return;
    const PortRegs r = port_regs(pin.port);
    if ((impl->avr->data[r.ddr] & (1 << pin.bit)) == 0) return;
    fn(level);
  };
  avr_irq_register_notify(impl_->pin_irq(pin), &on_pin, watch.get());
  impl_->watches.push_back(std::move(watch));
}

void Chip::set_analog_millivolts(int adc_channel, std::uint32_t millivolts) {
  avr_raise_irq(avr_io_getirq(impl_->avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC0 + adc_channel),
                millivolts);
}

void Chip::on_conversion(std::function<void(int)> fn) {
  impl_->on_conversion = std::move(fn);
}

std::vector<std::string> Chip::take_messages() {
  std::vector<std::string> out;
  out.swap(impl_->messages);
  return out;
}

}  // namespace hil::mocks::avr
