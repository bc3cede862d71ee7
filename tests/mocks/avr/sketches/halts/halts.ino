// A sketch that says one word and then sleeps with interrupts off: the
// chip can only be woken by a reset.
#include <avr/interrupt.h>
#include <avr/sleep.h>

void setup() {
  Serial.begin(9600);
  Serial.print("bye");
  Serial.flush();
  cli();
  set_sleep_mode(SLEEP_MODE_PWR_DOWN);
  sleep_enable();
  sleep_cpu();
}

void loop() {}
