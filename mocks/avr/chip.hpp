#pragma once
// An emulated ATmega328P at 16 MHz running one firmware image: simavr
// (libsimavr) behind a small C++ surface, so that nothing else in hil sees
// the C library. The chip only moves when run_to() is called; its clock is
// a cycle count that the caller maps to time (mocks/avr/avr_firmware.hpp).

#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "mocks/avr/pin_map.hpp"

namespace hil::mocks::avr {

/// What an ELF file holds, once checked to be ATmega328P firmware.
struct ElfInfo {
  std::filesystem::path path;
  std::uint32_t flash_bytes = 0;  ///< program and initialised data in flash
  std::string mmcu;               ///< the chip the image names (.mmcu), or empty
};

/// Reads `path` and checks that it is an AVR executable for the
/// ATmega328P's core (avr5, 32 KiB of flash). Throws std::invalid_argument
/// naming the file and what is wrong: not an ELF file, built for another
/// processor (x86-64, ...), for another AVR family (avr6: ATmega2560), a
/// .mmcu section naming another chip, larger than the flash.
ElfInfo check_elf(const std::filesystem::path& path);

class Chip {
 public:
  static constexpr std::uint32_t kFrequencyHz = 16'000'000;
  static constexpr std::uint32_t kFlashBytes = 32 * 1024;

  enum class State : std::uint8_t {
    running,  ///< executing (or in a sleep mode an interrupt ends)
    halted,   ///< asleep with interrupts off: nothing can wake it but a reset
    crashed,  ///< an invalid instruction or address stopped it
  };

  /// Loads the image (check_elf() first) and powers the chip on: cycle 0,
  /// at the reset vector.
  explicit Chip(const std::filesystem::path& elf);
  ~Chip();
  Chip(const Chip&) = delete;
  Chip& operator=(const Chip&) = delete;

  const ElfInfo& elf() const { return elf_; }

  /// Cycles since power-on; resets do not rewind it.
  std::uint64_t cycle() const;
  /// Runs until cycle() >= `cycle`, firing the at_cycle() calls that fall
  /// due on the way, or until the chip halts or crashes (then the clock
  /// stays where it stopped). A sleeping chip's clock jumps to its next
  /// timer, so cycle() may pass `cycle` by that much.
  void run_to(std::uint64_t cycle);
  State state() const;
  /// An external reset (the board's RESET line pulled low and released):
  /// registers and peripherals to their reset values, execution from the
  /// reset vector; RAM keeps its contents, as on the chip. Pending
  /// at_cycle() calls are kept; UART input not yet read is lost.
  void reset();

  /// Calls `fn` when the clock reaches `cycle` (at once in the next
  /// run_to() if it already has). For stimuli: an echo pulse, an encoder
  /// edge.
  void at_cycle(std::uint64_t cycle, std::function<void()> fn);

  // ---- UART0 ----

  /// A byte arrives on RXD. Bytes wait in the chip's receive FIFO, and
  /// beyond it here, until the firmware reads them; with the receiver off
  /// (before Serial.begin()) they are lost, as on the chip.
  void uart_receive(std::uint8_t byte);
  /// Told each byte the firmware writes to UDR0, and the cycle it did.
  void on_uart_transmit(std::function<void(std::uint8_t byte, std::uint64_t cycle)> fn);
  /// Whether the firmware has turned the receiver or the transmitter on.
  bool uart_enabled() const;
  /// The baud rate UBRR0 and U2X0 set (what Serial.begin() asked for,
  /// within the divider's rounding); 0 while the UART is off.
  std::uint32_t uart_baud() const;
  /// Bytes lost because they came faster than the firmware read them.
  std::uint64_t uart_overruns() const { return overruns_; }

  // ---- pins ----

  /// The level the firmware drives on `pin`: its PORT bit when the pin is
  /// an output, false when it is an input.
  bool output_level(const BoardPin& pin) const;
  /// What analogWrite() last set on `pin`: the compare value while the
  /// pin's timer output is connected, else 255 or 0 by its output level.
  int pwm_duty(const BoardPin& pin) const;
  /// Drives an input pin from outside (a sensor's output).
  void drive(const BoardPin& pin, bool level);
  /// Told each time the firmware changes `pin`'s output level.
  void on_output_change(const BoardPin& pin, std::function<void(bool level)> fn);
  /// The millivolts an analog pin shows (AVCC is 5,000 mV: 1023 reads at
  /// 5,000 mV and above).
  void set_analog_millivolts(int adc_channel, std::uint32_t millivolts);
  /// Told when a conversion starts, with its channel, before the value is
  /// taken: the moment to set_analog_millivolts().
  void on_conversion(std::function<void(int adc_channel)> fn);

  /// simavr's own error messages since the last call (a bad address, an
  /// overrun), for the firmware's log.
  std::vector<std::string> take_messages();

  struct Impl;

 private:
  ElfInfo elf_;
  std::unique_ptr<Impl> impl_;
  std::uint64_t overruns_ = 0;
};

}  // namespace hil::mocks::avr
