// A sketch that says one word and then jumps past its program, into
// erased flash.
void setup() {
  Serial.begin(9600);
  Serial.print("go");
  Serial.flush();
  void (*nowhere)() = reinterpret_cast<void (*)()>(0x3F00);
  nowhere();
}

void loop() {}
