/*
 * Test and benchmark driver for firmware/tactsense.c (tests/firmware/test_c_encoder.py,
 * benchmarks/bench_firmware.py). Not part of the library: it uses POSIX I/O.
 *
 *   ts_driver encode buffer|stream   jobs on stdin -> encoded packets on stdout
 *   ts_driver crc                    CRC-32 of stdin, whole and in pieces, as hex
 *   ts_driver receive                bytes on stdin -> the commands recognised, as hex
 *   ts_driver device FRAMES TOML ROWS COLS PERIOD_NS [AT:COUNT ...] [c=K]
 *                                    a device on stdin/stdout: answers IDENTIFY, on START
 *                                    sends the frames of the file FRAMES (u16 little-endian,
 *                                    row-major), dropping COUNT scans before frame AT, then END;
 *                                    c=K: K components per taxel (version-2 FRAMEs)
 *   ts_driver bench buffer|stream ROWS COLS N
 *                                    encode N frames; prints frames/s and a checksum
 *
 * Jobs (little-endian): 'F' u16 sequence, u64 time, u8 rows, u8 cols, u16 counts[rows*cols]
 *                       'G' u16 sequence, u64 time, u8 rows, u8 cols, u8 components,
 *                           u16 counts[rows*cols*components] (a version-2 FRAME; in stream
 *                           mode through ts_set_components and ts_send_frame, so components
 *                           must be 2 or more there)
 *                       'E' u16 last sequence, u32 frames
 *                       'P' u8 kind, u16 length, body
 *                       'I' or 'J' u8 rows, u8 cols, u32 period [ns], then four strings
 *                           (u16 length, bytes): device, firmware, serial, sensor TOML;
 *                           'I' sends IDENT whole, 'J' in pieces of 7 bytes (stream only);
 *                       'K' u8 components, then as 'I' (IDENT of a device of K components)
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "tactsense.h"

static unsigned char *input;
static size_t input_len, input_pos;

static void fail(const char *what)
{
    fprintf(stderr, "ts_driver: %s\n", what);
    exit(1);
}

static void read_all(FILE *file)
{
    size_t cap = 1 << 16, n;
    input = malloc(cap);
    if (!input) fail("out of memory");
    while ((n = fread(input + input_len, 1, cap - input_len, file)) > 0) {
        input_len += n;
        if (input_len == cap) {
            cap *= 2;
            input = realloc(input, cap);
            if (!input) fail("out of memory");
        }
    }
}

static unsigned long long take(int bytes)
{
    unsigned long long v = 0;
    int i;
    if (input_pos + (size_t)bytes > input_len) fail("job cut short");
    for (i = 0; i < bytes; i++) v |= (unsigned long long)input[input_pos++] << (8 * i);
    return v;
}

static char *take_string(void)
{
    size_t n = (size_t)take(2);
    char *s = malloc(n + 1);
    if (!s || input_pos + n > input_len) fail("bad string");
    memcpy(s, input + input_pos, n);
    s[n] = 0;
    input_pos += n;
    return s;
}

static void write_fd(int fd, const uint8_t *data, size_t len)
{
    while (len) {
        ssize_t n = write(fd, data, len);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) exit(0); /* the host went away */
        data += n;
        len -= (size_t)n;
    }
}

static void to_stdout(void *user, const uint8_t *data, size_t len)
{
    (void)user;
    if (len == 0 || len > 256) fail("a piece of more than 256 bytes or none");
    write_fd(1, data, len);
}

/* Encode one job into a buffer of exactly the right size (malloc'd, so that an
   overrun shows under AddressSanitizer), after checking that one byte less fails. */
static size_t buffer_job(char type, uint16_t seq, uint64_t time, uint8_t rows, uint8_t cols,
                         const uint16_t *counts, uint8_t kind, const uint8_t *body, size_t len,
                         uint32_t frames)
{
    /* kind is the components of a 'G' job */
    size_t max = TS_WIRE_MAX(TS_FRAME_V2_BYTES(255, 255, TS_MAX_COMPONENTS)), n = 0, pass;
    for (pass = 0; pass < 3; pass++) {
        size_t cap = pass == 0 ? max : pass == 1 ? n - 1 : n, got = 0;
        uint8_t *out = malloc(cap ? cap : 1);
        if (!out) fail("out of memory");
        if (type == 'F') got = ts_encode_frame(out, cap, seq, time, rows, cols, counts);
        if (type == 'G') got = ts_encode_frame_v2(out, cap, seq, time, rows, cols, kind, counts);
        if (type == 'E') got = ts_encode_end(out, cap, seq, frames);
        if (type == 'P') got = ts_encode_packet(out, cap, kind, body, len);
        if (pass == 0) {
            if (got == 0) fail("encoding failed");
            if (type == 'F' && got > TS_FRAME_WIRE_MAX(rows, cols)) fail("TS_FRAME_WIRE_MAX");
            if (type == 'G' && got > TS_FRAME_V2_WIRE_MAX(rows, cols, kind))
                fail("TS_FRAME_V2_WIRE_MAX");
            n = got;
        } else if (pass == 1 && got != 0) {
            fail("a buffer one byte short was accepted");
        } else if (pass == 2) {
            if (got != n) fail("an exact buffer was refused");
            write_fd(1, out, n);
        }
        free(out);
    }
    return n;
}

static int encode(int stream)
{
    static ts_context ts;
    ts_init(&ts, 1, 1, 0, to_stdout, NULL);
    read_all(stdin);
    while (input_pos < input_len) {
        char type = (char)take(1);
        if (type == 'F') {
            uint16_t seq = (uint16_t)take(2);
            uint64_t time = (uint64_t)take(8);
            uint8_t rows = (uint8_t)take(1), cols = (uint8_t)take(1);
            size_t i, n = (size_t)rows * cols;
            uint16_t *counts = malloc(2 * n + 2);
            if (!counts) fail("out of memory");
            for (i = 0; i < n; i++) counts[i] = (uint16_t)take(2);
            if (stream) {
                ts_init(&ts, rows, cols, 1000, to_stdout, NULL);
                ts.sequence = seq;
                ts_send_frame(&ts, time, counts);
                if (ts.sequence != (uint16_t)(seq + 1u) || ts.frames != 1) fail("counters");
            } else {
                buffer_job('F', seq, time, rows, cols, counts, 0, NULL, 0, 0);
            }
            free(counts);
        } else if (type == 'G') {
            uint16_t seq = (uint16_t)take(2);
            uint64_t time = (uint64_t)take(8);
            uint8_t rows = (uint8_t)take(1), cols = (uint8_t)take(1), k = (uint8_t)take(1);
            size_t i, n = (size_t)rows * cols * k;
            uint16_t *counts = malloc(2 * n + 2);
            if (!counts) fail("out of memory");
            for (i = 0; i < n; i++) counts[i] = (uint16_t)take(2);
            if (stream) {
                ts_init(&ts, rows, cols, 1000, to_stdout, NULL);
                if (ts_set_components(&ts, k) != 0) fail("ts_set_components refused");
                ts.sequence = seq;
                ts_send_frame(&ts, time, counts);
            } else {
                buffer_job('G', seq, time, rows, cols, counts, k, NULL, 0, 0);
            }
            free(counts);
        } else if (type == 'E') {
            uint16_t last = (uint16_t)take(2);
            uint32_t frames = (uint32_t)take(4);
            if (stream) {
                ts.frames = frames;
                ts.sequence = (uint16_t)(last + 1u);
                ts_send_end(&ts);
            } else {
                buffer_job('E', last, 0, 0, 0, NULL, 0, NULL, 0, frames);
            }
        } else if (type == 'P') {
            uint8_t kind = (uint8_t)take(1);
            size_t len = (size_t)take(2);
            const uint8_t *body = input + input_pos;
            if (input_pos + len > input_len) fail("body cut short");
            input_pos += len;
            if (stream) {
                size_t half = len / 2;
                ts_begin(&ts, kind);
                ts_write(&ts, body, half);
                ts_write(&ts, body + half, len - half);
                ts_end(&ts);
            } else {
                buffer_job('P', 0, 0, 0, 0, NULL, kind, body, len, 0);
            }
        } else if (type == 'I' || type == 'J' || type == 'K') {
            uint8_t components = type == 'K' ? (uint8_t)take(1) : 1u;
            uint8_t rows = (uint8_t)take(1), cols = (uint8_t)take(1);
            uint32_t period = (uint32_t)take(4);
            char *device = take_string(), *firmware = take_string(), *serial = take_string();
            char *toml = take_string();
            if (!stream) fail("IDENT is built in stream mode only");
            ts_init(&ts, rows, cols, period, to_stdout, NULL);
            if (ts_set_components(&ts, components) != 0) fail("ts_set_components refused");
            if (type != 'J') {
                ts_send_ident(&ts, device, firmware, serial, toml);
            } else {
                size_t at = 0, n = strlen(toml);
                ts_ident_begin(&ts, device, firmware, serial);
                while (at < n) {
                    size_t piece = n - at < 7 ? n - at : 7;
                    ts_ident_text(&ts, toml + at, piece);
                    at += piece;
                }
                ts_ident_end(&ts);
            }
            free(device);
            free(firmware);
            free(serial);
            free(toml);
        } else {
            fail("unknown job");
        }
    }
    return 0;
}

static int crc(void)
{
    uint32_t whole, pieces = 0;
    size_t at = 0;
    read_all(stdin);
    whole = ts_crc32(0, input, input_len);
    while (at < input_len) {
        size_t n = input_len - at < 5 ? input_len - at : 5;
        pieces = ts_crc32(pieces, input + at, n);
        at += n;
    }
    printf("%08lx %08lx\n", (unsigned long)whole, (unsigned long)pieces);
    return 0;
}

static int receive(void)
{
    static ts_context ts;
    size_t i;
    ts_init(&ts, 1, 1, 0, to_stdout, NULL);
    read_all(stdin);
    for (i = 0; i < input_len; i++) {
        uint8_t kind = ts_receive(&ts, input[i]);
        if (kind) printf("%02x\n", kind);
    }
    return 0;
}

static int device(int argc, char **argv)
{
    static ts_context ts;
    static uint8_t buf[4096];
    FILE *file;
    uint16_t *frames;
    char *toml;
    size_t n_frames, size, i;
    uint8_t rows, cols, components = 1;
    int a;
    if (argc < 7) fail("device FRAMES TOML ROWS COLS PERIOD_NS [AT:COUNT ...] [c=K]");
    rows = (uint8_t)atoi(argv[4]);
    cols = (uint8_t)atoi(argv[5]);
    for (a = 7; a < argc; a++)
        if (strncmp(argv[a], "c=", 2) == 0) components = (uint8_t)atoi(argv[a] + 2);
    size = (size_t)rows * cols * components;
    file = fopen(argv[2], "rb");
    if (!file) fail("cannot open FRAMES");
    read_all(file);
    fclose(file);
    n_frames = input_len / (2 * size);
    frames = malloc(n_frames * size * 2 + 2);
    if (!frames) fail("out of memory");
    for (i = 0; i < n_frames * size; i++) frames[i] = (uint16_t)take(2);
    free(input);
    input = NULL;
    input_len = input_pos = 0;
    file = fopen(argv[3], "rb");
    if (!file) fail("cannot open TOML");
    read_all(file);
    fclose(file);
    toml = malloc(input_len + 1);
    if (!toml) fail("out of memory");
    memcpy(toml, input, input_len);
    toml[input_len] = 0;
    ts_init(&ts, rows, cols, (uint32_t)strtoul(argv[6], NULL, 10), to_stdout, NULL);
    if (ts_set_components(&ts, components) != 0) fail("c=K: 1 to 4 components");
    for (;;) {
        ssize_t got = read(0, buf, sizeof buf), b;
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) return 0; /* the host closed the line */
        for (b = 0; b < got; b++) {
            uint8_t kind = ts_receive(&ts, buf[b]);
            if (kind == TS_IDENTIFY) {
                ts_send_ident(&ts, "tactsense C test driver", "1", "c-0001", toml);
            } else if (kind == TS_START) {
                size_t k;
                for (k = 0; k <= n_frames; k++) {
                    for (a = 7; a < argc; a++) {
                        unsigned long at, count, c;
                        if (sscanf(argv[a], "%lu:%lu", &at, &count) == 2 && at == k)
                            for (c = 0; c < count; c++) ts_drop_frame(&ts);
                    }
                    if (k < n_frames) ts_send_frame(&ts, ts_scan_time_us(&ts), frames + k * size);
                }
                ts_send_end(&ts);
            } /* STOP: the stream has ended already; an idle device does not answer */
        }
    }
}

static uint64_t bench_sum;

static void sink(void *user, const uint8_t *data, size_t len)
{
    (void)user;
    bench_sum += data[len - 1] + len;
}

static int bench(int argc, char **argv)
{
    static ts_context ts;
    static uint8_t out[TS_WIRE_MAX(TS_FRAME_BYTES(255, 255))];
    static uint16_t counts[64][256];
    struct timespec t0, t1;
    unsigned long n, k;
    uint8_t rows, cols;
    uint32_t x = 12345;
    size_t i;
    int stream;
    double seconds;
    if (argc < 6) fail("bench buffer|stream ROWS COLS N");
    stream = strcmp(argv[2], "stream") == 0;
    rows = (uint8_t)atoi(argv[3]);
    cols = (uint8_t)atoi(argv[4]);
    n = strtoul(argv[5], NULL, 10);
    if ((size_t)rows * cols > 256) fail("bench: at most 256 tactels");
    for (k = 0; k < 64; k++)
        for (i = 0; i < 256; i++) {
            x ^= x << 13, x ^= x >> 17, x ^= x << 5; /* xorshift32 */
            counts[k][i] = (uint16_t)(1900u + x % 400u);
        }
    ts_init(&ts, rows, cols, 142857143UL, sink, NULL);
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (k = 0; k < n; k++) {
        if (stream) {
            ts_send_frame(&ts, ts_scan_time_us(&ts), counts[k & 63]);
        } else {
            size_t len = ts_encode_frame(out, sizeof out, (uint16_t)k, 142857ULL * k, rows, cols,
                                         counts[k & 63]);
            bench_sum += out[len / 2] + len;
        }
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    printf("%.1f %lu\n", (double)n / seconds, (unsigned long)bench_sum);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc >= 3 && strcmp(argv[1], "encode") == 0) return encode(strcmp(argv[2], "stream") == 0);
    if (argc >= 2 && strcmp(argv[1], "crc") == 0) return crc();
    if (argc >= 2 && strcmp(argv[1], "receive") == 0) return receive();
    if (argc >= 2 && strcmp(argv[1], "device") == 0) return device(argc, argv);
    if (argc >= 2 && strcmp(argv[1], "bench") == 0) return bench(argc, argv);
    fail("usage: ts_driver encode|crc|receive|device|bench ...");
    return 1;
}
