/* A POSIX host playing an Arduino board for scan_array.ino (see arduino_stub.h). */
#include <errno.h>
#include <poll.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include "arduino_stub.h"

void setup(void);
void loop(void);

StubSerial Serial;

static uint8_t level[64], mode[64];
static uint8_t rx[4096];
static ssize_t rx_len, rx_pos;

void pinMode(uint8_t pin, uint8_t m) { mode[pin & 63] = m; }

void digitalWrite(uint8_t pin, uint8_t value) { level[pin & 63] = value; }

int analogRead(uint8_t pin)
{
    int row = -1, col, r, driven = 0;
    if (pin != A0) abort();
    for (r = 0; r < 8; r++) /* the sketch's row pins 2..9: exactly one driven high */
        if (mode[2 + r] == OUTPUT && level[2 + r] == HIGH) row = r, driven++;
    if (driven != 1) abort();
    col = level[10] + 2 * level[11] + 4 * level[12]; /* 74HC4051 S0..S2 on pins 10..12 */
    return STUB_READING(row, col);
}

void delayMicroseconds(unsigned us) { (void)us; }

uint32_t micros(void)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (uint32_t)((uint64_t)now.tv_sec * 1000000u + (uint64_t)now.tv_nsec / 1000u);
}

void StubSerial::begin(unsigned long baud) { (void)baud; }

int StubSerial::available(void)
{
    if (rx_pos < rx_len) return (int)(rx_len - rx_pos);
    struct pollfd fd = {0, POLLIN, 0};
    if (poll(&fd, 1, 0) <= 0) return 0;
    rx_len = ::read(0, rx, sizeof rx);
    rx_pos = 0;
    if (rx_len <= 0) exit(0); /* the host closed the line */
    return (int)rx_len;
}

int StubSerial::read(void) { return available() ? rx[rx_pos++] : -1; }

size_t StubSerial::write(const uint8_t *data, size_t len)
{
    size_t left = len;
    while (left) {
        ssize_t n = ::write(1, data, left);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) exit(0);
        data += n;
        left -= (size_t)n;
    }
    return len;
}

int main(void)
{
    setup();
    for (;;) {
        loop();
        usleep(50); /* a board spins; the test machine is shared */
    }
}
