/* The part of the Arduino API that firmware/examples/scan_array/scan_array.ino uses,
   on a POSIX host: the sketch is compiled as C++ with this header forced in
   (-include), Serial is standard input and output, micros() the monotonic clock, and
   analogRead returns a known pattern of the driven row and the multiplexer's address
   (tests/firmware/test_c_encoder.py). */
#ifndef ARDUINO_STUB_H
#define ARDUINO_STUB_H

#include <stddef.h>
#include <stdint.h>

#define HIGH 1
#define LOW 0
#define INPUT 0
#define OUTPUT 1
#define A0 54

void pinMode(uint8_t pin, uint8_t mode);
void digitalWrite(uint8_t pin, uint8_t value);
int analogRead(uint8_t pin);
void delayMicroseconds(unsigned us);
uint32_t micros(void);

class StubSerial {
  public:
    void begin(unsigned long baud);
    int available(void);
    int read(void);
    size_t write(const uint8_t *data, size_t len);
};

extern StubSerial Serial;

/* the expected reading of each taxel, for the test */
#define STUB_READING(row, col) ((uint16_t)(((row) * 8 + (col)) * 13 % 1024))

#endif
