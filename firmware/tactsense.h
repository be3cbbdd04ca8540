/*
 * tactsense.h - the tactsense wire protocol, versions 1 and 2, for the device side.
 *
 * A portable C99 encoder of the packets a tactile array sends to tactsense
 * (docs/protocol.md): FRAME, IDENT and END, each CRC-32/ISO-HDLC checked,
 * COBS-framed and followed by one 0x00 delimiter; and a decoder of the host's
 * commands IDENTIFY, START and STOP. No dynamic memory, no floating point, no
 * library calls beyond <stddef.h> and <stdint.h>; written for 8-, 16- and 32-bit
 * targets (int may be 16 bits wide). The CRC uses a table of 16 words (64 bytes);
 * compile with -DTS_CRC_BYTE_TABLE for one of 256 words (1 KB), about twice as fast.
 *
 * Two ways to use it:
 *
 * 1. One packet into a buffer of your own (ts_encode_frame, ts_encode_end,
 *    ts_encode_packet): returns the bytes written, delimiter included, or 0 if
 *    the buffer is too small (TS_FRAME_WIRE_MAX gives a size that always fits).
 *
 * 2. A device context (ts_init) that hands the bytes of each packet to a write
 *    callback as they are encoded, in pieces of at most 256 bytes, so that a
 *    frame of any size needs no buffer of its own (ts_send_frame, ts_drop_frame,
 *    ts_send_ident, ts_send_end), keeps the sequence counter and the count of
 *    frames for END, and recognises the host's commands (ts_receive).
 *
 * A device (docs/protocol.md, "Behaviour"):
 *
 *     for every byte b from the host:
 *         switch (ts_receive(&ts, b)) {
 *         case TS_IDENTIFY: ts_send_ident(&ts, "my array", "1.0", "0001", SENSOR_TOML); break;
 *         case TS_START:    streaming = 1; break;
 *         case TS_STOP:     if (streaming) ts_send_end(&ts); streaming = 0; break;
 *         }
 *     every scan period, while streaming:
 *         t = ts_scan_time_us(&ts);     (or your own clock, in microseconds)
 *         scan the array into counts[rows * cols], row-major;
 *         ts_send_frame(&ts, t, counts);  (or ts_drop_frame(&ts) for a scan not sent)
 *
 * See firmware/examples/scan_array/scan_array.ino for a whole sketch.
 *
 * Taxels of several components (a three-axis taxel's x, y, z; docs/protocol.md,
 * "Version 2"): ts_set_components(&ts, 3) after ts_init, and counts then holds
 * rows * cols * 3 readings, row-major by taxel with the component fastest
 * (counts[(row * cols + col) * 3 + k], k = 0, 1, 2 for x, y, z); ts_send_frame sends
 * version-2 FRAMEs and IDENT says "protocol": 2 and "components": 3. Into a buffer:
 * ts_encode_frame_v2. A device of one component keeps sending version 1.
 */
#ifndef TACTSENSE_H
#define TACTSENSE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define TS_PROTOCOL_VERSION 1 /* the host's commands, and FRAMEs of one component */
#define TS_PROTOCOL_VERSION_2 2 /* FRAMEs with a components byte */
#define TS_MAX_COMPONENTS 4    /* most components a taxel reports in a version-2 FRAME */

/* Packet kinds: device to host below 0x80, host to device from 0x80. */
#define TS_FRAME 0x01    /* one scan of the array */
#define TS_IDENT 0x02    /* who the device is: a UTF-8 JSON object */
#define TS_END 0x03      /* the device stopped: last sequence number, frames */
#define TS_IDENTIFY 0x81 /* host: send IDENT */
#define TS_START 0x82    /* host: start streaming frames */
#define TS_STOP 0x83     /* host: stop; the device answers END */

/* Bytes of a FRAME packet before COBS: header 14, counts, CRC 4. */
#define TS_FRAME_BYTES(rows, cols) (18UL + 2UL * (unsigned long)(rows) * (unsigned long)(cols))
/* Most bytes a packet of n bytes takes on the wire: COBS adds one byte per
   started 254 (at least one), then the delimiter. */
#define TS_WIRE_MAX(n) ((n) + (n) / 254UL + 2UL)
#define TS_FRAME_WIRE_MAX(rows, cols) TS_WIRE_MAX(TS_FRAME_BYTES(rows, cols))
/* Bytes of a version-2 FRAME before COBS: header 15, counts, CRC 4. */
#define TS_FRAME_V2_BYTES(rows, cols, components)                                         \
    (19UL + 2UL * (unsigned long)(rows) * (unsigned long)(cols) * (unsigned long)(components))
#define TS_FRAME_V2_WIRE_MAX(rows, cols, components)                                      \
    TS_WIRE_MAX(TS_FRAME_V2_BYTES(rows, cols, components))

/* Receives the encoded bytes (pieces of one packet, in order). */
typedef void (*ts_write_fn)(void *user, const uint8_t *data, size_t len);

/* The state of one packet being encoded (internal; use the functions below). */
typedef struct {
    uint8_t *buf;      /* where the current COBS block is assembled */
    size_t cap;        /* room in buf [bytes] */
    size_t len;        /* bytes in buf */
    size_t code;       /* index in buf of the current block's code byte */
    size_t total;      /* bytes handed to write so far */
    uint32_t crc;      /* running CRC-32 of the packet */
    ts_write_fn write; /* NULL: buf is the caller's output buffer */
    void *user;
    uint8_t overflow;  /* the output did not fit */
} ts_encoder;

/* ---- one packet into a caller's buffer ------------------------------------ */

/* CRC-32/ISO-HDLC (zlib's crc32) of len bytes; crc = 0 to start, or the value of
   the previous piece to continue. ts_crc32(0, "123456789", 9) == 0xCBF43926. */
uint32_t ts_crc32(uint32_t crc, const uint8_t *data, size_t len);

/* A FRAME: counts has rows * cols A/D readings, row-major (row 0 = the row under
   the fingertip), sequence wraps from 65535 to 0, device_time_us is the start of
   the scan on the device clock [us]. Returns bytes written to out, delimiter
   included; 0 if rows or cols is 0 or cap is too small. */
size_t ts_encode_frame(uint8_t *out, size_t cap, uint16_t sequence, uint64_t device_time_us,
                       uint8_t rows, uint8_t cols, const uint16_t *counts);

/* A version-2 FRAME: components (1..TS_MAX_COMPONENTS) readings per taxel, counts
   has rows * cols * components of them, row-major by taxel, the component fastest
   (counts[(row * cols + col) * components + k]). Returns as ts_encode_frame; 0 also
   if components is 0 or above TS_MAX_COMPONENTS. */
size_t ts_encode_frame_v2(uint8_t *out, size_t cap, uint16_t sequence, uint64_t device_time_us,
                          uint8_t rows, uint8_t cols, uint8_t components,
                          const uint16_t *counts);

/* An END: the last sequence number used and the frames generated (mod 2^32). */
size_t ts_encode_end(uint8_t *out, size_t cap, uint16_t last_sequence, uint32_t frames);

/* Any packet: version, kind, body_len bytes of body, CRC (e.g. an IDENT whose
   JSON you keep ready-made, or a host command in a test). */
size_t ts_encode_packet(uint8_t *out, size_t cap, uint8_t kind, const uint8_t *body,
                        size_t body_len);

/* ---- a device: packets streamed to a write callback ------------------------ */

#define TS_RX_MAX 32 /* longest host packet kept by ts_receive [bytes] */

typedef struct {
    uint8_t rows, cols;      /* shape of the array */
    uint8_t components;      /* readings per taxel: 1 (version-1 FRAMEs) .. 4 */
    uint32_t scan_period_ns; /* one scan period [ns] (7 Hz: 142857143) */
    uint16_t sequence;       /* sequence number of the next scan */
    uint32_t frames;         /* scans since ts_init, sent and dropped (mod 2^32) */
    uint64_t scans;          /* the same, unwrapped: the index of the next scan */
    uint64_t clock_us;       /* ts_clock_us: the extended clock [us] */
    uint32_t clock_last;     /* ts_clock_us: the last 32-bit reading */
    ts_encoder enc;
    uint8_t block[256];      /* one COBS block and the delimiter */
    uint8_t rx[TS_RX_MAX];
    uint8_t rx_len, rx_skip;
} ts_context;

/* Set up a device: rows x cols tactels (1..255 each) scanned every scan_period_ns
   nanoseconds; write(user, bytes, n) sends bytes to the host (e.g. Serial.write).
   The scan period must be the sensor description's 1 / scan_rate_hz: the host
   uses it to count frames lost in gaps longer than 65,535 frames. */
void ts_init(ts_context *ts, uint8_t rows, uint8_t cols, uint32_t scan_period_ns,
             ts_write_fn write, void *user);

/* Readings per taxel, 1..TS_MAX_COMPONENTS (ts_init sets 1): from 2 on, ts_send_frame
   sends version-2 FRAMEs of rows * cols * components counts and IDENT says
   "protocol": 2, "components": n. Returns 0, or -1 (unchanged) if out of range. */
int ts_set_components(ts_context *ts, uint8_t components);

/* Nominal start of the next scan on a clock that advances one scan period per
   scan from 0 at ts_init: round(scans * scan_period_ns / 1000) [us]. */
uint64_t ts_scan_time_us(const ts_context *ts);

/* A 64-bit microsecond clock from a 32-bit one that wraps (Arduino's micros()
   wraps every 71.6 minutes); call it at least once per wrap. */
uint64_t ts_clock_us(ts_context *ts, uint32_t now_us);

/* Send one FRAME with the next sequence number; counts as ts_encode_frame (as
   ts_encode_frame_v2 after ts_set_components with 2 or more).
   device_time_us must increase from frame to frame. */
void ts_send_frame(ts_context *ts, uint64_t device_time_us, const uint16_t *counts);

/* A scan that is not sent (no time, buffer full): it consumes its sequence number,
   so the host counts it as lost. */
void ts_drop_frame(ts_context *ts);

/* Send END: the last sequence number used and the frames generated since
   ts_init (sent and dropped). Send it on STOP while streaming, or when the
   device has nothing more to send. */
void ts_send_end(ts_context *ts);

/* Send IDENT, the JSON object {"device", "firmware", "serial", "protocol": 1,
   "rows", "cols", "frame_rate_hz", "sensor_toml"} ("protocol": 2 and "components"
   after "cols" for taxels of several components); the strings are UTF-8 and
   escaped here. sensor_toml is the sensor description (tactsense sensor show). */
void ts_send_ident(ts_context *ts, const char *device, const char *firmware, const char *serial,
                   const char *sensor_toml);

/* The same in pieces, for a sensor description held elsewhere (e.g. AVR flash):
   ts_ident_begin, then ts_ident_text as often as needed, then ts_ident_end. */
void ts_ident_begin(ts_context *ts, const char *device, const char *firmware, const char *serial);
void ts_ident_text(ts_context *ts, const char *text, size_t len);
void ts_ident_end(ts_context *ts);

/* Any packet in pieces: ts_begin(kind), ts_write(body bytes) any number of
   times, ts_end() (adds the CRC and the delimiter). */
void ts_begin(ts_context *ts, uint8_t kind);
void ts_write(ts_context *ts, const uint8_t *data, size_t len);
void ts_end(ts_context *ts);

/* Feed one byte from the host. Returns TS_IDENTIFY, TS_START or TS_STOP when it
   completes a valid command packet (of version 1 or 2); 0 otherwise (damaged packets, noise and
   packets of other kinds are ignored). */
uint8_t ts_receive(ts_context *ts, uint8_t byte);

#ifdef __cplusplus
}
#endif

#endif /* TACTSENSE_H */
