// hil_arduino.ino - hil's own test sketch for the Arduino robot's serial
// protocol, for an Arduino Uno (ATmega328P, 16 MHz).
//
// It answers the robot's framed requests (^SEQ|CMD|PAYLOAD*CS$ at 9600
// baud) as the board's sketch does, profile `firmware` of
// docs/protocols/arduino.md ("Profiles"), and byte for byte as hil's
// behavioural mock in that profile (mocks/arduino_sketch.cpp,
// protocol/arduino/sketch.cpp) wherever the answer does not depend on the
// world. The facts it follows are listed in docs/protocols/arduino.md and
// docs/mocks/arduino.md. hil runs it on its emulated ATmega328P, with the
// pins below wired to the simulated chassis and sensors, and the Arduino
// scenarios and client tests run against it as well as against the mock.
//
// Pin map (the protocol document's wiring table, hil's default pin map,
// mocks/avr/pin_map.hpp):
//
//   left motor   PWM D5   DIR forward A0   DIR reverse A1   encoder D2
//   right motor  PWM D6   DIR forward A3   DIR reverse A2   encoder D3
//   sonar        trigger D11   echo D12
//   IR left      analog A4     digital D7 (high on an obstacle)
//   IR right     analog A5     digital D8 (high on an obstacle)
//
// A side drives forward with its PWM pin at the duty, forward pin HIGH and
// reverse pin LOW; backward the other way round; it stops with duty 0 and
// both direction pins LOW. The encoders are not used (inputs only).
//
// This is the hil team's own code, written from the protocol facts, and
// is distributed under the same terms as the rest of the hil repository.
// It uses the Arduino core only (no libraries, no String) and declares
// every function before its use, so it builds with arduino-mk as well as
// with the Arduino IDE and `hil firmware build`.

#include <Arduino.h>

// ---- pins ------------------------------------------------------------------

const uint8_t kLeftPwmPin = 5;
const uint8_t kLeftForwardPin = A0;
const uint8_t kLeftReversePin = A1;
const uint8_t kLeftEncoderPin = 2;
const uint8_t kRightPwmPin = 6;
const uint8_t kRightForwardPin = A3;
const uint8_t kRightReversePin = A2;
const uint8_t kRightEncoderPin = 3;
const uint8_t kSonarTriggerPin = 11;
const uint8_t kSonarEchoPin = 12;
const uint8_t kIrLeftAnalogPin = A4;
const uint8_t kIrLeftDigitalPin = 7;
const uint8_t kIrRightAnalogPin = A5;
const uint8_t kIrRightDigitalPin = 8;

// ---- protocol and motion constants -----------------------------------------

const long kSerialBaud = 9600;
// The receive buffer: a frame of more bytes ('^' and '$' counted) is dropped.
const uint8_t kFrameBytes = 96;
// Frames shorter than this ('^' and '$' counted) are dropped.
const uint8_t kMinFrameBytes = 7;
// A reply's content (SEQ|ACK|TEXT, between '^' and '*') is cut here.
const uint8_t kReplyContentBytes = kFrameBytes - 1;
const uint8_t kBootPwm = 140;
const long kMaxPwm = 255;
// Moves are timed, whatever the duty.
const unsigned long kMsPerCm = 18;
const unsigned long kMsPerDegree = 6;
// The echo wait gives up after 30 ms, counted from the trigger (beyond
// about 5 m): B then reads 0.
const unsigned long kEchoTimeoutUs = 30000UL;
// Sound at 343 m/s: an echo of t microseconds travelled there and back, so
// the distance in cm is t * 34300 / (2 * 1000000) = t * 343 / 20000,
// truncated. An echo of 2 * d / 343 s therefore reads floor(d in cm).
const unsigned long kSoundCmNumerator = 343;
const unsigned long kSoundCmDenominator = 20000;

// ---- state -----------------------------------------------------------------

// What runs: no motion, an M move or an R rotation. Plain integers rather
// than an enum, so that every function signature uses built-in types only
// and a prototype inserted anywhere still compiles.
const uint8_t kIdle = 0;
const uint8_t kMove = 1;
const uint8_t kRotate = 2;

// The duty the next M or R drives at; V sets it.
uint8_t base_pwm = kBootPwm;
// The last drive direction, as STATUS reports it: 1 fwd, -1 rev, 0 stop.
int8_t last_dir = 0;
uint8_t motion = kIdle;
unsigned long motion_start_ms = 0;
unsigned long motion_duration_ms = 0;

// The frame being received, '^' first; one spare byte for a terminating NUL.
char frame[kFrameBytes + 1];
uint8_t frame_len = 0;
bool in_frame = false;

// The reply being written: content bytes so far and their XOR.
uint8_t reply_len = 0;
uint8_t reply_sum = 0;

// ---- declarations ----------------------------------------------------------

void drive_side(uint8_t pwm_pin, uint8_t forward_pin, uint8_t reverse_pin, int8_t dir,
                uint8_t duty);
void stop_motion();
void start_motion(uint8_t kind, long arg);
void end_due_motion(unsigned long now_ms);
int8_t nibble(char c);
long parse_long(const char* text);
bool word_is(const char* text, const __FlashStringHelper* word);
char* next_field(char** cursor);
void reply_char(char c);
void reply_text(const char* text);
void reply_flash(const __FlashStringHelper* text);
void reply_number(unsigned long value);
void begin_reply(const char* seq, bool ack);
void end_reply();
void reply_nack(const char* seq, const __FlashStringHelper* code);
void reply_ack(const char* seq, const __FlashStringHelper* text);
void reply_status(const char* seq);
void reply_sonar(const char* seq);
void reply_ir(const char* seq);
void execute(const char* seq, const char* cmd, const char* payload);
void handle_frame(uint8_t n);
void receive_byte(char c);

// ---- motors ----------------------------------------------------------------

// dir 1 forward, -1 backward, 0 stopped (duty 0, both direction pins LOW).
void drive_side(uint8_t pwm_pin, uint8_t forward_pin, uint8_t reverse_pin, int8_t dir,
                uint8_t duty) {
  if (dir == 0) duty = 0;
  analogWrite(pwm_pin, duty);
  digitalWrite(forward_pin, dir > 0 ? HIGH : LOW);
  digitalWrite(reverse_pin, dir < 0 ? HIGH : LOW);
}

void stop_motion() {
  drive_side(kLeftPwmPin, kLeftForwardPin, kLeftReversePin, 0, 0);
  drive_side(kRightPwmPin, kRightForwardPin, kRightReversePin, 0, 0);
  motion = kIdle;
  last_dir = 0;
}

// M (cm) or R (degrees): runs |arg| * 18 ms or |arg| * 6 ms from now and
// replaces a running motion; a motion of 0 ms stops at once. R > 0 turns
// right: the left side forward, the right side backward.
void start_motion(uint8_t kind, long arg) {
  const unsigned long magnitude =
      arg < 0 ? static_cast<unsigned long>(-(arg + 1)) + 1UL : static_cast<unsigned long>(arg);
  const unsigned long per = kind == kMove ? kMsPerCm : kMsPerDegree;
  // millis() counts to 2^32 - 1: a longer motion (more than 49 days) is cut
  // to that.
  const unsigned long duration = magnitude > 0xFFFFFFFFUL / per ? 0xFFFFFFFFUL : magnitude * per;
  if (duration == 0) {
    stop_motion();
    return;
  }
  const int8_t sign = arg < 0 ? -1 : 1;
  motion = kind;
  motion_start_ms = millis();
  motion_duration_ms = duration;
  last_dir = kind == kMove ? sign : 0;
  const int8_t right_sign = kind == kMove ? sign : static_cast<int8_t>(-sign);
  drive_side(kLeftPwmPin, kLeftForwardPin, kLeftReversePin, sign, base_pwm);
  drive_side(kRightPwmPin, kRightForwardPin, kRightReversePin, right_sign, base_pwm);
}

void end_due_motion(unsigned long now_ms) {
  if (motion != kIdle && now_ms - motion_start_ms >= motion_duration_ms) stop_motion();
}

// ---- text ------------------------------------------------------------------

int8_t nibble(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return 10 + c - 'A';
  if (c >= 'a' && c <= 'f') return 10 + c - 'a';
  return -1;
}

// A number read as C's atol reads it: blanks skipped, an optional sign,
// decimal digits up to the first other character; no digits read 0. A
// number beyond the 32-bit range saturates (atol's own result is undefined
// there).
long parse_long(const char* text) {
  while (*text == ' ' || (*text >= '\t' && *text <= '\r'))
    ++text;
  bool negative = false;
  if (*text == '+' || *text == '-') negative = *text++ == '-';
  const unsigned long limit = negative ? 2147483648UL : 2147483647UL;
  unsigned long value = 0;
  for (; *text >= '0' && *text <= '9'; ++text) {
    const unsigned long digit = static_cast<unsigned long>(*text - '0');
    value = value > (limit - digit) / 10 ? limit : value * 10 + digit;
  }
  return negative ? static_cast<long>(0UL - value) : static_cast<long>(value);
}

// Whether text is word, ASCII letters compared without regard to case.
bool word_is(const char* text, const __FlashStringHelper* word) {
  const char* w = reinterpret_cast<const char*>(word);
  for (;; ++text, ++w) {
    char a = *text;
    char b = static_cast<char>(pgm_read_byte(w));
    if (a >= 'a' && a <= 'z') a = static_cast<char>(a - 'a' + 'A');
    if (b >= 'a' && b <= 'z') b = static_cast<char>(b - 'a' + 'A');
    if (a != b) return false;
    if (a == '\0') return true;
  }
}

// The next '|'-separated field as C's strtok gives it: a run of '|' counts
// as one separator, so there are no empty fields. Null when none is left.
char* next_field(char** cursor) {
  char* p = *cursor;
  while (*p == '|')
    ++p;
  if (*p == '\0') {
    *cursor = p;
    return 0;
  }
  char* field = p;
  while (*p != '\0' && *p != '|')
    ++p;
  if (*p == '|') *p++ = '\0';
  *cursor = p;
  return field;
}

// ---- replies: ^SEQ|ACK|TEXT*CS$, CS the XOR of the content, upper-case hex --

void reply_char(char c) {
  if (reply_len >= kReplyContentBytes) return;
  ++reply_len;
  reply_sum ^= static_cast<uint8_t>(c);
  Serial.write(static_cast<uint8_t>(c));
}

void reply_text(const char* text) {
  for (; *text != '\0'; ++text)
    reply_char(*text);
}

void reply_flash(const __FlashStringHelper* text) {
  const char* p = reinterpret_cast<const char*>(text);
  for (char c = static_cast<char>(pgm_read_byte(p)); c != '\0';
       c = static_cast<char>(pgm_read_byte(++p)))
    reply_char(c);
}

void reply_number(unsigned long value) {
  char digits[11];
  uint8_t n = 0;
  do {
    digits[n++] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value != 0);
  while (n > 0)
    reply_char(digits[--n]);
}

void begin_reply(const char* seq, bool ack) {
  reply_len = 0;
  reply_sum = 0;
  Serial.write('^');
  reply_text(seq);
  reply_char('|');
  reply_flash(ack ? F("ACK") : F("NACK"));
  reply_char('|');
}

void end_reply() {
  static const char kHex[] = "0123456789ABCDEF";
  Serial.write('*');
  Serial.write(kHex[reply_sum >> 4]);
  Serial.write(kHex[reply_sum & 0x0F]);
  Serial.write('$');
}

void reply_nack(const char* seq, const __FlashStringHelper* code) {
  begin_reply(seq, false);
  reply_flash(code);
  end_reply();
}

void reply_ack(const char* seq, const __FlashStringHelper* text) {
  begin_reply(seq, true);
  reply_flash(text);
  end_reply();
}

// STATUS:V=<pwm>,DIR=<fwd|rev|stop>,MOT:IDLE, or ...,MOT:MOVE,tleft:<ms> /
// ...,MOT:ROT,tleft:<ms> while a motion runs (whole ms until its end).
void reply_status(const char* seq) {
  const unsigned long now_ms = millis();
  end_due_motion(now_ms);
  begin_reply(seq, true);
  reply_flash(F("STATUS:V="));
  reply_number(base_pwm);
  reply_flash(F(",DIR="));
  reply_flash(last_dir > 0 ? F("fwd") : last_dir < 0 ? F("rev") : F("stop"));
  if (motion == kIdle) {
    reply_flash(F(",MOT:IDLE"));
  } else {
    reply_flash(motion == kMove ? F(",MOT:MOVE") : F(",MOT:ROT"));
    reply_flash(F(",tleft:"));
    reply_number(motion_duration_ms - (now_ms - motion_start_ms));
  }
  end_reply();
}

// B:<cm>, B:0 when no echo comes back in time.
void reply_sonar(const char* seq) {
  digitalWrite(kSonarTriggerPin, LOW);
  delayMicroseconds(2);
  digitalWrite(kSonarTriggerPin, HIGH);
  delayMicroseconds(10);
  digitalWrite(kSonarTriggerPin, LOW);
  // pulseInLong() times the echo with micros() (4 us steps, 0.07 cm). The
  // cycle-counting pulseIn() reads about 0.7 % short because the timer and
  // serial interrupts stay enabled while it counts: 398 cm for 4.005 m.
  const unsigned long echo_us = pulseInLong(kSonarEchoPin, HIGH, kEchoTimeoutUs);
  const unsigned long cm = echo_us * kSoundCmNumerator / kSoundCmDenominator;
  begin_reply(seq, true);
  reply_flash(F("B:"));
  reply_number(cm);
  end_reply();
}

// I:AL=<0..1023>,AR=<0..1023>,DL=<0|1>,DR=<0|1>; 1 is an obstacle.
void reply_ir(const char* seq) {
  const int left_analog = analogRead(kIrLeftAnalogPin);
  const int right_analog = analogRead(kIrRightAnalogPin);
  const int left_digital = digitalRead(kIrLeftDigitalPin);
  const int right_digital = digitalRead(kIrRightDigitalPin);
  begin_reply(seq, true);
  reply_flash(F("I:AL="));
  reply_number(static_cast<unsigned long>(left_analog));
  reply_flash(F(",AR="));
  reply_number(static_cast<unsigned long>(right_analog));
  reply_flash(F(",DL="));
  reply_char(left_digital == HIGH ? '1' : '0');
  reply_flash(F(",DR="));
  reply_char(right_digital == HIGH ? '1' : '0');
  end_reply();
}

// ---- requests --------------------------------------------------------------

void execute(const char* seq, const char* cmd, const char* payload) {
  if (word_is(cmd, F("PING"))) {
    reply_ack(seq, F("PONG"));
  } else if (word_is(cmd, F("HELP"))) {
    reply_ack(seq, F("CMDS:PING,HELP,STATUS,V,M,R,S,B,I"));
  } else if (word_is(cmd, F("STATUS"))) {
    reply_status(seq);
  } else if (word_is(cmd, F("V"))) {
    const long v = parse_long(payload);
    if (v < 0 || v > kMaxPwm) {
      reply_nack(seq, F("BAD_V"));
    } else {
      base_pwm = static_cast<uint8_t>(v);
      reply_ack(seq, F("OK"));
    }
  } else if (word_is(cmd, F("M"))) {
    start_motion(kMove, parse_long(payload));
    reply_ack(seq, F("ACCEPTED"));
  } else if (word_is(cmd, F("R"))) {
    start_motion(kRotate, parse_long(payload));
    reply_ack(seq, F("ACCEPTED"));
  } else if (word_is(cmd, F("S"))) {
    stop_motion();
    reply_ack(seq, F("STOPPED"));
  } else if (word_is(cmd, F("B"))) {
    reply_sonar(seq);
  } else if (word_is(cmd, F("I"))) {
    reply_ir(seq);
  } else {
    reply_nack(seq, F("BAD_CMD"));
  }
}

// One stored frame of n bytes, '^' first and '$' last. Malformed framing is
// dropped without an answer; a bad checksum, too few fields or a bad SEQ is
// answered with a NACK; anything else is a request.
void handle_frame(uint8_t n) {
  if (n < kMinFrameBytes || frame[0] != '^' || frame[n - 1] != '$') return;
  // The first '*' separates the checksum; exactly two characters follow it.
  uint8_t star = 1;
  while (star < n && frame[star] != '*')
    ++star;
  if (star >= n || n - 1 - star != 3) return;
  const int8_t hi = nibble(frame[star + 1]);
  const int8_t lo = nibble(frame[star + 2]);
  if (hi < 0 || lo < 0) return;
  uint8_t sum = 0;
  for (uint8_t i = 1; i < star; ++i)
    sum ^= static_cast<uint8_t>(frame[i]);
  if (sum != static_cast<uint8_t>(hi * 16 + lo)) {
    // SEQ of the NACK: the first two content bytes, whatever they are (as a
    // C string: a NUL ends it).
    char seq[3] = {frame[1], frame[1] == '\0' ? '\0' : frame[2], '\0'};
    reply_nack(seq, F("BAD_CS"));
    return;
  }
  // From here the content is a C string: it ends at the '*', or at an
  // earlier NUL byte.
  frame[star] = '\0';
  char* cursor = frame + 1;
  char* seq = next_field(&cursor);
  char* cmd = seq != 0 ? next_field(&cursor) : 0;
  char* payload = cmd != 0 ? next_field(&cursor) : 0;  // a fourth field is ignored
  if (payload == 0) {
    reply_nack(seq != 0 && strlen(seq) == 2 ? seq : "00", F("BAD_FMT"));
    return;
  }
  if (strlen(seq) != 2 || nibble(seq[0]) < 0 || nibble(seq[1]) < 0) {
    reply_nack("00", F("BAD_SEQ"));
    return;
  }
  execute(seq, cmd, payload);
}

// The byte loop: bytes before a '^' are ignored; from a '^' every byte is
// stored (another '^' too) until '$'. The byte that would be the 97th drops
// the frame and is lost with it.
void receive_byte(char c) {
  if (!in_frame) {
    if (c == '^') {
      in_frame = true;
      frame[0] = c;
      frame_len = 1;
    }
    return;
  }
  if (frame_len >= kFrameBytes) {
    in_frame = false;
    frame_len = 0;
    return;
  }
  frame[frame_len++] = c;
  if (c == '$') {
    in_frame = false;
    const uint8_t n = frame_len;
    frame_len = 0;
    handle_frame(n);
  }
}

// ---- Arduino entry points --------------------------------------------------

void setup() {
  pinMode(kLeftPwmPin, OUTPUT);
  pinMode(kLeftForwardPin, OUTPUT);
  pinMode(kLeftReversePin, OUTPUT);
  pinMode(kRightPwmPin, OUTPUT);
  pinMode(kRightForwardPin, OUTPUT);
  pinMode(kRightReversePin, OUTPUT);
  pinMode(kLeftEncoderPin, INPUT);
  pinMode(kRightEncoderPin, INPUT);
  pinMode(kSonarTriggerPin, OUTPUT);
  digitalWrite(kSonarTriggerPin, LOW);
  pinMode(kSonarEchoPin, INPUT);
  pinMode(kIrLeftDigitalPin, INPUT);
  pinMode(kIrRightDigitalPin, INPUT);
  stop_motion();
  base_pwm = kBootPwm;
  Serial.begin(kSerialBaud);
}

void loop() {
  // A motion that is due ends before the next request is looked at.
  end_due_motion(millis());
  while (Serial.available() > 0) {
    receive_byte(static_cast<char>(Serial.read()));
    end_due_motion(millis());
  }
}
