// A sketch that never turns its UART on: it blinks the LED and nothing
// else. The emulated board warns that it will never answer.
void setup() { pinMode(LED_BUILTIN, OUTPUT); }

void loop() {
  digitalWrite(LED_BUILTIN, !digitalRead(LED_BUILTIN));
  delay(100);
}
