/*
 * host_device.c - a tactsense device that runs on a computer (Linux, macOS, any POSIX
 * system): the same library as on a microcontroller, with a TCP connection in place
 * of the serial line. Use it to try the protocol end to end before any hardware
 * exists, or as the start of a bridge for an array read on a computer (SPI on a
 * Raspberry Pi, a USB data-acquisition card): replace scan() with your own reading.
 *
 * Build and run (firmware/Makefile, or by hand):
 *
 *     make -C firmware host_device
 *     firmware/build/host_device 5000              (listens on 127.0.0.1:5000)
 *     tactsense record socket://127.0.0.1:5000 --out run.h5
 *
 *     cc -std=c99 -O2 -Ifirmware firmware/examples/host_device/host_device.c \
 *        firmware/tactsense.c -o host_device
 *
 * Usage: host_device [PORT [FRAMES]]
 *   PORT    TCP port on 127.0.0.1 (default 5000; 0: any free port). The port is
 *           printed on the first line of standard output, "listening on 127.0.0.1:PORT".
 *   FRAMES  frames per START (default 0: until STOP); after the last one the device
 *           sends END by itself.
 * One host at a time; when it disconnects, the device waits for the next.
 *
 * The array it pretends to be: 8 x 8 tactels scanned at 100 Hz, 10-bit readings of
 * 500 counts at rest, one tactel pressed at a time: in the k-th frame since START
 * (k = 0, 1, ...) the tactel k mod 64 (row-major) reads 800 counts. The device clock
 * is the nominal scan clock (ts_scan_time_us).
 */
#define _POSIX_C_SOURCE 200809L
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "tactsense.h"

#define ROWS 8
#define COLS 8
#define SCAN_PERIOD_NS 10000000UL /* 100 Hz: must be 1 / scan_rate_hz of SENSOR_TOML */
#define REST_COUNTS 500
#define PRESSED_COUNTS 800

/* The sensor description the host reads from IDENT (tactsense sensor show). */
static const char SENSOR_TOML[] = "extends = \"initial\"\n"
                                  "name = \"host_device\"\n"
                                  "description = \"8 x 8 array, firmware/examples/host_device\"\n"
                                  "[electronics]\n"
                                  "adc_bits = 10\n"
                                  "nominal_counts = 500.0\n"
                                  "scan_rate_hz = 100.0\n";

static ts_context ts;
static int connection = -1; /* the host's socket; -1 once it has gone */

/* The library hands over the bytes of each packet in pieces of at most 256. */
static void write_socket(void *user, const uint8_t *data, size_t len)
{
    (void)user;
    while (len > 0 && connection >= 0) {
        ssize_t n = send(connection, data, len, 0);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) { /* the host went away */
            close(connection);
            connection = -1;
            return;
        }
        data += n;
        len -= (size_t)n;
    }
}

/* One scan of the pretend array: tactel k mod 64 pressed in frame k. */
static void scan(uint16_t *counts, unsigned long k)
{
    size_t i;
    for (i = 0; i < ROWS * COLS; i++) counts[i] = REST_COUNTS;
    counts[k % (ROWS * COLS)] = PRESSED_COUNTS;
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Serve one host until it disconnects: its commands, and frames while streaming. */
static void serve(unsigned long frames_per_start)
{
    static uint16_t counts[ROWS * COLS];
    int streaming = 0;
    unsigned long k = 0;
    double next_scan = 0.0, period = (double)SCAN_PERIOD_NS * 1e-9;
    ts_init(&ts, ROWS, COLS, SCAN_PERIOD_NS, write_socket, NULL);
    while (connection >= 0) {
        struct pollfd wait = {0};
        double due = streaming ? next_scan - now_s() : 1.0;
        int timeout_ms = due > 0.0 ? (int)(due * 1000.0) + 1 : 0;
        wait.fd = connection;
        wait.events = POLLIN;
        if (poll(&wait, 1, timeout_ms) < 0 && errno != EINTR) break;
        if (wait.revents & (POLLIN | POLLHUP | POLLERR)) {
            uint8_t bytes[256];
            ssize_t n = recv(connection, bytes, sizeof bytes, 0), b;
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) break; /* the host closed the connection */
            for (b = 0; b < n; b++) {
                switch (ts_receive(&ts, bytes[b])) {
                case TS_IDENTIFY:
                    ts_send_ident(&ts, "host_device", "1.0.0", "host-0001", SENSOR_TOML);
                    break;
                case TS_START:
                    if (!streaming) {
                        k = 0;
                        next_scan = now_s();
                    }
                    streaming = 1;
                    break;
                case TS_STOP:
                    if (streaming) ts_send_end(&ts);
                    streaming = 0;
                    break;
                default:
                    break;
                }
            }
        }
        if (streaming && now_s() >= next_scan) {
            scan(counts, k);
            ts_send_frame(&ts, ts_scan_time_us(&ts), counts);
            k++;
            next_scan += period;
            if (frames_per_start > 0 && k == frames_per_start) {
                ts_send_end(&ts);
                streaming = 0;
            }
        }
    }
    if (connection >= 0) close(connection);
    connection = -1;
}

int main(int argc, char **argv)
{
    struct sockaddr_in address;
    socklen_t size = sizeof address;
    unsigned long port = argc > 1 ? strtoul(argv[1], NULL, 10) : 5000UL;
    unsigned long frames = argc > 2 ? strtoul(argv[2], NULL, 10) : 0UL;
    int listener, yes = 1;
    if (argc > 3 || port > 65535UL) {
        fprintf(stderr, "usage: host_device [PORT [FRAMES]]  (PORT 0..65535)\n");
        return 2;
    }
    signal(SIGPIPE, SIG_IGN); /* a host that disconnects is an error of send, not a signal */
    listener = socket(AF_INET, SOCK_STREAM, 0);
    if (listener < 0) {
        perror("host_device: socket");
        return 1;
    }
    setsockopt(listener, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    memset(&address, 0, sizeof address);
    address.sin_family = AF_INET;
    address.sin_port = htons((uint16_t)port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (bind(listener, (struct sockaddr *)&address, sizeof address) < 0 ||
        listen(listener, 1) < 0 ||
        getsockname(listener, (struct sockaddr *)&address, &size) < 0) {
        perror("host_device: 127.0.0.1");
        return 1;
    }
    printf("listening on 127.0.0.1:%u\n", (unsigned)ntohs(address.sin_port));
    fflush(stdout);
    for (;;) {
        connection = accept(listener, NULL, NULL);
        if (connection < 0) {
            if (errno == EINTR) continue;
            perror("host_device: accept");
            return 1;
        }
        setsockopt(connection, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes); /* frames go at once */
        serve(frames);
    }
}
