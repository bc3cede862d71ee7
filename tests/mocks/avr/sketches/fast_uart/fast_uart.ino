// A sketch that opens its port at 115,200 baud, not the robot's 9,600.
void setup() { Serial.begin(115200); }

void loop() {
  Serial.println("hello");
  delay(500);
}
